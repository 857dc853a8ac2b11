//! Tests of `tracker.rs`.

use nalgebra::Matrix6;

use super::*;
use crate::cloud::PointCloud;

/// A registrator whose basin is a cone: from a guess within `width` radians of heading of
/// `answer` it finds `answer` (matching `share` of the scan); from farther it converges to a
/// wrong pose matching little, or fails.
struct Basin {
    answer: Pose3,
    width: f64,
    share: f64,
    /// The share the wrong minimum matches.
    wrong_share: f64,
}

fn alignment(pose: Pose3, inlier_ratio: f64) -> Alignment {
    Alignment {
        pose,
        converged: true,
        iterations: 3,
        inliers: 100,
        inlier_ratio,
        rmse: 0.01,
        information: Matrix6::identity(),
        min_eigenvalue_ratio: 1.0,
    }
}

impl Registrator for Basin {
    type Source = ();
    type Target = ();
    fn prepare_source(&self, _: &PointCloud) -> Result<(), RegistrationError> {
        Ok(())
    }
    fn prepare_target(&self, _: &PointCloud) -> Result<(), RegistrationError> {
        Ok(())
    }
    fn align(&self, (): &(), (): &(), guess: &Pose3) -> Result<Alignment, RegistrationError> {
        let off = (guess.inverse() * self.answer).rotation.angle();
        if off <= self.width {
            Ok(alignment(self.answer, self.share))
        } else if off <= 2.0 * self.width {
            // A wrong minimum near the guess.
            Ok(alignment(*guess, self.wrong_share))
        } else {
            Err(RegistrationError::TooFewCorrespondences {
                found: 3,
                required: 20,
            })
        }
    }
    fn align_within(
        &self,
        s: &(),
        t: &(),
        guess: &Pose3,
        _: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        self.align(s, t, guess)
    }
}

fn yawed(degrees: f64) -> Pose3 {
    turned(&Pose3::identity(), degrees.to_radians())
}

/// A tracker that took `scans` scans of a basin `width` degrees wide around the identity (90 %
/// matched there, 35 % elsewhere), each predicted `off` degrees away, every one tracked; and the
/// basin.
fn warmed_up(width: f64, off: f64, scans: usize) -> (Tracker, Basin) {
    warmed_up_with(TrackerConfig::default(), width, off, scans)
}

/// [`warmed_up`] with `config`.
fn warmed_up_with(config: TrackerConfig, width: f64, off: f64, scans: usize) -> (Tracker, Basin) {
    let mut tracker = Tracker::new(config).unwrap_or_else(|e| panic!("{e}"));
    let scan = Basin {
        answer: yawed(0.0),
        width: width.to_radians(),
        share: 0.9,
        wrong_share: 0.35,
    };
    for _ in 0..scans {
        assert!(
            tracker
                .track(&scan, &(), Some(&()), &[yawed(off)], 10.0)
                .tracked()
        );
    }
    (tracker, scan)
}

#[test]
fn a_turn_beyond_the_basin_is_recovered_from_a_turned_heading() {
    // Warm up: predictions right, 90 % matched.
    let (mut tracker, scan) = warmed_up(12.0, 1.0, 5);
    let tracker = &mut tracker;
    // A sudden turn: the prediction 50 degrees off. From it the registration fails; from
    // the heading turned by 40 or 60 degrees it finds the answer.
    let turn = Basin {
        answer: yawed(50.0),
        ..scan
    };
    let outcome = tracker.track(&turn, &(), Some(&()), &[yawed(0.0)], 10.0);
    assert!(outcome.tracked() && outcome.recovered, "{outcome:?}");
    assert!((outcome.pose.rotation.angle().to_degrees() - 50.0).abs() < 1e-9);
    assert_eq!(tracker.health().recovered, 1);
    // The reach widened after the turn.
    assert!(tracker.reach() > 3.0, "{}", tracker.reach());
    // A wrong minimum matching much less than usual is suspect and retried too.
    let near = Basin {
        answer: yawed(20.0),
        ..scan
    };
    let outcome = tracker.track(&near, &(), Some(&()), &[yawed(-2.0)], 10.0);
    assert!(
        outcome.recovered && outcome.alignment.is_some(),
        "{outcome:?}"
    );
    assert!((outcome.pose.rotation.angle().to_degrees() - 20.0).abs() < 1e-9);
}

