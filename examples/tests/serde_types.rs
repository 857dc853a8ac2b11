//! The library's `serde` feature (on here through spot-adapter's): settings read from partial
//! TOML with their defaults for the rest, enums in their tagged form, a misspelt field refused by
//! name, and results (`Alignment`, `PoseGraph`) written and read back.
#![allow(clippy::expect_used, clippy::unwrap_used, clippy::panic)]

use spot_adapter::gridmap::UnknownCells;
use spot_adapter::posegraph::{GncConfig, KnownInliers, SolverConfig};
use spot_adapter::prelude::{
    Alignment, GraphSlamConfig, IcpConfig, IcpKernel, NavigatorConfig, PlannerKind, Pose3,
    PoseGraph,
};
use spot_adapter::slam_core::{EdgeInformation, GraphPose, RobustKernel};

#[test]
fn configs_read_from_partial_toml_keep_the_defaults_of_what_is_left_out() {
    let icp: IcpConfig =
        toml::from_str("max_iterations = 7\nkernel = { kind = \"Tukey\", k = 0.05 }\n").unwrap();
    assert_eq!(
        icp,
        IcpConfig {
            max_iterations: 7,
            kernel: IcpKernel::Tukey { k: 0.05 },
            ..IcpConfig::default()
        }
    );
    let nav: NavigatorConfig = toml::from_str(
        "speed = 0.4\nplanner = \"AStar\"\n[planning]\nunknown = \"Free\"\n[stuck]\nmax_attempts = 5\n",
    )
    .unwrap();
    let mut want = NavigatorConfig {
        speed: 0.4,
        planner: PlannerKind::AStar,
        ..NavigatorConfig::default()
    };
    want.planning.unknown = UnknownCells::Free;
    want.stuck.max_attempts = 5;
    assert_eq!(nav, want);
    let gnc: GncConfig = toml::from_str(
        "known_inliers = { kind = \"Flags\", flags = [true, false] }\n[solver]\nmax_iterations = 3\n",
    )
    .unwrap();
    assert_eq!(gnc.known_inliers, KnownInliers::Flags(vec![true, false]));
    assert_eq!(
        gnc.solver,
        SolverConfig {
            max_iterations: 3,
            ..SolverConfig::default()
        }
    );
}

#[test]
fn every_default_config_round_trips_through_toml() {
    fn round_trip<T>(value: &T)
    where
        T: serde::Serialize + serde::de::DeserializeOwned + PartialEq + std::fmt::Debug,
    {
        let text = toml::to_string(value).unwrap();
        assert_eq!(&toml::from_str::<T>(&text).unwrap(), value, "{text}");
    }
    round_trip(&IcpConfig::default());
    round_trip(&NavigatorConfig::default());
    round_trip(&GraphSlamConfig::default());
    round_trip(&GncConfig::default());
    round_trip(&spot_adapter::registration::LoamConfig::default());
    round_trip(&spot_adapter::posegraph::IncrementalConfig::default());
    // No loop kernel: written as `kind = "None"`, not left out (which reads as the default).
    let without = GraphSlamConfig {
        loop_kernel: None,
        odometry_information: EdgeInformation::FromRegistration { scale: 0.5 },
        ..GraphSlamConfig::default()
    };
    round_trip(&without);
    let text = toml::to_string(&without).unwrap();
    assert!(text.contains("kind = \"None\""), "{text}");
    let cauchy: GraphSlamConfig =
        toml::from_str("loop_kernel = { kind = \"Huber\", delta = 2.0 }\n").unwrap();
    assert_eq!(cauchy.loop_kernel, Some(RobustKernel::Huber { delta: 2.0 }));
}

#[test]
fn a_misspelt_field_is_refused_by_name() {
    let e = toml::from_str::<IcpConfig>("max_iteration = 7\n").unwrap_err();
    assert!(e.to_string().contains("max_iteration"), "{e}");
    let e = toml::from_str::<NavigatorConfig>("[stuck]\nmax_attempt = 5\n").unwrap_err();
    assert!(e.to_string().contains("max_attempt"), "{e}");
    let e = toml::from_str::<IcpConfig>("kernel = { kind = \"Tukey\", c = 1.0 }\n").unwrap_err();
    assert!(e.to_string().contains('c'), "{e}");
}

#[test]
fn results_write_and_read_back() {
    let a = Alignment {
        pose: Pose3::translation(1.0, 2.0, 3.0),
        converged: true,
        iterations: 4,
        inliers: 100,
        inlier_ratio: 0.5,
        rmse: 0.01,
        information: nalgebra::Matrix6::identity(),
        min_eigenvalue_ratio: 0.2,
    };
    let back: Alignment = serde_json::from_str(&serde_json::to_string(&a).unwrap()).unwrap();
    assert_eq!(back, a);

    let mut g = PoseGraph::<Pose3>::new();
    g.add_node(10, Pose3::identity()).unwrap();
    g.add_node(11, Pose3::translation(1.0, 0.0, 0.0)).unwrap();
    g.fix(10).unwrap();
    g.add_edge(
        10,
        11,
        Pose3::translation(1.0, 0.0, 0.0),
        Pose3::identity_information(),
        Some(RobustKernel::Cauchy { c: 1.0 }),
    )
    .unwrap();
    let json = serde_json::to_string(&g).unwrap();
    let back: PoseGraph<Pose3> = serde_json::from_str(&json).unwrap();
    assert_eq!(back.nodes(), g.nodes());
    assert_eq!(back.edges(), g.edges());
    assert_eq!(back.node_index(11), Some(1));
    // A graph read back passes the checks of one built: an edge to a node that is not there
    // is refused.
    let broken = json.replace("\"to\":1", "\"to\":7");
    assert!(broken != json);
    let e = serde_json::from_str::<PoseGraph<Pose3>>(&broken).unwrap_err();
    assert!(e.to_string().contains("node index 7"), "{e}");
}

