//! How to reach a Spot and how the client paces its background work.

use std::fmt;
use std::time::Duration;

use crate::grpc::ConfigProblem;
use crate::grpc::error::SpotError;
use crate::robot::RobotDescription;

/// A user name and password for the robot's auth service. `Debug` shows the user name only;
/// the password leaves the process in `GetAuthToken` and nowhere else.
#[derive(Clone)]
pub struct Credentials {
    username: String,
    password: String,
}

impl Credentials {
    /// Credentials from a user name and a password (read from an environment variable or a
    /// prompt, never from a command line).
    #[must_use]
    pub fn new(username: impl Into<String>, password: impl Into<String>) -> Self {
        Self {
            username: username.into(),
            password: password.into(),
        }
    }

    /// The user name.
    #[must_use]
    pub fn username(&self) -> &str {
        &self.username
    }

    pub(crate) fn password(&self) -> &str {
        &self.password
    }
}

impl fmt::Debug for Credentials {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Credentials")
            .field("username", &self.username)
            .field("password", &"<hidden>")
            .finish()
    }
}

/// How time sync runs: the first rounds before anything moves, then one round now and then in
/// the background.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeSyncConfig {
    /// Rounds tried at connection before giving up on convergence: 20.
    pub max_initial_rounds: usize,
    /// Pause between the first rounds: 50 ms.
    pub round_interval: Duration,
    /// Pause between background rounds: 5 s.
    pub resync_interval: Duration,
    /// Oldest converged estimate a motion command may be timed with: 30 s.
    pub max_age: Duration,
}

impl Default for TimeSyncConfig {
    fn default() -> Self {
        Self {
            max_initial_rounds: 20,
            round_interval: Duration::from_millis(50),
            resync_interval: Duration::from_secs(5),
            max_age: Duration::from_secs(30),
        }
    }
}

/// Everything [`SpotClient::connect`](crate::grpc::SpotClient::connect) needs. No `Default`
/// (there is no default robot): start from [`SpotConfig::new`] and change fields, or write
/// `SpotConfig { port: 8443, ..SpotConfig::new(host, ca_pem, credentials) }`.
#[derive(Clone, Debug)]
pub struct SpotConfig {
    /// The robot's address: a host name or IP (a Spot on its own Wi-Fi: `192.168.80.3`).
    pub host: String,
    /// The robot's TLS port: 443.
    pub port: u16,
    /// The CA certificate (PEM) the robot's certificate must chain to: for a Spot, Boston
    /// Dynamics' root CA, given by the user.
    pub ca_pem: Vec<u8>,
    /// Who logs in.
    pub credentials: Credentials,
    /// The name the robot shows for this client (request headers, lease owner): `spot-nav`.
    pub client_name: String,
    /// Longest wait for any one call, connection included: 5 s.
    pub call_timeout: Duration,
    /// How often the auth token is renewed (the robot's tokens live much longer): 30 min.
    pub token_refresh_interval: Duration,
    /// Take the body lease (`TakeLease`, the tablet's "force take") instead of acquiring it
    /// (`AcquireLease`, refused while another client such as the tablet holds it): `false`.
    pub take_lease: bool,
    /// Register a software E-stop endpoint of our own with this timeout (the robot cuts motor
    /// power when no check-in arrives within it) and keep it alive, checking in every third
    /// of it, as the SDK's `EstopEndpoint` and `EstopKeepAlive`: for a bench setup without an
    /// E-stop controller. `None` (the default): the tablet's or a controller's E-stop is used.
    pub software_estop: Option<Duration>,
    /// How often the lease is retained: 2 s, as the SDK's `LeaseKeepAlive`.
    pub lease_retain_interval: Duration,
    /// Time sync pacing.
    pub time_sync: TimeSyncConfig,
    /// The directory name of the point cloud service: `velodyne-point-cloud`.
    pub point_cloud_service: String,
    /// The point cloud source asked for: `velodyne-point-cloud`.
    pub point_cloud_source: String,
    /// How long a velocity command holds before the robot stops by itself: 0.6 s, a few LiDAR
    /// periods, so a driver that falls silent leaves the robot standing.
    pub velocity_hold: Duration,
    /// Time past a trajectory's last point before its command ends: 1 s.
    pub trajectory_slack: Duration,
    /// The longest wait for the motors to power on or off: 20 s (the SDK's `power_on`).
    pub power_timeout: Duration,
    /// The longest wait for the robot to stand or sit: 10 s (the SDK's `blocking_stand`).
    pub posture_timeout: Duration,
    /// How long the odometry may stay unchanged while the robot is commanded to move before
    /// the client reports [`SpotError::NotMoving`](crate::grpc::SpotError::NotMoving): 3 s.
    pub stall_timeout: Duration,
    /// The fixed period of motion commands: 0.1 s (10 Hz); a command asked for sooner waits.
    pub command_period: Duration,
    /// How often the robot state's E-stops and faults are checked while running: 0.5 s.
    pub health_interval: Duration,
    /// Geometry and speed limits (commands are clamped to the limits and the limits are sent
    /// to the robot as `MobilityParams.vel_limit`).
    pub description: RobotDescription,
}

