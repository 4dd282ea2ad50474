//! `dof`: in focus is the identity, a far checker blurs, a sharp foreground keeps its
//! edge without a halo, and a blurred foreground spreads over a sharp background.

use super::*;

/// A checker of 4-pixel squares in two colours with red = 0.
fn checker(w: u32, h: u32) -> Image {
    image_f32(w, h, |x, y| {
        if (x / 4 + y / 4) % 2 == 0 {
            [0.0, 0.875, 0.125, 1.0]
        } else {
            [0.0, 0.125, 0.75, 1.0]
        }
    })
}

/// An `n` x `n` scene: the pixels where `square` holds in `colour` at depth
/// `depths.0`, the checker elsewhere at depth `depths.1`: (G-buffer, scene).
fn square_over_checker(
    n: u32,
    square: impl Fn(u32, u32) -> bool,
    depths: (f32, f32),
    colour: [f32; 4],
) -> (GBuffer, Image) {
    let g = depth_map(n, n, |x, y| if square(x, y) { depths.0 } else { depths.1 });
    let bg = checker(n, n);
    let b = f32s(&bg.pixels);
    let scene = image_f32(n, n, |x, y| {
        let i = ((y * n + x) * 4) as usize;
        if square(x, y) {
            colour
        } else {
            [b[i], b[i + 1], b[i + 2], 1.0]
        }
    });
    (g, scene)
}

/// `dof` with `sets` (a 60° camera) on the `n` x `n` [`square_over_checker`]: the
/// scene's samples and the output's, which must be finite.
fn dof_of_square(
    eng: &mut Engine,
    n: u32,
    square: impl Fn(u32, u32) -> bool,
    (depths, colour): ((f32, f32), [f32; 4]),
    sets: &[&str],
) -> (Vec<f32>, Vec<f32>) {
    let (g, scene) = square_over_checker(n, square, depths, colour);
    let cam = perspective(60.0, 1.0);
    let out = run_gbuffer(eng, "dof", sets, &scene, &g, &cam);
    assert_finite(&out, "dof");
    (f32s(&scene.pixels).to_vec(), out)
}

#[test]
fn dof_in_focus_is_identity() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    let scene = colourful(n, n);
    let src = f32s(&scene.pixels);
    let g = depth_map(n, n, |_, _| 5.0);
    let cam = perspective(60.0, 1.0);
    for o in [
        &["focus_distance=5"][..],
        &["focus_distance=5", "focal_range=0", "aperture=30"][..],
        &["focus_distance=4.5", "focal_range=1.5", "max_radius=64"][..],
    ] {
        let out = run_gbuffer(&mut eng, "dof", o, &scene, &g, &cam);
        let d = max_abs_diff(&out, src);
        eprintln!("dof {o:?}, depth = focus: max diff {d:e}");
        assert!(d < 1e-3, "{o:?}: in-focus scene changed by {d}");
    }
    // The same through apply_in_memory (depth as an rgba16f image).
    let out = run_aux(&mut eng, "dof", &["focus_distance=5"], &scene, &g);
    let d = max_abs_diff(&out, src);
    assert!(d < 1e-3, "in-focus scene changed by {d}");
}

#[test]
fn dof_blurs_a_far_checker() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    let scene = checker(n, n);
    let g = depth_map(n, n, |_, _| 50.0);
    let cam = perspective(60.0, 1.0);
    // CoC radius 8 (1 - 3 / 50) = 7.52 px.
    let out = run_gbuffer(&mut eng, "dof", &["focus_distance=2"], &scene, &g, &cam);
    assert_finite(&out, "dof");
    // Away from the border (clamped taps there).
    let inner = |v: &[f32]| region(&channel(v, 1), n, 12, n - 12, 12, n - 12);
    let (before, after) = (
        variance(&inner(f32s(&scene.pixels))),
        variance(&inner(&out)),
    );
    eprintln!(
        "far checker: green variance {before:.5} -> {after:.6} ({:.1}%)",
        100.0 * after / before
    );
    assert!(after < 0.05 * before, "variance {before} -> {after}");
    // The blur preserves the mean colour (the checker's mean is 0.5 in green).
    let m = mean(&inner(&out));
    assert!((m - 0.5).abs() < 0.02, "mean green {m}");
    // A smaller aperture blurs less.
    let sets = ["focus_distance=2", "aperture=2"];
    let out2 = run_gbuffer(&mut eng, "dof", &sets, &scene, &g, &cam);
    let small = variance(&inner(&out2));
    eprintln!("aperture 2: variance {small:.5}");
    assert!(
        small > 3.0 * after && small < 0.8 * before,
        "aperture 2: {small}"
    );
}

