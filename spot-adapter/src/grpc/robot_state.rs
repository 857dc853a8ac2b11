//! The robot state's kinematic part: the frame tree now (`GetRobotState`).

use crate::grpc::api;
use crate::grpc::api::robot_state_service_client::RobotStateServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::frame_tree::FrameTree;
use crate::grpc::session::{Session, check_header};

impl Session {
    /// The frame tree of the latest robot state.
    pub(crate) async fn frame_tree(&self) -> Result<FrameTree, SpotError> {
        let mut client = RobotStateServiceClient::new(self.service("robot-state")?);
        let request = api::RobotStateRequest {
            header: Some(self.header()),
        };
        let response = self
            .rpc("GetRobotState", client.get_robot_state(request))
            .await?;
        check_header("GetRobotState", response.header.as_ref())?;
        let snapshot = response
            .robot_state
            .and_then(|s| s.kinematic_state)
            .and_then(|k| k.transforms_snapshot)
            .unwrap_or_default();
        Ok(FrameTree::from_snapshot(&snapshot)?)
    }
}