/// A corridor whose far pairs slide a scan: a stage reaching farther than 3 m finds `answer`'s
/// heading but moves the guess 5 m along; nearer, a guess within 1 m and 5 degrees of `answer`
/// converges to it, and any other stays where it is (matching 70 %).
struct SlidingCorridor {
    answer: Pose3,
}

impl Registrator for SlidingCorridor {
    type Source = ();
    type Target = ();
    fn prepare_source(&self, _: &PointCloud) -> Result<(), RegistrationError> {
        Ok(())
    }
    fn prepare_target(&self, _: &PointCloud) -> Result<(), RegistrationError> {
        Ok(())
    }
    fn align(&self, (): &(), (): &(), guess: &Pose3) -> Result<Alignment, RegistrationError> {
        let off = (guess.translation.vector - self.answer.translation.vector).norm();
        let turned = guess.rotation.angle_to(&self.answer.rotation);
        Ok(if off <= 1.0 && turned <= 5f64.to_radians() {
            alignment(self.answer, 0.9)
        } else {
            alignment(*guess, 0.7)
        })
    }
    fn align_within(
        &self,
        s: &(),
        t: &(),
        guess: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        if reach.distance > 3.0 {
            let slid = Pose3::from_parts(
                Translation3::new(guess.translation.x + 5.0, guess.translation.y, 0.0),
                self.answer.rotation,
            );
            Ok(alignment(slid, 0.7))
        } else {
            self.align(s, t, guess)
        }
    }
}

#[test]
fn a_scan_a_wide_reach_slides_along_a_corridor_is_found_at_the_initial_reach() {
    // Turns the prediction misses by 15 degrees widen the reach beyond 3 m.
    let (mut tracker, turning) = warmed_up(20.0, 15.0, 10);
    let tracker = &mut tracker;
    assert!(tracker.reach() > 3.0, "{}", tracker.reach());
    // The wide stages slide the scan 5 m (refused as too large a correction) from the
    // prediction and from every turned heading; the initial reach converges.
    let corridor = SlidingCorridor {
        answer: Pose3::from_parts(Translation3::new(0.3, 0.0, 0.0), UnitQuaternion::identity()),
    };
    // The fine stage run again from the predicted position finds it at once ...
    let outcome = tracker.track(&corridor, &(), Some(&()), &[Pose3::identity()], 10.0);
    assert!(outcome.tracked() && !outcome.recovered, "{outcome:?}");
    assert!(
        (outcome.pose.translation.x - 0.3).abs() < 1e-12,
        "{outcome:?}"
    );
    // ... and without that recheck, the retry at the initial reach.
    let no_recheck = TrackerConfig {
        recheck_distance: 0.0,
        ..TrackerConfig::default()
    };
    let (mut tracker, _) = warmed_up_with(no_recheck, 20.0, 15.0, 10);
    let outcome = tracker.track(&corridor, &(), Some(&()), &[Pose3::identity()], 10.0);
    assert!(outcome.tracked() && outcome.recovered, "{outcome:?}");
    assert!(
        (outcome.pose.translation.x - 0.3).abs() < 1e-12,
        "{outcome:?}"
    );
    // Without either the scan falls back for the refused correction.
    let mut strict = Tracker::new(TrackerConfig {
        retry: false,
        ..no_recheck
    })
    .unwrap_or_else(|e| panic!("{e}"));
    for _ in 0..10 {
        strict.track(&turning, &(), Some(&()), &[yawed(15.0)], 10.0);
    }
    let outcome = strict.track(&corridor, &(), Some(&()), &[Pose3::identity()], 10.0);
    assert_eq!(outcome.fallback, Some(FallbackReason::CorrectionTooLarge));
}

