//! Fits the environment term's lobe model (issue 29) and writes
//! `src/render/environment/lobe_table.rs`.
//!
//! The split sum reads the prefiltered specular cube once, along the lobe's
//! dominant direction, with the lobe of n = v: at n ≠ v the true lobe, the
//! glTF BRDF's `D·G2·cos / (4 n·v n·l)` cut at the surface's horizon, is
//! stretched along the plane of incidence and narrower across it, and the
//! split sum is 7–8 % off the integral for gold at roughness 0.3–0.7 under a
//! real map even with exact convolutions. Here, for a grid of (n·v, roughness),
//! the true lobe is approximated by [`TAPS`] reads of the prefiltered cube: tap
//! k reads along `normalize(r + o_k t)` (r the dominant direction of
//! environment.wgsl, t the unit vector in the plane of incidence
//! perpendicular to r, towards the normal) at the level of roughness `ρ_k`,
//! weighted by `w_k` (Σ w = 1, so a constant environment is kept exactly).
//! Each tap's lobe is the prefiltered level's, `D(d·h) G1(d·l)` about d,
//! normalised, of roughness `ρ_k` (at least 0.1, the first filtered level,
//! for surfaces from 0.1 on); below roughness 0.25 it is instead the mix of
//! two levels' lobes that the shader's trilinear read gives in a 1024 × 512
//! map's chain (levels of roughness 0, 0.1, 0.2, 0.3, 0.45, 0.7, 1: below 0.25
//! the lobe is no wider than the steps there),
//! with level 0, the unfiltered map, a lobe a texel wide (`LEVEL0_FOOTPRINT`).
//! At roughness 0 the taps are the split sum's (a mirror). The fit minimises the L1 distance between the normalised true
//! lobe and the weighted sum of tap lobes over the sphere (it bounds the
//! error of the mean radiance for any bounded map), by Nelder–Mead from the
//! neighbouring grid point's solution (so the table is smooth for bilinear
//! lookup; the first from the split sum's own lobe), restarted once.
//!
//! We wrote our own fit because the model is ours: the published fits
//! (Karis 2013, Lagarde 2014, Filament) give one direction and one level per
//! lookup, and none of them describes reading this renderer's chain (its
//! levels, its `D·G1` lobes, its level fraction) several times.
//!
//! Run (std only; under a minute with optimisations on two cores):
//! `cargo run --release --example ibl_lobe_fit > src/render/environment/lobe_table.rs`
//! or `rustc -O examples/ibl_lobe_fit.rs -o /tmp/fit && /tmp/fit > …`.

use std::f64::consts::PI;
use std::fmt::Write;

/// Taps per lobe.
const TAPS: usize = 4;
/// Grid: n·v = i / (MU − 1), roughness = j / (ROUGH − 1).
const MU: usize = 13;
const ROUGH: usize = 11;
/// The sphere's quadrature: polar about the dominant direction, θ = π t²
/// (dense near the centre, where narrow lobes are), `NT` × `NP` points.
const NT: usize = 64;
const NP: usize = 40;
/// Nelder–Mead evaluations per start.
const EVALS: usize = 600;

type V3 = [f64; 3];
/// A fitted grid point: the taps, the split sum's L1 distance, the fit's.
type Fitted = ([[f64; 3]; TAPS], f64, f64);

fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn add(a: V3, b: V3, s: f64) -> V3 {
    [a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]]
}
fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn norm(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    if l < 1e-12 {
        [0.0; 3]
    } else {
        [a[0] / l, a[1] / l, a[2] / l]
    }
}

/// The shader's α: roughness², at least 1e-3.
fn alpha(roughness: f64) -> f64 {
    (roughness * roughness).max(1e-3)
}