impl SpotConfig {
    /// A configuration with the defaults above for `host`, its CA and credentials.
    #[must_use]
    pub fn new(host: impl Into<String>, ca_pem: Vec<u8>, credentials: Credentials) -> Self {
        Self {
            host: host.into(),
            port: 443,
            ca_pem,
            credentials,
            client_name: "spot-nav".to_owned(),
            call_timeout: Duration::from_secs(5),
            token_refresh_interval: Duration::from_secs(30 * 60),
            take_lease: false,
            software_estop: None,
            lease_retain_interval: Duration::from_secs(2),
            time_sync: TimeSyncConfig::default(),
            point_cloud_service: "velodyne-point-cloud".to_owned(),
            point_cloud_source: "velodyne-point-cloud".to_owned(),
            velocity_hold: Duration::from_millis(600),
            trajectory_slack: Duration::from_secs(1),
            power_timeout: Duration::from_secs(20),
            posture_timeout: Duration::from_secs(10),
            stall_timeout: Duration::from_secs(3),
            command_period: Duration::from_millis(100),
            health_interval: Duration::from_millis(500),
            description: RobotDescription::default(),
        }
    }

    /// Every setting usable.
    ///
    /// # Errors
    /// [`SpotError::InvalidConfig`] naming the first bad setting.
    pub fn validate(&self) -> Result<(), SpotError> {
        let bad = |setting: &'static str, problem: ConfigProblem| {
            Err(SpotError::InvalidConfig { setting, problem })
        };
        if self.host.is_empty() {
            return bad("host", ConfigProblem::Empty);
        }
        if self.ca_pem.is_empty() {
            return bad("ca_pem", ConfigProblem::NoCaCertificate);
        }
        for (setting, value) in [
            ("call_timeout", self.call_timeout),
            ("token_refresh_interval", self.token_refresh_interval),
            ("lease_retain_interval", self.lease_retain_interval),
            ("time_sync.resync_interval", self.time_sync.resync_interval),
            ("time_sync.max_age", self.time_sync.max_age),
            ("velocity_hold", self.velocity_hold),
            (
                "software_estop",
                self.software_estop.unwrap_or(Duration::from_secs(1)),
            ),
        ] {
            if value.is_zero() {
                return bad(setting, ConfigProblem::ZeroDuration);
            }
        }
        if self.time_sync.max_initial_rounds == 0 {
            return bad("time_sync.max_initial_rounds", ConfigProblem::NoRounds);
        }
        if let Err(error) = self.description.limits.validate() {
            return bad("description.limits", ConfigProblem::Limits(error));
        }
        Ok(())
    }
}
