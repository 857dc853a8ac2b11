//! What the PCD and PLY readers share: errors that name the line or byte where the input went
//! wrong, reading the header line by line, and the x y z channels a header must name.

use super::scalar::Channel;
use crate::error::FormatError;

/// A [`FormatError::Line`] at 1-based line `line`.
pub(super) fn line_err(line: usize, message: impl Into<String>) -> FormatError {
    FormatError::Line {
        line,
        message: message.into(),
    }
}

/// A [`FormatError::Byte`] at byte `offset`.
pub(super) fn byte_err(offset: usize, message: impl Into<String>) -> FormatError {
    FormatError::Byte {
        offset,
        message: message.into(),
    }
}

/// The header line starting at byte `*pos` (up to the next `\n` or the end), trimmed; `*pos`
/// moves to the start of the next line. `line_no` names the line when it is not UTF-8.
pub(super) fn next_header_line<'a>(
    bytes: &'a [u8],
    pos: &mut usize,
    line_no: usize,
) -> Result<&'a str, FormatError> {
    let start = *pos;
    let end = bytes[start..]
        .iter()
        .position(|&b| b == b'\n')
        .map_or(bytes.len(), |e| start + e);
    let text = std::str::from_utf8(&bytes[start..end])
        .map_err(|_| line_err(line_no, "header line is not UTF-8"))?
        .trim();
    *pos = (end + 1).min(bytes.len());
    Ok(text)
}

/// [`FormatError::MissingField`] for the first of x, y, z that `has` does not find.
pub(super) fn require_xyz(has: impl Fn(Channel) -> bool) -> Result<(), FormatError> {
    for ch in [Channel::X, Channel::Y, Channel::Z] {
        if !has(ch) {
            return Err(FormatError::MissingField { field: ch.name() });
        }
    }
    Ok(())
}
