//! Invalid settings are errors, not panics.

#![allow(clippy::unwrap_used)]

use nalgebra::Vector2;
use spot_adapter::AdapterError;
use spot_adapter::nav::{LocaliserConfig, NavigatorConfig, StuckConfig};
use spot_adapter::sim::SimError;
use spot_adapter::sim::{
    Building, BuildingConfig, CommandedSpot, FastTurnsConfig, HandShake, HandheldConfig,
    LidarConfig, MotionProfile, OdometryDriftConfig, OdometryModel, Route, RouteConfig,
    SimulatedSpot, SimulationConfig, SpinningLidar,
};

/// Whether `r` is the invalid-setting error naming `setting`, with the value given.
#[allow(clippy::needless_pass_by_value)] // Takes the results straight from the calls.
fn invalid<T: std::fmt::Debug, E: Into<AdapterError>>(r: Result<T, E>, setting: &str) -> bool {
    let r = r.map_err(Into::into);
    match r.as_ref().map_err(AdapterError::invalid_setting) {
        Err(Some(s)) if s.setting == setting => true,
        _ => {
            eprintln!("expected an invalid {setting}, got {r:?}");
            false
        }
    }
}

#[test]
fn bad_building_lidar_and_odometry_settings_are_rejected() {
    let c = BuildingConfig {
        corridor_width: (2.0, 1.0),
        ..BuildingConfig::default()
    };
    assert!(invalid(Building::generate(0, &c), "corridor_width.1"));
    let c = BuildingConfig {
        door_height: 5.0,
        ..BuildingConfig::default()
    };
    assert!(invalid(Building::generate(0, &c), "door_height"));
    let c = BuildingConfig {
        wall_thickness: f64::NAN,
        ..BuildingConfig::default()
    };
    assert!(invalid(Building::generate(0, &c), "wall_thickness"));

    let l = LidarConfig {
        rings: 0,
        ..LidarConfig::default()
    };
    assert!(invalid(SpinningLidar::new(l), "rings"));
    let l = LidarConfig {
        dropout_probability: 1.5,
        ..LidarConfig::default()
    };
    assert!(invalid(SpinningLidar::new(l), "dropout_probability"));
    let l = LidarConfig {
        max_range: 0.1,
        ..LidarConfig::default()
    };
    assert!(invalid(SpinningLidar::new(l), "max_range"));

    let o = OdometryDriftConfig {
        drift_rate: -0.01,
        ..OdometryDriftConfig::default()
    };
    assert!(invalid(OdometryModel::new(o, 0), "drift_rate"));
    let o = OdometryDriftConfig {
        vertical_fraction: 2.0,
        ..OdometryDriftConfig::default()
    };
    assert!(invalid(OdometryModel::new(o, 0), "vertical_fraction"));
}

