//! The map-and-evaluate loop of the `slam` and `mission` examples: feed every sample to the
//! Graph-SLAM engine with progress on stderr ([`map_samples`]), then evaluate the body trajectory
//! against the ground truth when the source knows it ([`evaluate`]).

use std::time::Instant;

use anyhow::{Result, bail};
use slam_core::io::StampedPose;
use slam_core::{GraphSlam, MapRegistrator, Optimizer, Pose3, ScanOutcome};
use spot_adapter::eval::{TrajectoryEvaluation, body_trajectory};
use spot_adapter::robot::Sample;

use crate::progress::Progress;

/// What one mapping run gave besides the engine's own state and report.
#[derive(Clone, Debug)]
pub struct Mapping {
    /// The body trajectory estimate (`map_T_body` per scan), for writing out.
    pub estimate: Vec<StampedPose>,
    /// The estimate against the ground truth (ATE, drifts, loop end-point error), when known.
    pub evaluation: Option<TrajectoryEvaluation>,
    /// Wall-clock seconds of feeding the samples (reading or simulating them included).
    pub seconds: f64,
}

/// Feeds every sample to `slam` (progress labelled `label` on stderr, a line for each skipped
/// scan; with `lidar_only` without their odometry, so that the engine tracks the scans by
/// registration alone), then evaluates the body trajectory (`body_t_lidar`: the LiDAR mounting)
/// against `truth` (`world_T_body`) when given: [`map_samples`] then [`evaluate`].
///
/// # Errors
/// As [`map_samples`] and [`evaluate`].
pub fn map_and_evaluate<R, C, O, I, E>(
    slam: &mut GraphSlam<R, C, O>,
    samples: I,
    body_t_lidar: &Pose3,
    truth: Option<&[StampedPose]>,
    label: &str,
    lidar_only: bool,
) -> Result<Mapping>
where
    R: MapRegistrator,
    C: MapRegistrator,
    O: Optimizer<Pose3>,
    I: ExactSizeIterator<Item = Result<Sample, E>>,
    E: Into<anyhow::Error>,
{
    let run = map_samples(slam, samples, label, lidar_only)?;
    let (evaluation, estimate) = evaluate(slam, body_t_lidar, truth)?;
    Ok(Mapping {
        estimate,
        evaluation,
        seconds: run.seconds,
    })
}

/// What feeding the samples gave besides the engine's state.
#[derive(Clone, Debug)]
pub struct MappedScans {
    /// Wall-clock seconds of feeding the samples (reading or simulating them included).
    pub seconds: f64,
    /// The stamp of every sample read, in order (skipped scans too).
    pub stamps: Vec<f64>,
}

/// Feeds every sample to `slam` (without their odometry when `lidar_only`), with progress
/// labelled `label` on stderr and a line for each skipped scan.
///
/// # Errors
/// The first sample that could not be read, or an engine that accepted no scan at all.
pub fn map_samples<R, C, O, I, E>(
    slam: &mut GraphSlam<R, C, O>,
    samples: I,
    label: &str,
    lidar_only: bool,
) -> Result<MappedScans>
where
    R: MapRegistrator,
    C: MapRegistrator,
    O: Optimizer<Pose3>,
    I: ExactSizeIterator<Item = Result<Sample, E>>,
    E: Into<anyhow::Error>,
{
    let mut progress = Progress::new(label, "scans", Some(samples.len() as u64));
    let mut stamps = Vec::with_capacity(samples.len());
    let started = Instant::now();
    for (n, sample) in (1u64..).zip(samples) {
        let sample = sample.map_err(Into::into)?;
        stamps.push(sample.stamp);
        let input = if lidar_only {
            sample.lidar_only_input()
        } else {
            sample.scan_input()
        };
        if let ScanOutcome::Skipped(reason) = slam.process(&input) {
            progress.note(&format!("scan {n} skipped: {reason:?}"));
        }
        progress.update(
            n,
            format!(
                "{} keyframes, {} loops",
                slam.keyframe_count(),
                slam.report().loops_closed
            ),
        );
    }
    progress.finish();
    let seconds = started.elapsed().as_secs_f64();
    let report = slam.report();
    if report.keyframes == 0 {
        bail!(
            "the engine accepted none of the {} scans (see the skipped scans above)",
            report.scans
        );
    }
    Ok(MappedScans { seconds, stamps })
}

/// The body trajectory of `slam`'s scans (`body_t_lidar`: the LiDAR mounting), evaluated
/// against `truth` (`world_T_body`) when given.
///
/// # Errors
/// A failed evaluation (fewer than 3 poses matched by stamp).
pub fn evaluate<R, C, O>(
    slam: &GraphSlam<R, C, O>,
    body_t_lidar: &Pose3,
    truth: Option<&[StampedPose]>,
) -> Result<(Option<TrajectoryEvaluation>, Vec<StampedPose>)>
where
    R: MapRegistrator,
    C: MapRegistrator,
    O: Optimizer<Pose3>,
{
    Ok(match truth {
        Some(truth) => {
            let (evaluation, estimate) = TrajectoryEvaluation::of_lidar_trajectory(
                slam.scan_trajectory(),
                body_t_lidar,
                truth,
            )?;
            (Some(evaluation), estimate)
        }
        None => (None, body_trajectory(slam.scan_trajectory(), body_t_lidar)),
    })
}
