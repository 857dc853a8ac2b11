//! The registrator traits of an ICP backend, written once for both: a backend is its
//! [`IcpConfig`](crate::IcpConfig) and an [`IcpStep`](crate::icp::IcpStep), and its
//! [`Registrator`](slam_core::Registrator) and [`MapRegistrator`](slam_core::MapRegistrator)
//! impls hand the two to the shared loop ([`crate::icp`]) and target ([`crate::icp_target`]).

/// Implements [`Registrator`](slam_core::Registrator) and
/// [`MapRegistrator`](slam_core::MapRegistrator) for `$backend`, a struct with a
/// `config: IcpConfig` field, whose step is `$step`.
macro_rules! icp_backend {
    ($backend:ty, $step:ty) => {
        impl slam_core::Registrator for $backend {
            type Source = Vec<nalgebra::Point3<f64>>;
            type Target = $crate::target::PreparedTarget;

            fn prepare_source(
                &self,
                cloud: &slam_core::PointCloud,
            ) -> Result<Self::Source, slam_core::RegistrationError> {
                $crate::target::prepare_source_points(&self.config, cloud)
            }

            fn prepare_target(
                &self,
                cloud: &slam_core::PointCloud,
            ) -> Result<Self::Target, slam_core::RegistrationError> {
                $crate::icp_target::prepare_target::<$step>(&self.config, cloud)
            }

            fn align(
                &self,
                source: &Self::Source,
                target: &Self::Target,
                initial: &slam_core::Pose3,
            ) -> Result<slam_core::Alignment, slam_core::RegistrationError> {
                $crate::icp::align::<$step>(&self.config, source, target, initial)
            }

            fn align_within(
                &self,
                source: &Self::Source,
                target: &Self::Target,
                initial: &slam_core::Pose3,
                reach: &slam_core::Reach,
            ) -> Result<slam_core::Alignment, slam_core::RegistrationError> {
                $crate::icp::align::<$step>(&self.config.within(reach)?, source, target, initial)
            }

            /// Point-to-plane registration of the sweep together with the correction to the
            /// velocity it was deskewed with (see the crate docs' sweep section); `None` for
            /// point-to-point.
            fn align_sweep(
                &self,
                sweep: &slam_core::PointCloud,
                target: &Self::Target,
                initial: &slam_core::Pose3,
            ) -> Option<Result<slam_core::SweepAlignment, slam_core::RegistrationError>> {
                <$step as $crate::icp::IcpStep>::align_sweep(&self.config, sweep, target, initial)
            }
        }

        impl slam_core::MapRegistrator for $backend {
            fn target_from_sources(
                &self,
                parts: &[(&Self::Source, slam_core::Pose3)],
            ) -> Result<Self::Target, slam_core::RegistrationError> {
                $crate::icp_target::target_from_sources::<$step>(&self.config, parts)
            }

            /// With [`IcpConfig::sparse_scan_points`](crate::IcpConfig::sparse_scan_points)
            /// above zero, a scan of at most that many points sets the map's voxel to
            /// [`IcpConfig::sparse_target_voxel`](crate::IcpConfig::sparse_target_voxel) (and
            /// the rule is then spent: a later call changes nothing).
            fn fit_to_scan(&mut self, points: usize) {
                self.config.fit_to_scan(points);
            }

            /// [`IcpConfig::target_voxel`](crate::IcpConfig::target_voxel) (0 when the map keeps
            /// every point).
            fn map_voxel(&self) -> Option<f32> {
                Some(self.config.target_voxel)
            }

            /// The source as it is: its voxel centroids are already as thin as a map takes them.
            fn keyframe_source(&self, source: Self::Source) -> Self::Source {
                source
            }

            /// The points' coordinates as little-endian f64, exactly.
            fn stored_source(&self, source: &Self::Source) -> Option<Vec<u8>> {
                Some($crate::icp_target::points_to_bytes(source))
            }

            fn restored_source(&self, bytes: &[u8]) -> Option<Self::Source> {
                $crate::icp_target::points_from_bytes(bytes)
            }

            /// [`IcpConfig::source_voxel`](crate::IcpConfig::source_voxel) when above zero: the
            /// source is the scan's voxel centroids.
            fn source_voxel(&self) -> Option<f32> {
                $crate::icp_target::source_voxel(&self.config)
            }

            /// With a [`IcpConfig::target_voxel`](crate::IcpConfig::target_voxel) above zero
            /// (and a valid configuration), a map kept as per-voxel sums: a keyframe enters and
            /// leaves at the cost of its own points, and the k-d tree is rebuilt over the voxel
            /// centroids on the first alignment after a change. It holds the points
            /// [`MapRegistrator::target_from_sources`](slam_core::MapRegistrator::target_from_sources)
            /// would (up to rounding).
            fn empty_map(&self) -> Option<Self::Target> {
                $crate::icp_target::empty_map::<$step>(&self.config)
            }

            fn add_to_map(
                &self,
                map: &mut Self::Target,
                key: u32,
                source: &Self::Source,
                pose: &slam_core::Pose3,
            ) {
                map.add_part(key, source, pose);
            }

            fn remove_from_map(&self, map: &mut Self::Target, key: u32) {
                map.remove_part(key);
            }

            /// The map's k-d tree (rebuilt after each change of an in-place map) built on one
            /// core while `beside` runs on the other.
            fn ready_map_beside(&self, map: &mut Self::Target, beside: &mut (dyn FnMut() + Send)) {
                map.index_beside(beside);
            }

            /// The map's k-d tree (after a change of an in-place map) built on a thread of its
            /// own from now until the next alignment claims it.
            fn ready_map_ahead(&self, map: &mut Self::Target) {
                map.index_ahead();
            }
        }
    };
}

pub(crate) use icp_backend;