#[test]
fn bad_route_simulation_and_navigator_settings_are_rejected() {
    assert!(invalid(Route::new(vec![Vector2::zeros()], false), "points"));
    assert!(invalid(
        Route::new(vec![Vector2::zeros(); 3], false),
        "route length"
    ));
    let b = Building::generate(0, &BuildingConfig::default()).unwrap();
    let lap = Route::corridor_loop(&b);
    assert!(invalid(lap.walk(0.0, 5.0, 0.5), "speed"));
    assert!(invalid(lap.walk(0.6, f64::INFINITY, 0.5), "rate"));
    let s = SimulationConfig {
        speed: -1.0,
        ..SimulationConfig::default()
    };
    assert!(invalid(SimulatedSpot::new(b.clone(), &lap, &s), "speed"));
    let r = RouteConfig {
        clearance: -1.0,
        ..RouteConfig::default()
    };
    let p = b.rooms()[0].entry_point();
    assert!(invalid(Route::between(&b, p, p, &r), "clearance"));
    let r = RouteConfig {
        resolution: 0.0,
        ..RouteConfig::default()
    };
    assert!(matches!(
        Route::between(&b, p, p, &r),
        Err(SimError::Grid(_))
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

/// Not-a-number, negative and (where it means nothing) zero.
const NAN_NEGATIVE_ZERO: [f64; 3] = [f64::NAN, -1.0, 0.0];
const NAN_NEGATIVE: [f64; 2] = [f64::NAN, -1.0];

/// Every `bad` value of `setting`, set by `set`, makes `build` fail naming the setting.
fn refuses<T: std::fmt::Debug, C: Default>(
    setting: &str,
    bad: &[f64],
    set: impl Fn(&mut C, f64),
    build: impl Fn(&C) -> Result<T, SimError>,
) {
    for &value in bad {
        let mut config = C::default();
        set(&mut config, value);
        assert!(invalid(build(&config), setting), "{setting} = {value}");
    }
}

#[test]
fn bad_sensor_settings_are_rejected() {
    let lidar: [(&str, &[f64], Setter<LidarConfig>); 12] = [
        ("rings", &[0.0], |c, _| c.rings = 0),
        ("columns", &[0.0], |c, _| c.columns = 0),
        ("lowest_elevation", &[f64::NAN, -2.0], |c, v| {
            c.lowest_elevation = v;
        }),
        ("ring_spacing", &NAN_NEGATIVE_ZERO, |c, v| {
            c.ring_spacing = v;
        }),
        // The top ring past the zenith.
        ("ring_spacing", &[0.5], |c, v| c.ring_spacing = v),
        ("min_range", &NAN_NEGATIVE, |c, v| c.min_range = v),
        ("max_range", &NAN_NEGATIVE_ZERO, |c, v| c.max_range = v),
        ("max_range", &[f64::INFINITY], |c, v| c.max_range = v),
        ("range_noise", &NAN_NEGATIVE, |c, v| c.range_noise = v),
        ("dropout_probability", &[f64::NAN, -0.1, 1.5], |c, v| {
            c.dropout_probability = v;
        }),
        ("rotation_rate", &NAN_NEGATIVE_ZERO, |c, v| {
            c.rotation_rate = v;
        }),
        ("rotation_rate", &[f64::INFINITY], |c, v| {
            c.rotation_rate = v;
        }),
    ];
    for (setting, bad, set) in lidar {
        refuses(setting, bad, set, |c: &LidarConfig| {
            SpinningLidar::new(c.clone())
        });
    }
    // The presets and a single ring (spacing unused) are valid.
    assert!(SpinningLidar::new(LidarConfig::os1_128()).is_ok());
    let mut one_ring = LidarConfig::vlp16();
    (one_ring.rings, one_ring.ring_spacing) = (1, 0.0);
    assert!(SpinningLidar::new(one_ring).is_ok());
}

/// A simulation of `config` on a short route (no scan is cast).
fn simulate(config: &SimulationConfig) -> Result<SimulatedSpot, SimError> {
    let b = Building::generate(0, &BuildingConfig::default()).unwrap();
    let c = b.corridor_loop();
    let route = Route::new(vec![c[0], c[1], c[2]], false).unwrap();
    SimulatedSpot::new(b, &route, config)
}

/// Sets one setting of a `C` to a value.
type Setter<C> = fn(&mut C, f64);

/// Sets a simulation to fast turns with a setting changed by `set`.
fn turns(set: impl Fn(&mut FastTurnsConfig, f64)) -> impl Fn(&mut SimulationConfig, f64) {
    move |c, v| {
        let mut t = FastTurnsConfig::default();
        set(&mut t, v);
        c.motion = MotionProfile::FastTurns(t);
    }
}

/// Sets a simulation to a handheld walk with a setting changed by `set`.
fn hand(set: impl Fn(&mut HandheldConfig, f64)) -> impl Fn(&mut SimulationConfig, f64) {
    move |c, v| {
        let mut h = HandheldConfig::default();
        set(&mut h, v);
        c.motion = MotionProfile::Handheld(h);
    }
}

#[test]
fn bad_motion_settings_are_rejected() {
    // Zero is a gyro that does not drift.
    refuses(
        "gyro_drift",
        &NAN_NEGATIVE,
        |c: &mut SimulationConfig, v| c.gyro_drift = Some(v),
        simulate,
    );
    refuses(
        "fast_turns.acceleration",
        &NAN_NEGATIVE_ZERO,
        turns(|t: &mut FastTurnsConfig, v| t.acceleration = v),
        simulate,
    );
    refuses(
        "fast_turns.yaw_acceleration",
        &NAN_NEGATIVE_ZERO,
        turns(|t: &mut FastTurnsConfig, v| t.yaw_acceleration = v),
        simulate,
    );
    // The walking speed and the yaw rate limit are Spot's own settings.
    let fast = |c: &mut SimulationConfig| c.motion = MotionProfile::fast_turns();
    refuses(
        "speed",
        &NAN_NEGATIVE_ZERO,
        |c: &mut SimulationConfig, v| {
            fast(c);
            c.speed = v;
        },
        simulate,
    );
    refuses(
        "max_yaw_rate",
        &NAN_NEGATIVE_ZERO,
        |c: &mut SimulationConfig, v| {
            fast(c);
            c.limits.max_yaw_rate = v;
        },
        simulate,
    );

    // Faster through a corner than along the legs; more samples than sweeps (5 Hz VLP-16).
    let faster = [f64::NAN, -1.0, 1.5];
    let handheld: [(&str, &[f64], Setter<HandheldConfig>); 14] = [
        ("handheld.speed", &NAN_NEGATIVE_ZERO, |h, v| h.speed = v),
        ("handheld.acceleration", &NAN_NEGATIVE_ZERO, |h, v| {
            h.acceleration = v;
        }),
        ("handheld.turn_rate", &NAN_NEGATIVE_ZERO, |h, v| {
            h.turn_rate = v;
        }),
        ("handheld.turn_acceleration", &NAN_NEGATIVE_ZERO, |h, v| {
            h.turn_acceleration = v;
        }),
        ("handheld.height", &NAN_NEGATIVE_ZERO, |h, v| h.height = v),
        ("handheld.sample_rate", &NAN_NEGATIVE_ZERO, |h, v| {
            h.sample_rate = v;
        }),
        ("handheld.sample_rate", &[6.0], |h, v| h.sample_rate = v),
        ("handheld.corner_speed", &faster, |h, v| h.corner_speed = v),
        ("hand_shake.height", &NAN_NEGATIVE, |h, v| {
            h.shake.height = v;
        }),
        ("hand_shake.roll", &NAN_NEGATIVE, |h, v| h.shake.roll = v),
        ("hand_shake.pitch", &NAN_NEGATIVE, |h, v| h.shake.pitch = v),
        ("hand_shake.yaw", &NAN_NEGATIVE, |h, v| h.shake.yaw = v),
        ("hand_shake.step_frequency", &NAN_NEGATIVE_ZERO, |h, v| {
            h.shake.step_frequency = v;
        }),
        ("hand_shake.step_frequency", &[f64::INFINITY], |h, v| {
            h.shake.step_frequency = v;
        }),
    ];
    for (setting, bad, set) in handheld {
        refuses(setting, bad, hand(set), simulate);
    }
    // Zero means something for these: stop to turn on the spot, a steady hand.
    let mut still = HandheldConfig::default();
    (still.corner_speed, still.shake) = (0.0, HandShake::none());
    let c = SimulationConfig {
        motion: MotionProfile::Handheld(still),
        ..SimulationConfig::default()
    };
    assert!(simulate(&c).is_ok());
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
    let l = LidarConfig {
        range_noise: -0.5,
        ..LidarConfig::default()
    };
    let message = SpinningLidar::new(l).unwrap_err().to_string();
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
