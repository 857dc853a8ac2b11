//! Read a point cloud whichever of the supported formats its file name says it is.

use std::path::Path;

use crate::cloud::PointCloud;
use crate::error::FormatError;

use super::{read_kitti_bin, read_pcd, read_ply};

/// Read a cloud by its extension: `.pcd`, `.ply` or KITTI's `.bin` (case-insensitive).
///
/// # Errors
/// [`FormatError::UnknownExtension`] for another extension; otherwise the reader's errors.
pub fn read_cloud(path: impl AsRef<Path>) -> Result<PointCloud, FormatError> {
    let path = path.as_ref();
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "pcd" => read_pcd(path),
        "ply" => read_ply(path),
        "bin" => read_kitti_bin(path),
        other => Err(FormatError::UnknownExtension {
            path: path.to_path_buf(),
            extension: other.to_owned(),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unknown_extension_is_an_error() {
        assert!(matches!(
            read_cloud("scan.xyz"),
            Err(FormatError::UnknownExtension { extension, .. }) if extension == "xyz"
        ));
    }
}
