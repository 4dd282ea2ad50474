//! The environment term's lobe model (issue 29): the specular lobe at n ≠ v
//! as [`LOBE_TAPS`] reads of the prefiltered cube, each an offset from the
//! dominant direction along the plane of incidence, a roughness (a level of
//! the cube) and a weight, per (n·v, roughness). The table is fitted offline
//! by `examples/ibl_lobe_fit.rs` (the method is described there and in
//! docs/environment.md, "Shading") into `lobe_table.rs`; the renderer uploads
//! it resampled to the DFG table's grid as layers 1..=3 of that texture
//! (`dfg.rs`; offsets, roughnesses, weights, each the rgba of the four taps),
//! which environment.wgsl's `fx_env_prefiltered` reads.

pub use super::lobe_table::{LOBE_MU, LOBE_ROUGHNESS, LOBE_TABLE, LOBE_TAPS};

/// The taps at (`ndv`, `roughness`): per tap [offset, roughness, weight],
/// bilinear in the table's grid (n·v = i / (LOBE_MU − 1), roughness = j /
/// (LOBE_ROUGHNESS − 1)), clamped to it: what the shader's filtered lookup
/// returns up to the resampling to the DFG grid.
pub fn lobe_taps(ndv: f32, roughness: f32) -> [[f32; 3]; LOBE_TAPS] {
    let cell = |x: f32, n: usize| {
        let f = x.clamp(0.0, 1.0) * (n - 1) as f32;
        let i = (f.floor() as usize).min(n - 2);
        (i, f - i as f32)
    };
    let (i, fx) = cell(ndv, LOBE_MU);
    let (j, fy) = cell(roughness, LOBE_ROUGHNESS);
    std::array::from_fn(|k| {
        std::array::from_fn(|c| {
            let at = |j: usize, i: usize| LOBE_TABLE[j][i][k][c];
            let lo = at(j, i) + (at(j, i + 1) - at(j, i)) * fx;
            let hi = at(j + 1, i) + (at(j + 1, i + 1) - at(j + 1, i)) * fx;
            lo + (hi - lo) * fy
        })
    })
}

/// What layer 1 + `k` of the DFG texture holds for each tap (rgba = taps 0–3):
/// 0 the offsets, 1 the roughnesses, 2 the weights.
pub(crate) const LOBE_LAYERS: usize = 3;

const _: () = assert!(
    LOBE_TAPS == 4,
    "the shader reads the taps as the rgba of a texel"
);

/// Layer `k` (< [`LOBE_LAYERS`]) of the lobe's part of the DFG texture: `side`²
/// RGBA f32 rows, texel (x, y) at n·v = (x + 0.5) / side, roughness = (y +
/// 0.5) / side (the DFG table's texel centres), channel c = field k of tap c.
pub(crate) fn lobe_layer(k: usize, side: u32) -> Vec<f32> {
    let mut out = Vec::with_capacity((side * side * 4) as usize);
    for y in 0..side {
        for x in 0..side {
            let at = |i: u32| (i as f32 + 0.5) / side as f32;
            out.extend(lobe_taps(at(x), at(y)).map(|tap| tap[k]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_the_mirror_is_the_split_sum() {
        for (j, row) in LOBE_TABLE.iter().enumerate() {
            for (i, taps) in row.iter().enumerate() {
                let w: f32 = taps.iter().map(|t| t[2]).sum();
                assert!((w - 1.0).abs() < 1e-4, "({i}, {j}): weights sum to {w}");
            }
        }
        // roughness 0: every tap on the dominant direction at roughness 0
        for t in lobe_taps(0.5, 0.0) {
            assert!(t[0].abs() < 1e-6 && t[1] < 1e-6, "{t:?}");
        }
    }

    #[test]
    fn the_shader_reads_every_tap() {
        let wgsl = include_str!("../../../shaders/render/environment.wgsl");
        let line = format!("for (var k = 0; k < {LOBE_TAPS}; k++)");
        assert!(wgsl.contains(&line), "environment.wgsl lacks `{line}`");
    }

    #[test]
    fn the_fit_reads_levels_as_the_shader_does() {
        // the fit models the shader's level fraction with the shader's fit of
        // the lobe's spread (spread.rs checks it against its integral)
        let fit = include_str!("../../../examples/ibl_lobe_fit.rs");
        let line = "a * a * (30.124 - 9.4665 * sa + 1.4145 * a) / (1.0 + 8.8945 * sa + 3.2514 * a + 46.424 * a * a)";
        assert!(
            fit.contains(line),
            "examples/ibl_lobe_fit.rs lacks `{line}`"
        );
        let wgsl = include_str!("../../../shaders/render/environment.wgsl");
        assert!(wgsl.contains(line), "environment.wgsl lacks `{line}`");
    }

    #[test]
    fn lookups_hit_the_grid_points() {
        let (i, j) = (5, 7);
        let got = lobe_taps(
            i as f32 / (LOBE_MU - 1) as f32,
            j as f32 / (LOBE_ROUGHNESS - 1) as f32,
        );
        for (g, w) in got.iter().zip(&LOBE_TABLE[j][i]) {
            for c in 0..3 {
                assert!((g[c] - w[c]).abs() < 1e-5, "{g:?} vs {w:?}");
            }
        }
    }
}
