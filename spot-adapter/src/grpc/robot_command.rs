//! Motion commands in the shapes the SDK's `RobotCommandBuilder` sends: a `body`-frame
//! `SE2VelocityCommand` or an `odom`/`vision` `SE2TrajectoryCommand` inside a synchronized
//! mobility command, with the speed limits as `MobilityParams`; a full-body stop. Motion
//! carries its end time in robot time, the robot's clock name and our lease.

use prost::Message;

use crate::grpc::api;
use crate::grpc::api::robot_command_service_client::RobotCommandServiceClient;
use crate::grpc::clock;
use crate::grpc::error::SpotError;
use crate::grpc::session::{Session, check_header};
use crate::robot::{MobilityCommand, MotionLimits, Se2Trajectory, VelocityCommand};

/// The velocity frame of Spot's mobility API: the body, gravity-aligned.
const VELOCITY_FRAME: &str = "body";
/// `MobilityParams` packed in a `google.protobuf.Any`.
const MOBILITY_PARAMS_TYPE_URL: &str = "type.googleapis.com/bosdyn.api.spot.MobilityParams";
/// The SDK's slew-rate limit for velocity commands (m/s^2, rad/s^2).
const SLEW_LINEAR: f64 = 4.0;
const SLEW_ANGULAR: f64 = 2.0;

fn se2_velocity(x: f64, y: f64, angular: f64) -> api::Se2Velocity {
    api::Se2Velocity {
        linear: Some(api::Vec2 { x, y }),
        angular,
    }
}

/// The limits as the robot's own velocity limit, and the stairs mode on for a walk over a
/// flight (left unset otherwise: the robot's default).
fn mobility_params(limits: &MotionLimits, stairs: bool) -> prost_types::Any {
    let params = api::spot::MobilityParams {
        stairs_mode: if stairs {
            api::spot::mobility_params::StairsMode::On as i32
        } else {
            0
        },
        vel_limit: Some(api::Se2VelocityLimit {
            max_vel: Some(se2_velocity(
                limits.max_forward_speed,
                limits.max_lateral_speed,
                limits.max_yaw_rate,
            )),
            min_vel: Some(se2_velocity(
                -limits.max_forward_speed,
                -limits.max_lateral_speed,
                -limits.max_yaw_rate,
            )),
        }),
    };
    prost_types::Any {
        type_url: MOBILITY_PARAMS_TYPE_URL.to_owned(),
        value: params.encode_to_vec(),
    }
}

fn mobility(
    command: api::mobility_command::request::Command,
    limits: &MotionLimits,
    stairs: bool,
) -> api::RobotCommand {
    api::RobotCommand {
        command: Some(api::robot_command::Command::SynchronizedCommand(
            api::synchronized_command::Request {
                mobility_command: Some(api::mobility_command::Request {
                    command: Some(command),
                    params: Some(mobility_params(limits, stairs)),
                }),
            },
        )),
    }
}

/// `command` clamped to `limits`, held until robot time `end_time`, with the stairs mode on
/// when `stairs`.
pub(crate) fn velocity_command(
    command: &VelocityCommand,
    limits: &MotionLimits,
    end_time: f64,
    stairs: bool,
) -> api::RobotCommand {
    let clamp = |v: f64, max: f64| v.clamp(-max, max);
    mobility(
        api::mobility_command::request::Command::Se2VelocityRequest(
            api::se2_velocity_command::Request {
                end_time: Some(clock::timestamp(end_time)),
                se2_frame_name: VELOCITY_FRAME.to_owned(),
                velocity: Some(se2_velocity(
                    clamp(command.forward, limits.max_forward_speed),
                    clamp(command.lateral, limits.max_lateral_speed),
                    clamp(command.yaw_rate, limits.max_yaw_rate),
                )),
                slew_rate_limit: Some(se2_velocity(SLEW_LINEAR, SLEW_LINEAR, SLEW_ANGULAR)),
            },
        ),
        limits,
        stairs,
    )
}

