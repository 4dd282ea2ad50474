//! `fog` against the analytic blend (linear, exponential, exponential squared) at
//! constant depth, depth 0 left alone, radial distance and height falloff.

use super::*;

const FOG_COLOR: [f32; 3] = [0.5, 0.6, 0.7];

/// The transmittance f(D) of fog mode `mode` (as documented in effects/fog.fx).
fn fog_transmittance(mode: &str, d: f64, density: f64, start: f64, end: f64) -> f64 {
    match mode {
        "linear" => ((end - d) / (end - start)).clamp(0.0, 1.0),
        "exponential" => (-density * d).exp(),
        "exponential_squared" => (-(density * d).powi(2)).exp(),
        other => panic!("unknown fog mode {other}"),
    }
}

/// Largest difference of `out` from mix(scene, FOG_COLOR, 1 - f(pixel)), alpha kept.
fn fog_error(out: &[f32], scene: &Image, f: impl Fn(usize) -> f64) -> f64 {
    let src = f32s(&scene.pixels);
    let mut worst = 0.0f64;
    for (i, (o, s)) in out.chunks_exact(4).zip(src.chunks_exact(4)).enumerate() {
        let t = f(i);
        for c in 0..3 {
            let want = s[c] as f64 * t + FOG_COLOR[c] as f64 * (1.0 - t);
            worst = worst.max((o[c] as f64 - want).abs());
        }
        worst = worst.max((o[3] - s[3]).abs() as f64);
    }
    worst
}

#[test]
fn fog_matches_the_analytic_blend_at_constant_depth() {
    let Some(mut eng) = engine() else { return };
    let n = 32;
    let scene = colourful(n, n);
    let cam = perspective(60.0, 1.0);
    let (density, start, end) = (0.12, 2.0, 20.0);
    for mode in ["linear", "exponential", "exponential_squared"] {
        for d in [0.5f32, 3.0, 8.0, 19.0, 40.0] {
            let g = depth_map(n, n, |_, _| d);
            let o = [
                format!("mode={mode}"),
                format!("density={density}"),
                format!("start={start}"),
                format!("end={end}"),
            ];
            let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
            let f = fog_transmittance(mode, d as f64, density, start, end);
            let out = run_gbuffer(&mut eng, "fog", &o, &scene, &g, &cam);
            let err = fog_error(&out, &scene, |_| f);
            eprintln!("fog {mode} at depth {d}: f = {f:.4}, max error {err:.2e}");
            assert!(err < 1e-3, "{mode} at depth {d}: error {err}");
        }
    }
    // The defaults (exponential, density 0.05) through apply_in_memory.
    let g = depth_map(n, n, |_, _| 10.0);
    let out = run_aux(&mut eng, "fog", &[], &scene, &g);
    let err = fog_error(&out, &scene, |_| (-0.5f64).exp());
    eprintln!("fog defaults at depth 10 (apply_in_memory): max error {err:.2e}");
    assert!(err < 1e-3, "defaults: error {err}");
}

#[test]
fn fog_leaves_depth_zero_unchanged() {
    let Some(mut eng) = engine() else { return };
    let n = 32;
    let scene = colourful(n, n);
    let src = f32s(&scene.pixels);
    let cam = perspective(60.0, 1.0);
    // Depth 0 everywhere but one column at depth 30 (which is fogged).
    let g = depth_map(n, n, |x, _| if x == 5 { 30.0 } else { 0.0 });
    for mode in ["linear", "exponential", "exponential_squared"] {
        for extra in [
            &[][..],
            &["height_falloff=0.3", "camera_height=2", "distance=radial"][..],
        ] {
            let mut o = vec![
                format!("mode={mode}"),
                "density=0.2".to_string(),
                "end=10".to_string(),
            ];
            o.extend(extra.iter().map(|s| s.to_string()));
            let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
            let out = run_gbuffer(&mut eng, "fog", &o, &scene, &g, &cam);
            let mut worst = 0.0f32;
            for (i, (a, b)) in out.iter().zip(src).enumerate() {
                if (i / 4) as u32 % n != 5 {
                    worst = worst.max((a - b).abs());
                }
            }
            let fogged = (out[5 * 4] - src[5 * 4]).abs();
            eprintln!("fog {o:?}: depth 0 max diff {worst:e}, depth 30 diff {fogged:.3}");
            assert_eq!(worst, 0.0, "{o:?}: depth 0 changed");
            assert!(fogged > 0.01, "{o:?}: depth 30 not fogged");
        }
    }
}

