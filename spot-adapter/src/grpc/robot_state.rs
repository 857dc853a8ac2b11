//! The robot state (`GetRobotState`): the frame tree now, and the robot's readiness to move:
//! motor power, E-stops, system and behaviour faults.

use crate::grpc::api;
use crate::grpc::api::robot_state_service_client::RobotStateServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::frame_tree::FrameTree;
use crate::grpc::session::{Session, check_header};

/// The motors' power as the robot reports it (`PowerState.MotorPowerState`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MotorPower {
    /// Off: the robot sits and takes no mobility command.
    Off,
    /// On: the robot can stand and walk.
    On,
    /// Powering on.
    PoweringOn,
    /// Powering off.
    PoweringOff,
    /// The motors are in error.
    Error,
    /// Unknown or not reported.
    Unknown,
}

impl MotorPower {
    fn from_wire(value: i32) -> Self {
        use api::power_state::MotorPowerState as S;
        match S::try_from(value) {
            Ok(S::Off) => Self::Off,
            Ok(S::On) => Self::On,
            Ok(S::PoweringOn) => Self::PoweringOn,
            Ok(S::PoweringOff) => Self::PoweringOff,
            Ok(S::Error) => Self::Error,
            Ok(S::Unknown) | Err(_) => Self::Unknown,
        }
    }
}

/// One E-stop endpoint the robot knows (`EStopState`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct EStop {
    /// Its name (`hardware_estop`, `payload_estop`, a software endpoint's name).
    pub name: String,
    /// `TYPE_HARDWARE`, `TYPE_SOFTWARE` or `TYPE_UNKNOWN`.
    pub kind: &'static str,
    /// Whether it is asserted (`STATE_ESTOPPED`); an unknown state counts as asserted.
    pub asserted: bool,
    /// The robot's description of its state.
    pub description: String,
}

/// What the robot state says about the robot's readiness to move.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RobotStatus {
    /// The motors' power.
    pub motor_power: MotorPower,
    /// The robot's error message about the motor power, empty if none.
    pub motor_power_error: String,
    /// Every E-stop endpoint the robot lists.
    pub estops: Vec<EStop>,
    /// Names of the active system faults.
    pub system_faults: Vec<String>,
    /// Active behaviour faults as `CAUSE_* (STATUS_*)`.
    pub behavior_faults: Vec<String>,
}

impl RobotStatus {
    fn from_wire(state: &api::RobotState) -> Self {
        let power = state.power_state.clone().unwrap_or_default();
        let estops = state
            .estop_states
            .iter()
            .map(|e| EStop {
                name: e.name.clone(),
                kind: api::e_stop_state::Type::try_from(e.r#type)
                    .map_or("TYPE_UNRECOGNISED", |t| t.as_str_name()),
                asserted: e.state != api::e_stop_state::State::NotEstopped as i32,
                description: e.state_description.clone(),
            })
            .collect();
        let system_faults = state
            .system_fault_state
            .iter()
            .flat_map(|s| &s.faults)
            .map(|f| f.name.clone())
            .collect();
        let behavior_faults = state
            .behavior_fault_state
            .iter()
            .flat_map(|s| &s.faults)
            .map(|f| {
                let cause = api::behavior_fault::Cause::try_from(f.cause)
                    .map_or("CAUSE_UNRECOGNISED", |c| c.as_str_name());
                let status = api::behavior_fault::Status::try_from(f.status)
                    .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name());
                format!("{cause} ({status})")
            })
            .collect();
        Self {
            motor_power: MotorPower::from_wire(power.motor_power_state),
            motor_power_error: power.motor_power_error_message,
            estops,
            system_faults,
            behavior_faults,
        }
    }

    /// Whether the robot may be asked to move: no E-stop asserted, at least one E-stop
    /// endpoint registered, no system or behaviour fault.
    ///
    /// # Errors
    /// [`SpotError::EStopped`], [`SpotError::NoEStop`] or [`SpotError::Faulted`].
    pub fn check_ready(&self) -> Result<(), SpotError> {
        let asserted: Vec<String> = self
            .estops
            .iter()
            .filter(|e| e.asserted)
            .map(|e| e.name.clone())
            .collect();
        if !asserted.is_empty() {
            return Err(SpotError::EStopped { names: asserted });
        }
        if self.estops.is_empty() {
            return Err(SpotError::NoEStop);
        }
        if !self.system_faults.is_empty() || !self.behavior_faults.is_empty() {
            return Err(SpotError::Faulted {
                system: self.system_faults.clone(),
                behavior: self.behavior_faults.clone(),
            });
        }
        Ok(())
    }
}

impl Session {
    async fn robot_state(&self) -> Result<api::RobotState, SpotError> {
        let mut client = RobotStateServiceClient::new(self.service("robot-state")?);
        let request = api::RobotStateRequest {
            header: Some(self.header()),
        };
        let response = self
            .rpc("GetRobotState", client.get_robot_state(request))
            .await?;
        check_header("GetRobotState", response.header.as_ref())?;
        Ok(response.robot_state.unwrap_or_default())
    }

    /// The frame tree of the latest robot state.
    pub(crate) async fn frame_tree(&self) -> Result<FrameTree, SpotError> {
        let snapshot = self
            .robot_state()
            .await?
            .kinematic_state
            .and_then(|k| k.transforms_snapshot)
            .unwrap_or_default();
        Ok(FrameTree::from_snapshot(&snapshot)?)
    }

    /// Power, E-stops and faults of the latest robot state.
    pub(crate) async fn status(&self) -> Result<RobotStatus, SpotError> {
        Ok(RobotStatus::from_wire(&self.robot_state().await?))
    }
}
