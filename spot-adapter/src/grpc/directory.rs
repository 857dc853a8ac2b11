//! The robot's identity (`GetRobotId`) and its directory (`ListServiceEntries`): which
//! authority serves each service.

use crate::grpc::api;
use crate::grpc::api::directory_service_client::DirectoryServiceClient;
use crate::grpc::api::robot_id_service_client::RobotIdServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::session::{DIRECTORY_AUTHORITY, ROBOT_ID_AUTHORITY, Session, check_header};

/// Who the robot says it is.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RobotIdentity {
    /// Serial number.
    pub serial_number: String,
    /// Kind of robot (`spot`).
    pub species: String,
    /// Robot version.
    pub version: String,
    /// The name its owner gave it.
    pub nickname: String,
}

impl Session {
    /// The robot's identity.
    pub(crate) async fn robot_id(&self) -> Result<RobotIdentity, SpotError> {
        let mut client = RobotIdServiceClient::new(self.channel(ROBOT_ID_AUTHORITY)?);
        let request = api::RobotIdRequest {
            header: Some(self.header()),
        };
        let response = self.rpc("GetRobotId", client.get_robot_id(request)).await?;
        check_header("GetRobotId", response.header.as_ref())?;
        let id = response.robot_id.unwrap_or_default();
        Ok(RobotIdentity {
            serial_number: id.serial_number,
            species: id.species,
            version: id.version,
            nickname: id.nickname,
        })
    }

    /// Read the directory and open a channel to every authority it names.
    pub(crate) async fn read_directory(&self) -> Result<(), SpotError> {
        let mut client = DirectoryServiceClient::new(self.channel(DIRECTORY_AUTHORITY)?);
        let request = api::ListServiceEntriesRequest {
            header: Some(self.header()),
        };
        let response = self
            .rpc("ListServiceEntries", client.list_service_entries(request))
            .await?;
        check_header("ListServiceEntries", response.header.as_ref())?;
        self.set_services(&response.service_entries)
    }
}