#[test]
fn fog_radial_distance_and_height_falloff() {
    let Some(mut eng) = engine() else { return };
    let n = 48;
    let scene = colourful(n, n);
    let density = 0.15;
    // A wall facing a level camera: the radial distance grows off-centre.
    let cam = perspective(70.0, 1.0);
    let g = raycast(n, n, &cam, &[plane([0.0, 0.0, -8.0], [0.0, 0.0, 1.0])]);
    let dist = |i: usize| DVec3::from(g.position[i].map(|v| v as f64)).length();
    let out = run_gbuffer(
        &mut eng,
        "fog",
        &["distance=radial", "density=0.15"],
        &scene,
        &g,
        &cam,
    );
    let err = fog_error(&out, &scene, |i| (-density * dist(i)).exp());
    eprintln!(
        "radial exponential fog: max error {err:.2e} (distance {:.3} .. {:.3})",
        dist(((n / 2) * n + n / 2) as usize),
        dist(0)
    );
    assert!(err < 1e-3, "radial: error {err}");

    // Height fog seen by the pitched camera of the room (2.5 above the floor): the
    // floor and the wall, world heights from the rig, up = the world's up in view space.
    let cam = perspective(60.0, 1.0);
    let g = raycast(
        n,
        n,
        &cam,
        &[
            ROOM.plane([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], |_| true),
            ROOM.plane([0.0, 0.0, -6.0], [0.0, 0.0, 1.0], |_| true),
        ],
    );
    let up = glam::DMat3::from_rotation_x(ROOM.pitch) * DVec3::Y;
    let (k, h0) = (0.8, 0.5);
    for (mode, distance) in [
        ("exponential", "radial"),
        ("exponential_squared", "depth"),
        ("linear", "radial"),
    ] {
        let o = [
            format!("mode={mode}"),
            format!("distance={distance}"),
            format!("density={density}"),
            "start=1".to_string(),
            "end=12".to_string(),
            format!("height_falloff={k}"),
            format!("fog_height={h0}"),
            format!("camera_height={}", ROOM.height),
            format!("up=({},{},{})", up.x, up.y, up.z),
        ];
        let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
        let out = run_gbuffer(&mut eng, "fog", &o, &scene, &g, &cam);
        assert_finite(&out, "fog");
        let f = |i: usize| {
            let p = DVec3::from(g.position[i].map(|v| v as f64));
            let l = if distance == "radial" {
                p.length()
            } else {
                g.depth[i] as f64
            };
            // The mean density along the segment, from world heights.
            let (hc, hp) = (ROOM.height, ROOM.to_world(p).y);
            let x = k * (hp - hc);
            let mean_exp = if x.abs() < 1e-9 {
                1.0
            } else {
                (1.0 - (-x).exp()) / x
            };
            let d = l * (-k * (hc - h0)).exp() * mean_exp;
            fog_transmittance(mode, d, density, 1.0, 12.0)
        };
        let err = fog_error(&out, &scene, f);
        eprintln!("height fog {mode}/{distance}: max error {err:.2e}");
        assert!(err < 1e-3, "height fog {mode}/{distance}: error {err}");
    }
    // Denser low fog: the floor near the camera (low) gets more fog than uniform fog
    // of the density at the camera's height would give.
    let o = [
        format!("density={density}"),
        format!("height_falloff={k}"),
        format!("camera_height={}", ROOM.height),
        format!("up=({},{},{})", up.x, up.y, up.z),
    ];
    let o: Vec<&str> = o.iter().map(|s| s.as_str()).collect();
    let low = run_gbuffer(&mut eng, "fog", &o, &grey(n, n, 0.0), &g, &cam);
    let i = (((n - 1) * n + n / 2) * 4) as usize;
    let at_camera = 1.0 - (-density * (-k * ROOM.height).exp() * g.depth[i / 4] as f64).exp();
    eprintln!(
        "floor below the camera: fog {:.4} vs {at_camera:.4} at the camera's density",
        low[i] / FOG_COLOR[0]
    );
    assert!((low[i] / FOG_COLOR[0]) as f64 > at_camera * 1.5);
}
