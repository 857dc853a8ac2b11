//! The two ways ROS puts a message on the wire, read field by field: ROS 1 serialisation (little
//! endian, packed, strings without a terminator) and the CDR of ROS 2 (an encapsulation header
//! giving the byte order, every primitive aligned to its size counted from after that header,
//! strings with a terminating NUL). One reader serves both, so each message type is decoded once.

use crate::record::MessageError;

/// Which serialisation a payload uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wire {
    /// ROS 1 serialisation (ROS 1 bags).
    Ros1,
    /// OMG CDR with its 4-byte encapsulation header (ROS 2, MCAP `cdr` channels).
    Cdr,
}

/// A cursor over one message payload.
#[derive(Debug)]
pub(crate) struct WireReader<'a> {
    data: &'a [u8],
    pos: usize,
    /// Where alignment is counted from (CDR: after the encapsulation header).
    origin: usize,
    wire: Wire,
    big_endian: bool,
}

/// Largest element count a sequence may claim before its elements are read: no allocation
/// beyond what the payload can hold is ever made.
fn check_count(
    count: usize,
    element_size: usize,
    left: usize,
    offset: usize,
) -> Result<(), MessageError> {
    if count.saturating_mul(element_size.max(1)) > left {
        return Err(MessageError::Truncated {
            offset,
            needed: count.saturating_mul(element_size.max(1)),
            left,
        });
    }
    Ok(())
}

impl<'a> WireReader<'a> {
    /// A reader of `data` in `wire`'s serialisation.
    ///
    /// # Errors
    /// [`MessageError::Encapsulation`] for a CDR payload whose header is not plain CDR
    /// (little or big endian), [`MessageError::Truncated`] when it is shorter than the header.
    pub(crate) fn new(data: &'a [u8], wire: Wire) -> Result<Self, MessageError> {
        match wire {
            Wire::Ros1 => Ok(Self {
                data,
                pos: 0,
                origin: 0,
                wire,
                big_endian: false,
            }),
            Wire::Cdr => {
                let Some(header) = data.get(..4) else {
                    return Err(MessageError::Truncated {
                        offset: 0,
                        needed: 4,
                        left: data.len(),
                    });
                };
                let big_endian = match [header[0], header[1]] {
                    [0, 0] => true,
                    [0, 1] => false,
                    other => return Err(MessageError::Encapsulation { kind: other }),
                };
                Ok(Self {
                    data,
                    pos: 4,
                    origin: 4,
                    wire,
                    big_endian,
                })
            }
        }
    }

    /// Whether this is a ROS 1 payload (its `Header` has a sequence number, its stamp unsigned).
    pub(crate) fn is_ros1(&self) -> bool {
        self.wire == Wire::Ros1
    }

    fn align(&mut self, size: usize) {
        if self.wire == Wire::Cdr && size > 1 {
            let rel = self.pos - self.origin;
            self.pos += (size - rel % size) % size;
        }
    }

