//! Files a recording names, read only when they are regular files and at most
//! [`MAX_RECORDING_FILE_BYTES`] long: an index or a symbolic link may point at `/dev/zero`, a pipe
//! or a file larger than memory, and reading one whole must not hang or exhaust memory.

use std::fs::{self, File};
use std::io::Read;
use std::path::Path;

use crate::record::RecordError;

/// Largest file a recording or KITTI folder may hold (1 GiB): a scan of two million points in
/// binary PCD is 44 MB.
pub const MAX_RECORDING_FILE_BYTES: u64 = 1 << 30;

/// Check that `path` (after following links) is a regular file of at most `limit` bytes.
pub(crate) fn check_regular_file(path: &Path, limit: u64) -> Result<(), RecordError> {
    let meta = fs::metadata(path).map_err(|e| RecordError::io(path, e))?;
    if !meta.is_file() {
        return Err(RecordError::NotRegularFile {
            path: path.to_path_buf(),
        });
    }
    if meta.len() > limit {
        return Err(RecordError::FileTooLarge {
            path: path.to_path_buf(),
            bytes: meta.len(),
            limit,
        });
    }
    Ok(())
}

/// Open `path` for reading when it is a regular file of at most `limit` bytes.
pub(crate) fn open_regular_file(path: &Path, limit: u64) -> Result<File, RecordError> {
    check_regular_file(path, limit)?;
    File::open(path).map_err(|e| RecordError::io(path, e))
}

/// The bytes of `path`, a regular file of at most `limit` bytes (also when it grows while read).
pub(crate) fn read_bounded(path: &Path, limit: u64) -> Result<Vec<u8>, RecordError> {
    let file = open_regular_file(path, limit)?;
    let mut bytes = Vec::new();
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| RecordError::io(path, e))?;
    if bytes.len() as u64 > limit {
        return Err(RecordError::FileGrew {
            path: path.to_path_buf(),
            limit,
        });
    }
    Ok(bytes)
}

/// The text of `path`, as [`read_bounded`].
pub(crate) fn read_bounded_text(path: &Path, limit: u64) -> Result<String, RecordError> {
    String::from_utf8(read_bounded(path, limit)?).map_err(|_| RecordError::NotUtf8 {
        path: path.to_path_buf(),
    })
}
