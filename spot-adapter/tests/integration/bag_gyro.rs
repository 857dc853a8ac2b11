//! The gyro of a bag's `sensor_msgs/Imu` topic as each sample's `gyro_orientation`, against the
//! rotation trajectory the bag was written from: `tests/bags/write_bags.py` writes (with rosbags,
//! in both formats) clouds at 10 Hz and a 200 Hz gyro mounted upside down and turned a quarter
//! against the body, whose rates are those of a known body rotation (yaw at 0.3-1.3 rad/s with
//! pitch and roll sway), and the body's true orientation at every cloud's stamp. A second pair of
//! bags holds a NaN rate, an out-of-order stamp and a 0.7 s gap; a third an IMU in a frame no
//! transform joins to the body.

#![allow(clippy::unwrap_used, clippy::panic, clippy::expect_used)]

use std::path::{Path, PathBuf};

use nalgebra::{Quaternion, UnitQuaternion};
use spot_adapter::record::RecordError;
use spot_adapter::record::{
    Bag, BagConfig, GyroCounts, ImuSource, OdometrySource, SourceConfig, open_recording,
};
use spot_adapter::robot::Sample;

use super::bags::bags;

/// Clouds in the gyro bags.
const CLOUDS: usize = 40;
/// Radians two consecutive samples' rotation may be off the truth's: the gyro's integration
/// (third order in its 5 ms step) and the stamps' rounding at 1.7e9 s (2.4e-7 s) come to about
/// 1e-6 rad; a wrong mounting or frame is off by 1e-2 or more.
const TOLERANCE: f64 = 1e-5;

fn both(dir: &Path, name: &str) -> [PathBuf; 2] {
    [
        dir.join(format!("bags/{name}/{name}.mcap")),
        dir.join(format!("bags/{name}.bag")),
    ]
}

/// `x y z w` numbers as a rotation.
fn rotation(xyzw: &[f64]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_quaternion(Quaternion::new(xyzw[3], xyzw[0], xyzw[1], xyzw[2]))
}

/// The body's true orientation at each cloud's stamp, as the bags were written.
fn truth(dir: &Path) -> Vec<(f64, UnitQuaternion<f64>)> {
    std::fs::read_to_string(dir.join("bags/gyro_truth.txt"))
        .unwrap()
        .lines()
        .map(|line| {
            let v: Vec<f64> = line
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect();
            (v[0], rotation(&v[1..]))
        })
        .collect()
}

/// A mounting's rotation from `gyro_frames.txt` (`name tx ty tz qx qy qz qw`).
fn mounting(dir: &Path, name: &str) -> UnitQuaternion<f64> {
    let text = std::fs::read_to_string(dir.join("bags/gyro_frames.txt")).unwrap();
    let line = text.lines().find(|l| l.starts_with(name)).unwrap();
    let v: Vec<f64> = line
        .split_whitespace()
        .skip(1)
        .map(|x| x.parse().unwrap())
        .collect();
    rotation(&v[3..])
}

fn read(path: &Path, config: &BagConfig) -> (Bag, Vec<Sample>) {
    let bag = Bag::open(path, config).unwrap();
    let samples = bag.samples().unwrap().map(Result::unwrap).collect();
    (bag, samples)
}

/// The worst angle between the gyro's rotation from one sample to the next and the truth's
/// (`frame` turns the body's rotation into the frame the samples' body is), over the pairs of
/// consecutive samples that both have a gyro orientation; and how many pairs there were.
fn worst_step(
    samples: &[Sample],
    truth: &[(f64, UnitQuaternion<f64>)],
    frame: UnitQuaternion<f64>,
) -> (f64, usize) {
    assert_eq!(samples.len(), truth.len());
    let mut worst = 0f64;
    let mut pairs = 0;
    for (i, pair) in samples.windows(2).enumerate() {
        let (a, b) = (&pair[0], &pair[1]);
        assert!(
            (a.stamp - truth[i].0).abs() < 1e-6,
            "{} vs {}",
            a.stamp,
            truth[i].0
        );
        let (Some(qa), Some(qb)) = (a.gyro_orientation, b.gyro_orientation) else {
            continue;
        };
        let got = qa.inverse() * qb;
        let want = frame.inverse() * truth[i].1.inverse() * truth[i + 1].1 * frame;
        worst = worst.max(got.angle_to(&want));
        pairs += 1;
    }
    (worst, pairs)
}

