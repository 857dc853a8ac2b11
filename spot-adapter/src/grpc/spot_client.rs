//! [`SpotClient`]: a blocking client of a real Spot over a small tokio runtime of its own, and
//! the [`Robot`] the navigator drives.

use std::sync::Arc;
use std::time::{Duration, Instant};

use tokio::runtime::Runtime;
use tokio::task::JoinHandle;

use crate::grpc::config::SpotConfig;
use crate::grpc::directory::RobotIdentity;
use crate::grpc::error::SpotError;
use crate::grpc::frame_tree::FrameTree;
use crate::grpc::local_grid::LocalGrid;
use crate::grpc::point_cloud::SpotCloud;
use crate::grpc::session::Session;
use crate::robot::{MobilityCommand, Robot, RobotDescription, Sample};

/// First pause before retrying a failed token renewal.
const RENEWAL_RETRY: Duration = Duration::from_secs(1);

/// Pause between two asks for a scan newer than the last one.
const SCAN_POLL: Duration = Duration::from_millis(20);

/// A connected, authenticated client holding the body lease.
///
/// [`SpotClient::connect`] logs in, reads the directory, syncs time and acquires the lease;
/// in the background it then retains the lease every [`SpotConfig::lease_retain_interval`],
/// runs a time-sync round every [`TimeSyncConfig::resync_interval`](crate::grpc::TimeSyncConfig)
/// and renews the token every [`SpotConfig::token_refresh_interval`]. Dropping it stops the
/// background work and returns the lease. Every call waits at most
/// [`SpotConfig::call_timeout`].
///
/// It is a blocking client with a one-thread tokio runtime of its own: call it from ordinary
/// threads, not from inside another async runtime (tokio refuses to block there).
pub struct SpotClient {
    session: Arc<Session>,
    runtime: Runtime,
    background: Vec<JoinHandle<()>>,
    identity: RobotIdentity,
    last_scan_time: Option<f64>,
}

impl SpotClient {
    /// Connect to the robot of `config`.
    ///
    /// # Errors
    /// [`SpotError::InvalidConfig`], [`SpotError::Unreachable`], [`SpotError::Login`] for bad
    /// credentials, [`SpotError::UnknownService`] for a directory without a service we need,
    /// [`SpotError::TimeSyncNotConverged`], [`SpotError::LeaseRefused`], and any call's error.
    pub fn connect(config: SpotConfig) -> Result<Self, SpotError> {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .worker_threads(1)
            .thread_name("spot-client")
            .enable_all()
            .build()
            .map_err(SpotError::Runtime)?;
        let session = Arc::new(runtime.block_on(async { Session::new(config) })?);
        let identity = runtime.block_on(async {
            session.authenticate().await?;
            let identity = session.robot_id().await?;
            session.read_directory().await?;
            session.converge_time_sync().await?;
            session.acquire_lease().await?;
            Ok::<_, SpotError>(identity)
        })?;
        let background = spawn_background(&runtime, &session);
        Ok(Self {
            session,
            runtime,
            background,
            identity,
            last_scan_time: None,
        })
    }

    /// Who the robot said it is.
    #[must_use]
    pub fn identity(&self) -> &RobotIdentity {
        &self.identity
    }

    /// The service names the robot's directory lists.
    #[must_use]
    pub fn services(&self) -> Vec<String> {
        self.session.service_names()
    }

    /// Robot clock minus this host's clock (seconds), from the last converged time sync.
    #[must_use]
    pub fn clock_skew(&self) -> Option<f64> {
        self.session
            .clock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .skew
    }

    /// The robot's time now (seconds since the epoch, robot clock).
    ///
    /// # Errors
    /// [`SpotError::TimeSyncNotConverged`] or [`SpotError::TimeSyncStale`].
    pub fn robot_time(&self) -> Result<f64, SpotError> {
        Ok(self.session.robot_now()?.0)
    }

    /// The frame tree of the robot's current state.
    ///
    /// # Errors
    /// Any call's error, [`SpotError::Frame`] for an invalid transform.
    pub fn frame_tree(&self) -> Result<FrameTree, SpotError> {
        self.runtime.block_on(self.session.frame_tree())
    }

    /// The latest scan of the configured point cloud source.
    ///
    /// # Errors
    /// Any call's error, [`SpotError::NoData`] for an unknown source,
    /// [`SpotError::MalformedCloud`] for a cloud that cannot be decoded.
    pub fn point_cloud(&self) -> Result<SpotCloud, SpotError> {
        self.runtime.block_on(self.session.point_cloud())
    }

    /// The local grids named `names` (`terrain`, `no_step`, `obstacle_distance`, ...).
    ///
    /// # Errors
    /// Any call's error, [`SpotError::NoData`] for a grid the robot does not have,
    /// [`SpotError::MalformedGrid`] for one that cannot be decoded.
    pub fn local_grids(&self, names: &[&str]) -> Result<Vec<LocalGrid>, SpotError> {
        self.runtime.block_on(self.session.local_grids(names))
    }

