//! The connection to one robot: a TLS channel per authority (the `:authority` and the TLS name
//! both set to it, as the SDK does), the bearer token on every call, the common request and
//! response headers, and one bounded wait per call.

use std::collections::HashMap;
use std::future::Future;
use std::sync::{Arc, Mutex, PoisonError, RwLock};

use tonic::codegen::http::Uri;
use tonic::metadata::{Ascii, MetadataValue};
use tonic::service::{Interceptor, interceptor::InterceptedService};
use tonic::transport::{Certificate, Channel, ClientTlsConfig, Endpoint};

use crate::grpc::ConfigProblem;
use crate::grpc::api;
use crate::grpc::clock;
use crate::grpc::config::SpotConfig;
use crate::grpc::error::SpotError;
use crate::grpc::estop::EstopState;
use crate::grpc::lease::LeaseState;
use crate::grpc::time_sync::ClockSync;

/// Authorities the SDK hard-codes (robot.py's bootstrap table); every other one comes from the
/// directory.
pub(crate) const AUTH_AUTHORITY: &str = "auth.spot.robot";
pub(crate) const DIRECTORY_AUTHORITY: &str = "api.spot.robot";
pub(crate) const ROBOT_ID_AUTHORITY: &str = "id.spot.robot";

/// A channel to one authority with the bearer token added to every call.
pub(crate) type AuthorizedChannel = InterceptedService<Channel, BearerToken>;

/// Adds `authorization: Bearer <token>` once a token is held (marked sensitive, so tonic's
/// `Debug` output never shows it).
#[derive(Clone, Debug, Default)]
pub(crate) struct BearerToken(Arc<RwLock<Option<MetadataValue<Ascii>>>>);

impl BearerToken {
    pub(crate) fn set(&self, token: &str) -> Result<(), SpotError> {
        let mut value: MetadataValue<Ascii> =
            format!("Bearer {token}")
                .parse()
                .map_err(|_| SpotError::ResponseHeader {
                    method: "GetAuthToken",
                    code: 0,
                    message: "the token is not printable ASCII".to_owned(),
                })?;
        value.set_sensitive(true);
        *self.0.write().unwrap_or_else(PoisonError::into_inner) = Some(value);
        Ok(())
    }
}

impl Interceptor for BearerToken {
    fn call(
        &mut self,
        mut request: tonic::Request<()>,
    ) -> Result<tonic::Request<()>, tonic::Status> {
        if let Some(value) = self
            .0
            .read()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
        {
            request.metadata_mut().insert("authorization", value);
        }
        Ok(request)
    }
}

/// What the client and its background tasks share.
pub(crate) struct Session {
    pub(crate) config: SpotConfig,
    address: String,
    channels: RwLock<HashMap<String, Channel>>,
    services: RwLock<HashMap<String, String>>,
    pub(crate) token: BearerToken,
    /// The token itself, for its renewal.
    pub(crate) token_text: Mutex<String>,
    pub(crate) clock: Mutex<ClockSync>,
    pub(crate) lease: Mutex<LeaseState>,
    /// Our software E-stop endpoint, when one is registered.
    pub(crate) estop: Mutex<EstopState>,
}

impl Session {
    /// Channels to the bootstrap authorities; nothing is dialled until the first call.
    pub(crate) fn new(config: SpotConfig) -> Result<Self, SpotError> {
        config.validate()?;
        let address = format!("{}:{}", config.host, config.port);
        let session = Self {
            config,
            address,
            channels: RwLock::default(),
            services: RwLock::default(),
            token: BearerToken::default(),
            token_text: Mutex::default(),
            clock: Mutex::default(),
            lease: Mutex::default(),
            estop: Mutex::default(),
        };
        for authority in [AUTH_AUTHORITY, DIRECTORY_AUTHORITY, ROBOT_ID_AUTHORITY] {
            session.add_channel(authority)?;
        }
        Ok(session)
    }

    /// Open (lazily) a channel to `authority` unless one is open.
    pub(crate) fn add_channel(&self, authority: &str) -> Result<(), SpotError> {
        let mut channels = self
            .channels
            .write()
            .unwrap_or_else(PoisonError::into_inner);
        if channels.contains_key(authority) {
            return Ok(());
        }
        let channel_error = |source| SpotError::Channel {
            address: self.address.clone(),
            authority: authority.to_owned(),
            source,
        };
        let origin: Uri =
            format!("https://{authority}")
                .parse()
                .map_err(|_| SpotError::InvalidConfig {
                    setting: "authority",
                    problem: ConfigProblem::NotAHostName(authority.to_owned()),
                })?;
        let tls = ClientTlsConfig::new()
            .ca_certificate(Certificate::from_pem(&self.config.ca_pem))
            .domain_name(authority);
        let endpoint = Endpoint::from_shared(format!("https://{}", self.address))
            .map_err(channel_error)?
            .tls_config(tls)
            .map_err(channel_error)?
            .origin(origin)
            .connect_timeout(self.config.call_timeout)
            .timeout(self.config.call_timeout);
        channels.insert(authority.to_owned(), endpoint.connect_lazy());
        Ok(())
    }

    /// The channel to `authority`, token attached.
    pub(crate) fn channel(&self, authority: &str) -> Result<AuthorizedChannel, SpotError> {
        let channels = self.channels.read().unwrap_or_else(PoisonError::into_inner);
        let channel = channels
            .get(authority)
            .ok_or_else(|| SpotError::UnknownService {
                service: authority.to_owned(),
            })?;
        Ok(InterceptedService::new(channel.clone(), self.token.clone()))
    }

