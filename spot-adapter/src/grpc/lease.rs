//! The body lease: acquired once, retained in the background, attached to every command,
//! returned on drop; a retain or a command the robot answers "not your lease" marks it lost,
//! and the client then refuses to command.

use crate::grpc::api;
use crate::grpc::api::lease_service_client::LeaseServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::session::{Session, check_header};

/// The resource the navigator needs: the legs.
pub(crate) const BODY_RESOURCE: &str = "body";

/// The lease held, and why it was lost if it was.
#[derive(Clone, Debug, Default)]
pub(crate) struct LeaseState {
    pub(crate) lease: Option<api::Lease>,
    /// `(LeaseUseResult.Status name, owner)` once the robot said the lease is not ours.
    pub(crate) lost: Option<(&'static str, String)>,
}

fn use_status_name(status: i32) -> &'static str {
    api::lease_use_result::Status::try_from(status)
        .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name())
}

impl Session {
    /// The lease to attach to a command, or why there is none.
    pub(crate) fn lease_for_command(&self) -> Result<api::Lease, SpotError> {
        let state = self
            .lease
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((status, owner)) = &state.lost {
            return Err(SpotError::LeaseLost {
                status,
                owner: owner.clone(),
            });
        }
        state.lease.clone().ok_or(SpotError::LeaseLost {
            status: "NO_LEASE_HELD",
            owner: String::new(),
        })
    }

    /// Record what the robot said about our lease; an error when it is no longer ours.
    pub(crate) fn note_lease_use(
        &self,
        result: Option<&api::LeaseUseResult>,
    ) -> Result<(), SpotError> {
        let Some(result) = result else { return Ok(()) };
        if result.status == api::lease_use_result::Status::Ok as i32 {
            return Ok(());
        }
        let status = use_status_name(result.status);
        let owner = result
            .owner
            .as_ref()
            .map(|o| o.client_name.clone())
            .unwrap_or_default();
        let mut state = self
            .lease
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        state.lost = Some((status, owner.clone()));
        Err(SpotError::LeaseLost { status, owner })
    }

    /// Acquire the body lease, or with `take` take it from whoever holds it (the SDK's
    /// `LeaseClient.take`, as the tablet's "force take").
    pub(crate) async fn acquire_lease(&self, take: bool) -> Result<(), SpotError> {
        let mut client = LeaseServiceClient::new(self.service("lease")?);
        let (lease, status, owner) = if take {
            let request = api::TakeLeaseRequest {
                header: Some(self.header()),
                resource: BODY_RESOURCE.to_owned(),
            };
            let response = self.rpc("TakeLease", client.take_lease(request)).await?;
            check_header("TakeLease", response.header.as_ref())?;
            let ok = response.status == api::take_lease_response::Status::Ok as i32;
            let status = api::take_lease_response::Status::try_from(response.status)
                .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name());
            (response.lease.filter(|_| ok), status, response.lease_owner)
        } else {
            let request = api::AcquireLeaseRequest {
                header: Some(self.header()),
                resource: BODY_RESOURCE.to_owned(),
            };
            let response = self
                .rpc("AcquireLease", client.acquire_lease(request))
                .await?;
            check_header("AcquireLease", response.header.as_ref())?;
            let ok = response.status == api::acquire_lease_response::Status::Ok as i32;
            let status = api::acquire_lease_response::Status::try_from(response.status)
                .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name());
            (response.lease.filter(|_| ok), status, response.lease_owner)
        };
        let Some(lease) = lease else {
            return Err(SpotError::LeaseRefused {
                resource: BODY_RESOURCE.to_owned(),
                status,
                owner: owner.map(|o| o.client_name).unwrap_or_default(),
            });
        };
        let mut state = self
            .lease
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        state.lease = Some(lease);
        state.lost = None;
        Ok(())
    }

    /// Tell the robot the lease is still in use.
    pub(crate) async fn retain_lease(&self) -> Result<(), SpotError> {
        let lease = self.lease_for_command()?;
        let mut client = LeaseServiceClient::new(self.service("lease")?);
        let request = api::RetainLeaseRequest {
            header: Some(self.header()),
            lease: Some(lease),
        };
        let response = self
            .rpc("RetainLease", client.retain_lease(request))
            .await?;
        check_header("RetainLease", response.header.as_ref())?;
        self.note_lease_use(response.lease_use_result.as_ref())
    }

    /// Give the lease back (when it is still ours).
    pub(crate) async fn return_lease(&self) -> Result<(), SpotError> {
        let lease = self.lease_for_command()?;
        let mut client = LeaseServiceClient::new(self.service("lease")?);
        let request = api::ReturnLeaseRequest {
            header: Some(self.header()),
            lease: Some(lease),
        };
        let response = self
            .rpc("ReturnLease", client.return_lease(request))
            .await?;
        check_header("ReturnLease", response.header.as_ref())?;
        self.lease
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .lease = None;
        Ok(())
    }
}
