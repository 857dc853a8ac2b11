//! Files a recording names, read only when they are regular files and at most
//! [`MAX_RECORDING_FILE_BYTES`] long: an index or a symbolic link may point at `/dev/zero`, a pipe
//! or a file larger than memory, and reading one whole must not hang or exhaust memory.

use std::fs::{self, File};
use std::io::Read;
use std::path::Path;

use crate::error::AdapterError;

/// Largest file a recording or KITTI folder may hold (1 GiB): a scan of two million points in
/// binary PCD is 44 MB.
pub const MAX_RECORDING_FILE_BYTES: u64 = 1 << 30;

fn refuse(path: &Path, message: String) -> AdapterError {
    AdapterError::Recording {
        path: path.to_path_buf(),
        message,
    }
}

/// Check that `path` (after following links) is a regular file of at most `limit` bytes.
pub(crate) fn check_regular_file(path: &Path, limit: u64) -> Result<(), AdapterError> {
    let meta = fs::metadata(path).map_err(|e| AdapterError::io(path, e))?;
    if !meta.is_file() {
        return Err(refuse(path, "not a regular file".into()));
    }
    if meta.len() > limit {
        return Err(refuse(
            path,
            format!("{} bytes, more than the limit of {limit}", meta.len()),
        ));
    }
    Ok(())
}

/// Open `path` for reading when it is a regular file of at most `limit` bytes.
pub(crate) fn open_regular_file(path: &Path, limit: u64) -> Result<File, AdapterError> {
    check_regular_file(path, limit)?;
    File::open(path).map_err(|e| AdapterError::io(path, e))
}

/// The bytes of `path`, a regular file of at most `limit` bytes (also when it grows while read).
pub(crate) fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, AdapterError> {
    let file = open_regular_file(path, limit)?;
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| AdapterError::io(path, e))?;
    if bytes.len() as u64 > limit {
        return Err(refuse(
            path,
            format!("grew past the limit of {limit} bytes"),
        ));
    }
    Ok(bytes)
}

/// The text of `path`, as [`read_bounded`].
pub(crate) fn read_bounded_text(path: &Path, limit: u64) -> Result<String, AdapterError> {
    String::from_utf8(read_bounded(path, limit)?).map_err(|_| refuse(path, "not UTF-8 text".into()))
}
