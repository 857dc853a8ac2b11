//! [`SpotClient`]: a blocking client of a real Spot over a small tokio runtime of its own, and
//! the [`Robot`] the navigator drives.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use slam_core::Pose3;

use tokio::runtime::Runtime;
use tokio::task::JoinHandle;

use crate::grpc::config::SpotConfig;
use crate::grpc::directory::RobotIdentity;
use crate::grpc::error::SpotError;
use crate::grpc::estop::StopLevel;
use crate::grpc::frame_tree::FrameTree;
use crate::grpc::local_grid::LocalGrid;
use crate::grpc::point_cloud::SpotCloud;
use crate::grpc::posture::Posture;
use crate::grpc::robot_state::RobotStatus;
use crate::grpc::session::Session;
use crate::robot::{MobilityCommand, Robot, RobotDescription, Sample};

/// First pause before retrying a failed token renewal.
const RENEWAL_RETRY: Duration = Duration::from_secs(1);

/// Pause between two asks for a scan newer than the last one.
const SCAN_POLL: Duration = Duration::from_millis(20);

/// The odometry must move this much (metres, radians) to count as motion.
const MOTION_TRANSLATION: f64 = 0.01;
const MOTION_ROTATION: f64 = 0.01;

/// A command at least this fast (m/s, rad/s) asks the robot to move: over the 3 s stall
/// timeout it moves the odometry well past the motion thresholds above, so a crawl on the
/// final approach is not mistaken for a robot that does not respond.
const MOVING_SPEED: f64 = 0.05;

/// Since when the robot has been commanded to move, and where its odometry was then.
#[derive(Clone, Copy, Debug)]
struct Motion {
    since: Instant,
    odom_t_body: Pose3,
}

