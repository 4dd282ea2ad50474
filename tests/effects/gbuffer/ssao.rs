//! `ssao` on ray-cast G-buffers: a concave corner darkens and the open floor does
//! not, the defaults give visible contact shadows, a flat plane gives exactly 1, and
//! the blur does not cross depth discontinuities.

use super::*;

/// The AO of `g` seen by `cam` with `sets` (`output=ao` among them): asserted finite,
/// one value per pixel.
fn ao_map(eng: &mut Engine, sets: &[&str], scene: &Image, g: &GBuffer, cam: &Camera) -> Vec<f32> {
    let v = run_gbuffer(eng, "ssao", sets, scene, g, cam);
    assert_finite(&v, "ssao");
    channel(&v, 0)
}

/// Asserts that no pixel of a flat surface's AO is occluded: all above 0.99.
#[track_caller]
fn assert_unoccluded(what: &str, ao: &[f32]) {
    let lo = min_of(ao);
    eprintln!("{what}: min AO {lo:.5}");
    assert!(lo > 0.99, "{what}: AO min {lo}");
}

#[test]
fn ssao_darkens_a_concave_corner_and_leaves_the_open_floor() {
    let Some(mut eng) = engine() else { return };
    let n = 96;
    let (g, cam, row) = corner_scene(n, Vec::new());
    // The ray-cast scene: the wall above the corner row, the floor below, both
    // reaching it (continuous depth across the corner).
    let (above, below) = (g.depth_at(48, row - 1), g.depth_at(48, row + 1));
    assert!(
        (above - below).abs() < 0.25 && above > 5.5,
        "{above} {below}"
    );
    let scene = grey(n, n, 0.5);
    let ao = ao_map(
        &mut eng,
        &["output=ao", "radius=1", "intensity=1"],
        &scene,
        &g,
        &cam,
    );
    dump("ssao corner", &ao, n, 1.0, 0.0);
    eprintln!("corner row {row}");
    // Along the corner (both sides, central columns): clearly darkened.
    let corner = region(&ao, n, 16, 80, row - 1, row + 2);
    let corner_mean = mean(&corner);
    let corner_max = max_of(&corner);
    eprintln!("corner: mean {corner_mean:.3}, max {corner_max:.3}");
    assert!(corner_max < 0.9, "corner AO max {corner_max}");
    assert!(corner_mean < 0.85, "corner AO mean {corner_mean}");
    let darkest = min_of(&region(&ao, n, 0, n, row - 4, row + 4));
    eprintln!("darkest near the corner: {darkest:.3}");
    assert!(darkest < 0.8, "darkest AO near the corner {darkest}");
    // Open floor near the camera (the bottom rows: 4 units or more from the wall).
    let floor = region(&ao, n, 0, n, n - 12, n);
    let floor_min = min_of(&floor);
    eprintln!("open floor: min {floor_min:.4}");
    assert!(floor_min > 0.95, "open floor AO min {floor_min}");
    // The wall high above the floor (> 3 units from it).
    let wall = region(&ao, n, 0, n, 0, 8);
    assert!(min_of(&wall) > 0.95, "open wall AO min {}", min_of(&wall));
    // AO darkens monotonically towards the corner from the open floor (coarsely).
    let band = |y0: u32| mean(&region(&ao, n, 16, 80, y0, y0 + 4));
    assert!(band(row + 1) < band(row + 8) && band(row + 8) <= band(n - 8) + 1e-6);

    // The intensity scales the occlusion (the blur is linear in the AO).
    let sets = ["output=ao", "radius=1", "intensity=2"];
    let ao2 = channel(&run_gbuffer(&mut eng, "ssao", &sets, &scene, &g, &cam), 0);
    let scaled = ao
        .iter()
        .zip(&ao2)
        .map(|(&a, &b)| ((1.0 - b) - 2.0 * (1.0 - a)).abs())
        .fold(0.0f32, f32::max);
    eprintln!("intensity 2 vs 2 x occlusion: max diff {scaled:.5}");
    assert!(
        scaled < 2e-3,
        "intensity 2: occlusion not doubled ({scaled})"
    );

    // The composite multiplies the scene by the same AO.
    let scene = colourful(n, n);
    let out = run_gbuffer(
        &mut eng,
        "ssao",
        &["radius=1", "intensity=1"],
        &scene,
        &g,
        &cam,
    );
    let src = f32s(&scene.pixels);
    let mut worst = 0.0f32;
    for i in 0..(n * n) as usize {
        for c in 0..3 {
            worst = worst.max((out[i * 4 + c] - src[i * 4 + c] * ao[i]).abs());
        }
        assert_eq!(out[i * 4 + 3], 1.0);
    }
    assert!(worst < 2e-3, "composite differs from scene * ao by {worst}");
}