/// The simulator's settings: read from partial TOML (the motion profile by its `kind`, the
/// rest at the defaults), round-tripped with every motion profile and sensor, a misspelt field
/// refused by name.
#[test]
fn simulation_settings_read_from_partial_toml_and_round_trip() {
    use spot_adapter::sim::{HandheldConfig, LidarConfig, MotionProfile, SimulationConfig};
    let read: SimulationConfig = toml::from_str(
        "seed = 3\nmotion_distortion = true\nmotion = { kind = \"Handheld\", speed = 1.2 }\n\
         [lidar]\nrings = 128\n[building]\nloop_length_x = [30.0, 40.0]\n",
    )
    .unwrap();
    let mut want = SimulationConfig {
        seed: 3,
        motion_distortion: true,
        motion: MotionProfile::Handheld(HandheldConfig {
            speed: 1.2,
            ..HandheldConfig::default()
        }),
        ..SimulationConfig::default()
    };
    want.lidar.rings = 128;
    want.building.loop_length_x = (30.0, 40.0);
    assert_eq!(read, want);
    for (motion, lidar) in [
        (MotionProfile::default(), LidarConfig::vlp16()),
        (MotionProfile::fast_turns(), LidarConfig::vlp16()),
        (MotionProfile::handheld(), LidarConfig::os1_128()),
    ] {
        let config = SimulationConfig {
            motion,
            lidar,
            gyro_drift: Some(0.01),
            ..SimulationConfig::default()
        };
        let text = toml::to_string(&config).unwrap();
        assert_eq!(
            toml::from_str::<SimulationConfig>(&text).unwrap(),
            config,
            "{text}"
        );
    }
    let e = toml::from_str::<SimulationConfig>("[lidar]\nring = 128\n").unwrap_err();
    assert!(e.to_string().contains("ring"), "{e}");
}

#[test]
fn recording_settings_read_from_partial_toml_and_round_trip() {
    use spot_adapter::record::{
        BagConfig, CloudFolderConfig, ImuSource, OdometrySource, SourceConfig, TimeUnit,
    };
    use spot_adapter::slam_core::Pose3;
    let read: SourceConfig = toml::from_str(
        "odometry = \"odom.tum\"\n\
         [bag]\ncloud_topic = \"/points\"\nodometry = { kind = \"Topic\", topic = \"/odom\" }\n\
         imu = { kind = \"None\" }\n\
         [bag.cloud]\ntime_unit = \"NanosecondsRelative\"\nreturns = { min_range = 0.3 }\n",
    )
    .unwrap();
    let mut want = SourceConfig {
        odometry: Some("odom.tum".into()),
        bag: BagConfig {
            cloud_topic: Some("/points".into()),
            odometry: OdometrySource::Topic("/odom".into()),
            imu: ImuSource::None,
            ..BagConfig::default()
        },
        ..SourceConfig::default()
    };
    want.bag.cloud.time_unit = Some(TimeUnit::NanosecondsRelative);
    want.bag.cloud.returns.min_range = 0.3;
    assert_eq!(read, want);
    // Every form of the two tagged sources, a mounting and a folder's settings round-trip.
    for (odometry, imu) in [
        (OdometrySource::Auto, ImuSource::Auto),
        (
            OdometrySource::Tf {
                odom_frame: "vision".into(),
            },
            ImuSource::Topic("/imu/data".into()),
        ),
        (OdometrySource::None, ImuSource::None),
    ] {
        let config = SourceConfig {
            bag: BagConfig {
                odometry,
                imu,
                base_frame: Some("body".into()),
                ..BagConfig::default()
            },
            body_t_lidar: Some(Pose3::translation(0.1, 0.0, 0.4)),
            ..SourceConfig::default()
        };
        let text = toml::to_string(&config).unwrap();
        assert_eq!(
            toml::from_str::<SourceConfig>(&text).unwrap(),
            config,
            "{text}"
        );
    }
    let folder = CloudFolderConfig {
        body_t_lidar: Some(Pose3::translation(0.0, 0.0, 1.3)),
        ..CloudFolderConfig::default()
    };
    let text = toml::to_string(&folder).unwrap();
    assert_eq!(toml::from_str::<CloudFolderConfig>(&text).unwrap(), folder);
    // A misspelt field, a source of no known kind and a topic field on the wrong kind are
    // refused by name.
    for (bad, named) in [
        ("[bag]\ncloud_topc = \"/x\"\n", "cloud_topc"),
        ("[bag]\nodometry = { kind = \"Bag\" }\n", "Bag"),
        (
            "[bag]\nimu = { kind = \"None\", topic = \"/imu\" }\n",
            "topic",
        ),
    ] {
        let e = toml::from_str::<SourceConfig>(bad).unwrap_err();
        assert!(e.to_string().contains(named), "{bad}: {e}");
    }
}
