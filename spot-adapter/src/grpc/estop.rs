//! A software E-stop endpoint for bench setups, as the SDK's `EstopEndpoint` and
//! `EstopKeepAlive` do it: the active configuration read (`GetEstopConfig`), an endpoint
//! registered in its `PDB_rooted` role (`RegisterEstopEndpoint`), a first check-in at
//! `ESTOP_LEVEL_CUT` that seeds the challenge, then check-ins at `ESTOP_LEVEL_NONE` every third
//! of the endpoint's timeout, each answering the last challenge with its bitwise complement.
//! Without a check-in within the timeout the robot cuts motor power; on drop the client checks
//! in at `ESTOP_LEVEL_SETTLE_THEN_CUT` (the robot sits, then cuts power).

use std::time::Duration;

use crate::grpc::api;
use crate::grpc::api::estop_service_client::EstopServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::session::{Session, check_header};

/// The role every E-stop configuration has (the SDK's `EstopEndpoint.REQUIRED_ROLE`).
const REQUIRED_ROLE: &str = "PDB_rooted";
/// The directory name of the E-stop service.
const ESTOP_SERVICE: &str = "estop";

/// Our registered endpoint and the challenge the robot expects answered next.
#[derive(Clone, Debug, Default)]
pub(crate) struct EstopState {
    endpoint: Option<api::EstopEndpoint>,
    challenge: Option<u64>,
}

/// The stop levels this client sends.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum StopLevel {
    /// Cut motor power at once.
    Cut,
    /// Sit, then cut power.
    SettleThenCut,
    /// Allow motor power.
    None,
}

impl StopLevel {
    fn wire(self) -> api::EstopStopLevel {
        match self {
            Self::Cut => api::EstopStopLevel::EstopLevelCut,
            Self::SettleThenCut => api::EstopStopLevel::EstopLevelSettleThenCut,
            Self::None => api::EstopStopLevel::EstopLevelNone,
        }
    }
}

fn duration(d: Duration) -> prost_types::Duration {
    prost_types::Duration {
        seconds: i64::try_from(d.as_secs()).unwrap_or(i64::MAX),
        nanos: i32::try_from(d.subsec_nanos()).unwrap_or(0),
    }
}

impl Session {
    /// Register our endpoint with `timeout` in the robot's active E-stop configuration and
    /// check in once at `ESTOP_LEVEL_CUT` to seed the challenge, then at `ESTOP_LEVEL_NONE`.
    pub(crate) async fn register_estop(&self, timeout: Duration) -> Result<(), SpotError> {
        let mut client = EstopServiceClient::new(self.service(ESTOP_SERVICE)?);
        let request = api::GetEstopConfigRequest {
            header: Some(self.header()),
            target_config_id: String::new(),
        };
        let response = self
            .rpc("GetEstopConfig", client.get_estop_config(request))
            .await?;
        check_header("GetEstopConfig", response.header.as_ref())?;
        let config_id = response.active_config.unwrap_or_default().unique_id;
        let request = api::RegisterEstopEndpointRequest {
            header: Some(self.header()),
            target_endpoint: Some(api::EstopEndpoint {
                role: REQUIRED_ROLE.to_owned(),
                ..api::EstopEndpoint::default()
            }),
            target_config_id: config_id,
            new_endpoint: Some(api::EstopEndpoint {
                role: REQUIRED_ROLE.to_owned(),
                name: self.config.client_name.clone(),
                unique_id: String::new(),
                timeout: Some(duration(timeout)),
                cut_power_timeout: None,
            }),
        };
        let response = self
            .rpc(
                "RegisterEstopEndpoint",
                client.register_estop_endpoint(request),
            )
            .await?;
        check_header("RegisterEstopEndpoint", response.header.as_ref())?;
        if response.status != api::register_estop_endpoint_response::Status::Success as i32 {
            return Err(SpotError::EstopRefused {
                method: "RegisterEstopEndpoint",
                status: api::register_estop_endpoint_response::Status::try_from(response.status)
                    .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name()),
            });
        }
        // Check-ins carry the endpoint as the robot registered it; like the SDK's
        // `EstopEndpoint.from_proto`, a cut-power timeout it left out is sent as zero.
        let endpoint = response.new_endpoint.map(|mut e| {
            e.cut_power_timeout
                .get_or_insert_with(prost_types::Duration::default);
            e
        });
        *self.estop_state() = EstopState {
            endpoint,
            challenge: None,
        };
        // The first check-in has no challenge to answer: the robot says so and sends one.
        self.estop_check_in_once(StopLevel::Cut).await?;
        self.estop_check_in(StopLevel::None).await
    }

    /// Check in at `level`, answering the last challenge; a no-op without an endpoint. A
    /// challenge answered wrong (a check-in whose reply was lost, cancelled in flight, carried
    /// the robot's newer one) is answered again with the challenge that reply brought.
    pub(crate) async fn estop_check_in(&self, level: StopLevel) -> Result<(), SpotError> {
        let incorrect = api::estop_check_in_response::Status::IncorrectChallengeResponse as i32;
        let mut status = self.estop_check_in_once(level).await?;
        if status == incorrect {
            status = self.estop_check_in_once(level).await?;
        }
        if status == api::estop_check_in_response::Status::Ok as i32 {
            return Ok(());
        }
        Err(SpotError::EstopRefused {
            method: "EstopCheckIn",
            status: api::estop_check_in_response::Status::try_from(status)
                .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name()),
        })
    }

    /// One check-in at `level`: the robot's status (`STATUS_OK` without an endpoint).
    async fn estop_check_in_once(&self, level: StopLevel) -> Result<i32, SpotError> {
        let (endpoint, challenge) = {
            let state = self.estop_state();
            let Some(endpoint) = state.endpoint.clone() else {
                return Ok(api::estop_check_in_response::Status::Ok as i32);
            };
            (endpoint, state.challenge)
        };
        let mut client = EstopServiceClient::new(self.service(ESTOP_SERVICE)?);
        let request = api::EstopCheckInRequest {
            header: Some(self.header()),
            endpoint: Some(endpoint),
            challenge: challenge.unwrap_or(0),
            response: challenge.map_or(0, |c| !c),
            stop_level: level.wire() as i32,
        };
        let response = self
            .rpc("EstopCheckIn", client.estop_check_in(request))
            .await?;
        check_header("EstopCheckIn", response.header.as_ref())?;
        self.estop_state().challenge = Some(response.challenge);
        Ok(response.status)
    }

    fn estop_state(&self) -> std::sync::MutexGuard<'_, EstopState> {
        self.estop
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
    }
}