/// n = +Z, v in the xz plane at n·v = `mu`: (v, r the dominant direction as
/// environment.wgsl leans it, t the in-plane unit vector ⟂ r towards n).
fn frame(mu: f64, roughness: f64) -> (V3, V3, V3) {
    let n = [0.0, 0.0, 1.0];
    let v = [(1.0 - mu * mu).max(0.0).sqrt(), 0.0, mu];
    let a = roughness * roughness;
    let g = 1.0 - a;
    let mirror = add(scale(v, -1.0), n, 2.0 * mu);
    let r = norm(add(n, add(mirror, n, -1.0), g * (g.sqrt() + a)));
    let t = norm(add(n, r, -dot(n, r)));
    (v, r, t)
}

/// Quadrature points (direction, solid angle) about `c`.
fn grid(c: V3) -> Vec<(V3, f64)> {
    let up = if c[2].abs() < 0.9 {
        [0.0, 0.0, 1.0]
    } else {
        [1.0, 0.0, 0.0]
    };
    let b1 = norm(add(up, c, -dot(up, c)));
    let b2 = [
        c[1] * b1[2] - c[2] * b1[1],
        c[2] * b1[0] - c[0] * b1[2],
        c[0] * b1[1] - c[1] * b1[0],
    ];
    let mut out = Vec::with_capacity(NT * NP);
    let dt = 1.0 / NT as f64;
    let dp = 2.0 * PI / NP as f64;
    for i in 0..NT {
        let t = (i as f64 + 0.5) * dt;
        let theta = PI * t * t;
        let d_theta = 2.0 * PI * t * dt;
        for j in 0..NP {
            let phi = (j as f64 + 0.5) * dp;
            let (s, co) = theta.sin_cos();
            let d = add(add(scale(c, co), b1, s * phi.cos()), b2, s * phi.sin());
            out.push((d, s * d_theta * dp));
        }
    }
    out
}

/// The true lobe at each point, normalised: f·cos of the glTF BRDF for
/// F0 = 1 (D·V·n·l, height-correlated Smith), zero below the horizon.
fn true_lobe(pts: &[(V3, f64)], mu: f64, roughness: f64) -> Vec<f64> {
    let (v, _, _) = frame(mu, roughness);
    let a2 = alpha(roughness).powi(2);
    let ndv = mu.max(1e-4);
    let vals: Vec<f64> = pts
        .iter()
        .map(|&(l, _)| {
            let ndl = l[2];
            if ndl <= 0.0 {
                return 0.0;
            }
            let h = norm(add(l, v, 1.0));
            let dd = h[2] * h[2] * (a2 - 1.0) + 1.0;
            let d = a2 / (PI * dd * dd);
            let vis = 0.5
                / (ndl * (ndv * ndv * (1.0 - a2) + a2).sqrt()
                    + ndv * (ndl * ndl * (1.0 - a2) + a2).sqrt());
            d * vis * ndl
        })
        .collect();
    normalised(pts, vals)
}

/// A prefiltered level's lobe about `d`: D(d·h) G1(d·l), normalised.
fn tap_lobe(pts: &[(V3, f64)], d: V3, roughness: f64) -> Vec<f64> {
    let a2 = alpha(roughness).powi(2);
    let vals = pts
        .iter()
        .map(|&(l, _)| {
            let c = dot(d, l);
            if c <= 0.0 {
                return 0.0;
            }
            let ndh = dot(d, norm(add(d, l, 1.0)));
            let dd = ndh * ndh * (a2 - 1.0) + 1.0;
            let g1 = 2.0 / (1.0 + (1.0 + a2 * (1.0 - c * c) / (c * c)).sqrt());
            a2 / (PI * dd * dd) * g1
        })
        .collect();
    normalised(pts, vals)
}

fn normalised(pts: &[(V3, f64)], mut vals: Vec<f64>) -> Vec<f64> {
    let s: f64 = vals.iter().zip(pts).map(|(k, p)| k * p.1).sum();
    if s > 0.0 {
        vals.iter_mut().for_each(|k| *k /= s);
    }
    vals
}

/// The taps of parameter vector `p`: (offset, roughness, weight), weights
/// normalised to sum 1, roughness clamped to [0, 1].
fn taps(p: &[f64], floor: f64) -> [[f64; 3]; TAPS] {
    let total: f64 = (0..TAPS)
        .map(|k| p[3 * k + 2].abs())
        .sum::<f64>()
        .max(1e-12);
    std::array::from_fn(|k| {
        [
            p[3 * k],
            p[3 * k + 1].clamp(floor, 1.0),
            p[3 * k + 2].abs() / total,
        ]
    })
}