    /// Send a motion command; returns the robot's command id.
    ///
    /// # Errors
    /// [`SpotError::LeaseLost`], [`SpotError::TimeSyncNotConverged`] or
    /// [`SpotError::TimeSyncStale`] before anything is sent; [`SpotError::CommandRefused`] and
    /// any call's error after.
    pub fn command(&self, command: &MobilityCommand) -> Result<u32, SpotError> {
        self.runtime.block_on(self.session.send_mobility(command))
    }

    /// Stand still.
    ///
    /// # Errors
    /// [`SpotError::LeaseLost`], [`SpotError::CommandRefused`] and any call's error.
    pub fn stand_still(&self) -> Result<u32, SpotError> {
        self.runtime.block_on(self.session.send_stop())
    }

    /// Renew the auth token now (the background does it on its interval).
    ///
    /// # Errors
    /// [`SpotError::Login`] when the robot refuses the token, and any call's error.
    pub fn refresh_token(&self) -> Result<(), SpotError> {
        let token = self.session.current_token();
        self.runtime.block_on(self.session.refresh_token(token))
    }

    /// Why the lease is lost, if it is: `(LeaseUseResult status, new owner)`.
    #[must_use]
    pub fn lease_lost(&self) -> Option<(&'static str, String)> {
        self.session
            .lease
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .lost
            .clone()
    }

    /// A scan newer than the last one delivered, as a [`Sample`].
    fn next_scan(&mut self) -> Result<Sample, SpotError> {
        let deadline = Instant::now() + self.session.config.call_timeout;
        let scan = loop {
            let scan = self.point_cloud()?;
            if self
                .last_scan_time
                .is_none_or(|t| scan.acquisition_time > t)
            {
                break scan;
            }
            if Instant::now() > deadline {
                return Err(SpotError::NoNewScan {
                    source_name: self.session.config.point_cloud_source.clone(),
                    seconds: self.session.config.call_timeout.as_secs_f64(),
                });
            }
            std::thread::sleep(SCAN_POLL);
        };
        self.last_scan_time = Some(scan.acquisition_time);
        let odom_t_body = scan.frames.a_t_b("odom", "body")?;
        let body_t_lidar = scan.frames.a_t_b("body", &scan.frame_name)?;
        Ok(Sample {
            stamp: scan.acquisition_time,
            odom_t_body,
            body_t_lidar,
            cloud: scan.cloud,
            ground_truth: None,
            gyro_orientation: None,
        })
    }
}

impl std::fmt::Debug for SpotClient {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpotClient")
            .field("host", &self.session.config.host)
            .field("identity", &self.identity)
            .field("lease_lost", &self.lease_lost())
            .finish_non_exhaustive()
    }
}

impl Robot for SpotClient {
    type Error = SpotError;

    fn description(&self) -> &RobotDescription {
        &self.session.config.description
    }

    fn next_sample(&mut self) -> Result<Sample, SpotError> {
        self.next_scan()
    }

    fn send(&mut self, command: &MobilityCommand) -> Result<(), SpotError> {
        self.command(command).map(|_| ())
    }

    fn stop(&mut self) -> Result<(), SpotError> {
        self.stand_still().map(|_| ())
    }
}

impl Drop for SpotClient {
    fn drop(&mut self) {
        for task in &self.background {
            task.abort();
        }
        // Best effort: a robot that cannot be reached takes the lease back when retains stop.
        let _ = self.runtime.block_on(self.session.return_lease());
    }
}

/// The lease retain, time-sync and token renewal loops. Their failures are not fatal here:
/// a lost lease is recorded by the retain and refused at the next command, a stale time sync
/// is refused at the next motion, a failed renewal is retried soon.
fn spawn_background(runtime: &Runtime, session: &Arc<Session>) -> Vec<JoinHandle<()>> {
    let retain = Arc::clone(session);
    let sync = Arc::clone(session);
    let renew = Arc::clone(session);
    vec![
        runtime.spawn(async move {
            let mut ticks = ticks(retain.config.lease_retain_interval);
            loop {
                ticks.tick().await;
                let _ = retain.retain_lease().await;
            }
        }),
        runtime.spawn(async move {
            let mut ticks = ticks(sync.config.time_sync.resync_interval);
            loop {
                ticks.tick().await;
                let _ = sync.time_sync_round().await;
            }
        }),
        runtime.spawn(async move {
            // As the SDK's token manager: on a failed renewal retry after 1 s, doubling.
            let period = renew.config.token_refresh_interval;
            let mut wait = period;
            loop {
                tokio::time::sleep(wait).await;
                wait = match renew.refresh_token(renew.current_token()).await {
                    Ok(()) => period,
                    Err(_) if wait >= period => RENEWAL_RETRY.min(period),
                    Err(_) => (wait * 2).min(period),
                };
            }
        }),
    ]
}

/// Ticks every `period`, the first one `period` from now; late ticks are not bunched up.
fn ticks(period: Duration) -> tokio::time::Interval {
    let mut ticks = tokio::time::interval_at(tokio::time::Instant::now() + period, period);
    ticks.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    ticks
}
