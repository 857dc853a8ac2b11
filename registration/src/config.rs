//! Settings of the ICP backends.

use slam_core::{InvalidSetting, RegistrationError};

use crate::kernel::IcpKernel;

/// Settings of [`PointToPointIcp`](crate::PointToPointIcp) and
/// [`PointToPlaneIcp`](crate::PointToPlaneIcp). Lengths in metres, angles in radians.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(default, deny_unknown_fields)
)]
pub struct IcpConfig {
    /// Voxel size of the source cloud (0 keeps every point).
    pub source_voxel: f32,
    /// Voxel size of the target cloud (0 keeps every point).
    pub target_voxel: f32,
    /// Correspondences farther apart than this are ignored.
    pub max_correspondence_distance: f64,
    /// Iteration cap.
    pub max_iterations: usize,
    /// Converged when an update moves less than this (metres, default 0.1 mm) ...
    pub translation_tolerance: f64,
    /// ... and turns less than this (radians, default 1e-4, 0.006°). Tighter settings only add
    /// iterations: on the HDL-32E pair 1e-5 m / 1e-6 rad takes 17 iterations to the same pose
    /// (within 0.01°) that these reach in 7.
    pub rotation_tolerance: f64,
    /// Neighbours for target normals (point-to-plane).
    pub normal_neighbours: usize,
    /// Robust weights of the residuals.
    pub kernel: IcpKernel,
    /// Fewer correspondences than this is an error.
    pub min_correspondences: usize,
    /// Point-to-point: each source point pairs with the mean of its this many nearest target
    /// points (at most 16). 1 is textbook ICP, whose pairs pull the source onto the target's
    /// sampling lattice: two random halves of a real HDL-32E scan, one moved by a known
    /// transform, end 0.11-0.14° off with it (one azimuth step of that LiDAR is 0.16°), and
    /// 0.01-0.04° off with the default 2, which pairs a point with the midpoint of two target
    /// samples (3 splits x 3 transforms x 4 voxel settings). A source point with fewer target
    /// points within reach is left out. Point-to-plane always pairs with the nearest point and
    /// its normal.
    pub pair_target_points: usize,
    /// Coarse stage: every `coarse_stride`-th source point aligns first, with one plain
    /// nearest-neighbour search per point and iteration, until an update moves less than 1 cm
    /// and turns less than 0.1 degrees; then every point refines with neighbours reused across
    /// iterations. 1 skips the stage. Default 4: on the HDL-32E pair the alignment then runs
    /// 6,200 single-nearest and 6,200 four-nearest searches where it ran 13,700 four-nearest
    /// ones, and ends 0.006° and 0.05 mm from the pose it reaches without the stage
    /// (point-to-point: 0.004° and 0.6 mm).
    pub coarse_stride: usize,
    /// Point-to-plane: compute every target point's normal when the target is prepared (on
    /// all cores) instead of each on its first use. Off by default: an alignment against a
    /// local map touches a fraction of its points. On for a fixed map that many scans are
    /// aligned against over time (a navigator's), where first uses would otherwise land in
    /// whichever cycle first sees a place.
    pub normals_up_front: bool,
    /// Point-to-plane: directions of the motion that the matched surfaces barely constrain
    /// get no update, so the initial guess's motion stands along them (solution remapping,
    /// Zhang, Kaess & Singh, ICRA 2016). A direction `v` (unit 6-vector of the left
    /// perturbation, `[translation; rotation]`) counts as unconstrained when `v^T H v`, the
    /// information along it, is below this times the sum of the pairs' weights: for a
    /// translation that is the weighted mean of `(n . v)^2` over the pairs' normals, so 0.01
    /// means about one pair in a hundred faces that way. In a corridor without features
    /// registration otherwise slides along the walls on noise; with a prediction from the
    /// robot's motion it keeps that instead. 0 (the default) turns it off.
    pub degeneracy_threshold: f64,
    /// Point-to-plane: a target point pairs only when its neighbourhood is a plane, its middle
    /// PCA eigenvalue at least this times the largest (0 to 1). A neighbourhood along a line
    /// (one ring of a LiDAR on the floor, thinned to a voxel row) has a normal that could point
    /// anywhere across the line; such normals turn along-the-wall motion into residuals, which
    /// pull the scan towards the sampling pattern it was matched to. 0 (the default) keeps
    /// every normal.
    pub min_planarity: f64,
    /// An alignment uses at most this many source points, every k-th of the voxelised scan
    /// (0, the default, uses them all). A dense scan (an OS1-128's 131,072 points leave 4,000
    /// or more at a 0.25 m voxel) then costs what a VLP-16's does (about 2,000), while the
    /// scan kept for a map (a keyframe's) stays whole.
    pub max_source_points: usize,
    /// Scans of at most this many points (as the sensor gave them) get their maps thinned to
    /// [`IcpConfig::sparse_target_voxel`] instead of [`IcpConfig::target_voxel`], once an
    /// engine has set the backend up for its first scan
    /// ([`MapRegistrator::fit_to_scan`](slam_core::MapRegistrator::fit_to_scan)); 0 (the
    /// default) never.
    pub sparse_scan_points: usize,
    /// The map voxel for scans of at most [`IcpConfig::sparse_scan_points`] points (0 keeps
    /// every point).
    pub sparse_target_voxel: f32,
}

