//! Keyframe interpolation, glTF 2.0 Appendix C ("Animation Sampler Interpolation
//! Modes").
//!
//! With keys `t_1 < … < t_n`, a requested time `t_c` with `t_k < t_c < t_{k+1}`,
//! `t_d = t_{k+1} − t_k` and `t = (t_c − t_k) / t_d`:
//! - STEP: `v_k`;
//! - LINEAR: `(1 − t) · v_k + t · v_{k+1}`; for rotations the spherical linear
//!   interpolation `sin(a(1 − t))/sin(a) · v_k + s · sin(a t)/sin(a) · v_{k+1}` with
//!   `a = arccos(|v_k · v_{k+1}|)` and `s` the sign of the dot product (the short
//!   way round), which becomes the linear one as `a` → 0;
//! - CUBICSPLINE (in-tangent `a_k`, value `v_k`, out-tangent `b_k` per key):
//!   `(2t³ − 3t² + 1) v_k + t_d (t³ − 2t² + t) b_k + (−2t³ + 3t²) v_{k+1} +
//!   t_d (t³ − t²) a_{k+1}`, rotations normalised afterwards.
//!
//! A time equal to a key's returns that key's value as is (Appendix C: "its
//! associated property value MUST be used as-is"); before the first key the first
//! value, after the last the last (§3.11). The segment arithmetic is in `f64`.

use super::{Interpolation, Sampler};
use glam::{Quat, Vec4};

/// Below this angle (radians) between two rotation keys the slerp weights are
/// replaced by the linear ones (their limit), avoiding `0 / 0`.
const SLERP_LINEAR_BELOW: f64 = 1e-6;

/// Where a time falls among a sampler's keys.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Segment {
    /// Exactly key `k`, before the first key (k = 0) or after the last.
    Key(usize),
    /// Between key `k` and `k + 1`: interpolation factor `t` in (0, 1) and the
    /// segment duration `t_d`.
    Between { k: usize, t: f64, td: f64 },
}

/// The segment of `time` in strictly increasing `times` (non-empty).
fn segment(times: &[f32], time: f64) -> Segment {
    let n = times.len();
    // NaN times hold the first key.
    if n <= 1 || time.is_nan() || time <= times[0] as f64 {
        return Segment::Key(0);
    }
    if time >= times[n - 1] as f64 {
        return Segment::Key(n - 1);
    }
    // The first key after `time`: 1..n-1 by the checks above.
    let next = times.partition_point(|&t| t as f64 <= time);
    let k = next - 1;
    let (t0, t1) = (times[k] as f64, times[next] as f64);
    if time == t0 {
        return Segment::Key(k);
    }
    let td = t1 - t0;
    Segment::Between {
        k,
        t: (time - t0) / td,
        td,
    }
}

impl Sampler {
    /// Element `e` of key `k` (`e` = 0 for STEP and LINEAR; 0 in-tangent, 1 value,
    /// 2 out-tangent for CUBICSPLINE).
    fn element(&self, k: usize, e: usize) -> &[f32] {
        let w = self.width();
        let i = (k * self.elements_per_key() + e) * w;
        &self.values[i..i + w]
    }

    /// The value of key `k`.
    pub(super) fn key_value(&self, k: usize) -> &[f32] {
        match self.interpolation {
            Interpolation::CubicSpline => self.element(k, 1),
            _ => self.element(k, 0),
        }
    }

    /// Samples component-wise (translation, scale, weights) at `time` seconds into
    /// `out` ([`Sampler::width`] floats). A sampler without keys leaves `out`
    /// unchanged.
    pub fn sample_into(&self, time: f64, out: &mut [f32]) {
        let w = self.width();
        if w == 0 || out.len() < w {
            return;
        }
        let out = &mut out[..w];
        match segment(&self.times, time) {
            Segment::Key(k) => out.copy_from_slice(self.key_value(k)),
            Segment::Between { k, t, td } => match self.interpolation {
                Interpolation::Step => out.copy_from_slice(self.key_value(k)),
                Interpolation::Linear => {
                    let (a, b) = (self.element(k, 0), self.element(k + 1, 0));
                    for i in 0..w {
                        out[i] = ((1.0 - t) * a[i] as f64 + t * b[i] as f64) as f32;
                    }
                }
                Interpolation::CubicSpline => {
                    let [h00, h10, h01, h11] = hermite(t, td);
                    let v0 = self.element(k, 1);
                    let b0 = self.element(k, 2);
                    let v1 = self.element(k + 1, 1);
                    let a1 = self.element(k + 1, 0);
                    for i in 0..w {
                        out[i] = (h00 * v0[i] as f64
                            + h10 * b0[i] as f64
                            + h01 * v1[i] as f64
                            + h11 * a1[i] as f64) as f32;
                    }
                }
            },
        }
    }

    /// Samples into a new vector.
    pub fn sample(&self, time: f64) -> Vec<f32> {
        let mut out = vec![0.0; self.width()];
        self.sample_into(time, &mut out);
        out
    }

