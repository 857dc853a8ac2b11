//! The error enum of the gRPC client. No variant holds a password or a token: errors are safe
//! to log.

use crate::grpc::{CloudProblem, ConfigProblem, GridProblem};
use thiserror::Error;

/// Why a call to a Spot failed, or why the client refused to make it.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SpotError {
    /// A setting of [`SpotConfig`](crate::grpc::SpotConfig) is unusable.
    #[error("setting {setting}")]
    InvalidConfig {
        /// The setting, as its field is named.
        setting: &'static str,
        /// What is wrong with it.
        #[source]
        problem: ConfigProblem,
    },
    /// The robot's CA certificate or address cannot be used for a TLS channel.
    #[error("cannot set up a TLS channel to {address} as {authority}")]
    Channel {
        /// `host:port` dialled.
        address: String,
        /// The authority (TLS name) of the channel.
        authority: String,
        /// The cause.
        #[source]
        source: tonic::transport::Error,
    },
    /// The robot cannot be reached (refused, unroutable, TLS handshake failed, connection lost).
    #[error("{method}: the robot at {address} cannot be reached")]
    Unreachable {
        /// The RPC attempted.
        method: &'static str,
        /// `host:port` dialled.
        address: String,
        /// gRPC's status, with the transport error as its source.
        #[source]
        source: tonic::Status,
    },
    /// An RPC did not answer within the call timeout.
    #[error("{method}: no answer within {seconds} s")]
    Timeout {
        /// The RPC attempted.
        method: &'static str,
        /// The timeout, seconds.
        seconds: f64,
    },
    /// An RPC failed with a gRPC status other than "unavailable" or "deadline exceeded".
    #[error("{method}: the robot answered gRPC status {code:?}")]
    Rpc {
        /// The RPC attempted.
        method: &'static str,
        /// The gRPC status code.
        code: tonic::Code,
        /// The status itself.
        #[source]
        source: tonic::Status,
    },
    /// The robot refused the user name and password, or the token it is asked to refresh.
    #[error("the robot refused to log in user {username:?}: {status}")]
    Login {
        /// The user name (the password is never kept in an error).
        username: String,
        /// The refusal, as `GetAuthTokenResponse.Status` names it.
        status: &'static str,
    },
    /// A response header reports an error (or none at all, which the SDK treats as one).
    #[error("{method}: the robot reported error {code}: {message}")]
    ResponseHeader {
        /// The RPC.
        method: &'static str,
        /// `CommonError.Code` (0 unset, 2 internal, 3 invalid request).
        code: i32,
        /// The robot's message.
        message: String,
    },
    /// The robot's directory lists no service of this name.
    #[error("the robot's directory has no service {service:?}")]
    UnknownService {
        /// The service name looked up.
        service: String,
    },
    /// Time sync has not converged: no command can be timed in robot time.
    #[error("time sync has not converged (last status {status})")]
    TimeSyncNotConverged {
        /// The robot's last `TimeSyncState.Status`.
        status: &'static str,
    },
    /// The last converged time sync is too old to time a command.
    #[error("time sync is {age:.2} s old, at most {max_age:.2} s is allowed before moving")]
    TimeSyncStale {
        /// Seconds since the last converged round.
        age: f64,
        /// The configured bound, seconds.
        max_age: f64,
    },
    /// The robot would not grant the lease: `STATUS_RESOURCE_ALREADY_CLAIMED` while another
    /// client (the tablet) holds it, which [`SpotConfig::take_lease`] takes from it.
    ///
    /// [`SpotConfig::take_lease`]: crate::grpc::SpotConfig::take_lease
    #[error("the lease of {resource:?} was refused: {status} (held by {owner:?})")]
    LeaseRefused {
        /// The resource asked for (`body`).
        resource: String,
        /// `AcquireLeaseResponse.Status` (or `TakeLeaseResponse.Status`) as named on the wire.
        status: &'static str,
        /// The client holding it, when the robot says.
        owner: String,
    },
    /// The lease is no longer ours (taken by another client, revoked): no more commands.
    #[error("the lease is lost: {status} (now held by {owner:?})")]
    LeaseLost {
        /// `LeaseUseResult.Status` as named on the wire.
        status: &'static str,
        /// The client holding it now, when the robot says.
        owner: String,
    },
    /// The robot refused a command.
    #[error("the robot refused the command: {status} {message:?}")]
    CommandRefused {
        /// `RobotCommandResponse.Status` as named on the wire.
        status: &'static str,
        /// The robot's message.
        message: String,
    },
    /// A frame lookup failed.
    #[error(transparent)]
    Frame(#[from] crate::grpc::FrameError),
    /// A point cloud could not be decoded.
    #[error("point cloud from {source_name:?}")]
    MalformedCloud {
        /// The point cloud source.
        source_name: String,
        /// What is wrong.
        #[source]
        problem: CloudProblem,
    },
    /// A local grid could not be decoded.
    #[error("local grid {grid:?}")]
    MalformedGrid {
        /// The grid type name.
        grid: String,
        /// What is wrong.
        #[source]
        problem: GridProblem,
    },
    /// The robot has no data for a request (an unknown source or grid, data unavailable).
    #[error("{what:?}: the robot answered {status}")]
    NoData {
        /// The point cloud source or local grid asked for.
        what: String,
        /// The response status as named on the wire.
        status: &'static str,
    },
    /// The robot delivered no scan newer than the last one within the call timeout.
    #[error("no new scan from {source_name:?} within {seconds} s")]
    NoNewScan {
        /// The point cloud source.
        source_name: String,
        /// Seconds waited.
        seconds: f64,
    },
    /// A step of bringing the robot up or down (power on, stand, sit, power off) did not
    /// finish within its timeout.
    #[error("{step}: not done within {seconds} s (the robot's last reply: {last_reply})")]
    StepTimedOut {
        /// The step: `power on`, `stand`, `sit`, `power off`.
        step: &'static str,
        /// The step's timeout, seconds.
        seconds: f64,
        /// What the robot last said about it.
        last_reply: String,
    },
    /// The robot refused or abandoned a step of bringing it up or down.
    #[error("{step}: the robot answered {reply}")]
    StepFailed {
        /// The step: `power on`, `stand`, `sit`, `power off`.
        step: &'static str,
        /// The robot's reply (a status as named on the wire, blocking faults).
        reply: String,
    },
    /// An E-stop is asserted: the robot cannot move until it is released.
    #[error("E-stop asserted: {names:?}; release it (E-stop controller or tablet) and start again")]
    EStopped {
        /// The asserted E-stops' names.
        names: Vec<String>,
    },
    /// No E-stop endpoint is registered, so nothing could stop the robot in an emergency.
    #[error(
        "no E-stop endpoint is registered: connect the tablet or an E-stop controller to the \
         robot and keep its E-stop in hand, then start again"
    )]
    NoEStop,
    /// The robot reports system or behaviour faults.
    #[error(
        "the robot reports faults: system {system:?}, behaviour {behavior:?}; clear them \
         (tablet) and start again"
    )]
    Faulted {
        /// Names of the active system faults.
        system: Vec<String>,
        /// Active behaviour faults, `CAUSE_* (STATUS_*)`.
        behavior: Vec<String>,
    },
    /// The odometry did not change while the robot was commanded to move.
    #[error(
        "the robot does not respond: commanded to move for {seconds:.1} s, its odometry did not change"
    )]
    NotMoving {
        /// Seconds commanded to move without the odometry changing.
        seconds: f64,
    },
    /// The robot refused our software E-stop endpoint or its check-in.
    #[error("software E-stop: {method} answered {status}")]
    EstopRefused {
        /// `RegisterEstopEndpoint` or `EstopCheckIn`.
        method: &'static str,
        /// The response status as named on the wire.
        status: &'static str,
    },
    /// The run was interrupted (Ctrl-C).
    #[error("interrupted")]
    Interrupted,
    /// The client's async runtime could not be started.
    #[error("the client's runtime could not start")]
    Runtime(#[source] std::io::Error),
}
