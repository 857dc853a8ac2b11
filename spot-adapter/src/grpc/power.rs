//! Motor power as the SDK's `power_on_motors` and `safe_power_off_motors` do it: a
//! `PowerCommand` (`REQUEST_ON_MOTORS`) polled through `PowerCommandFeedback` until success,
//! then the robot state until the motors are on; a full-body `SafePowerOffCommand` (the robot
//! sits first) polled through the robot state until the motors are off.

use std::time::Duration;

use tokio::time::Instant;

use crate::grpc::api;
use crate::grpc::api::power_service_client::PowerServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::robot_state::MotorPower;
use crate::grpc::session::{Session, check_header};

/// Pause between two polls of a step's progress (the SDK polls at 1 Hz).
pub(crate) const STEP_POLL: Duration = Duration::from_millis(200);

/// The step names errors carry.
pub(crate) const POWER_ON: &str = "power on";
pub(crate) const POWER_OFF: &str = "power off";

fn power_status_name(status: i32) -> &'static str {
    api::PowerCommandStatus::try_from(status).map_or("STATUS_UNRECOGNISED", |s| s.as_str_name())
}

/// `status` and the faults that block it, as one line for an error.
fn power_reply(status: i32, faults: &[api::SystemFault]) -> String {
    let status = power_status_name(status);
    if faults.is_empty() {
        return status.to_owned();
    }
    let names: Vec<&str> = faults.iter().map(|f| f.name.as_str()).collect();
    format!("{status}, blocking faults {names:?}")
}

impl Session {
    /// Power the motors on and wait until the robot state says they are, within `timeout`.
    pub(crate) async fn power_on(&self, timeout: Duration) -> Result<(), SpotError> {
        let deadline = Instant::now() + timeout;
        let timed_out = |last_reply: String| SpotError::StepTimedOut {
            step: POWER_ON,
            seconds: timeout.as_secs_f64(),
            last_reply,
        };
        let lease = self.lease_for_command()?;
        let mut client = PowerServiceClient::new(self.service("power")?);
        let request = api::PowerCommandRequest {
            header: Some(self.header()),
            lease: Some(lease),
            request: api::power_command_request::Request::OnMotors as i32,
        };
        let response = self
            .rpc("PowerCommand", client.power_command(request))
            .await?;
        check_header("PowerCommand", response.header.as_ref())?;
        self.note_lease_use(response.lease_use_result.as_ref())?;
        let mut status = response.status;
        let mut reply = power_reply(status, &response.blocking_faults);
        while status != api::PowerCommandStatus::StatusSuccess as i32 {
            if status != api::PowerCommandStatus::StatusInProgress as i32 {
                return Err(SpotError::StepFailed {
                    step: POWER_ON,
                    reply,
                });
            }
            if Instant::now() > deadline {
                return Err(timed_out(reply));
            }
            tokio::time::sleep(STEP_POLL).await;
            let request = api::PowerCommandFeedbackRequest {
                header: Some(self.header()),
                power_command_id: response.power_command_id,
            };
            let feedback = self
                .rpc(
                    "PowerCommandFeedback",
                    client.power_command_feedback(request),
                )
                .await?;
            check_header("PowerCommandFeedback", feedback.header.as_ref())?;
            status = feedback.status;
            reply = power_reply(status, &feedback.blocking_faults);
        }
        self.await_motor_power(MotorPower::On, POWER_ON, deadline, timeout)
            .await
    }

    /// Sit and power the motors off (the SDK's safe power off), waiting until they are off.
    pub(crate) async fn safe_power_off(&self, timeout: Duration) -> Result<(), SpotError> {
        let deadline = Instant::now() + timeout;
        let command = api::RobotCommand {
            command: Some(api::robot_command::Command::FullBodyCommand(
                api::full_body_command::Request {
                    command: Some(
                        api::full_body_command::request::Command::SafePowerOffRequest(
                            api::safe_power_off_command::Request {},
                        ),
                    ),
                },
            )),
        };
        self.send_unclocked(command).await?;
        self.await_motor_power(MotorPower::Off, POWER_OFF, deadline, timeout)
            .await
    }

    /// Poll the robot state until the motors are `wanted`; an E-stop or a motor error ends
    /// the wait at once.
    async fn await_motor_power(
        &self,
        wanted: MotorPower,
        step: &'static str,
        deadline: Instant,
        timeout: Duration,
    ) -> Result<(), SpotError> {
        loop {
            let status = self.status().await?;
            if status.motor_power == wanted {
                return Ok(());
            }
            let reply = format!(
                "motor power {:?} {}",
                status.motor_power, status.motor_power_error
            );
            if status.motor_power == MotorPower::Error {
                return Err(SpotError::StepFailed { step, reply });
            }
            if wanted == MotorPower::On {
                status.check_ready()?;
            }
            if Instant::now() > deadline {
                return Err(SpotError::StepTimedOut {
                    step,
                    seconds: timeout.as_secs_f64(),
                    last_reply: reply.trim_end().to_owned(),
                });
            }
            tokio::time::sleep(STEP_POLL).await;
        }
    }
}