#[test]
fn the_gyro_gives_the_rotation_between_scans() {
    let dir = bags();
    let truth = truth(dir);
    assert_eq!(truth.len(), CLOUDS);
    let base_r_imu = mounting(dir, "base_T_imu");
    let base_r_lidar = mounting(dir, "base_T_lidar");
    for path in both(dir, "gyro") {
        let (bag, samples) = read(&path, &BagConfig::default());
        let imu = bag.summary().imu.clone().unwrap();
        assert_eq!(
            (imu.topic.as_str(), imu.frame.as_str()),
            ("/imu", "imu_link")
        );
        assert!(imu.body_r_imu.angle_to(&base_r_imu) < 1e-12);
        assert_eq!(
            imu.counts,
            GyroCounts {
                used: 840,
                ..GyroCounts::default()
            }
        );
        assert_eq!(imu.clouds_outside, 0);
        assert_eq!(samples.len(), CLOUDS);
        assert!(samples.iter().all(|s| s.gyro_orientation.is_some()));
        let (worst, pairs) = worst_step(&samples, &truth, UnitQuaternion::identity());
        assert_eq!(pairs, CLOUDS - 1);
        assert!(worst < TOLERANCE, "{}: {worst} rad", path.display());
        // Over the whole 3.9 s turn (2.7 rad of yaw) too.
        let got = samples[0].gyro_orientation.unwrap().inverse()
            * samples[CLOUDS - 1].gyro_orientation.unwrap();
        let want = truth[0].1.inverse() * truth[CLOUDS - 1].1;
        assert!(got.angle_to(&want) < TOLERANCE, "{}", got.angle_to(&want));
        eprintln!(
            "{}: worst step {worst:.1e} rad, whole turn {:.1e} rad",
            path.display(),
            got.angle_to(&want)
        );
        // Without odometry the body is the LiDAR: the gyro turned through lidar -> base -> imu.
        let (_, samples) = read(
            &path,
            &BagConfig {
                odometry: OdometrySource::None,
                ..BagConfig::default()
            },
        );
        let (worst, pairs) = worst_step(&samples, &truth, base_r_lidar);
        assert_eq!(pairs, CLOUDS - 1);
        assert!(worst < TOLERANCE, "{}: {worst} rad", path.display());
        // The description says where the orientation comes from.
        let source = open_recording(&path, &SourceConfig::default()).unwrap();
        assert!(
            source.description.contains(
                "imu         /imu in \"imu_link\" (840 readings, 200.0 Hz): gyro integrated into the body's orientation\n"
            ),
            "{}",
            source.description
        );
        // Asked for none, there is none.
        let config = BagConfig {
            imu: ImuSource::None,
            ..BagConfig::default()
        };
        let (bag, samples) = read(&path, &config);
        assert!(bag.summary().imu.is_none());
        assert!(samples.iter().all(|s| s.gyro_orientation.is_none()));
    }
}

#[test]
fn bad_gyro_readings_are_dropped_and_gaps_not_integrated_across() {
    let dir = bags();
    let truth = truth(dir);
    for path in both(dir, "gyro_bad") {
        let (bag, samples) = read(&path, &BagConfig::default());
        let summary = bag.summary();
        let imu = summary.imu.clone().unwrap();
        let c = imu.counts;
        assert_eq!(
            (c.out_of_order, c.non_finite, c.other_frame, c.gaps),
            (1, 1, 0, 1),
            "{}",
            path.display()
        );
        let messages = summary
            .topics
            .iter()
            .find(|t| t.info.name == "/imu")
            .unwrap()
            .count;
        assert_eq!(c.used + c.dropped(), messages);
        let text = summary.to_string();
        for said in [
            "readings dropped: 1 out of order, 1 with a non-finite rate;",
            "gaps over 0.5 s: 1 (not integrated across",
        ] {
            assert!(text.contains(said), "{said:?} not in {text}");
        }
        // The clouds stamped inside the gap (2.0 to 2.7 s) have no orientation; the one after
        // it has one again (its predecessor had none, so no pair straddles the gap).
        assert_eq!(samples.len(), CLOUDS);
        let start = truth[0].0 - 0.0123;
        for s in &samples {
            let t = s.stamp - start;
            let in_gap = t > 2.0 && t < 2.7;
            assert_eq!(s.gyro_orientation.is_none(), in_gap, "at {t} s");
        }
        // Every pair of consecutive samples with an orientation: the truth's rotation, across
        // the NaN reading and the out-of-order one too.
        let (worst, pairs) = worst_step(&samples, &truth, UnitQuaternion::identity());
        assert_eq!(pairs, CLOUDS - 1 - 8);
        assert!(worst < TOLERANCE, "{}: {worst} rad", path.display());
    }
}

#[test]
fn an_imu_not_joined_to_the_body_is_left_out_or_an_error() {
    let dir = bags();
    for path in both(dir, "unlinked") {
        // By default: no gyro, and why.
        let (bag, samples) = read(&path, &BagConfig::default());
        assert!(bag.summary().imu.is_none());
        assert!(samples.iter().all(|s| s.gyro_orientation.is_none()));
        let text = bag.summary().to_string();
        assert!(
            text.contains(
                "note        IMU topic /imu ignored: its frame \"imu_link\" is not joined to the body frame \"lidar\" by /tf_static"
            ),
            "{text}"
        );
        // Asked for: an error naming both frames.
        let err = Bag::open(
            &path,
            &BagConfig {
                imu: ImuSource::Topic("/imu".into()),
                ..BagConfig::default()
            },
        )
        .unwrap_err();
        assert!(
            matches!(&err, RecordError::UnlinkedImu { imu_frame, body_frame, .. } if imu_frame == "imu_link" && body_frame == "lidar"),
            "{err}"
        );
        for said in ["/tf_static: not in the bag", "--no-imu", "--base-frame"] {
            assert!(err.to_string().contains(said), "{said:?} not in {err}");
        }
        // A topic the bag does not have, or of another type.
        for (topic, said) in [
            ("/nope", "no topic /nope"),
            ("/luminar/points", "where sensor_msgs/Imu is needed"),
        ] {
            let err = Bag::open(
                &path,
                &BagConfig {
                    imu: ImuSource::Topic(topic.into()),
                    ..BagConfig::default()
                },
            )
            .unwrap_err();
            assert!(err.to_string().contains(said), "{err}");
        }
    }
}