/// The last level of the specular cube the taps are read from: a 1024 × 512
/// map's chain, level m at roughness [`LEVEL_ROUGHNESS`]`[m]`
/// (docs/environment.md, "Prefiltering"); other chains read the same taps from
/// their own levels.
const LAST_LEVEL: f64 = 6.0;

/// src/render/environment/levels.rs's knots: a 1024 × 512 map's levels.
const LEVEL_ROUGHNESS: [f64; 7] = [0.0, 0.1, 0.2, 0.3, 0.45, 0.7, 1.0];

/// The level (0 ..= `LAST_LEVEL`, fractional) of roughness `rho`.
fn level_of(rho: f64) -> f64 {
    let r = rho.clamp(0.0, 1.0);
    let i = LEVEL_ROUGHNESS[1..]
        .iter()
        .position(|&k| r <= k)
        .unwrap_or(LEVEL_ROUGHNESS.len() - 2);
    i as f64 + (r - LEVEL_ROUGHNESS[i]) / (LEVEL_ROUGHNESS[i + 1] - LEVEL_ROUGHNESS[i])
}

/// environment.wgsl's `fx_env_lobe_spread` (the same constants).
fn spread(roughness: f64) -> f64 {
    let a = (roughness * roughness).max(1e-3);
    let sa = a.sqrt();
    a * a * (30.124 - 9.4665 * sa + 1.4145 * a) / (1.0 + 8.8945 * sa + 3.2514 * a + 46.424 * a * a)
}

/// What the shader's read at roughness `rho` mixes (`fx_env_specular_level`):
/// (the lower level, the fraction of the upper level's lobe).
fn levels(rho: f64) -> (usize, f64) {
    let k = level_of(rho).floor().min(LAST_LEVEL - 1.0) as usize;
    let (s0, s1) = (spread(LEVEL_ROUGHNESS[k]), spread(LEVEL_ROUGHNESS[k + 1]));
    let f = ((spread(rho) - s0) / (s1 - s0).max(1e-12)).clamp(0.0, 1.0);
    (k, f)
}

/// The lowest roughness a tap of a surface of roughness `roughness` reads:
/// any where the reads are modelled as mixes of levels (level 0 included, see
/// [`LEVEL0_FOOTPRINT`]), else not below the first filtered level.
fn floor(roughness: f64) -> f64 {
    if reads_levels(roughness) {
        0.0
    } else {
        roughness.min(LEVEL_ROUGHNESS[1])
    }
}

/// Level 0, the unfiltered source cube of a 1024 × 512 map (256² faces, 0.35°
/// texels), read bilinearly: not a point but a lobe about a texel wide, taken
/// as GGX of this roughness (2α = 0.006 rad, a texel). At grazing view the
/// true lobe of roughness 0.1 is narrower across the plane of incidence than
/// level 1's round lobe (2α n·v), and mixes with level 0 fit it: with level 0
/// counted as a misplaced point instead, the fit's L1 at roughness 0.1 was
/// 0.53 at n·v = 0.5 and 0.98 at 0.25 (now 0.22 and 0.38).
const LEVEL0_FOOTPRINT: f64 = 0.055;

/// The lobe level `level` of the chain holds.
fn level_lobe(level: usize) -> f64 {
    if level == 0 {
        LEVEL0_FOOTPRINT
    } else {
        LEVEL_ROUGHNESS[level]
    }
}

/// Whether the fit at `roughness` models the shader's reads as the mix of two
/// levels (below 0.25, where the lobe is no wider than the levels' steps) or
/// as the lobe of the tap's roughness (which did better on the GPU from 0.3
/// on: docs/environment.md, "Accuracy").
fn reads_levels(roughness: f64) -> bool {
    roughness < 0.25
}

