//! Sub-pixel jitter: the `JITTER = halton23` effect attribute and the sequence of
//! offsets a frame source (the renderer) applies to its frames when an effect asks
//! for it (temporal anti-aliasing). No GPU code here.
//!
//! Convention: a jitter is the offset, in pixels, of the position a frame's pixel
//! was sampled at from that pixel's centre; x to the right, y down. A frame
//! rendered with jitter `j` holds at pixel `(x, y)` the scene seen at the image
//! position `(x + 0.5 + j.x, y + 0.5 + j.y)` (pixel units, origin at the top-left
//! corner of the top-left pixel). Motion vectors never contain the jitter.

use serde::Serialize;
use std::fmt;

/// A sequence of sub-pixel offsets an effect asks its frames to be rendered with.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum JitterPattern {
    /// The Halton (2, 3) sequence, centred: see [`halton23`].
    Halton23,
}

impl JitterPattern {
    pub const ALL: [JitterPattern; 1] = [JitterPattern::Halton23];

    /// The name in a script (`JITTER = halton23`).
    pub fn name(self) -> &'static str {
        match self {
            JitterPattern::Halton23 => "halton23",
        }
    }

    pub fn from_name(s: &str) -> Option<JitterPattern> {
        JitterPattern::ALL.into_iter().find(|p| p.name() == s)
    }

    /// The offset of frame `frame_index` (0 for the first frame of a sequence), in
    /// pixels from the pixel centre, x right, y down, each in (-0.5, 0.5).
    pub fn offset(self, frame_index: u64) -> [f32; 2] {
        match self {
            JitterPattern::Halton23 => halton23(frame_index),
        }
    }

    /// Frames after which the offsets repeat.
    pub fn period(self) -> u64 {
        match self {
            JitterPattern::Halton23 => HALTON23_PERIOD,
        }
    }
}

impl fmt::Display for JitterPattern {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Frames after which [`halton23`] repeats.
pub const HALTON23_PERIOD: u64 = 16;

/// The radical inverse of `index` in `base` (the Halton sequence's element).
/// Written here (a few lines) rather than taken from a crate: no maintained crate
/// offers this alone, and the exact indexing is part of the documented contract.
pub fn radical_inverse(mut index: u64, base: u64) -> f64 {
    let inv = 1.0 / base as f64;
    let mut f = inv;
    let mut r = 0.0;
    while index > 0 {
        r += f * (index % base) as f64;
        index /= base;
        f *= inv;
    }
    r
}

/// The jitter of frame `frame_index`: element `i = (frame_index mod 16) + 1` of
/// the Halton sequence in bases 2 (x) and 3 (y), centred on the pixel:
/// `(radical_inverse(i, 2) - 0.5, radical_inverse(i, 3) - 0.5)`, in pixels, x
/// right, y down. Index 0 of the sequence (the pixel's corner) is skipped, so every
/// offset lies strictly inside (-0.5, 0.5); the sequence repeats every 16 frames.
/// Frame 0 gives (0, -1/6), frame 1 (-1/4, 1/6), frame 2 (1/4, -7/18).
pub fn halton23(frame_index: u64) -> [f32; 2] {
    let i = frame_index % HALTON23_PERIOD + 1;
    [
        (radical_inverse(i, 2) - 0.5) as f32,
        (radical_inverse(i, 3) - 0.5) as f32,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn halton23_follows_the_documented_indexing() {
        let close = |a: [f32; 2], b: [f64; 2]| {
            (a[0] as f64 - b[0]).abs() < 1e-6 && (a[1] as f64 - b[1]).abs() < 1e-6
        };
        assert!(close(halton23(0), [0.0, -1.0 / 6.0]), "{:?}", halton23(0));
        assert!(close(halton23(1), [-0.25, 1.0 / 6.0]), "{:?}", halton23(1));
        assert!(close(halton23(2), [0.25, -7.0 / 18.0]), "{:?}", halton23(2));
        // Period 16.
        for n in 0..40 {
            assert_eq!(halton23(n), halton23(n + HALTON23_PERIOD));
        }
        // Strictly inside the pixel, all 16 distinct, mean near the centre.
        let all: Vec<[f32; 2]> = (0..HALTON23_PERIOD).map(halton23).collect();
        for (k, j) in all.iter().enumerate() {
            assert!(j.iter().all(|c| *c > -0.5 && *c < 0.5), "{j:?}");
            assert!(all[..k].iter().all(|o| o != j), "repeat at {k}");
        }
        let mean = |c: usize| all.iter().map(|j| j[c] as f64).sum::<f64>() / 16.0;
        assert!(
            mean(0).abs() < 0.04 && mean(1).abs() < 0.04,
            "{} {}",
            mean(0),
            mean(1)
        );
        // x: the base-2 elements 1..=16 are k/16 for k = 1..15 and 1/32.
        let mut xs: Vec<f64> = all.iter().map(|j| j[0] as f64 + 0.5).collect();
        xs.sort_by(f64::total_cmp);
        assert!((xs[0] - 1.0 / 32.0).abs() < 1e-6);
        for (k, x) in xs[1..].iter().enumerate() {
            assert!((x - (k + 1) as f64 / 16.0).abs() < 1e-6, "{xs:?}");
        }
    }

    #[test]
    fn names_round_trip() {
        for p in JitterPattern::ALL {
            assert_eq!(JitterPattern::from_name(p.name()), Some(p));
            assert_eq!(p.offset(5), halton23(5));
            assert_eq!(p.period(), 16);
        }
        assert_eq!(JitterPattern::from_name("halton"), None);
    }
}