    /// Samples a rotation (`x, y, z, w` keys) at `time` seconds: STEP, slerp on
    /// the shortest arc, or the normalised cubic spline. `None` when the sampler
    /// does not hold quaternions or the result is degenerate (zero length).
    pub fn sample_rotation(&self, time: f64) -> Option<Quat> {
        if self.width() != 4 {
            return None;
        }
        let quat = |v: &[f32]| Quat::from_xyzw(v[0], v[1], v[2], v[3]);
        let q = match (segment(&self.times, time), self.interpolation) {
            (Segment::Key(k), _) | (Segment::Between { k, .. }, Interpolation::Step) => {
                quat(self.key_value(k))
            }
            (Segment::Between { k, t, .. }, Interpolation::Linear) => slerp(
                Vec4::from_slice(self.element(k, 0)),
                Vec4::from_slice(self.element(k + 1, 0)),
                t,
            ),
            (Segment::Between { .. }, Interpolation::CubicSpline) => {
                let mut out = [0.0f32; 4];
                self.sample_into(time, &mut out);
                let v = Vec4::from_array(out);
                Quat::from_vec4(v.try_normalize()?)
            }
        };
        q.is_finite().then_some(q)
    }
}

/// The cubic Hermite basis of Appendix C, tangent terms scaled by the segment
/// duration `td`: the weights of `v_k`, `b_k`, `v_{k+1}`, `a_{k+1}`.
fn hermite(t: f64, td: f64) -> [f64; 4] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        2.0 * t3 - 3.0 * t2 + 1.0,
        td * (t3 - 2.0 * t2 + t),
        -2.0 * t3 + 3.0 * t2,
        td * (t3 - t2),
    ]
}

/// Appendix C's spherical linear interpolation of two unit quaternions (as
/// `x, y, z, w`), in `f64`, following the shorter arc.
fn slerp(a: Vec4, b: Vec4, t: f64) -> Quat {
    let (a, b) = (a.as_dvec4(), b.as_dvec4());
    let dot = a.dot(b);
    let s = if dot < 0.0 { -1.0 } else { 1.0 };
    let angle = dot.abs().min(1.0).acos();
    let (wa, wb) = if angle < SLERP_LINEAR_BELOW {
        (1.0 - t, t)
    } else {
        let sin = angle.sin();
        ((angle * (1.0 - t)).sin() / sin, (angle * t).sin() / sin)
    };
    let v = a * wa + b * (s * wb);
    // Unit for unit keys up to rounding; normalised so that keys a little off
    // unit length (quantised files) still give a rotation.
    Quat::from_vec4(v.normalize_or_zero().as_vec4())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampler(interpolation: Interpolation, times: &[f32], values: &[f32]) -> Sampler {
        Sampler {
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
        }
    }

    #[test]
    fn segments() {
        let t = [0.5f32, 1.0, 2.0];
        assert_eq!(segment(&t, 0.0), Segment::Key(0));
        assert_eq!(segment(&t, 0.5), Segment::Key(0));
        assert_eq!(segment(&t, 1.0), Segment::Key(1));
        assert_eq!(segment(&t, 9.0), Segment::Key(2));
        assert_eq!(segment(&t, f64::NAN), Segment::Key(0));
        match segment(&t, 1.5) {
            Segment::Between { k, t, td } => {
                assert_eq!(k, 1);
                assert!((t - 0.5).abs() < 1e-12 && (td - 1.0).abs() < 1e-12);
            }
            s => panic!("{s:?}"),
        }
    }

    #[test]
    fn step_linear_and_holds() {
        let s = sampler(Interpolation::Linear, &[1.0, 3.0], &[0.0, 10.0]);
        assert_eq!(s.sample(0.0), vec![0.0]);
        assert_eq!(s.sample(2.0), vec![5.0]);
        assert_eq!(s.sample(4.0), vec![10.0]);
        let s = Sampler {
            interpolation: Interpolation::Step,
            ..s
        };
        assert_eq!(s.sample(2.9), vec![0.0]);
        assert_eq!(s.sample(3.0), vec![10.0]);
    }

    #[test]
    fn slerp_takes_the_short_way() {
        // 0° and 350° about z, the second stored with a negative dot product.
        let a = Quat::IDENTITY;
        let b = -Quat::from_rotation_z(350f32.to_radians());
        let s = sampler(
            Interpolation::Linear,
            &[0.0, 1.0],
            &[a.x, a.y, a.z, a.w, b.x, b.y, b.z, b.w],
        );
        let q = s.sample_rotation(0.5).unwrap();
        let want = Quat::from_rotation_z(-5f32.to_radians());
        assert!(q.dot(want).abs() > 1.0 - 1e-6, "{q:?}");
        // identical keys: no 0/0
        let s = sampler(
            Interpolation::Linear,
            &[0.0, 1.0],
            &[0., 0., 0., 1., 0., 0., 0., 1.],
        );
        assert_eq!(s.sample_rotation(0.3), Some(Quat::IDENTITY));
    }

    #[test]
    fn cubic_spline_hits_keys_and_scales_tangents() {
        // v: 0 -> 1 over td = 2 with out-tangent 1 and in-tangent 0: the slope at
        // the start is b_0 (per second).
        let s = sampler(
            Interpolation::CubicSpline,
            &[0.0, 2.0],
            &[0.0, 0.0, 1.0, 0.0, 1.0, 0.0],
        );
        assert_eq!(s.width(), 1);
        assert_eq!(s.sample(0.0), vec![0.0]);
        assert_eq!(s.sample(2.0), vec![1.0]);
        let eps = 1e-4;
        let slope = s.sample(eps)[0] as f64 / eps;
        assert!((slope - 1.0).abs() < 1e-3, "{slope}");
    }
}
