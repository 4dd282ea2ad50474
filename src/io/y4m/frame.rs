//! One frame's planes.

use super::*;

/// One frame: the planes, and the `FRAME` line's parameters.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct YuvFrame {
    /// Luma, `width x height` samples (one byte each at 8 bits, two bytes
    /// little-endian above: see [`Y4mHeader::depth`]).
    pub y: Vec<u8>,
    /// Cb, [`Chroma::chroma_size`] (empty for mono).
    pub u: Vec<u8>,
    /// Cr, [`Chroma::chroma_size`] (empty for mono).
    pub v: Vec<u8>,
    /// Parameters after `FRAME` (such as `Itpi` in mixed streams), written back as is.
    pub params: Vec<String>,
}

impl YuvFrame {
    /// A black frame for `header` (Y 16 or 0 for `range`, Cb = Cr = 128; scaled by
    /// 2^(depth - 8) above 8 bits).
    pub fn black(header: &Y4mHeader, range: Range) -> YuvFrame {
        let (yn, cn) = header.plane_bytes();
        let shift = header.depth - 8;
        let y = if range == Range::Limited {
            16 << shift
        } else {
            0
        };
        let c = 128u16 << shift;
        let plane = |v: u16, n: usize| -> Vec<u8> {
            if header.depth == 8 {
                vec![v as u8; n]
            } else {
                v.to_le_bytes().repeat(n / 2)
            }
        };
        YuvFrame {
            y: plane(y, yn),
            u: plane(c, cn),
            v: plane(c, cn),
            params: Vec::new(),
        }
    }

    /// Check the plane sizes against `header`.
    pub fn check_size(&self, header: &Y4mHeader) -> Result<(), String> {
        let (yn, cn) = header.plane_bytes();
        for (plane, len, want) in [
            ("Y", self.y.len(), yn),
            ("Cb", self.u.len(), cn),
            ("Cr", self.v.len(), cn),
        ] {
            if len != want {
                return Err(format!(
                    "the {plane} plane has {len} bytes, the header ({}x{} C{}) needs {want}",
                    header.width,
                    header.height,
                    header.colorspace_tag()
                ));
            }
        }
        Ok(())
    }

    /// Whether this frame's 4:2:0 chroma is stored per field under `conv` (see the module
    /// documentation): always false for layouts other than `420jpeg`, `420mpeg2`, `420`.
    pub fn field_chroma(&self, header: &Y4mHeader, conv: &YuvConversion) -> bool {
        if !header.colorspace.is_420() || header.colorspace.vertical_siting() != Siting::Between {
            return false;
        }
        match conv.chroma_fields {
            ChromaFields::Progressive => false,
            ChromaFields::Interlaced => true,
            ChromaFields::Auto => match header.interlace {
                Interlace::TopFieldFirst | Interlace::BottomFieldFirst => true,
                Interlace::Mixed => self
                    .params
                    .iter()
                    .find_map(|p| p.strip_prefix('I'))
                    .map(|i| {
                        let c: Vec<char> = i.chars().collect();
                        // Ixyz: z = chroma sampling (p / i / ?), y = temporal sampling.
                        match c.get(2) {
                            Some('i') => true,
                            Some('p') => false,
                            _ => c.get(1) == Some(&'i'),
                        }
                    })
                    .unwrap_or(false),
                Interlace::Progressive | Interlace::Unknown => false,
            },
        }
    }
}