    /// The channel to the service the directory lists as `service`.
    pub(crate) fn service(&self, service: &str) -> Result<AuthorizedChannel, SpotError> {
        let authority = self
            .services
            .read()
            .unwrap_or_else(PoisonError::into_inner)
            .get(service)
            .cloned()
            .ok_or_else(|| SpotError::UnknownService {
                service: service.to_owned(),
            })?;
        self.channel(&authority)
    }

    /// Remember the directory's entries (service name to authority) and open their channels.
    pub(crate) fn set_services(&self, entries: &[api::ServiceEntry]) -> Result<(), SpotError> {
        for entry in entries {
            self.add_channel(&entry.authority)?;
        }
        let mut services = self
            .services
            .write()
            .unwrap_or_else(PoisonError::into_inner);
        services.extend(
            entries
                .iter()
                .map(|e| (e.name.clone(), e.authority.clone())),
        );
        Ok(())
    }

    /// Service names the directory listed.
    pub(crate) fn service_names(&self) -> Vec<String> {
        let mut names: Vec<String> = self
            .services
            .read()
            .unwrap_or_else(PoisonError::into_inner)
            .keys()
            .cloned()
            .collect();
        names.sort();
        names
    }

    /// A request header as the SDK fills it: this client's name and the time now.
    pub(crate) fn header(&self) -> api::RequestHeader {
        api::RequestHeader {
            request_timestamp: Some(clock::timestamp(clock::local_now())),
            client_name: self.config.client_name.clone(),
            disable_rpc_logging: false,
        }
    }

    /// Await one call within the call timeout, gRPC failures mapped to [`SpotError`].
    pub(crate) async fn rpc<T>(
        &self,
        method: &'static str,
        call: impl Future<Output = Result<tonic::Response<T>, tonic::Status>>,
    ) -> Result<T, SpotError> {
        let timeout = self.config.call_timeout;
        match tokio::time::timeout(timeout, call).await {
            Err(_) => Err(SpotError::Timeout {
                method,
                seconds: timeout.as_secs_f64(),
            }),
            Ok(Ok(response)) => Ok(response.into_inner()),
            Ok(Err(status)) => Err(status_error(method, &self.address, timeout, status)),
        }
    }
}

/// A failed call's status as a [`SpotError`]: "unavailable", and a status made on this side
/// from a transport error (it carries that error as its source; one the robot sent carries
/// none), as [`SpotError::Unreachable`]. A connection the robot closes mid-call (HTTP/2
/// GOAWAY) reaches tonic as `Unknown` with hyper's error as its source, not as `Unavailable`.
fn status_error(
    method: &'static str,
    address: &str,
    timeout: std::time::Duration,
    status: tonic::Status,
) -> SpotError {
    let local = std::error::Error::source(&status).is_some();
    match status.code() {
        tonic::Code::Unavailable => SpotError::Unreachable {
            method,
            address: address.to_owned(),
            source: status,
        },
        tonic::Code::Unknown if local => SpotError::Unreachable {
            method,
            address: address.to_owned(),
            source: status,
        },
        tonic::Code::DeadlineExceeded => SpotError::Timeout {
            method,
            seconds: timeout.as_secs_f64(),
        },
        code => SpotError::Rpc {
            method,
            code,
            source: status,
        },
    }
}

/// The response header must be present and say `CODE_OK`, as the SDK demands.
pub(crate) fn check_header(
    method: &'static str,
    header: Option<&api::ResponseHeader>,
) -> Result<(), SpotError> {
    let error = header.and_then(|h| h.error.as_ref());
    match error {
        Some(e) if e.code == api::common_error::Code::Ok as i32 => Ok(()),
        Some(e) => Err(SpotError::ResponseHeader {
            method,
            code: e.code,
            message: e.message.clone(),
        }),
        None => Err(SpotError::ResponseHeader {
            method,
            code: 0,
            message: "no error code set in the response header".to_owned(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn classify(status: tonic::Status) -> SpotError {
        status_error(
            "GetPointCloud",
            "10.0.0.3:443",
            Duration::from_secs(5),
            status,
        )
    }

    /// A connection lost mid-call (tonic makes the status on this side, with the transport's
    /// error as its source and code `Unknown`) is the robot unreachable, not a gRPC answer; a
    /// status the robot sent with the same code stays an answer.
    #[test]
    fn a_connection_lost_mid_call_is_unreachable_and_a_sent_status_is_an_answer() {
        let reset = std::io::Error::new(std::io::ErrorKind::ConnectionReset, "GOAWAY");
        let lost = tonic::Status::from_error(Box::new(reset));
        assert_eq!(lost.code(), tonic::Code::Unknown);
        assert!(
            matches!(classify(lost), SpotError::Unreachable { method: "GetPointCloud", ref address, .. } if address == "10.0.0.3:443")
        );
        let sent = tonic::Status::unknown("the robot's own failure");
        assert!(matches!(
            classify(sent),
            SpotError::Rpc {
                code: tonic::Code::Unknown,
                ..
            }
        ));
        assert!(matches!(
            classify(tonic::Status::unavailable("refused")),
            SpotError::Unreachable { .. }
        ));
        assert!(matches!(
            classify(tonic::Status::deadline_exceeded("late")),
            SpotError::Timeout { seconds, .. } if (seconds - 5.0).abs() < 1e-12
        ));
        assert!(matches!(
            classify(tonic::Status::permission_denied("no")),
            SpotError::Rpc {
                code: tonic::Code::PermissionDenied,
                ..
            }
        ));
    }
}
