//! Invalid settings are errors, not panics.

#![allow(clippy::unwrap_used)]

use nalgebra::Vector2;
use spot_adapter::{
    AdapterError, Building, BuildingConfig, OdometryDriftConfig, OdometryModel, Route, RouteConfig,
    SimulatedSpot, SimulationConfig, Vlp16, Vlp16Config,
};

#[allow(clippy::needless_pass_by_value)] // Takes the results straight from the calls.
fn invalid<T: std::fmt::Debug>(r: Result<T, AdapterError>) -> bool {
    matches!(r, Err(AdapterError::InvalidConfig(_)))
}

#[test]
fn bad_settings_are_rejected() {
    let mut c = BuildingConfig::default();
    c.corridor_width = (2.0, 1.0);
    assert!(invalid(Building::generate(0, &c)));
    let mut c = BuildingConfig::default();
    c.door_height = 5.0;
    assert!(invalid(Building::generate(0, &c)));
    let mut c = BuildingConfig::default();
    c.wall_thickness = f64::NAN;
    assert!(invalid(Building::generate(0, &c)));

    let mut l = Vlp16Config::default();
    l.rings = 0;
    assert!(invalid(Vlp16::new(l)));
    let mut l = Vlp16Config::default();
    l.dropout_probability = 1.5;
    assert!(invalid(Vlp16::new(l)));
    let mut l = Vlp16Config::default();
    l.max_range = 0.1;
    assert!(invalid(Vlp16::new(l)));

    let mut o = OdometryDriftConfig::default();
    o.drift_rate = -0.01;
    assert!(invalid(OdometryModel::new(o, 0)));
    let mut o = OdometryDriftConfig::default();
    o.vertical_fraction = 2.0;
    assert!(invalid(OdometryModel::new(o, 0)));

    assert!(invalid(Route::new(vec![Vector2::zeros()], false)));
    assert!(invalid(Route::new(vec![Vector2::zeros(); 3], false)));
    let b = Building::generate(0, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&b);
    assert!(invalid(lap.walk(0.0, 5.0, 0.5)));
    assert!(invalid(lap.walk(0.6, f64::INFINITY, 0.5)));
    let mut s = SimulationConfig::default();
    s.speed = -1.0;
    assert!(invalid(SimulatedSpot::new(b.clone(), &lap, &s)));
    let mut r = RouteConfig::default();
    r.clearance = -1.0;
    let p = b.rooms()[0].entry_point();
    assert!(invalid(Route::between(&b, p, p, &r)));
    let mut r = RouteConfig::default();
    r.resolution = 0.0;
    assert!(matches!(
        Route::between(&b, p, p, &r),
        Err(AdapterError::Grid(_))
    ));
}