#[test]
fn without_retries_a_lost_scan_falls_back_with_its_reason_and_losses_are_counted() {
    let config = TrackerConfig {
        retry: false,
        ..TrackerConfig::default()
    };
    let mut tracker = Tracker::new(config).unwrap_or_else(|e| panic!("{e}"));
    let far = Basin {
        answer: yawed(90.0),
        width: 10f64.to_radians(),
        share: 0.9,
        wrong_share: 0.2,
    };
    for k in 1..=4 {
        let outcome = tracker.track(&far, &(), Some(&()), &[yawed(0.0)], 10.0);
        assert_eq!(
            outcome.fallback,
            Some(FallbackReason::TooFewCorrespondences)
        );
        assert_eq!(outcome.pose, yawed(0.0), "the prediction is kept");
        assert_eq!(tracker.health().consecutive_fallbacks, k);
    }
    assert!(tracker.is_lost());
    assert_eq!(
        tracker.health().losses,
        1,
        "counted once per run of fallbacks"
    );
    let outcome = tracker.track(&far, &(), None, &[yawed(0.0)], 10.0);
    assert_eq!(outcome.fallback, Some(FallbackReason::NoTarget));
    // A wrong minimum matching too little is refused, with the refused alignment kept.
    let wrong = Basin {
        answer: yawed(15.0),
        ..far
    };
    let outcome = tracker.track(&wrong, &(), Some(&()), &[yawed(0.0)], 10.0);
    assert_eq!(outcome.fallback, Some(FallbackReason::TooFewInliers));
    assert!(outcome.refused.is_some());
    assert_eq!(tracker.health().fallbacks.total(), 6);
    assert!(tracker.health().fallback_ratio() > 0.99);
}

#[test]
fn every_bad_setting_is_refused_by_name() {
    let d = TrackerConfig::default();
    let cases = [
        (
            TrackerConfig {
                coarse_kernel: 0.0,
                ..d
            },
            "TrackerConfig::coarse_kernel",
        ),
        (
            TrackerConfig {
                coarse_kernel: f64::NAN,
                ..d
            },
            "TrackerConfig::coarse_kernel",
        ),
        (
            TrackerConfig {
                min_inlier_ratio: -0.1,
                ..d
            },
            "TrackerConfig::min_inlier_ratio",
        ),
        (
            TrackerConfig {
                min_inlier_ratio: 1.5,
                ..d
            },
            "TrackerConfig::min_inlier_ratio",
        ),
        (
            TrackerConfig {
                suspect_ratio: f64::NAN,
                ..d
            },
            "TrackerConfig::suspect_ratio",
        ),
        (
            TrackerConfig {
                max_translation_correction: 0.0,
                ..d
            },
            "TrackerConfig::max_translation_correction",
        ),
        (
            TrackerConfig {
                max_rotation_correction: -1.0,
                ..d
            },
            "TrackerConfig::max_rotation_correction",
        ),
        (
            TrackerConfig {
                arbitration_distance: f64::INFINITY,
                ..d
            },
            "TrackerConfig::arbitration_distance",
        ),
        (
            TrackerConfig {
                retry_turn_step: 0.0,
                ..d
            },
            "TrackerConfig::retry_turn_step",
        ),
        (
            TrackerConfig { lost_after: 0, ..d },
            "TrackerConfig::lost_after",
        ),
        (
            TrackerConfig {
                reach: ReachConfig {
                    sigmas: 0.0,
                    ..d.reach
                },
                ..d
            },
            "ReachConfig::sigmas",
        ),
    ];
    for (config, setting) in cases {
        assert_eq!(
            Tracker::new(config).err().map(|e| e.setting),
            Some(setting),
            "{config:?}"
        );
    }
}

