//! The lines of a graph text file as the g2o and TORO readers see them: a tag and the words
//! after it, and errors that name the line.

use crate::error::GraphFileError;

/// A [`GraphFileError::Line`] at 1-based line `line`.
pub(crate) fn line_err(line: usize, message: impl Into<String>) -> GraphFileError {
    GraphFileError::Line {
        line,
        message: message.into(),
    }
}

/// Each line that holds a tag, as `(1-based line number, tag, the words after it)`; blank lines
/// and `#` comments are skipped.
pub(crate) fn tagged_lines(text: &str) -> impl Iterator<Item = (usize, &str, Vec<&str>)> {
    text.lines().enumerate().filter_map(|(k, raw)| {
        let mut words = raw.split_whitespace();
        let tag = words.next()?;
        (!tag.starts_with('#')).then(|| (k + 1, tag, words.collect()))
    })
}
