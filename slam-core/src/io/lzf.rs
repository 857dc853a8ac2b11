//! LZF decompression of PCL's `binary_compressed` PCD data (Marc Lehmann's format: literal
//! runs and back references), bounded so that a forged length cannot allocate without limit.

use super::reading::byte_err;
use crate::error::FormatError;

/// Most bytes one byte of LZF data can expand to: a 3-byte back reference copies 264 bytes.
const LZF_MAX_EXPANSION: usize = 88;

/// Decompress PCL's LZF blocks (`binary_compressed`).
pub(super) fn lzf_decompress(
    input: &[u8],
    out_len: usize,
    base: usize,
) -> Result<Vec<u8>, FormatError> {
    if out_len > input.len().saturating_mul(LZF_MAX_EXPANSION) {
        return Err(byte_err(
            base,
            format!(
                "{} bytes of LZF data cannot decompress to the {out_len} bytes stated",
                input.len()
            ),
        ));
    }
    // Grow with the output rather than trusting the stated size up front.
    let mut out = Vec::with_capacity(out_len.min(input.len().saturating_mul(4)));
    let mut ip = 0;
    while ip < input.len() {
        let ctrl = usize::from(input[ip]);
        ip += 1;
        if ctrl < 32 {
            let n = ctrl + 1;
            let lit = input
                .get(ip..ip + n)
                .ok_or_else(|| byte_err(base + ip, "LZF literal runs past the data"))?;
            out.extend_from_slice(lit);
            ip += n;
        } else {
            let mut len = ctrl >> 5;
            if len == 7 {
                len += usize::from(
                    *input
                        .get(ip)
                        .ok_or_else(|| byte_err(base + ip, "LZF data truncated"))?,
                );
                ip += 1;
            }
            let lo = usize::from(
                *input
                    .get(ip)
                    .ok_or_else(|| byte_err(base + ip, "LZF data truncated"))?,
            );
            ip += 1;
            let back = ((ctrl & 0x1f) << 8) + lo + 1;
            let start = out
                .len()
                .checked_sub(back)
                .ok_or_else(|| byte_err(base + ip, "LZF back reference before the start"))?;
            for k in 0..len + 2 {
                let b = out[start + k];
                out.push(b);
            }
        }
        if out.len() > out_len {
            return Err(byte_err(
                base + ip,
                "LZF data decompresses past its stated size",
            ));
        }
    }
    if out.len() != out_len {
        return Err(byte_err(
            base + ip,
            format!("LZF data gave {} bytes, {} stated", out.len(), out_len),
        ));
    }
    Ok(out)
}
