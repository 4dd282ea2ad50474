//! Structure checks the decoders leave out: a file they would decode although it is
//! cut short or damaged is refused before decoding (docs/cli.md, "Damaged files").
//!
//! - JPEG: the marker segments are walked to the end-of-image marker (the JPEG
//!   decoder pads a truncated scan with grey and accepts it).
//! - WebP: the RIFF header's length must fit in the file, and every chunk in the
//!   RIFF payload (the `image-webp` decoder decodes a file cut by a byte or more
//!   when the bitstream it needs is complete).
//!
//! PNG's checks (CRCs, Adler-32, `IEND`) are made by its decoder (`png_decode.rs`).

/// Walk a JPEG's marker structure: the JPEG decoder pads a truncated file with grey
/// and accepts it, so a file is only taken whole when its segments are intact and an
/// end-of-image marker (EOI) follows the last scan.
pub(super) fn check_jpeg_structure(bytes: &[u8]) -> Result<(), String> {
    const TRUNCATED: &str = "the file is truncated (no end-of-image marker)";
    if !bytes.starts_with(&[0xFF, 0xD8]) {
        return Err("no start-of-image marker".into());
    }
    let mut i = 2;
    let mut scans = 0usize;
    loop {
        // Find the next marker (fill bytes 0xFF may precede it).
        if i >= bytes.len() {
            return Err(TRUNCATED.into());
        }
        if bytes[i] != 0xFF {
            return Err(format!("corrupt data: expected a marker at byte {i}"));
        }
        while i < bytes.len() && bytes[i] == 0xFF {
            i += 1;
        }
        let Some(&marker) = bytes.get(i) else {
            return Err(TRUNCATED.into());
        };
        i += 1;
        match marker {
            0xD9 => {
                return if scans == 0 {
                    Err("corrupt data: the image has no scan data".into())
                } else {
                    Ok(())
                };
            }
            0x01 | 0xD0..=0xD7 => continue,
            0x00 => return Err(format!("corrupt data: invalid marker at byte {}", i - 2)),
            _ => {}
        }
        let Some(len) = bytes.get(i..i + 2) else {
            return Err(TRUNCATED.into());
        };
        let len = u16::from_be_bytes([len[0], len[1]]) as usize;
        if len < 2 {
            return Err(format!("corrupt data: invalid segment length at byte {i}"));
        }
        i += len;
        if i > bytes.len() {
            return Err(TRUNCATED.into());
        }
        if marker == 0xDA {
            scans += 1;
            // Entropy-coded data: runs to the next marker that is neither a stuffed
            // 0xFF00 nor a restart marker.
            loop {
                let Some(p) = bytes[i..].iter().position(|&b| b == 0xFF) else {
                    return Err(TRUNCATED.into());
                };
                i += p;
                match bytes.get(i + 1) {
                    None => return Err(TRUNCATED.into()),
                    Some(0x00) | Some(0xD0..=0xD7) | Some(0xFF) => i += 1,
                    Some(_) => break,
                }
            }
        }
    }
}

/// Walk a WebP file's RIFF container: `RIFF`, the payload length, `WEBP`, then
/// chunks (a four-character code, a length, the data, a pad byte after an odd
/// length), each inside the payload, which must be inside the file.
pub(super) fn check_webp_structure(bytes: &[u8]) -> Result<(), String> {
    const TRUNCATED: &str = "the file is truncated";
    let u32_at = |i: usize| {
        bytes
            .get(i..i + 4)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]) as usize)
    };
    if bytes.len() < 12 || &bytes[..4] != b"RIFF" || &bytes[8..12] != b"WEBP" {
        return Err("no RIFF/WEBP header".into());
    }
    let riff_len = u32_at(4).ok_or(TRUNCATED)?;
    let end = riff_len.checked_add(8).ok_or(TRUNCATED)?;
    if end > bytes.len() {
        return Err(format!(
            "{TRUNCATED} (the RIFF header gives {end} bytes, the file has {})",
            bytes.len()
        ));
    }
    let mut i = 12;
    while i < end {
        let len = u32_at(i + 4)
            .filter(|_| i + 8 <= end)
            .ok_or_else(|| format!("{TRUNCATED} (a chunk header at byte {i} is cut)"))?;
        let next = (i + 8).checked_add(len + (len & 1)).ok_or(TRUNCATED)?;
        // (A last chunk's pad byte that the RIFF length leaves out is tolerated.)
        if next > end && !(len & 1 == 1 && next == end + 1) {
            let name = String::from_utf8_lossy(&bytes[i..i + 4]).into_owned();
            return Err(format!(
                "{TRUNCATED} (chunk `{name}` at byte {i} needs {} bytes, {} are left)",
                next - i,
                end - i
            ));
        }
        i = next;
    }
    Ok(())
}
