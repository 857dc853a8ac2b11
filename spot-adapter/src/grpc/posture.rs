//! Stand and sit as the SDK's `blocking_stand` and `blocking_sit` do: a synchronized mobility
//! command (`stand_request` / `sit_request`), then `RobotCommandFeedback` polled until the
//! robot says it is standing (sitting); a command that is no longer processing fails the step.

use std::time::Duration;

use tokio::time::Instant;

use crate::grpc::api;
use crate::grpc::api::robot_command_service_client::RobotCommandServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::power::STEP_POLL;
use crate::grpc::session::{Session, check_header};

/// The step names errors carry.
pub(crate) const STAND: &str = "stand";
pub(crate) const SIT: &str = "sit";

/// The posture asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Posture {
    Stand,
    Sit,
}

impl Posture {
    fn step(self) -> &'static str {
        match self {
            Self::Stand => STAND,
            Self::Sit => SIT,
        }
    }

    /// The SDK's `synchro_stand_command` / `synchro_sit_command` (without its body params:
    /// the robot's default stance).
    fn command(self) -> api::RobotCommand {
        use api::mobility_command::request::Command;
        let command = match self {
            Self::Stand => Command::StandRequest(api::stand_command::Request {}),
            Self::Sit => Command::SitRequest(api::sit_command::Request {}),
        };
        api::RobotCommand {
            command: Some(api::robot_command::Command::SynchronizedCommand(
                api::synchronized_command::Request {
                    mobility_command: Some(api::mobility_command::Request {
                        command: Some(command),
                        params: None,
                    }),
                },
            )),
        }
    }

    /// `Ok(true)` once reached, `Ok(false)` while in progress, the reply when it failed.
    fn reached(self, feedback: Option<&api::RobotCommandFeedback>) -> Result<bool, String> {
        use api::mobility_command::feedback::Feedback;
        use api::robot_command_feedback::Command;
        let Some(Command::SynchronizedFeedback(synchronized)) =
            feedback.and_then(|f| f.command.as_ref())
        else {
            return Err("no synchronized command feedback".to_owned());
        };
        let Some(mobility) = &synchronized.mobility_command_feedback else {
            return Err("no mobility command feedback".to_owned());
        };
        if mobility.status != api::robot_command_feedback_status::Status::Processing as i32 {
            return Err(
                api::robot_command_feedback_status::Status::try_from(mobility.status)
                    .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name())
                    .to_owned(),
            );
        }
        Ok(match (self, &mobility.feedback) {
            (Self::Stand, Some(Feedback::StandFeedback(f))) => {
                f.status == api::stand_command::feedback::Status::IsStanding as i32
            }
            (Self::Sit, Some(Feedback::SitFeedback(f))) => {
                f.status == api::sit_command::feedback::Status::IsSitting as i32
            }
            _ => false,
        })
    }
}

impl Session {
    /// Command `posture` and wait for the robot's feedback to say it is reached.
    pub(crate) async fn blocking_posture(
        &self,
        posture: Posture,
        timeout: Duration,
    ) -> Result<(), SpotError> {
        let deadline = Instant::now() + timeout;
        let step = posture.step();
        let id = self
            .send_unclocked(posture.command())
            .await
            .map_err(|e| match e {
                SpotError::CommandRefused { status, message } => SpotError::StepFailed {
                    step,
                    reply: format!("{status} {message}").trim_end().to_owned(),
                },
                other => other,
            })?;
        let mut client = RobotCommandServiceClient::new(self.service("robot-command")?);
        loop {
            let request = api::RobotCommandFeedbackRequest {
                header: Some(self.header()),
                robot_command_id: id,
            };
            let response = self
                .rpc(
                    "RobotCommandFeedback",
                    client.robot_command_feedback(request),
                )
                .await?;
            check_header("RobotCommandFeedback", response.header.as_ref())?;
            match posture.reached(response.feedback.as_ref()) {
                Ok(true) => return Ok(()),
                Ok(false) if Instant::now() > deadline => {
                    return Err(SpotError::StepTimedOut {
                        step,
                        seconds: timeout.as_secs_f64(),
                        last_reply: "in progress".to_owned(),
                    });
                }
                Ok(false) => tokio::time::sleep(STEP_POLL).await,
                Err(reply) => return Err(SpotError::StepFailed { step, reply }),
            }
        }
    }
}