    fn take(&mut self, n: usize) -> Result<&'a [u8], MessageError> {
        let left = self.data.len().saturating_sub(self.pos);
        if n > left {
            return Err(MessageError::Truncated {
                offset: self.pos,
                needed: n,
                left,
            });
        }
        let bytes = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(bytes)
    }

    fn fixed<const N: usize>(&mut self) -> Result<[u8; N], MessageError> {
        self.align(N);
        let mut out = [0u8; N];
        out.copy_from_slice(self.take(N)?);
        if self.big_endian {
            out.reverse();
        }
        Ok(out)
    }

    pub(crate) fn u8(&mut self) -> Result<u8, MessageError> {
        Ok(self.take(1)?[0])
    }

    pub(crate) fn bool(&mut self) -> Result<bool, MessageError> {
        Ok(self.u8()? != 0)
    }

    pub(crate) fn u32(&mut self) -> Result<u32, MessageError> {
        Ok(u32::from_le_bytes(self.fixed()?))
    }

    pub(crate) fn i32(&mut self) -> Result<i32, MessageError> {
        Ok(i32::from_le_bytes(self.fixed()?))
    }

    pub(crate) fn f64(&mut self) -> Result<f64, MessageError> {
        Ok(f64::from_le_bytes(self.fixed()?))
    }

    /// `N` doubles (a fixed-size array: no count on either wire).
    pub(crate) fn f64_array<const N: usize>(&mut self) -> Result<[f64; N], MessageError> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f64()?;
        }
        Ok(out)
    }

    /// A sequence's element count, checked against the bytes left (`element_size` each).
    pub(crate) fn count(&mut self, element_size: usize) -> Result<usize, MessageError> {
        let n = self.u32()? as usize;
        check_count(
            n,
            element_size,
            self.data.len().saturating_sub(self.pos),
            self.pos,
        )?;
        Ok(n)
    }

    /// A `uint8[]` (count, then the bytes), borrowed from the payload.
    pub(crate) fn byte_sequence(&mut self) -> Result<&'a [u8], MessageError> {
        let n = self.count(1)?;
        self.take(n)
    }

    /// A `string`.
    pub(crate) fn string(&mut self) -> Result<String, MessageError> {
        let offset = self.pos;
        let n = self.count(1)?;
        let mut bytes = self.take(n)?;
        if self.wire == Wire::Cdr {
            // CDR counts the terminating NUL.
            match bytes.split_last() {
                Some((0, rest)) => bytes = rest,
                _ => return Err(MessageError::InvalidString { offset }),
            }
        }
        std::str::from_utf8(bytes)
            .map(str::to_owned)
            .map_err(|_| MessageError::InvalidString { offset })
    }
}

#[cfg(test)]
#[allow(clippy::float_cmp)]
mod tests {
    use super::*;

    #[test]
    fn cdr_aligns_from_after_its_header_and_honours_byte_order() {
        // LE: u8 1, pad 3, u32 7, string "ab" (len 3 incl. NUL), pad 1 to 16, f64 0.5
        let mut le = vec![
            0, 1, 0, 0, 1, 0, 0, 0, 7, 0, 0, 0, 3, 0, 0, 0, b'a', b'b', 0,
        ];
        le.push(0);
        le.extend_from_slice(&0.5f64.to_le_bytes());
        let mut r = WireReader::new(&le, Wire::Cdr).unwrap();
        assert_eq!(r.u8().unwrap(), 1);
        assert_eq!(r.u32().unwrap(), 7);
        assert_eq!(r.string().unwrap(), "ab");
        assert_eq!(r.f64().unwrap(), 0.5);
        let be = [0, 0, 0, 0, 0, 0, 1, 2];
        let mut r = WireReader::new(&be, Wire::Cdr).unwrap();
        assert_eq!(r.u32().unwrap(), 0x0102);
    }

    #[test]
    fn ros1_is_packed_and_bad_payloads_are_errors() {
        let data = [9, 2, 0, 0, 0, b'h', b'i', 5, 0, 0];
        let mut r = WireReader::new(&data, Wire::Ros1).unwrap();
        assert_eq!(r.u8().unwrap(), 9);
        assert_eq!(r.string().unwrap(), "hi");
        assert!(matches!(r.u32(), Err(MessageError::Truncated { .. })));
        // A count larger than the payload is refused before anything is allocated.
        let huge = [0xff, 0xff, 0xff, 0x7f];
        let mut r = WireReader::new(&huge, Wire::Ros1).unwrap();
        assert!(matches!(
            r.byte_sequence(),
            Err(MessageError::Truncated { .. })
        ));
        assert!(matches!(
            WireReader::new(&[0, 7, 0, 0], Wire::Cdr),
            Err(MessageError::Encapsulation { kind: [0, 7] })
        ));
        // A CDR string must end with its NUL.
        let no_nul = [0, 1, 0, 0, 2, 0, 0, 0, b'h', b'i'];
        let mut r = WireReader::new(&no_nul, Wire::Cdr).unwrap();
        assert!(matches!(
            r.string(),
            Err(MessageError::InvalidString { .. })
        ));
    }
}