impl Default for IcpConfig {
    fn default() -> Self {
        Self {
            source_voxel: 0.25,
            target_voxel: 0.25,
            max_correspondence_distance: 1.0,
            max_iterations: 50,
            translation_tolerance: 1e-4,
            rotation_tolerance: 1e-4,
            normal_neighbours: 10,
            kernel: IcpKernel::Huber { k: 0.1 },
            min_correspondences: 20,
            pair_target_points: 2,
            coarse_stride: 4,
            normals_up_front: false,
            degeneracy_threshold: 0.0,
            min_planarity: 0.0,
            max_source_points: 0,
            sparse_scan_points: 0,
            sparse_target_voxel: 0.0,
        }
    }
}

impl IcpConfig {
    /// These settings for a sensor whose first scan has `points` points: with
    /// [`IcpConfig::sparse_scan_points`] above zero and `points` no more than it, the map voxel
    /// becomes [`IcpConfig::sparse_target_voxel`]; the rule is then spent (set to 0), so that the
    /// settings describe what the backend does from then on.
    ///
    /// ```
    /// use registration::IcpConfig;
    ///
    /// let rule = IcpConfig { target_voxel: 0.2, sparse_scan_points: 50_000, sparse_target_voxel: 0.15, ..IcpConfig::default() };
    /// let (mut vlp16, mut os1_128) = (rule, rule);
    /// vlp16.fit_to_scan(28_800);
    /// os1_128.fit_to_scan(131_072);
    /// assert_eq!((vlp16.target_voxel, os1_128.target_voxel), (0.15, 0.2));
    /// ```
    pub fn fit_to_scan(&mut self, points: usize) {
        if self.sparse_scan_points > 0 && points <= self.sparse_scan_points {
            self.target_voxel = self.sparse_target_voxel;
        }
        self.sparse_scan_points = 0;
    }

    /// These settings with the correspondence reach and the kernel's threshold of `reach` (a
    /// kernel without a threshold stays as it is), for a tracker's coarse stage: at most 600
    /// source points, a coarse stride of at least 4, tolerances of at least 1 mm and 1 mrad and
    /// no degeneracy remapping, since the tracker's own fine alignment follows.
    ///
    /// # Errors
    /// [`RegistrationError::InvalidConfig`] for a `reach` that is not finite and positive.
    pub fn within(&self, reach: &slam_core::Reach) -> Result<Self, RegistrationError> {
        check(
            reach.distance.is_finite() && reach.distance > 0.0,
            "Reach::distance",
            reach.distance,
            POSITIVE,
        )?;
        check(
            reach.kernel.is_finite() && reach.kernel > 0.0,
            "Reach::kernel",
            reach.kernel,
            POSITIVE,
        )?;
        let kernel = match self.kernel {
            IcpKernel::None => IcpKernel::None,
            IcpKernel::Huber { .. } => IcpKernel::Huber { k: reach.kernel },
            IcpKernel::Tukey { .. } => IcpKernel::Tukey { k: reach.kernel },
        };
        Ok(Self {
            max_correspondence_distance: reach.distance,
            kernel,
            // A wide reach pulls a scan into the basin of the alignment that follows: every
            // fourth point first, and millimetres are enough.
            coarse_stride: self.coarse_stride.max(4),
            max_source_points: match self.max_source_points {
                0 => WIDE_SOURCE_POINTS,
                n => n.min(WIDE_SOURCE_POINTS),
            },
            // A wide stage must move the guess along every direction.
            degeneracy_threshold: 0.0,
            translation_tolerance: self.translation_tolerance.max(WIDE_TRANSLATION_TOLERANCE),
            rotation_tolerance: self.rotation_tolerance.max(WIDE_ROTATION_TOLERANCE),
            ..*self
        })
    }

