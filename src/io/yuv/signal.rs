//! R'G'B' rows of a signal that is not sRGB / BT.709 (PQ, HLG, BT.1886, linear, or
//! other primaries) to and from linear working-space rows, with
//! [`crate::pixels::color`]'s formulas; the sRGB / BT.709 signals keep the
//! vectorised curve of [`super::curve`].

use crate::pixels::color::{Matrix3, SignalColor};

/// Decode a row in place: signal R'G'B' (unit range) to linear working-space RGB.
/// With `clip`, SDR signals are clipped to [0, 1] first (PQ and HLG always are).
pub(crate) fn decode_row(
    color: &SignalColor,
    to_working: &Matrix3,
    clip: bool,
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
) {
    let clip = clip || color.transfer.is_hdr();
    for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
        let mut s = [*r, *g, *b];
        if clip {
            s = s.map(|v| v.clamp(0.0, 1.0));
        }
        [*r, *g, *b] = color.decode(s, to_working);
    }
}

/// Encode a row in place: linear working-space RGB to signal R'G'B'. NaN counts
/// as 0; PQ saturates at 10,000 cd/m² (+∞ gives code 1.0), HLG at the display
/// peak. With `clip` (always for PQ and HLG), the signal is clipped to [0, 1].
pub(crate) fn encode_row(
    color: &SignalColor,
    from_working: &Matrix3,
    clip: bool,
    r: &mut [f32],
    g: &mut [f32],
    b: &mut [f32],
) {
    let clip = clip || color.transfer.is_hdr();
    let nan0 = |v: f32| if v.is_nan() { 0.0 } else { v };
    for ((r, g), b) in r.iter_mut().zip(g.iter_mut()).zip(b.iter_mut()) {
        let lin = [nan0(*r), nan0(*g), nan0(*b)];
        let mut s = color.encode(lin, from_working);
        if clip {
            s = s.map(|v| nan0(v).clamp(0.0, 1.0));
        }
        [*r, *g, *b] = s;
    }
}

/// Whether a conversion's signal needs this module (anything but sRGB / BT.709).
pub(crate) fn is_plain_srgb(color: &SignalColor) -> bool {
    color.is_srgb()
}
