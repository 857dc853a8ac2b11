//! The forms the bag's odometry and IMU sources take in a settings file (feature `serde`): tagged
//! by `kind`, with the topic named by a field, since a tagged enum's variant cannot hold a bare
//! string. Variants without fields are empty structs, so that a stray field is refused.

use crate::record::{ImuSource, OdometrySource};

/// [`OdometrySource`] in a settings file.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", deny_unknown_fields)]
pub(crate) enum OdometrySourceForm {
    Auto {},
    Topic { topic: String },
    Tf { odom_frame: String },
    None {},
}

impl From<OdometrySourceForm> for OdometrySource {
    fn from(form: OdometrySourceForm) -> Self {
        match form {
            OdometrySourceForm::Auto {} => Self::Auto,
            OdometrySourceForm::Topic { topic } => Self::Topic(topic),
            OdometrySourceForm::Tf { odom_frame } => Self::Tf { odom_frame },
            OdometrySourceForm::None {} => Self::None,
        }
    }
}

impl From<OdometrySource> for OdometrySourceForm {
    fn from(source: OdometrySource) -> Self {
        match source {
            OdometrySource::Auto => Self::Auto {},
            OdometrySource::Topic(topic) => Self::Topic { topic },
            OdometrySource::Tf { odom_frame } => Self::Tf { odom_frame },
            OdometrySource::None => Self::None {},
        }
    }
}

/// [`ImuSource`] in a settings file.
#[derive(serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", deny_unknown_fields)]
pub(crate) enum ImuSourceForm {
    Auto {},
    Topic { topic: String },
    None {},
}

impl From<ImuSourceForm> for ImuSource {
    fn from(form: ImuSourceForm) -> Self {
        match form {
            ImuSourceForm::Auto {} => Self::Auto,
            ImuSourceForm::Topic { topic } => Self::Topic(topic),
            ImuSourceForm::None {} => Self::None,
        }
    }
}

impl From<ImuSource> for ImuSourceForm {
    fn from(source: ImuSource) -> Self {
        match source {
            ImuSource::Auto => Self::Auto {},
            ImuSource::Topic(topic) => Self::Topic { topic },
            ImuSource::None => Self::None {},
        }
    }
}
