//! Decoding Spot's `PointCloud` message: `ENCODING_XYZ_32F` data is `num_points` times three
//! little-endian `f32` (x, y, z) in the source's sensor frame.

use nalgebra::Point3;
use slam_core::PointCloud;

use crate::grpc::CloudProblem;
use crate::grpc::api;
use crate::grpc::api::point_cloud_service_client::PointCloudServiceClient;
use crate::grpc::clock;
use crate::grpc::error::SpotError;
use crate::grpc::frame_tree::FrameTree;
use crate::grpc::session::{Session, check_header};

/// One scan from a point cloud source, with the frame tree at its acquisition.
#[derive(Clone, Debug, PartialEq)]
pub struct SpotCloud {
    /// Points in [`SpotCloud::frame_name`].
    pub cloud: PointCloud,
    /// The sensor frame (`frame_name_sensor`).
    pub frame_name: String,
    /// Acquisition time, robot clock, seconds since the epoch.
    pub acquisition_time: f64,
    /// The frame tree at acquisition (the sensor, `body`, `odom`, `vision`).
    pub frames: FrameTree,
}

impl Session {
    /// One scan from the configured source.
    pub(crate) async fn point_cloud(&self) -> Result<SpotCloud, SpotError> {
        let source_name = self.config.point_cloud_source.clone();
        let mut client =
            PointCloudServiceClient::new(self.service(&self.config.point_cloud_service)?);
        let request = api::GetPointCloudRequest {
            header: Some(self.header()),
            point_cloud_requests: vec![api::PointCloudRequest {
                point_cloud_source_name: source_name.clone(),
                cloud_type: 0,
            }],
        };
        let response = self
            .rpc("GetPointCloud", client.get_point_cloud(request))
            .await?;
        check_header("GetPointCloud", response.header.as_ref())?;
        let reply = response
            .point_cloud_responses
            .into_iter()
            .next()
            .ok_or_else(|| SpotError::MalformedCloud {
                source_name: source_name.clone(),
                problem: CloudProblem::Missing,
            })?;
        if reply.status != api::point_cloud_response::Status::Ok as i32 {
            return Err(SpotError::NoData {
                what: source_name,
                status: api::point_cloud_response::Status::try_from(reply.status)
                    .map_or("STATUS_UNRECOGNISED", |s| s.as_str_name()),
            });
        }
        let Some(api::point_cloud_response::CloudData::PointCloud(cloud)) = reply.cloud_data else {
            return Err(SpotError::MalformedCloud {
                source_name,
                problem: CloudProblem::OkWithoutCloud,
            });
        };
        let points = decode_cloud(&cloud)?;
        let source = cloud.source.unwrap_or_default();
        let frames = source
            .transforms_snapshot
            .as_ref()
            .map(FrameTree::from_snapshot)
            .transpose()?
            .unwrap_or_default();
        Ok(SpotCloud {
            cloud: points,
            frame_name: source.frame_name_sensor,
            acquisition_time: source.acquisition_time.as_ref().map_or(0.0, clock::seconds),
            frames,
        })
    }
}

/// The points of `cloud`, checked against its declared count and encoding.
///
/// # Errors
/// [`SpotError::MalformedCloud`] for an encoding other than XYZ 32F, a negative count, data
/// whose size is not `12 * num_points` bytes, or a non-finite coordinate.
pub(crate) fn decode_cloud(cloud: &api::PointCloud) -> Result<PointCloud, SpotError> {
    let source_name = cloud
        .source
        .as_ref()
        .map_or_else(String::new, |s| s.name.clone());
    let bad = |problem: CloudProblem| SpotError::MalformedCloud {
        source_name: source_name.clone(),
        problem,
    };
    if cloud.encoding != api::point_cloud::Encoding::Xyz32f as i32 {
        let name = api::point_cloud::Encoding::try_from(cloud.encoding)
            .map_or("an unknown encoding", |e| e.as_str_name());
        return Err(bad(CloudProblem::Encoding {
            code: cloud.encoding,
            name,
        }));
    }
    let count = usize::try_from(cloud.num_points)
        .map_err(|_| bad(CloudProblem::NegativeCount(cloud.num_points)))?;
    let expected = count
        .checked_mul(12)
        .ok_or_else(|| bad(CloudProblem::CountOverflows(count)))?;
    if cloud.data.len() != expected {
        return Err(bad(CloudProblem::DataSize {
            bytes: cloud.data.len(),
            points: count,
            needed: expected,
        }));
    }
    let mut points = Vec::with_capacity(count);
    for (k, chunk) in cloud.data.chunks_exact(12).enumerate() {
        let coordinate =
            |i: usize| f32::from_le_bytes([chunk[i], chunk[i + 1], chunk[i + 2], chunk[i + 3]]);
        let p = Point3::new(coordinate(0), coordinate(4), coordinate(8));
        if !(p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
            return Err(bad(CloudProblem::NonFinitePoint(k)));
        }
        points.push(p);
    }
    Ok(PointCloud::from_points(points))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cloud(points: &[[f32; 3]], num_points: i32) -> api::PointCloud {
        api::PointCloud {
            source: Some(api::PointCloudSource {
                name: "velodyne-point-cloud".into(),
                ..Default::default()
            }),
            num_points,
            encoding: api::point_cloud::Encoding::Xyz32f as i32,
            data: points
                .iter()
                .flat_map(|p| p.iter().flat_map(|c| c.to_le_bytes()))
                .collect(),
        }
    }

    #[test]
    fn xyz_32f_points_decode_in_order() {
        let decoded = decode_cloud(&cloud(&[[1.0, -2.0, 0.5], [3.25, 0.0, -1.0]], 2)).unwrap();
        assert_eq!(
            decoded.points(),
            &[Point3::new(1.0, -2.0, 0.5), Point3::new(3.25, 0.0, -1.0)]
        );
    }

    #[test]
    fn a_count_that_disagrees_with_the_data_is_an_error() {
        let error = decode_cloud(&cloud(&[[1.0, 2.0, 3.0]], 2)).unwrap_err();
        assert!(
            matches!(
                &error,
                SpotError::MalformedCloud {
                    problem: CloudProblem::DataSize {
                        bytes: 12,
                        points: 2,
                        needed: 24
                    },
                    ..
                }
            ),
            "{error}"
        );
        assert!(decode_cloud(&cloud(&[], -1)).is_err());
        let mut other = cloud(&[], 0);
        other.encoding = api::point_cloud::Encoding::Xyz4sc as i32;
        assert!(decode_cloud(&other).is_err());
        assert!(decode_cloud(&cloud(&[[f32::NAN, 0.0, 0.0]], 1)).is_err());
    }
}
