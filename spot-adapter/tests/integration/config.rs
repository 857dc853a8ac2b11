//! Invalid settings are errors, not panics.

#![allow(clippy::unwrap_used)]

use nalgebra::Vector2;
use spot_adapter::AdapterError;
use spot_adapter::nav::{LocaliserConfig, NavigatorConfig, StuckConfig};
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, OdometryDriftConfig, OdometryModel, Route,
    RouteConfig, SimulatedSpot, SimulationConfig, Vlp16, Vlp16Config,
};

/// Whether `r` is the invalid-setting error naming `setting`, with the value given.
#[allow(clippy::needless_pass_by_value)] // Takes the results straight from the calls.
fn invalid<T: std::fmt::Debug>(r: Result<T, AdapterError>, setting: &str) -> bool {
    match r {
        Err(AdapterError::InvalidConfig { setting: s, .. }) if s == setting => true,
        other => {
            eprintln!("expected an invalid {setting}, got {other:?}");
            false
        }
    }
}

#[test]
fn bad_settings_are_rejected() {
    let mut c = BuildingConfig::default();
    c.corridor_width = (2.0, 1.0);
    assert!(invalid(Building::generate(0, &c), "corridor_width.1"));
    let mut c = BuildingConfig::default();
    c.door_height = 5.0;
    assert!(invalid(Building::generate(0, &c), "door_height"));
    let mut c = BuildingConfig::default();
    c.wall_thickness = f64::NAN;
    assert!(invalid(Building::generate(0, &c), "wall_thickness"));

    let mut l = Vlp16Config::default();
    l.rings = 0;
    assert!(invalid(Vlp16::new(l), "rings"));
    let mut l = Vlp16Config::default();
    l.dropout_probability = 1.5;
    assert!(invalid(Vlp16::new(l), "dropout_probability"));
    let mut l = Vlp16Config::default();
    l.max_range = 0.1;
    assert!(invalid(Vlp16::new(l), "max_range"));

    let mut o = OdometryDriftConfig::default();
    o.drift_rate = -0.01;
    assert!(invalid(OdometryModel::new(o, 0), "drift_rate"));
    let mut o = OdometryDriftConfig::default();
    o.vertical_fraction = 2.0;
    assert!(invalid(OdometryModel::new(o, 0), "vertical_fraction"));

    assert!(invalid(Route::new(vec![Vector2::zeros()], false), "points"));
    assert!(invalid(
        Route::new(vec![Vector2::zeros(); 3], false),
        "route length"
    ));
    let b = Building::generate(0, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&b);
    assert!(invalid(lap.walk(0.0, 5.0, 0.5), "speed"));
    assert!(invalid(lap.walk(0.6, f64::INFINITY, 0.5), "rate"));
    let mut s = SimulationConfig::default();
    s.speed = -1.0;
    assert!(invalid(SimulatedSpot::new(b.clone(), &lap, &s), "speed"));
    let mut r = RouteConfig::default();
    r.clearance = -1.0;
    let p = b.rooms()[0].entry_point();
    assert!(invalid(Route::between(&b, p, p, &r), "clearance"));
    let mut r = RouteConfig::default();
    r.resolution = 0.0;
    assert!(matches!(
        Route::between(&b, p, p, &r),
        Err(AdapterError::Grid(_))
    ));

    let mut s = SimulationConfig::default();
    s.limits.max_yaw_rate = 0.0;
    let start = b.corridor_loop()[0];
    assert!(invalid(
        CommandedSpot::new(b.clone(), start, 0.0, &s),
        "max_yaw_rate"
    ));
    assert!(invalid(
        CommandedSpot::new(b.clone(), start, f64::NAN, &SimulationConfig::default()),
        "yaw"
    ));
    let n = NavigatorConfig {
        goal_tolerance: -0.1,
        ..NavigatorConfig::default()
    };
    assert!(invalid(n.validate(), "goal_tolerance"));
    let n = NavigatorConfig {
        localiser: LocaliserConfig {
            max_correction: f64::NAN,
            ..LocaliserConfig::default()
        },
        ..NavigatorConfig::default()
    };
    assert!(invalid(n.validate(), "max_correction"));
    let n = NavigatorConfig {
        localiser: LocaliserConfig {
            search_step: 0.001,
            ..LocaliserConfig::default()
        },
        ..NavigatorConfig::default()
    };
    assert!(invalid(n.validate(), "search_step"));
    let n = NavigatorConfig {
        stuck: StuckConfig {
            window: 0,
            ..StuckConfig::default()
        },
        ..NavigatorConfig::default()
    };
    assert!(invalid(n.validate(), "stuck.window"));
}

/// The walking scan's voxel is off (0) or a usable size; a tiny one would make every scan's
/// thinning fail, and the full scan be used without a word.
#[test]
fn bad_walking_scan_settings_are_rejected() {
    for (voxel, within) in [
        (f64::NAN, 1.5),
        (-0.35, 1.5),
        (1e-30, 1.5),
        (0.35, f64::INFINITY),
    ] {
        let n = NavigatorConfig {
            localiser: LocaliserConfig {
                walking_scan_voxel: voxel,
                full_scan_within: within,
                ..LocaliserConfig::default()
            },
            ..NavigatorConfig::default()
        };
        let setting = if within.is_finite() {
            "walking_scan_voxel"
        } else {
            "full_scan_within"
        };
        assert!(invalid(n.validate(), setting), "{voxel} {within}");
    }
}

#[test]
fn the_error_message_names_the_setting_and_its_value() {
    let mut l = Vlp16Config::default();
    l.range_noise = -0.5;
    let message = Vlp16::new(l).unwrap_err().to_string();
    assert!(
        message.contains("range_noise") && message.contains("-0.5"),
        "{message}"
    );
}

/// A bad tracker setting handed to `point_to_plane_slam_with` is refused up front, named, and
/// not left for every scan to fail on.
#[test]
fn a_bad_tracker_setting_is_refused_when_the_engine_is_built() {
    use spot_adapter::pipelines::{point_to_plane_slam_with, point_to_plane_tracker, slam_config};
    for (setting, value) in [
        ("IcpConfig::min_planarity", 1.5),
        ("IcpConfig::min_planarity", f64::NAN),
        ("IcpConfig::max_correspondence_distance", -1.0),
    ] {
        let mut tracker = point_to_plane_tracker();
        if setting == "IcpConfig::min_planarity" {
            tracker.config.min_planarity = value;
        } else {
            tracker.config.max_correspondence_distance = value;
        }
        match point_to_plane_slam_with(slam_config(), tracker) {
            Err(e) => {
                assert_eq!(e.setting, setting);
                assert!(e.value.to_bits() == value.to_bits(), "{e:?}");
            }
            Ok(_) => panic!("{setting} = {value} accepted"),
        }
    }
    assert!(point_to_plane_slam_with(slam_config(), point_to_plane_tracker()).is_ok());
}