/// `trajectory` starting at robot time `reference_time`, ending at `end_time`.
pub(crate) fn trajectory_command(
    trajectory: &Se2Trajectory,
    limits: &MotionLimits,
    reference_time: f64,
    end_time: f64,
) -> api::RobotCommand {
    let points = trajectory
        .points()
        .iter()
        .map(|p| {
            let t = p.pose.translation.vector;
            api::Se2TrajectoryPoint {
                pose: Some(api::Se2Pose {
                    position: Some(api::Vec2 { x: t.x, y: t.y }),
                    angle: p.pose.rotation.angle(),
                }),
                time_since_reference: Some(clock::duration(p.time)),
            }
        })
        .collect();
    mobility(
        api::mobility_command::request::Command::Se2TrajectoryRequest(
            api::se2_trajectory_command::Request {
                end_time: Some(clock::timestamp(end_time)),
                se2_frame_name: trajectory.frame().name().to_owned(),
                trajectory: Some(api::Se2Trajectory {
                    points,
                    reference_time: Some(clock::timestamp(reference_time)),
                    interpolation: api::PositionalInterpolation::PosInterpUnknown as i32,
                }),
            },
        ),
        limits,
        false,
    )
}

/// Stand still: the SDK's `stop_command` (a full-body stop, no end time).
pub(crate) fn stop_command() -> api::RobotCommand {
    api::RobotCommand {
        command: Some(api::robot_command::Command::FullBodyCommand(
            api::full_body_command::Request {
                command: Some(api::full_body_command::request::Command::StopRequest(
                    api::stop_command::Request {},
                )),
            },
        )),
    }
}

impl Session {
    /// Send a mobility command: checked for finite values, timed in robot time (refused
    /// without a converged, fresh time sync), with our lease.
    pub(crate) async fn send_mobility(&self, command: &MobilityCommand) -> Result<u32, SpotError> {
        let limits = &self.config.description.limits;
        let lease = self.lease_for_command()?;
        let (robot_now, clock_identifier) = self.robot_now()?;
        let message = match command {
            MobilityCommand::Velocity(v) | MobilityCommand::Stairs(v) => {
                if !v.is_finite() {
                    return Err(SpotError::CommandRefused {
                        status: "NOT_SENT_NON_FINITE_VELOCITY",
                        message: String::new(),
                    });
                }
                velocity_command(
                    v,
                    limits,
                    robot_now + self.config.velocity_hold.as_secs_f64(),
                    matches!(command, MobilityCommand::Stairs(_)),
                )
            }
            MobilityCommand::Trajectory(t) => {
                let end = robot_now + t.duration() + self.config.trajectory_slack.as_secs_f64();
                trajectory_command(t, limits, robot_now, end)
            }
        };
        self.robot_command(message, lease, clock_identifier).await
    }

    /// Send a stop (needs the lease, not the time sync).
    pub(crate) async fn send_stop(&self) -> Result<u32, SpotError> {
        self.send_unclocked(stop_command()).await
    }

    /// Send a command without an end time (stop, stand, sit, safe power off): it needs the
    /// lease, not the time sync.
    pub(crate) async fn send_unclocked(
        &self,
        command: api::RobotCommand,
    ) -> Result<u32, SpotError> {
        let lease = self.lease_for_command()?;
        let clock_identifier = self
            .clock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .clock_identifier
            .clone();
        self.robot_command(command, lease, clock_identifier).await
    }

    async fn robot_command(
        &self,
        command: api::RobotCommand,
        lease: api::Lease,
        clock_identifier: String,
    ) -> Result<u32, SpotError> {
        let mut client = RobotCommandServiceClient::new(self.service("robot-command")?);
        let request = api::RobotCommandRequest {
            header: Some(self.header()),
            lease: Some(lease),
            command: Some(command),
            clock_identifier,
        };
        let response = self
            .rpc("RobotCommand", client.robot_command(request))
            .await?;
        check_header("RobotCommand", response.header.as_ref())?;
        self.note_lease_use(response.lease_use_result.as_ref())?;
        if response.status != api::robot_command_response::Status::Ok as i32 {
            return Err(SpotError::CommandRefused {
                status: api::robot_command_response::Status::try_from(response.status)
                    .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name()),
                message: response.message,
            });
        }
        Ok(response.robot_command_id)
    }
}