#[test]
fn ssao_defaults_give_visible_contact_shadows() {
    // Issue 10: at its defaults (radius 0.5, intensity 2) SSAO visibly darkens a
    // concave corner (intensity 1 left about 0.8 there: barely visible), and still
    // leaves the open floor and wall alone.
    let Some(mut eng) = engine() else { return };
    let n = 96;
    let (g, cam, row) = corner_scene(n, Vec::new());
    let ao = ao_map(&mut eng, &["output=ao"], &grey(n, n, 0.5), &g, &cam);
    let darkest = min_of(&region(&ao, n, 0, n, row - 4, row + 4));
    let corner_mean = mean(&region(&ao, n, 16, 80, row - 1, row + 2));
    let floor_min = min_of(&region(&ao, n, 0, n, n - 12, n));
    let wall_min = min_of(&region(&ao, n, 0, n, 0, 8));
    eprintln!("defaults: corner mean {corner_mean:.3}, darkest {darkest:.3}, open floor min {floor_min:.3}, wall min {wall_min:.3}");
    assert!(darkest < 0.75, "darkest AO near the corner {darkest}");
    assert!(corner_mean < 0.82, "corner AO mean {corner_mean}");
    assert!(
        floor_min > 0.95 && wall_min > 0.95,
        "open floor {floor_min}, wall {wall_min}"
    );
}

#[test]
fn ssao_of_a_flat_plane_is_one_everywhere() {
    let Some(mut eng) = engine() else { return };
    // A plane filling the view, tilted in both axes, seen in perspective.
    let n = 64;
    let cam = perspective(70.0, 1.0);
    let g = raycast(n, n, &cam, &[plane([0.0, 0.0, -5.0], [0.4, 0.5, 0.75])]);
    assert!(g.depth.iter().all(|&d| d > 0.0));
    let white = grey(n, n, 1.0);
    let ao = ao_map(&mut eng, &["output=ao", "samples=32"], &white, &g, &cam);
    assert_unoccluded("tilted plane (perspective)", &ao);

    // The floor alone under an empty sky (the renderer's background: depth = far,
    // normal 0), grazing far away.
    let g = raycast(
        n,
        n,
        &cam,
        &[plane_where([0.0, -1.0, 0.0], [0.0, 1.0, 0.0], |p| {
            p.z > -60.0
        })],
    );
    assert_eq!((g.depth_at(0, 0), g.normal[0]), (100.0, [0.0; 3]));
    let ao = ao_map(&mut eng, &["output=ao", "radius=1"], &white, &g, &cam);
    assert_unoccluded("floor and sky", &ao);

    // Without a renderer (identity camera, rgba16f G-buffer images): a slanted plane.
    let cam = identity_camera();
    let g = raycast(n, n, &cam, &[plane([0.0, 0.0, 5.0], [0.3, -0.2, -1.0])]);
    let ao = run_aux(
        &mut eng,
        "ssao",
        &["output=ao", "radius=0.3"],
        &grey(n, n, 1.0),
        &g,
    );
    assert_finite(&ao, "ssao");
    assert_unoccluded("slanted plane (identity camera)", &channel(&ao, 0));
}

#[test]
fn ssao_blur_does_not_cross_depth_discontinuities() {
    let Some(mut eng) = engine() else { return };
    // The corner scene with a board parallel to the wall, 3 units ahead, floating
    // 1 unit above the floor, covering the left half of the view: its AO is exactly
    // 1 before the blur; the corner beside it is dark.
    let n = 96;
    let board = ROOM.plane([0.0, 0.0, -3.0], [0.0, 0.0, 1.0], |p| {
        p.x < 0.0 && p.y > 1.0
    });
    let (g, cam, row) = corner_scene(n, vec![board]);
    let half = n / 2;
    assert!(g.depth_at(half - 1, row) < 4.0 && g.depth_at(half, row) > 5.0);
    let ao = |eng: &mut Engine, o: &[&str]| ao_map(eng, o, &grey(n, n, 1.0), &g, &cam);
    let raw = ao(
        &mut eng,
        &["output=ao", "radius=1", "intensity=1", "blur=false"],
    );
    let blurred = ao(&mut eng, &["output=ao", "radius=1", "intensity=1"]);
    dump("ssao raw", &raw, n, 1.0, 0.0);
    dump("ssao blurred", &blurred, n, 1.0, 0.0);
    // The board, up to its edge, stays unoccluded: no dark AO of the corner behind
    // it leaks onto it.
    let on_board = |v: &[f32]| -> Vec<f32> {
        v.iter()
            .zip(&g.depth)
            .filter(|(_, &d)| d > 0.0 && d < 4.0)
            .map(|(&a, _)| a)
            .collect()
    };
    let board_raw = min_of(&on_board(&raw));
    let board = min_of(&on_board(&blurred));
    eprintln!("board: raw min {board_raw:.5}, blurred min {board:.5}");
    assert!(
        board_raw > 0.999 && board > 0.999,
        "board AO {board_raw} / {board}"
    );
    // Right beside it the corner stays dark: the board's AO of 1 does not leak
    // into it either.
    let beside_raw = mean(&region(&raw, n, half, half + 2, row - 1, row + 2));
    let beside = mean(&region(&blurred, n, half, half + 2, row - 1, row + 2));
    eprintln!("corner beside the board: mean raw {beside_raw:.4}, blurred {beside:.4}");
    assert!(
        beside < 0.9 && (beside - beside_raw).abs() < 0.06,
        "corner beside the board {beside_raw} -> {beside}"
    );
    // The blur smooths the rotation noise along the corner.
    let noisy = variance(&region(&raw, n, half + 8, n - 8, row - 2, row + 2));
    let smooth = variance(&region(&blurred, n, half + 8, n - 8, row - 2, row + 2));
    eprintln!("corner variance: raw {noisy:.6}, blurred {smooth:.6}");
    assert!(
        smooth < 0.5 * noisy,
        "blur did not reduce the noise: {noisy} -> {smooth}"
    );
}