/// A corridor where the wide stages carry any guess 0.2 m short of the truth along it (a basin
/// that fits a little worse: `short_fit`), and the fine stage converges to the truth from
/// within 0.1 m of it and stays put farther away. A stage at the reach's minimum (a recheck's
/// first pass) behaves as the fine stage, ending 3 mm from where the fine stage would.
struct ShortBasin {
    truth: Pose3,
    /// Matched share and RMS error of the short pose.
    short_fit: (f64, f64),
    /// Whole fine stages run.
    fine_stages: std::cell::Cell<usize>,
}

impl ShortBasin {
    fn short(&self) -> Pose3 {
        Pose3::translation(-0.2, 0.0, 0.0) * self.truth
    }
}

/// An alignment ending at `pose` with this matched share and RMS error.
fn fitted(pose: Pose3, (inlier_ratio, rmse): (f64, f64)) -> Alignment {
    Alignment {
        rmse,
        ..alignment(pose, inlier_ratio)
    }
}

impl Registrator for ShortBasin {
    type Source = ();
    type Target = ();
    fn prepare_source(&self, _: &PointCloud) -> Result<(), RegistrationError> {
        Ok(())
    }
    fn prepare_target(&self, _: &PointCloud) -> Result<(), RegistrationError> {
        Ok(())
    }
    fn align(&self, (): &(), (): &(), guess: &Pose3) -> Result<Alignment, RegistrationError> {
        self.fine_stages.set(self.fine_stages.get() + 1);
        let off = (guess.translation.vector - self.truth.translation.vector).norm();
        Ok(if off <= 0.1 {
            fitted(self.truth, (0.9, 0.017))
        } else {
            fitted(self.short(), self.short_fit)
        })
    }
    fn align_within(
        &self,
        (): &(),
        (): &(),
        guess: &Pose3,
        reach: &Reach,
    ) -> Result<Alignment, RegistrationError> {
        let off = (guess.translation.vector - self.truth.translation.vector).norm();
        let min = TrackerConfig::default().reach.min;
        Ok(if reach.distance <= min && off <= 0.1 {
            fitted(
                Pose3::translation(0.003, 0.0, 0.0) * self.truth,
                (0.9, 0.017),
            )
        } else {
            fitted(self.short(), self.short_fit)
        })
    }
}