#[test]
fn dof_sharp_foreground_keeps_its_edge_without_halo() {
    let Some(mut eng) = engine() else { return };
    // An in-focus red square (depth 5 = focus) in front of a far checker (depth 50).
    let n = 64;
    let fg = |x: u32, y: u32| (16..40).contains(&x) && (20..44).contains(&y);
    let square = ((5.0, 50.0), [1.0, 0.25, 0.125, 1.0]);
    let (src, out) = dof_of_square(&mut eng, n, fg, square, &["focus_distance=5"]);
    let (mut fg_diff, mut halo) = (0.0f32, 0.0f32);
    for y in 0..n {
        for x in 0..n {
            let i = ((y * n + x) * 4) as usize;
            if fg(x, y) {
                // The sharp object, up to its edge, is unchanged.
                for c in 0..4 {
                    fg_diff = fg_diff.max((out[i + c] - src[i + c]).abs());
                }
            } else {
                // No red from the object spreads onto the blurred background.
                halo = halo.max(out[i]);
            }
        }
    }
    eprintln!("sharp foreground: max diff {fg_diff:e}; red on the background: max {halo:e}");
    assert!(fg_diff < 1e-3, "foreground changed by {fg_diff}");
    assert!(halo < 1e-3, "halo: red {halo} on the background");
    // The background itself is blurred, right up to the object.
    let strip = |v: &[f32]| region(&channel(v, 1), n, 44, 60, 4, 60);
    let (before, after) = (variance(&strip(&src)), variance(&strip(&out)));
    eprintln!("background beside the object: green variance {before:.4} -> {after:.5}");
    assert!(
        after < 0.1 * before,
        "background variance {before} -> {after}"
    );
}

#[test]
fn dof_blurred_foreground_spreads_over_a_sharp_background() {
    let Some(mut eng) = engine() else { return };
    // A near red square (depth 1) in front of an in-focus checker (depth 5):
    // CoC of the square -2 (4.5 / 1 - 1) = -7 px.
    let n = 64;
    let fg = |x: u32, y: u32| (20..44).contains(&x) && (20..44).contains(&y);
    let square = ((1.0, 5.0), [1.0, 0.0, 0.0, 1.0]);
    let sets = ["focus_distance=5", "focal_range=1", "aperture=2"];
    let (src, out) = dof_of_square(&mut eng, n, fg, square, &sets);
    let red = channel(&out, 0);
    dump("dof near field (red)", &red, n, 0.0, 1.0);
    // Distance (Chebyshev) of a background pixel from the square.
    let dist = |x: u32, y: u32| {
        let dx = (20i32 - x as i32).max(x as i32 - 43).max(0);
        let dy = (20i32 - y as i32).max(y as i32 - 43).max(0);
        dx.max(dy)
    };
    // The square's middle stays red; its blur reaches over the background next to
    // it (about half at the silhouette); beyond its CoC the background is sharp.
    let middle = min_of(&region(&red, n, 28, 36, 28, 36));
    let edge = mean(&region(&red, n, 43, 44, 28, 36));
    let next = mean(&region(&red, n, 44, 45, 28, 36));
    let mut far_diff = 0.0f32;
    for y in 0..n {
        for x in 0..n {
            if !fg(x, y) && dist(x, y) > 8 {
                let i = ((y * n + x) * 4) as usize;
                for c in 0..4 {
                    far_diff = far_diff.max((out[i + c] - src[i + c]).abs());
                }
            }
        }
    }
    let beyond = mean(&region(&red, n, 49, 50, 28, 36));
    eprintln!("near field: middle red min {middle:.3}, its edge {edge:.3}, next to it {next:.3}, 5 px out {beyond:.3}, >8 px max diff {far_diff:e}");
    assert!(middle > 0.99, "middle of the blurred square {middle}");
    assert!(
        edge > 0.4 && edge < 0.8,
        "red on the edge of the square {edge}"
    );
    assert!(next > 0.25 && next < edge, "red next to the square {next}");
    assert!(
        beyond > 0.01 && beyond < next,
        "red 5 px from the square {beyond}"
    );
    assert!(
        far_diff < 1e-3,
        "background beyond the CoC changed by {far_diff}"
    );
}
