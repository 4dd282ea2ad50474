//! `outline`: a depth step is marked exactly on its near side, flat and slanted
//! planes give nothing, a normal crease is found, and antialiasing blends only across
//! edges.

use super::*;

/// The columns (x) where `mask` is above 0.5, row by row.
fn marked_columns(mask: &[f32], w: u32) -> Vec<Vec<u32>> {
    mask.chunks_exact(w as usize)
        .map(|row| (0..w).filter(|&x| row[x as usize] > 0.5).collect())
        .collect()
}

/// The largest |out - want(x, i, c)| over the samples of an `n` x `n` image: x the
/// pixel's column, i the index of its first sample, c the channel.
fn worst_diff(out: &[f32], n: u32, want: impl Fn(u32, usize, usize) -> f32) -> f32 {
    let mut worst = 0.0f32;
    for y in 0..n {
        for x in 0..n {
            let i = ((y * n + x) * 4) as usize;
            for c in 0..4 {
                worst = worst.max((out[i + c] - want(x, i, c)).abs());
            }
        }
    }
    worst
}

fn outline_mask(eng: &mut Engine, o: &[&str], g: &GBuffer, cam: &Camera) -> Vec<f32> {
    let mut o = o.to_vec();
    o.push("mode=mask");
    let out = run_gbuffer(eng, "outline", &o, &grey(g.w, g.h, 0.5), g, cam);
    assert_finite(&out, "outline");
    // The mask is binary at width 1 and grey.
    channel(&out, 0)
}

/// An `n` x `n` view of a board at depth 4 on the left half and a wall at depth 6
/// on the right half (x >= n / 2).
fn depth_step(n: u32) -> GBuffer {
    depth_map(n, n, |x, _| if x < n / 2 { 4.0 } else { 6.0 })
}

#[test]
fn outline_marks_a_depth_step_exactly() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    let g = depth_step(n);
    let cam = perspective(60.0, 1.0);
    let mask = outline_mask(&mut eng, &[], &g, &cam);
    assert!(
        mask.iter().all(|&v| v == 0.0 || v == 1.0),
        "mask not binary"
    );
    let cols = marked_columns(&mask, n);
    assert!(
        cols.iter().all(|c| c == &vec![31]),
        "outline columns {:?}",
        &cols[..4]
    );
    eprintln!(
        "depth step: outline exactly on column 31 (the near side), {} pixels",
        mask.iter().filter(|&&v| v > 0.5).count()
    );

    // Thresholds: the step is 2 / 4 = 0.5 of the near depth.
    for (t, expect) in [(0.4, true), (0.6, false)] {
        let o = format!("depth_threshold={t}");
        let m = outline_mask(&mut eng, &[&o], &g, &cam);
        let count = m.iter().filter(|&&v| v > 0.5).count();
        eprintln!("depth_threshold {t}: {count} outline pixels");
        assert_eq!(
            count,
            if expect { n as usize } else { 0 },
            "depth_threshold {t}"
        );
    }

    // Width 2: the columns beside the line too; overlay draws the colour there.
    let m = outline_mask(&mut eng, &["width=2"], &g, &cam);
    assert!(marked_columns(&m, n).iter().all(|c| c == &vec![30, 31, 32]));
    let scene = colourful(n, n);
    let src = f32s(&scene.pixels);
    let sets = ["color=(1,0,1)", "opacity=0.5"];
    let out = run_gbuffer(&mut eng, "outline", &sets, &scene, &g, &cam);
    let worst = worst_diff(&out, n, |x, i, c| {
        if x == 31 && c < 3 {
            0.5 * src[i + c] + 0.5 * [1.0, 0.0, 1.0][c]
        } else {
            src[i + c]
        }
    });
    eprintln!("overlay: max diff from the expected image {worst:e}");
    assert!(worst < 1e-6, "overlay differs by {worst}");

    // The same through apply_in_memory (rgba16f G-buffer images, no camera).
    let out = run_aux(&mut eng, "outline", &["mode=mask"], &grey(n, n, 0.5), &g);
    assert!(marked_columns(&channel(&out, 0), n)
        .iter()
        .all(|c| c == &vec![31]));
}

