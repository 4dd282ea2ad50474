//! The sRGB curve of `fxgraph::io::srgb`: reference values, and 8-bit encoding exact
//! at every decision threshold.

use super::*;

#[test]
fn srgb_reference_values() {
    assert_eq!(srgb::srgb_to_linear(0.0), 0.0);
    assert_eq!(srgb::srgb_to_linear(1.0), 1.0);
    assert!((srgb::srgb_to_linear(0.5) - 0.214_041_14).abs() < 1e-7);
    assert!((srgb::linear_to_srgb(0.214_041_14) - 0.5).abs() < 1e-6);
    assert!((srgb::srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-9);
    let lut = srgb::decode_lut_u8();
    assert_eq!(lut[0], 0.0);
    assert_eq!(lut[255], 1.0);
    assert!((lut[128] - 0.215_860_5).abs() < 1e-6);
    for v in 0..=255u8 {
        assert_eq!(srgb::encode_u8(lut[v as usize]), v);
    }
    assert_eq!(srgb::encode_u8(f32::NAN), 0);
    assert_eq!(srgb::encode_u8(-3.0), 0);
    assert_eq!(srgb::encode_u8(7.0), 255);
    assert_eq!(srgb::encode_u8(0.5), 188); // 255 * 0.735356 = 187.52
    assert_eq!(srgb::encode_u16(0.5), 48192); // 65535 * 0.735356 = 48191.6
    assert_eq!(srgb::encode_u16(f32::NAN), 0);
    assert_eq!(srgb::encode_u16(2.0), 65535);
}

#[test]
fn encode_u8_is_exact_at_every_decision_threshold() {
    // For each code k the exact threshold lies between two adjacent floats: find it by bisection
    // on the exact formula and check the fast encoder on both sides.
    for k in 1..=255u32 {
        let exact = |x: f32| (255.0 * srgb::linear_to_srgb_f64(x as f64)).round() as u32;
        let (mut lo, mut hi) = (0u32, 1.0f32.to_bits());
        while hi - lo > 1 {
            let mid = (lo + hi) / 2;
            if exact(f32::from_bits(mid)) >= k {
                hi = mid
            } else {
                lo = mid
            }
        }
        assert_eq!(
            srgb::encode_u8(f32::from_bits(lo)) as u32,
            k - 1,
            "below threshold {k}"
        );
        assert_eq!(
            srgb::encode_u8(f32::from_bits(hi)) as u32,
            k,
            "at threshold {k}"
        );
    }
}

proptest::proptest! {
    #[test]
    fn encode_u8_matches_exact_formula(x in 0.0f32..=1.0) {
        proptest::prop_assert_eq!(srgb::encode_u8(x), srgb::encode_u8_exact(x));
    }

    #[test]
    fn encode_u8_matches_exact_formula_dark(x in 0.0f32..0.01) {
        proptest::prop_assert_eq!(srgb::encode_u8(x), srgb::encode_u8_exact(x));
    }

    #[test]
    fn srgb_round_trip(x in 0.0f32..=1.0) {
        let back = srgb::srgb_to_linear(srgb::linear_to_srgb(x));
        proptest::prop_assert!((back - x).abs() <= 1e-6 * x.max(1e-3));
    }
}