#[test]
fn a_registration_carried_short_along_a_corridor_is_rechecked_from_the_predicted_position() {
    let truth = Pose3::from_parts(
        Translation3::new(3.0, 1.0, 0.0),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), 0.3),
    );
    // The prediction 3 cm and 10 degrees off: the wide stages fix the heading but end short.
    let prediction = Pose3::translation(0.03, 0.0, 0.0) * turned(&truth, -10f64.to_radians());
    let track_from = |config: TrackerConfig, short_fit: (f64, f64), prediction: Pose3| {
        let mut tracker = Tracker::new(config).unwrap_or_else(|e| panic!("{e}"));
        let corridor = ShortBasin {
            truth,
            short_fit,
            fine_stages: std::cell::Cell::new(0),
        };
        let outcome = tracker.track(&corridor, &(), Some(&()), &[prediction], 10.0);
        assert!(outcome.tracked(), "{outcome:?}");
        (outcome.pose, corridor.fine_stages.get())
    };
    let track = |config, short_fit| track_from(config, short_fit, prediction).0;
    let gap = |a: Pose3, b: Pose3| (a.translation.vector - b.translation.vector).norm();
    let short = Pose3::translation(-0.2, 0.0, 0.0) * truth;
    // Worse on both counts there: the recheck from the predicted position finds the truth.
    let d = TrackerConfig::default();
    assert!(gap(track(d, (0.85, 0.02)), truth) < 1e-12);
    // Off: the staged result stands.
    let off = TrackerConfig {
        recheck_distance: 0.0,
        ..d
    };
    assert!(gap(track(off, (0.85, 0.02)), short) < 1e-12);
    // Only when the other fits at least as well on both counts: matching more of the scan with
    // a larger error is no proof.
    assert!(gap(track(d, (0.85, 0.015)), short) < 1e-12);
    assert!(gap(track(d, (0.95, 0.02)), short) < 1e-12);
    // A recheck whose first pass ends in the registration's own basin stops there: from a
    // prediction 0.3 m off, both end short, and only the registration's fine stage runs (two
    // when the recheck runs whole).
    let far_off = Pose3::translation(0.3, 0.0, 0.0) * prediction;
    let (pose, fine) = track_from(d, (0.85, 0.02), far_off);
    assert!(gap(pose, short) < 1e-12 && fine == 1, "{fine}");
    let whole = TrackerConfig {
        recheck_basin: 0.0,
        ..d
    };
    let (pose, fine) = track_from(whole, (0.85, 0.02), far_off);
    assert!(gap(pose, short) < 1e-12 && fine == 2, "{fine}");
    // Ending within the distance of the prediction, nothing is rechecked.
    let far = TrackerConfig {
        recheck_distance: 0.5,
        ..d
    };
    assert!(gap(track(far, (0.85, 0.02)), short) < 1e-12);
    // A distance or basin that is negative or not finite is refused by name.
    for bad in [-0.1, f64::INFINITY, f64::NAN] {
        let config = TrackerConfig {
            recheck_distance: bad,
            ..d
        };
        assert_eq!(
            Tracker::new(config).err().map(|e| e.setting),
            Some("TrackerConfig::recheck_distance")
        );
        let config = TrackerConfig {
            recheck_basin: bad,
            ..d
        };
        assert_eq!(
            Tracker::new(config).err().map(|e| e.setting),
            Some("TrackerConfig::recheck_basin")
        );
    }
}

#[test]
fn a_registration_refused_for_sliding_at_a_sudden_turn_is_retried_with_its_turn() {
    // Turns the prediction misses by 15 degrees widen the reach beyond 3 m; no recheck, so that
    // only the retry can find the scan.
    let no_recheck = TrackerConfig {
        recheck_distance: 0.0,
        ..TrackerConfig::default()
    };
    let (mut tracker, _) = warmed_up_with(no_recheck, 20.0, 15.0, 10);
    assert!(tracker.reach() > 3.0, "{}", tracker.reach());
    // Turned 47 degrees: none of the retry's turned headings (20, 40, 60) is within 5 degrees,
    // and every one slides at the widest reach. From the predicted position with the refused
    // registration's turn, at the initial reach, it converges.
    let corridor = SlidingCorridor {
        answer: Pose3::from_parts(
            Translation3::new(0.3, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.0, 0.0, 47f64.to_radians()),
        ),
    };
    let outcome = tracker.track(&corridor, &(), Some(&()), &[Pose3::identity()], 10.0);
    assert!(outcome.tracked() && outcome.recovered, "{outcome:?}");
    assert!(
        (outcome.pose.translation.vector - corridor.answer.translation.vector).norm() < 1e-12
            && outcome.pose.rotation.angle_to(&corridor.answer.rotation) < 1e-12,
        "{outcome:?}"
    );
    // Without that first try the turned headings miss it, and only the prediction's own pose
    // (47 degrees off, 70 % matched) is left to take.
    let (mut tracker, _) = warmed_up_with(
        TrackerConfig {
            retry_found_turn: false,
            ..no_recheck
        },
        20.0,
        15.0,
        10,
    );
    let outcome = tracker.track(&corridor, &(), Some(&()), &[Pose3::identity()], 10.0);
    assert!(
        outcome.pose.rotation.angle_to(&corridor.answer.rotation) > 40f64.to_radians(),
        "{outcome:?}"
    );
}