    /// Checks every setting: voxels finite and not negative; reach, kernel threshold and
    /// tolerances finite and positive (tolerances and the degeneracy threshold may be 0);
    /// `min_planarity` 0 to 1; at least one iteration, 3 normal neighbours, one correspondence;
    /// `pair_target_points` 1 to 16; `coarse_stride` at least 1.
    /// Preparation and alignment call it, so a bad setting is an error, not a silent change.
    ///
    /// # Errors
    /// [`InvalidSetting`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        let c = self;
        for (setting, v) in [
            ("IcpConfig::source_voxel", c.source_voxel),
            ("IcpConfig::target_voxel", c.target_voxel),
            ("IcpConfig::sparse_target_voxel", c.sparse_target_voxel),
        ] {
            InvalidSetting::check_f32(v.is_finite() && v >= 0.0, setting, v, NON_NEGATIVE)?;
        }
        let reach = c.max_correspondence_distance;
        InvalidSetting::check(
            reach.is_finite() && reach > 0.0,
            "IcpConfig::max_correspondence_distance",
            reach,
            POSITIVE,
        )?;
        for (setting, v) in [
            ("IcpConfig::translation_tolerance", c.translation_tolerance),
            ("IcpConfig::rotation_tolerance", c.rotation_tolerance),
            ("IcpConfig::degeneracy_threshold", c.degeneracy_threshold),
        ] {
            InvalidSetting::check(v.is_finite() && v >= 0.0, setting, v, NON_NEGATIVE)?;
        }
        if let IcpKernel::Huber { k } | IcpKernel::Tukey { k } = c.kernel {
            InvalidSetting::check(
                k.is_finite() && k > 0.0,
                "IcpConfig::kernel",
                k,
                "a finite and positive threshold",
            )?;
        }
        InvalidSetting::check(
            (0.0..=1.0).contains(&c.min_planarity),
            "IcpConfig::min_planarity",
            c.min_planarity,
            "0 to 1",
        )?;
        for (setting, v, least, expected) in [
            (
                "IcpConfig::max_iterations",
                c.max_iterations,
                1,
                "at least 1",
            ),
            (
                "IcpConfig::min_correspondences",
                c.min_correspondences,
                1,
                "at least 1",
            ),
            (
                "IcpConfig::normal_neighbours",
                c.normal_neighbours,
                3,
                "at least 3",
            ),
            (
                "IcpConfig::pair_target_points",
                c.pair_target_points,
                1,
                "1 to 16",
            ),
            (
                "IcpConfig::coarse_stride",
                c.coarse_stride,
                1,
                "at least 1 (1 skips the coarse stage)",
            ),
        ] {
            InvalidSetting::check(v >= least, setting, v as f64, expected)?;
        }
        InvalidSetting::check(
            c.pair_target_points <= 16,
            "IcpConfig::pair_target_points",
            c.pair_target_points as f64,
            "1 to 16",
        )
    }
}

/// An alignment [`IcpConfig::within`] a reach uses at most this many source points: it only
/// brings the guess into the basin of the alignment that follows (on the hand-held OS1-128 walk
/// 600 points do that as well as 2,500, in half the time).
const WIDE_SOURCE_POINTS: usize = 600;
/// An alignment [`IcpConfig::within`] a reach converges once a step moves less than this
/// (metres) ...
const WIDE_TRANSLATION_TOLERANCE: f64 = 1e-3;
/// ... and turns less than this (radians).
const WIDE_ROTATION_TOLERANCE: f64 = 1e-3;

/// "Finite and not negative", the range of voxel sizes and tolerances.
pub(crate) const NON_NEGATIVE: &str = "finite and not negative";
/// "Finite and positive", the range of distances and thresholds.
pub(crate) const POSITIVE: &str = "finite and positive";

/// [`RegistrationError::InvalidConfig`] for `setting` unless `ok`.
pub(crate) fn check(
    ok: bool,
    setting: &'static str,
    value: f64,
    expected: &'static str,
) -> Result<(), RegistrationError> {
    Ok(InvalidSetting::check(ok, setting, value, expected)?)
}

/// [`check`] for an `f32` setting, whose value the error gives as written.
pub(crate) fn check_f32(
    ok: bool,
    setting: &'static str,
    value: f32,
    expected: &'static str,
) -> Result<(), RegistrationError> {
    Ok(InvalidSetting::check_f32(ok, setting, value, expected)?)
}
