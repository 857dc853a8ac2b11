//! Authentication: `GetAuthToken` with the user's name and password, then with the token itself
//! to renew it before it expires.

use crate::grpc::api;
use crate::grpc::api::auth_service_client::AuthServiceClient;
use crate::grpc::error::SpotError;
use crate::grpc::session::{AUTH_AUTHORITY, Session, check_header};

/// A refusal's name on the wire.
fn status_name(status: i32) -> &'static str {
    api::get_auth_token_response::Status::try_from(status)
        .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name())
}

impl Session {
    /// Log in with the configured credentials and hold the token.
    pub(crate) async fn authenticate(&self) -> Result<(), SpotError> {
        let credentials = &self.config.credentials;
        self.get_auth_token(api::GetAuthTokenRequest {
            header: Some(self.header()),
            username: credentials.username().to_owned(),
            password: credentials.password().to_owned(),
            token: String::new(),
        })
        .await
    }

    /// Trade the token held for a fresh one.
    pub(crate) async fn refresh_token(&self, token: String) -> Result<(), SpotError> {
        self.get_auth_token(api::GetAuthTokenRequest {
            header: Some(self.header()),
            username: String::new(),
            password: String::new(),
            token,
        })
        .await
    }

    async fn get_auth_token(&self, request: api::GetAuthTokenRequest) -> Result<(), SpotError> {
        let mut client = AuthServiceClient::new(self.channel(AUTH_AUTHORITY)?);
        let response = self
            .rpc("GetAuthToken", client.get_auth_token(request))
            .await?;
        check_header("GetAuthToken", response.header.as_ref())?;
        if response.status != api::get_auth_token_response::Status::Ok as i32 {
            return Err(SpotError::Login {
                username: self.config.credentials.username().to_owned(),
                status: status_name(response.status),
            });
        }
        self.token.set(&response.token)?;
        *self
            .token_text
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = response.token;
        Ok(())
    }

    /// The token held (for renewal); empty before the first login.
    pub(crate) fn current_token(&self) -> String {
        self.token_text
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .clone()
    }
}