#[test]
fn outline_finds_nothing_on_flat_or_slanted_planes() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    let cam = perspective(60.0, 1.0);
    // A plane slanted by 41 degrees filling the view, and the floor grazing to the
    // horizon under a sky.
    let slanted = raycast(n, n, &cam, &[plane([0.0, 0.0, -5.0], [0.55, 0.35, 0.75])]);
    assert!(slanted.depth.iter().all(|&d| d > 0.0));
    let floor = raycast(
        n,
        n,
        &cam,
        &[plane_where([0.0, -1.0, 0.0], [0.0, 1.0, 0.0], |p| {
            p.z > -80.0
        })],
    );
    for (what, g) in [("slanted plane", &slanted), ("floor", &floor)] {
        let mask = outline_mask(&mut eng, &["depth_threshold=0.02"], g, &cam);
        let cols = marked_columns(&mask, n);
        // The floor's far edge against the sky (the renderer's background: depth =
        // far, normal 0) is a silhouette: the last floor row, nothing else.
        let rows: Vec<usize> = (0..n as usize).filter(|&y| !cols[y].is_empty()).collect();
        eprintln!("{what}: outline rows {rows:?}");
        if what == "floor" {
            let last = (0..n).rev().find(|&y| g.depth_at(0, y) == 100.0).unwrap() + 1;
            assert_eq!(rows, vec![last as usize], "floor outline rows");
            assert_eq!(cols[last as usize].len(), n as usize);
        } else {
            assert!(rows.is_empty(), "outline on a plane: rows {rows:?}");
        }
    }
}

#[test]
fn outline_detects_a_normal_crease() {
    let Some(mut eng) = engine() else { return };
    let n = 64;
    // A valley seen without a renderer (identity camera: view x = ndc x): two planes
    // meeting at x = 0 at 53.13 degrees, depth continuous (5 + |x| / 2).
    let cam = identity_camera();
    let valley = raycast(
        n,
        n,
        &cam,
        &[
            plane_where([0.0, 0.0, 5.0], [0.5, 0.0, 1.0], |p| p.x < 0.0),
            plane_where([0.0, 0.0, 5.0], [-0.5, 0.0, 1.0], |p| p.x >= 0.0),
        ],
    );
    let step = (valley.depth_at(32, 0) - valley.depth_at(31, 0)).abs();
    assert!(
        step < 1e-4,
        "depth not continuous across the crease: {step}"
    );
    for (t, want) in [(30.0, vec![31, 32]), (50.0, vec![31, 32]), (55.0, vec![])] {
        let o = format!("normal_threshold={t}");
        let out = run_aux(
            &mut eng,
            "outline",
            &["mode=mask", &o],
            &grey(n, n, 0.5),
            &valley,
        );
        let cols = marked_columns(&channel(&out, 0), n);
        eprintln!("valley, normal_threshold {t}: columns {:?}", cols[0]);
        assert!(
            cols.iter().all(|c| c == &want),
            "normal_threshold {t}: {:?}",
            cols[0]
        );
    }

    // The concave corner of the room in perspective: floor meeting the wall at 90
    // degrees. The outline follows the corner line, one pixel per column.
    let (g, cam, row) = corner_scene(n, Vec::new());
    let mask = outline_mask(&mut eng, &[], &g, &cam);
    let mut rows_per_col = Vec::new();
    for x in 0..n {
        let rows: Vec<u32> = (0..n)
            .filter(|&y| mask[(y * n + x) as usize] > 0.5)
            .collect();
        assert!(
            !rows.is_empty() && rows.iter().all(|&y| y.abs_diff(row) <= 1),
            "column {x}: rows {rows:?} (corner row {row})"
        );
        rows_per_col.push(rows.len());
    }
    eprintln!(
        "room corner (row {row}): outline rows per column {:?}",
        &rows_per_col[..8]
    );
    assert!(
        rows_per_col.iter().all(|&k| k == 1),
        "more than one outline row in a column"
    );
    let o = outline_mask(&mut eng, &["normal_threshold=95"], &g, &cam);
    assert!(o.iter().all(|&v| v == 0.0), "corner found above its angle");
}

#[test]
fn outline_antialias_blends_across_edges_only() {
    let Some(mut eng) = engine() else { return };
    let n = 32;
    let g = depth_step(n);
    let cam = perspective(60.0, 1.0);
    let (red, blue) = ([1.0, 0.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]);
    let scene = image_f32(n, n, |x, y| {
        if x < 16 {
            red
        } else if y % 2 == 0 {
            blue
        } else {
            [0.0, 0.5, 1.0, 1.0]
        }
    });
    let src = f32s(&scene.pixels);
    for strength in [1.0f32, 0.5] {
        let o = format!("strength={strength}");
        let out = run_gbuffer(
            &mut eng,
            "outline",
            &["mode=antialias", &o],
            &scene,
            &g,
            &cam,
        );
        let worst = worst_diff(&out, n, |x, i, c| {
            let across = match x {
                15 => Some(i + 4),
                16 => Some(i - 4),
                _ => None,
            };
            match across {
                Some(j) => src[i + c] + 0.5 * strength * (src[j + c] - src[i + c]),
                None => src[i + c],
            }
        });
        eprintln!("antialias strength {strength}: max diff from the expected blend {worst:e}");
        assert!(worst < 1e-6, "antialias strength {strength}: {worst}");
    }
}
