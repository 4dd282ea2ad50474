//! Two-channel normal encodings for the RGB10A2 G-buffer target, on the CPU.
//!
//! The same maths is in `common.wgsl` (`encode_normal` / `decode_normal`); the tests
//! check both against each other through the GPU. Measured with 10-bit
//! round-to-nearest quantisation over a dense Fibonacci sphere (see
//! [`measure_error`]), the octahedral encoding has the smaller worst-case error over
//! the whole sphere, so it is the default.

use glam::{Vec2, Vec3};

/// How a unit normal is stored in two unorm channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum NormalEncoding {
    /// Octahedral mapping (Meyer et al. 2010): the sphere folded onto the
    /// octahedron and unfolded into the unit square. Uniform-ish error everywhere.
    #[default]
    Octahedral,
    /// The spheremap transform of Tang et al. (table 3), a Lambert azimuthal equal-area
    /// projection: `enc = n.xy / sqrt(8·n.z + 8) + 0.5`. Precise towards the viewer,
    /// singular at `n = (0, 0, −1)`.
    Spheremap,
}

impl NormalEncoding {
    /// The value of the `NORMAL_ENCODING` constant in the shaders.
    pub fn shader_id(self) -> u32 {
        match self {
            NormalEncoding::Octahedral => 0,
            NormalEncoding::Spheremap => 1,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            NormalEncoding::Octahedral => "octahedral",
            NormalEncoding::Spheremap => "spheremap",
        }
    }

    /// Encodes a unit vector into [0, 1]².
    pub fn encode(self, n: Vec3) -> Vec2 {
        match self {
            NormalEncoding::Octahedral => {
                let l1 = n.x.abs() + n.y.abs() + n.z.abs();
                let mut p = Vec2::new(n.x, n.y) / l1.max(1e-20);
                if n.z < 0.0 {
                    p = Vec2::new(
                        (1.0 - p.y.abs()) * sign_not_zero(p.x),
                        (1.0 - p.x.abs()) * sign_not_zero(p.y),
                    );
                }
                p * 0.5 + Vec2::splat(0.5)
            }
            NormalEncoding::Spheremap => {
                let d = (n.z * 8.0 + 8.0).max(1e-12).sqrt();
                (Vec2::new(n.x, n.y) / d + Vec2::splat(0.5)).clamp(Vec2::ZERO, Vec2::ONE)
            }
        }
    }

    /// Decodes [0, 1]² back into a unit vector.
    pub fn decode(self, e: Vec2) -> Vec3 {
        match self {
            NormalEncoding::Octahedral => {
                let f = e * 2.0 - Vec2::ONE;
                let mut n = Vec3::new(f.x, f.y, 1.0 - f.x.abs() - f.y.abs());
                let t = (-n.z).clamp(0.0, 1.0);
                n.x += if n.x >= 0.0 { -t } else { t };
                n.y += if n.y >= 0.0 { -t } else { t };
                n.normalize_or(Vec3::Z)
            }
            NormalEncoding::Spheremap => {
                let fenc = e * 4.0 - Vec2::splat(2.0);
                let f = fenc.dot(fenc);
                let g = (1.0 - f / 4.0).max(0.0).sqrt();
                Vec3::new(fenc.x * g, fenc.y * g, 1.0 - f / 2.0).normalize_or(Vec3::Z)
            }
        }
    }

    /// Encode, quantise both channels to `bits`-bit unorm (round to nearest, as the
    /// GPU stores RGB10A2) and decode.
    pub fn round_trip(self, n: Vec3, bits: u32) -> Vec3 {
        let e = self.encode(n);
        self.decode(Vec2::new(
            quantize_unorm(e.x, bits),
            quantize_unorm(e.y, bits),
        ))
    }
}

fn sign_not_zero(v: f32) -> f32 {
    if v >= 0.0 {
        1.0
    } else {
        -1.0
    }
}

/// `v` stored as a `bits`-bit unorm and read back.
pub fn quantize_unorm(v: f32, bits: u32) -> f32 {
    let max = ((1u32 << bits) - 1) as f32;
    (v.clamp(0.0, 1.0) * max).round() / max
}

/// `count` points evenly spread over the unit sphere (Fibonacci lattice), plus the
/// six axis directions (including the spheremap's singular pole).
pub fn fibonacci_sphere(count: usize) -> Vec<Vec3> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let mut v: Vec<Vec3> = (0..count)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / count as f64;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f64;
            Vec3::new((r * phi.cos()) as f32, (r * phi.sin()) as f32, z as f32)
        })
        .collect();
    // the six axis directions, as a cube's faces face
    v.extend(super::shadows::CUBE_FACES);
    v
}

/// Angle between two unit vectors in degrees (robust near 0).
pub fn angle_deg(a: Vec3, b: Vec3) -> f64 {
    let a = a.as_dvec3().normalize();
    let b = b.as_dvec3().normalize();
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

/// Angular error statistics of an encoding.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EncodingError {
    pub encoding: NormalEncoding,
    pub bits: u32,
    pub samples: usize,
    /// Largest error over the whole sphere, degrees.
    pub max_deg: f64,
    /// Mean error over the whole sphere, degrees.
    pub mean_deg: f64,
    /// Largest error over the hemisphere facing the camera (`n.z >= 0`), degrees.
    pub max_front_deg: f64,
    /// The normal with the largest error.
    pub worst: Vec3,
}

/// Round-trips `samples` Fibonacci-sphere normals through `encoding` at `bits` bits
/// per channel and reports the angular errors.
pub fn measure_error(encoding: NormalEncoding, bits: u32, samples: usize) -> EncodingError {
    let normals = fibonacci_sphere(samples);
    let decoded: Vec<Vec3> = normals
        .iter()
        .map(|&n| encoding.round_trip(n, bits))
        .collect();
    error_stats(encoding, bits, &normals, &decoded)
}

/// Error statistics of `decoded` against `normals`.
pub fn error_stats(
    encoding: NormalEncoding,
    bits: u32,
    normals: &[Vec3],
    decoded: &[Vec3],
) -> EncodingError {
    let mut out = EncodingError {
        encoding,
        bits,
        samples: normals.len(),
        max_deg: 0.0,
        mean_deg: 0.0,
        max_front_deg: 0.0,
        worst: Vec3::Z,
    };
    let mut sum = 0.0;
    for (&n, &d) in normals.iter().zip(decoded) {
        let e = angle_deg(n, d);
        let e = if e.is_finite() { e } else { 180.0 };
        sum += e;
        if e > out.max_deg {
            out.max_deg = e;
            out.worst = n;
        }
        if n.z >= 0.0 {
            out.max_front_deg = out.max_front_deg.max(e);
        }
    }
    out.mean_deg = sum / normals.len().max(1) as f64;
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_round_trip_without_quantisation() {
        for enc in [NormalEncoding::Octahedral, NormalEncoding::Spheremap] {
            for n in fibonacci_sphere(2000) {
                if enc == NormalEncoding::Spheremap && n.z < -0.99 {
                    continue;
                }
                let d = enc.decode(enc.encode(n));
                assert!(angle_deg(n, d) < 0.01, "{enc:?} {n} -> {d}");
            }
        }
    }
}
