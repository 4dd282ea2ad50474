//! Which roughness each level of the prefiltered specular cube holds.
//!
//! A chain of L levels spans roughness 0 (level 0, the unfiltered map) to 1
//! (level L − 1). Level m holds the roughness of [`LEVEL_ROUGHNESS`] at
//! x = m / (L − 1), piecewise linear between its knots (at x = 0, 1/6, …, 1):
//! for a 1024 × 512 map's seven levels exactly the knots, 0, 0.1, 0.2, 0.3,
//! 0.45, 0.7 and 1. The levels are closer together at low roughness, where a
//! mix of two levels' lobes (what the shader's trilinear read between them
//! gives) is furthest from the lobe between them (issue 29; docs/environment.md,
//! "Prefiltering"). The knot at 0.1 is there for smooth metals: with the first
//! filtered level at 0.2, a lobe of 0.1 was read as a mix of the unfiltered map
//! and a lobe twice as wide, and gold at roughness 0.1 was 19–58 % off the
//! BRDF integral under the corpus maps. environment.wgsl's `fx_env_level_roughness` and
//! `fx_env_level_position`, and examples/ibl_lobe_fit.rs, hold the same knots
//! (checked below).

/// The roughness at x = 0, 1/6, 2/6, …, 1 of the chain.
pub const LEVEL_ROUGHNESS: [f32; 7] = [0.0, 0.1, 0.2, 0.3, 0.45, 0.7, 1.0];

/// The roughness at position `x` (0 ..= 1) of the chain.
pub fn roughness_at(x: f32) -> f32 {
    let segments = (LEVEL_ROUGHNESS.len() - 1) as f32;
    let t = x.clamp(0.0, 1.0) * segments;
    let i = (t.floor() as usize).min(LEVEL_ROUGHNESS.len() - 2);
    let f = t - i as f32;
    LEVEL_ROUGHNESS[i] + (LEVEL_ROUGHNESS[i + 1] - LEVEL_ROUGHNESS[i]) * f
}

/// The position x (0 ..= 1) in the chain of roughness `roughness`: the
/// inverse of [`roughness_at`].
pub fn position_of(roughness: f32) -> f32 {
    let r = roughness.clamp(0.0, 1.0);
    let segments = (LEVEL_ROUGHNESS.len() - 1) as f32;
    for (i, pair) in LEVEL_ROUGHNESS.windows(2).enumerate() {
        if r <= pair[1] || i + 2 == LEVEL_ROUGHNESS.len() {
            return (i as f32 + (r - pair[0]) / (pair[1] - pair[0])) / segments;
        }
    }
    1.0
}

/// The roughness level `level` of a chain of `levels` holds.
pub fn level_roughness(level: u32, levels: u32) -> f32 {
    roughness_at(level as f32 / (levels.max(2) - 1) as f32)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn position_inverts_roughness() {
        for i in 0..=100 {
            let x = i as f32 / 100.0;
            assert!((position_of(roughness_at(x)) - x).abs() < 1e-5, "at {x}");
        }
        assert_eq!(level_roughness(1, 7), 0.1);
        assert_eq!(level_roughness(3, 7), 0.3);
        assert_eq!(level_roughness(6, 7), 1.0);
    }

    #[test]
    fn the_shader_and_the_fit_hold_the_knots() {
        let wgsl = include_str!("../../../shaders/render/environment.wgsl");
        let knots: Vec<String> = LEVEL_ROUGHNESS.iter().map(|r| format!("{r:?}")).collect();
        let line = format!(
            "const FX_ENV_LEVEL_ROUGHNESS = array<f32, 7>({});",
            knots.join(", ")
        );
        assert!(wgsl.contains(&line), "environment.wgsl lacks `{line}`");
        // the fit models the shader's reads of a seven-level chain
        let fit = include_str!("../../../examples/ibl_lobe_fit.rs");
        let line = format!("const LEVEL_ROUGHNESS: [f64; 7] = [{}];", knots.join(", "));
        assert!(
            fit.contains(&line),
            "examples/ibl_lobe_fit.rs lacks `{line}`"
        );
    }
}
