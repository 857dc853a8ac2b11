//! The files of a recording's folder that a reader takes, in name order (scans named by their
//! index or stamp come out in recording order).

use std::fs;
use std::path::{Path, PathBuf};

use crate::record::RecordError;

/// The files in `dir` for which `keep` holds, sorted by path.
///
/// # Errors
/// [`RecordError::Io`] when `dir` cannot be read.
pub(crate) fn sorted_files(
    dir: &Path,
    keep: impl Fn(&Path) -> bool,
) -> Result<Vec<PathBuf>, RecordError> {
    let mut files: Vec<PathBuf> = fs::read_dir(dir)
        .map_err(|e| RecordError::io(dir, e))?
        .filter_map(Result::ok)
        .map(|e| e.path())
        .filter(|p| keep(p))
        .collect();
    files.sort();
    Ok(files)
}
