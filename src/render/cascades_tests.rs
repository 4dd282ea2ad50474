//! Unit tests of `cascades.rs`: the stable fit holds its slice, keeps its square
//! while the slice moves inside a cell, takes the scene's square when that is
//! no larger or the slice sees nothing, and the per-frame fit is the reference.

use super::*;

const SIZE: f32 = 2048.0;
const BORDER: f32 = SIZE / (SIZE - 6.0);

/// A scene far larger than every slice of these tests.
fn huge() -> Aabb {
    Aabb {
        min: Vec3::splat(-1e4),
        max: Vec3::splat(1e4),
    }
}

#[test]
fn the_ladder_rounds_up_to_its_rungs() {
    for x in [0.013f32, 0.5, 1.0, 1.7, 2.0, 3.3, 250.0] {
        let up = ladder_up(x);
        assert!(
            up >= x && up < x * 2f32.powf(1.0 / LADDER_STEPS) * 1.0001,
            "{x} {up}"
        );
        assert_eq!(ladder_up(up), up, "a rung is its own rung");
    }
    assert_eq!(ladder_up(1.0), 1.0);
}

#[test]
fn the_stable_square_holds_the_slice_with_a_bounded_margin() {
    let rung = 2f32.powf(1.0 / LADDER_STEPS);
    for r in [0.05f32, 0.9, 1.0, 3.7, 42.0] {
        for i in 0..200 {
            let t = i as f32 * 0.618_034;
            let c = Vec3::new(
                (t * 7.3).sin() * 50.0 * r,
                (t * 3.1).cos() * 20.0 * r - 3.0,
                t,
            );
            let s = stable(c, r, &huge(), (SIZE, BORDER), false);
            let d = (c.truncate() - s.center).abs().max_element();
            assert!(d + r <= s.half * (1.0 + 1e-5), "{c} {r}: {s:?}");
            assert!(s.half >= r * (1.0 + MARGIN), "{r}: {}", s.half);
            assert!(
                s.half < r * (1.0 + MARGIN) * rung * 1.0001,
                "{r}: {}",
                s.half
            );
            assert_eq!(s.z, (-1e4, 1e4), "the scene's depth range");
        }
    }
}

#[test]
fn the_stable_square_moves_once_per_cell_crossed() {
    // the slice's centre walks 10 radii along x: the square changes only when
    // the centre crosses into the next cell
    let r = 1.3;
    let first = stable(Vec3::ZERO, r, &huge(), (SIZE, BORDER), false);
    let cell = cell_texels(SIZE) * first.texel(SIZE);
    assert!(cell > 2.0 * MARGIN * r * 0.9, "{cell}");
    let steps = 1000;
    let mut moves = 0;
    let mut last = first;
    for i in 1..=steps {
        let c = Vec3::new(10.0 * r * i as f32 / steps as f32, 0.25, -2.0);
        let s = stable(c, r, &huge(), (SIZE, BORDER), false);
        if s != last {
            moves += 1;
            // by whole texels of the map
            let shift = (s.center - last.center) / s.texel(SIZE);
            assert!(
                (shift - shift.round()).abs().max_element() < 1e-2,
                "{shift}"
            );
        }
        last = s;
    }
    let crossings = (10.0 * r / cell).ceil() as usize;
    assert!(moves <= crossings, "{moves} moves, {crossings} cells");
    // the per-frame fit moves with nearly every step
    let mut refits = 0;
    let mut last = refit(Vec3::ZERO, r, &huge(), SIZE);
    for i in 1..=steps {
        let c = Vec3::new(10.0 * r * i as f32 / steps as f32, 0.25, -2.0);
        let s = refit(c, r, &huge(), SIZE);
        refits += usize::from(s != last);
        last = s;
    }
    assert!(refits > 10 * moves, "{refits} refits, {moves} moves");
}

#[test]
fn the_scene_square_serves_slices_that_cover_or_miss_the_scene() {
    let scene = Aabb {
        min: Vec3::new(-2.0, -1.0, -9.0),
        max: Vec3::new(4.0, 1.0, -3.0),
    };
    let whole = CascadeSquare {
        center: Vec2::new(1.0, 0.0),
        half: 3.0 * BORDER,
        z: (-9.0, -3.0),
    };
    // a sphere larger than the scene, anywhere near it
    assert_eq!(
        stable(
            Vec3::new(0.5, 0.3, -6.0),
            5.0,
            &scene,
            (SIZE, BORDER),
            false
        ),
        whole
    );
    assert_eq!(
        stable(
            Vec3::new(-3.0, 2.0, 0.0),
            9.0,
            &scene,
            (SIZE, BORDER),
            false
        ),
        whole
    );
    // a small sphere that holds none of the scene
    assert_eq!(
        stable(Vec3::new(1.0, 0.0, 2.0), 1.0, &scene, (SIZE, BORDER), true),
        whole
    );
    assert!(misses(Vec3::new(1.0, 0.0, 2.0), 1.0, &scene));
    assert!(!misses(Vec3::new(1.0, 0.0, -2.5), 1.0, &scene));
    assert!(
        misses(Vec3::new(5.0, 2.0, -2.0), 1.5, &scene),
        "beyond an edge"
    );
    // a small sphere inside the scene gets a square of its own
    let own = stable(
        Vec3::new(1.0, 0.0, -6.0),
        1.0,
        &scene,
        (SIZE, BORDER),
        false,
    );
    assert!(own.half < 1.3 && own.z == whole.z, "{own:?}");
}

#[test]
fn the_per_frame_fit_is_the_snapped_sphere_over_the_stretched_depth() {
    let scene = Aabb {
        min: Vec3::new(-2.0, -1.0, -9.0),
        max: Vec3::new(4.0, 1.0, -3.0),
    };
    let s = refit(Vec3::new(0.3, 0.2, -1.0), 2.0, &scene, SIZE);
    let texel = 4.0 / SIZE;
    assert_eq!(s.half, 2.0);
    assert_eq!(s.center, (Vec2::new(0.3, 0.2) / texel).floor() * texel);
    assert_eq!(s.z, (-9.0, 1.0), "stretched over the sphere");
}

#[test]
fn the_stable_far_end_holds_the_scene_whichever_way_the_camera_looks() {
    let b = Aabb {
        min: Vec3::new(-6.0, 0.0, -6.0),
        max: Vec3::new(6.0, 5.0, 6.0),
    };
    let eye = Vec3::new(3.0, 4.0, 12.0);
    let far = stable_far(eye, &b);
    for i in 0..8 {
        let corner = Vec3::new(
            if i & 1 == 0 { b.min.x } else { b.max.x },
            if i & 2 == 0 { b.min.y } else { b.max.y },
            if i & 4 == 0 { b.min.z } else { b.max.z },
        );
        assert!((corner - eye).length() <= far, "{corner}");
    }
}
