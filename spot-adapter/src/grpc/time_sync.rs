//! Time sync: `TimeSyncUpdate` rounds, each reporting the previous round trip's four times, let
//! the robot estimate this host's clock skew; commands are then timed in robot time
//! (`local + skew`). Motion needs a converged estimate no older than the configured bound.

use std::time::Instant;

use crate::grpc::api;
use crate::grpc::api::time_sync_service_client::TimeSyncServiceClient;
use crate::grpc::clock;
use crate::grpc::error::SpotError;
use crate::grpc::session::{Session, check_header};

/// The client's side of time sync: the last round trip, the robot's clock and best estimate.
#[derive(Clone, Debug, Default)]
pub(crate) struct ClockSync {
    /// The robot's clock name, echoed in later rounds and in commands.
    pub(crate) clock_identifier: String,
    /// The previous round's four times, sent with the next round.
    previous: Option<api::TimeSyncRoundTrip>,
    /// Robot clock minus local clock, seconds, from the robot's last converged estimate.
    pub(crate) skew: Option<f64>,
    /// When the last converged estimate arrived.
    converged_at: Option<Instant>,
    /// The robot's last `TimeSyncState.Status`.
    status: i32,
}

/// A status's name on the wire.
fn status_name(status: i32) -> &'static str {
    api::time_sync_state::Status::try_from(status)
        .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name())
}

impl ClockSync {
    /// The skew to time a motion command with: converged and fresh, or why not.
    pub(crate) fn fresh_skew(&self, max_age: std::time::Duration) -> Result<f64, SpotError> {
        let (Some(skew), Some(at)) = (self.skew, self.converged_at) else {
            return Err(SpotError::TimeSyncNotConverged {
                status: status_name(self.status),
            });
        };
        let age = at.elapsed();
        if age > max_age {
            return Err(SpotError::TimeSyncStale {
                age: age.as_secs_f64(),
                max_age: max_age.as_secs_f64(),
            });
        }
        Ok(skew)
    }
}

impl Session {
    /// One round; returns whether the robot's estimate has converged.
    pub(crate) async fn time_sync_round(&self) -> Result<bool, SpotError> {
        let (previous, clock_identifier) = {
            let sync = self
                .clock
                .lock()
                .unwrap_or_else(std::sync::PoisonError::into_inner);
            (sync.previous, sync.clock_identifier.clone())
        };
        let mut client = TimeSyncServiceClient::new(self.service("time-sync")?);
        let request = api::TimeSyncUpdateRequest {
            header: Some(self.header()),
            previous_round_trip: previous,
            clock_identifier,
        };
        let client_tx = clock::local_now();
        let response = self
            .rpc("TimeSyncUpdate", client.time_sync_update(request))
            .await?;
        let client_rx = clock::local_now();
        check_header("TimeSyncUpdate", response.header.as_ref())?;
        let header = response.header.unwrap_or_default();
        let state = response.state.unwrap_or_default();
        let mut sync = self
            .clock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        sync.previous = Some(api::TimeSyncRoundTrip {
            client_tx: Some(clock::timestamp(client_tx)),
            server_rx: header.request_received_timestamp,
            server_tx: header.response_timestamp,
            client_rx: Some(clock::timestamp(client_rx)),
        });
        if sync.clock_identifier != response.clock_identifier {
            // A new robot clock: an estimate against the old one means nothing.
            sync.skew = None;
            sync.converged_at = None;
        }
        sync.clock_identifier = response.clock_identifier;
        sync.status = state.status;
        let skew = state
            .best_estimate
            .and_then(|e| e.clock_skew)
            .map(|d| clock::duration_seconds(&d));
        let converged = state.status == api::time_sync_state::Status::Ok as i32;
        if let (true, Some(skew)) = (converged, skew) {
            sync.skew = Some(skew);
            sync.converged_at = Some(Instant::now());
        }
        Ok(converged)
    }

    /// Rounds until the estimate converges, at most the configured number.
    pub(crate) async fn converge_time_sync(&self) -> Result<(), SpotError> {
        let config = &self.config.time_sync;
        for _ in 0..config.max_initial_rounds {
            if self.time_sync_round().await? {
                return Ok(());
            }
            tokio::time::sleep(config.round_interval).await;
        }
        let status = self
            .clock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .status;
        Err(SpotError::TimeSyncNotConverged {
            status: status_name(status),
        })
    }

    /// Robot time now, from a converged and fresh estimate, and the robot's clock name.
    pub(crate) fn robot_now(&self) -> Result<(f64, String), SpotError> {
        let sync = self
            .clock
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        let skew = sync.fresh_skew(self.config.time_sync.max_age)?;
        Ok((clock::local_now() + skew, sync.clock_identifier.clone()))
    }
}