/// A connected, authenticated client holding the body lease.
///
/// [`SpotClient::connect`] logs in, reads the directory, syncs time and acquires the lease;
/// in the background it then retains the lease every [`SpotConfig::lease_retain_interval`],
/// runs a time-sync round every [`TimeSyncConfig::resync_interval`](crate::grpc::TimeSyncConfig)
/// and renews the token every [`SpotConfig::token_refresh_interval`]. Dropping it stops the
/// background work, sends a stop and returns the lease (also when a panic unwinds). Every
/// call waits at most [`SpotConfig::call_timeout`].
///
/// As a [`Robot`] it watches the robot it drives: each scan is delivered once (by its
/// acquisition time); motion commands go out at the fixed [`SpotConfig::command_period`];
/// every [`SpotConfig::health_interval`] the robot state is checked for E-stops and faults;
/// odometry unchanged for [`SpotConfig::stall_timeout`] while commanded to move ends the run
/// with [`SpotError::NotMoving`]; a raised interrupt flag ([`SpotClient::set_interrupt`])
/// with [`SpotError::Interrupted`].
///
/// It is a blocking client with a one-thread tokio runtime of its own: call it from ordinary
/// threads, not from inside another async runtime (tokio refuses to block there).
pub struct SpotClient {
    session: Arc<Session>,
    runtime: Runtime,
    background: Vec<JoinHandle<()>>,
    identity: RobotIdentity,
    last_scan_time: Option<f64>,
    last_odom_t_body: Option<Pose3>,
    motion: Option<Motion>,
    last_command: Option<Instant>,
    last_health: Option<Instant>,
    interrupt: Option<Arc<AtomicBool>>,
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
            session.acquire_lease(session.config.take_lease).await?;
            if let Some(timeout) = session.config.software_estop
                && let Err(error) = session.register_estop(timeout).await
            {
                let _ = session.return_lease().await;
                return Err(error);
            }
            Ok::<_, SpotError>(identity)
        })?;
        let background = spawn_background(&runtime, &session);
        Ok(Self {
            session,
            runtime,
            background,
            identity,
            last_scan_time: None,
            last_odom_t_body: None,
            motion: None,
            last_command: None,
            last_health: None,
            interrupt: None,
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

    /// Power, E-stops and faults as the robot state reports them now.
    ///
    /// # Errors
    /// Any call's error.
    pub fn status(&self) -> Result<RobotStatus, SpotError> {
        self.runtime.block_on(self.session.status())
    }

    /// Power the motors on (the SDK's `power_on`): `PowerCommand`, then its feedback and the
    /// robot state polled until the motors are on, within [`SpotConfig::power_timeout`].
    ///
    /// # Errors
    /// [`SpotError::StepFailed`] when the robot refuses (E-stopped, faulted),
    /// [`SpotError::StepTimedOut`], [`SpotError::EStopped`], [`SpotError::NoEStop`],
    /// [`SpotError::Faulted`], [`SpotError::LeaseLost`] and any call's error.
    pub fn power_on(&self) -> Result<(), SpotError> {
        let timeout = self.session.config.power_timeout;
        self.interruptible(self.session.power_on(timeout))
    }

    /// Stand (the SDK's `blocking_stand`): a synchronized stand command, then its feedback
    /// polled until standing, within [`SpotConfig::posture_timeout`].
    ///
    /// # Errors
    /// [`SpotError::StepFailed`], [`SpotError::StepTimedOut`], [`SpotError::LeaseLost`] and
    /// any call's error.
    pub fn stand(&self) -> Result<(), SpotError> {
        let timeout = self.session.config.posture_timeout;
        self.interruptible(self.session.blocking_posture(Posture::Stand, timeout))
    }

    /// Sit (the SDK's `blocking_sit`), within [`SpotConfig::posture_timeout`].
    ///
    /// # Errors
    /// As [`SpotClient::stand`].
    pub fn sit(&self) -> Result<(), SpotError> {
        let timeout = self.session.config.posture_timeout;
        self.runtime
            .block_on(self.session.blocking_posture(Posture::Sit, timeout))
    }

    /// Power the motors off safely (the SDK's `safe_power_off_motors`: the robot sits first),
    /// waiting for the robot state to say they are off, within [`SpotConfig::power_timeout`].
    ///
    /// # Errors
    /// [`SpotError::StepFailed`], [`SpotError::StepTimedOut`], [`SpotError::CommandRefused`],
    /// [`SpotError::LeaseLost`] and any call's error.
    pub fn power_off(&self) -> Result<(), SpotError> {
        let timeout = self.session.config.power_timeout;
        self.runtime.block_on(self.session.safe_power_off(timeout))
    }

    /// A flag that, once raised (by a Ctrl-C handler), makes the next sample or command fail
    /// with [`SpotError::Interrupted`], and ends a power-on or a stand being waited for.
    pub fn set_interrupt(&mut self, flag: Arc<AtomicBool>) {
        self.interrupt = Some(flag);
    }

    /// Run `step` to its end, or until the interrupt flag is raised (checked every 50 ms):
    /// then [`SpotError::Interrupted`], the step's remaining polls dropped.
    fn interruptible<T>(
        &self,
        step: impl Future<Output = Result<T, SpotError>>,
    ) -> Result<T, SpotError> {
        self.check_interrupt()?;
        let Some(flag) = self.interrupt.clone() else {
            return self.runtime.block_on(step);
        };
        self.runtime.block_on(async move {
            tokio::select! {
                result = step => result,
                () = async {
                    while !flag.load(Ordering::Relaxed) {
                        tokio::time::sleep(Duration::from_millis(50)).await;
                    }
                } => Err(SpotError::Interrupted),
            }
        })
    }

    fn check_interrupt(&self) -> Result<(), SpotError> {
        match &self.interrupt {
            Some(flag) if flag.load(Ordering::Relaxed) => Err(SpotError::Interrupted),
            _ => Ok(()),
        }
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

    /// E-stops and faults, every [`SpotConfig::health_interval`].
    fn check_health(&mut self) -> Result<(), SpotError> {
        if self
            .last_health
            .is_none_or(|t| t.elapsed() >= self.session.config.health_interval)
        {
            self.status()?.check_ready()?;
            self.last_health = Some(Instant::now());
        }
        Ok(())
    }

    /// [`SpotError::NotMoving`] when the odometry has not changed for the stall timeout while
    /// the robot was commanded to move.
    fn check_motion(&mut self, odom_t_body: Pose3) -> Result<(), SpotError> {
        self.last_odom_t_body = Some(odom_t_body);
        let Some(motion) = &mut self.motion else {
            return Ok(());
        };
        let step = motion.odom_t_body.inverse() * odom_t_body;
        if step.translation.vector.norm() > MOTION_TRANSLATION
            || step.rotation.angle() > MOTION_ROTATION
        {
            *motion = Motion {
                since: Instant::now(),
                odom_t_body,
            };
            return Ok(());
        }
        let still = motion.since.elapsed();
        if still > self.session.config.stall_timeout {
            return Err(SpotError::NotMoving {
                seconds: still.as_secs_f64(),
            });
        }
        Ok(())
    }

    /// Note whether `command` asks the robot to move (starting the stall clock).
    fn note_motion(&mut self, command: &MobilityCommand) {
        let moving = match command {
            MobilityCommand::Velocity(v) | MobilityCommand::Stairs(v) => {
                v.forward.abs().max(v.lateral.abs()).max(v.yaw_rate.abs()) > MOVING_SPEED
            }
            MobilityCommand::Trajectory(_) => true,
        };
        self.motion = match (moving, self.motion, self.last_odom_t_body) {
            (true, Some(motion), _) => Some(motion),
            (true, None, Some(odom_t_body)) => Some(Motion {
                since: Instant::now(),
                odom_t_body,
            }),
            _ => None,
        };
    }

    /// Wait for the next slot of the fixed command rate.
    fn pace(&mut self) {
        if let Some(last) = self.last_command {
            let next = last + self.session.config.command_period;
            let now = Instant::now();
            if next > now {
                std::thread::sleep(next - now);
            }
        }
        self.last_command = Some(Instant::now());
    }

    /// A scan newer than the last one delivered, as a [`Sample`].
    fn next_scan(&mut self) -> Result<Sample, SpotError> {
        self.check_interrupt()?;
        self.check_health()?;
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
            self.check_interrupt()?;
            std::thread::sleep(SCAN_POLL);
        };
        self.last_scan_time = Some(scan.acquisition_time);
        let odom_t_body = scan.frames.a_t_b("odom", "body")?;
        let body_t_lidar = scan.frames.a_t_b("body", &scan.frame_name)?;
        self.check_motion(odom_t_body)?;
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
        self.check_interrupt()?;
        self.pace();
        self.command(command)?;
        self.note_motion(command);
        Ok(())
    }

    fn stop(&mut self) -> Result<(), SpotError> {
        self.motion = None;
        self.stand_still().map(|_| ())
    }
}

impl Drop for SpotClient {
    fn drop(&mut self) {
        for task in &self.background {
            task.abort();
        }
        // Best effort: a robot that cannot be reached stops when the last velocity command
        // ends and takes the lease back when retains stop.
        let _ = self.runtime.block_on(async {
            let _ = self.session.send_stop().await;
            let returned = self.session.return_lease().await;
            let _ = self.session.estop_check_in(StopLevel::SettleThenCut).await;
            returned
        });
    }
}

/// The lease retain, time-sync and token renewal loops. Their failures are not fatal here:
/// a lost lease is recorded by the retain and refused at the next command, a stale time sync
/// is refused at the next motion, a failed renewal is retried soon.
fn spawn_background(runtime: &Runtime, session: &Arc<Session>) -> Vec<JoinHandle<()>> {
    let retain = Arc::clone(session);
    let sync = Arc::clone(session);
    let renew = Arc::clone(session);
    let estop = Arc::clone(session);
    let mut tasks = vec![
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
    ];
    if let Some(timeout) = estop.config.software_estop {
        // The SDK's `EstopKeepAlive`: a check-in every third of the endpoint's timeout.
        tasks.push(runtime.spawn(async move {
            let mut ticks = ticks(timeout / 3);
            loop {
                ticks.tick().await;
                let _ = estop.estop_check_in(StopLevel::None).await;
            }
        }));
    }
    tasks
}

/// Ticks every `period`, the first one `period` from now; late ticks are not bunched up.
fn ticks(period: Duration) -> tokio::time::Interval {
    let mut ticks = tokio::time::interval_at(tokio::time::Instant::now() + period, period);
    ticks.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    ticks
}