/// L1 distance between the true lobe and the taps' sum. Each tap is the lobe
/// of its roughness or, where [`reads_levels`], the mix of two levels' lobes
/// that the shader's trilinear read gives (level 0, the unfiltered map, as
/// [`LEVEL0_FOOTPRINT`]'s lobe).
fn loss(pts: &[(V3, f64)], want: &[f64], mu: f64, roughness: f64, p: &[f64]) -> f64 {
    let (_, r, t) = frame(mu, roughness);
    let mut sum = vec![0.0; pts.len()];
    for [o, rho, w] in taps(p, floor(roughness)) {
        let d = norm(add(r, t, o));
        let mut add_lobe = |level: f64, share: f64| {
            let lobe = tap_lobe(pts, d, level);
            sum.iter_mut().zip(lobe).for_each(|(s, k)| *s += share * k);
        };
        if !reads_levels(roughness) {
            add_lobe(rho, w);
            continue;
        }
        let (low, f) = levels(rho);
        add_lobe(level_lobe(low), w * (1.0 - f));
        add_lobe(LEVEL_ROUGHNESS[low + 1], w * f);
    }
    sum.iter()
        .zip(want)
        .zip(pts)
        .map(|((s, w), p)| (s - w).abs() * p.1)
        .sum::<f64>()
}

/// Nelder–Mead from `x0` with initial steps `step`: (best point, its value).
fn nelder_mead(f: &dyn Fn(&[f64]) -> f64, x0: &[f64], step: &[f64]) -> (Vec<f64>, f64) {
    let n = x0.len();
    let mut xs: Vec<Vec<f64>> = vec![x0.to_vec()];
    for i in 0..n {
        let mut x = x0.to_vec();
        x[i] += step[i];
        xs.push(x);
    }
    let mut fs: Vec<f64> = xs.iter().map(|x| f(x)).collect();
    let mut evals = n + 1;
    let lerp = |a: &[f64], b: &[f64], s: f64| -> Vec<f64> {
        a.iter().zip(b).map(|(a, b)| a + s * (b - a)).collect()
    };
    while evals < EVALS {
        let mut order: Vec<usize> = (0..=n).collect();
        order.sort_by(|&a, &b| fs[a].total_cmp(&fs[b]));
        xs = order.iter().map(|&i| xs[i].clone()).collect();
        fs = order.iter().map(|&i| fs[i]).collect();
        let c: Vec<f64> = (0..n)
            .map(|k| xs[..n].iter().map(|x| x[k]).sum::<f64>() / n as f64)
            .collect();
        let xr = lerp(&c, &xs[n], -1.0);
        let fr = f(&xr);
        evals += 1;
        if fr < fs[0] {
            let xe = lerp(&c, &xs[n], -2.0);
            let fe = f(&xe);
            evals += 1;
            (xs[n], fs[n]) = if fe < fr { (xe, fe) } else { (xr, fr) };
        } else if fr < fs[n - 1] {
            (xs[n], fs[n]) = (xr, fr);
        } else {
            let xc = lerp(&c, &xs[n], 0.5);
            let fc = f(&xc);
            evals += 1;
            if fc < fs[n] {
                (xs[n], fs[n]) = (xc, fc);
            } else {
                for i in 1..=n {
                    xs[i] = lerp(&xs[0], &xs[i], 0.5);
                    fs[i] = f(&xs[i]);
                }
                evals += n;
            }
        }
    }
    let best = (0..=n).min_by(|&a, &b| fs[a].total_cmp(&fs[b])).unwrap();
    (xs[best].clone(), fs[best])
}

/// The split sum's lobe as taps: every tap on r at the surface's roughness.
fn split_sum(roughness: f64) -> Vec<f64> {
    (0..TAPS)
        .flat_map(|k| [0.02 * (k as f64 - 0.5 * (TAPS - 1) as f64), roughness, 1.0])
        .collect()
}

/// One row of the table (roughness index `j`), n·v from 1 down to 0, each
/// fit started from its neighbour's solution and from the split sum: per
/// n·v, the taps and (L1 of the split sum, L1 of the fit).
fn fit_row(j: usize) -> Vec<Fitted> {
    let roughness = j as f64 / (ROUGH - 1) as f64;
    let mut row = vec![([[0.0; 3]; TAPS], 0.0, 0.0); MU];
    let mut prev = split_sum(roughness);
    for i in (0..MU).rev() {
        let mu = (i as f64 / (MU - 1) as f64).max(0.02);
        if roughness < 0.05 {
            // a mirror: the split sum, every tap on the dominant direction
            row[i] = ([[0.0, roughness, 1.0 / TAPS as f64]; TAPS], 0.0, 0.0);
            continue;
        }
        let (_, r, _) = frame(mu, roughness);
        let pts = grid(r);
        let want = true_lobe(&pts, mu, roughness);
        let f = |p: &[f64]| loss(&pts, &want, mu, roughness, p);
        let base = f(&split_sum(roughness));
        // offsets in steps no wider than the lobe (α = 0.01 at roughness 0.1)
        let o_step = 0.05 * (roughness / 0.2).min(1.0);
        let step: Vec<f64> = (0..TAPS).flat_map(|_| [o_step, 0.05, 0.2]).collect();
        let (start, _) = nelder_mead(&f, &prev, &step);
        let fine: Vec<f64> = step.iter().map(|s| s * 0.3).collect();
        let (best, fbest) = nelder_mead(&f, &start, &fine);
        eprintln!("roughness {roughness:.1} n.v {mu:.3}: L1 split sum {base:.3}, fit {fbest:.3}");
        row[i] = (taps(&best, floor(roughness)), base, fbest);
        prev = best;
    }
    row
}

fn main() {
    let rows: Vec<_> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..ROUGH).map(|j| s.spawn(move || fit_row(j))).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    let mut out = String::new();
    let _ = writeln!(
        out,
        "//! Generated by `examples/ibl_lobe_fit.rs` (run it to regenerate; do not edit):\n\
         //! the environment term's lobe model, [`LOBE_TAPS`] reads of the prefiltered\n\
         //! cube per (n·v, roughness) fitted to the glTF BRDF's lobe at n ≠ v.\n\
         //! L1 distance of the normalised lobes (the shader's reads of a 1024 × 512\n\
         //! map's chain), mean over the grid from roughness 0.1:\n\
         //! split sum {:.3}, fit {:.3}.\n",
        mean(&rows, 1),
        mean(&rows, 2)
    );
    let _ = writeln!(
        out,
        "/// Taps per lobe.\npub const LOBE_TAPS: usize = {TAPS};"
    );
    let _ = writeln!(
        out,
        "/// Grid points in n·v (i / (LOBE_MU − 1)).\npub const LOBE_MU: usize = {MU};"
    );
    let _ = writeln!(
        out,
        "/// Grid points in roughness (j / (LOBE_ROUGHNESS − 1)).\npub const LOBE_ROUGHNESS: usize = {ROUGH};"
    );
    let _ = writeln!(
        out,
        "/// `[roughness][n·v][tap]` = [offset along t, roughness of the level, weight].\n\
         #[rustfmt::skip]\n\
         pub const LOBE_TABLE: [[[[f32; 3]; LOBE_TAPS]; LOBE_MU]; LOBE_ROUGHNESS] = ["
    );
    for row in &rows {
        let _ = writeln!(out, "    [");
        for (taps, _, _) in row {
            let cells: Vec<String> = taps
                .iter()
                .map(|[o, r, w]| format!("[{o:.5}, {r:.5}, {w:.5}]"))
                .collect();
            let _ = writeln!(out, "        [{}],", cells.join(", "));
        }
        let _ = writeln!(out, "    ],");
    }
    let _ = writeln!(out, "];");
    print!("{out}");
}

/// Mean of field `k` (1: split sum's L1, 2: the fit's) over the fitted rows.
fn mean(rows: &[Vec<Fitted>], k: usize) -> f64 {
    let vals: Vec<f64> = rows[1..]
        .iter()
        .flatten()
        .map(|c| if k == 1 { c.1 } else { c.2 })
        .collect();
    vals.iter().sum::<f64>() / vals.len() as f64
}
