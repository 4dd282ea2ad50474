//! RGB primaries and the matrices between them, derived from the chromaticities of
//! ITU-R BT.709, ITU-R BT.2020 and SMPTE EG 432-1 (Display P3, D65 white) the way
//! SMPTE RP 177 gives: RGB→XYZ from the primaries scaled to the white point. The
//! BT.709↔BT.2020 results match ITU-R BT.2087's printed matrix (see the tests).

/// A 3×3 matrix, rows applied to column vectors.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Matrix3(pub [[f32; 3]; 3]);

impl Matrix3 {
    pub const IDENTITY: Matrix3 = Matrix3([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);

    /// `M v`.
    #[inline]
    pub fn apply(&self, v: [f32; 3]) -> [f32; 3] {
        let m = &self.0;
        [
            m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
            m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
            m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
        ]
    }

    /// Whether this is the identity (a conversion that can be skipped).
    pub fn is_identity(&self) -> bool {
        self.0
            .iter()
            .flatten()
            .zip(Matrix3::IDENTITY.0.iter().flatten())
            .all(|(a, b)| (a - b).abs() < 1e-7)
    }
}

/// RGB colour primaries (all with the D65 white point).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Primaries {
    /// ITU-R BT.709 (and sRGB): HD video, the working space.
    Bt709,
    /// ITU-R BT.2020 / BT.2100: UHD and HDR video.
    Bt2020,
    /// Display P3 (SMPTE EG 432-1: DCI-P3 primaries, D65 white).
    DisplayP3,
}

/// CIE 1931 xy of D65.
const D65: [f64; 2] = [0.3127, 0.3290];

impl Primaries {
    /// xy chromaticities of red, green, blue.
    pub fn xy(self) -> [[f64; 2]; 3] {
        match self {
            Primaries::Bt709 => [[0.640, 0.330], [0.300, 0.600], [0.150, 0.060]],
            Primaries::Bt2020 => [[0.708, 0.292], [0.170, 0.797], [0.131, 0.046]],
            Primaries::DisplayP3 => [[0.680, 0.320], [0.265, 0.690], [0.150, 0.060]],
        }
    }

    /// The primaries of an ffmpeg `color_primaries` name (`bt709`, `bt2020`,
    /// `smpte432`); `None` for names fxrun does not convert.
    pub fn from_ffmpeg(name: &str) -> Option<Primaries> {
        match name {
            "bt709" => Some(Primaries::Bt709),
            "bt2020" => Some(Primaries::Bt2020),
            "smpte432" => Some(Primaries::DisplayP3),
            _ => None,
        }
    }

    /// The ffmpeg `color_primaries` name.
    pub fn ffmpeg_name(self) -> &'static str {
        match self {
            Primaries::Bt709 => "bt709",
            Primaries::Bt2020 => "bt2020",
            Primaries::DisplayP3 => "smpte432",
        }
    }

    /// The name used in options and messages (`bt709`, `bt2020`, `p3`).
    pub fn name(self) -> &'static str {
        match self {
            Primaries::Bt709 => "bt709",
            Primaries::Bt2020 => "bt2020",
            Primaries::DisplayP3 => "p3",
        }
    }

    /// The relative luminance of linear R, G, B: the middle row of RGB→XYZ
    /// ([`rgb_to_xyz`], checked by the tests), as constants (the HLG OOTF needs
    /// them per pixel).
    pub fn luminance_weights(self) -> [f32; 3] {
        match self {
            Primaries::Bt709 => [0.212_639, 0.715_169, 0.072_192],
            Primaries::Bt2020 => [0.262_700, 0.677_998, 0.059_302],
            Primaries::DisplayP3 => [0.228_975, 0.691_739, 0.079_287],
        }
    }
}

fn xyz_of(xy: [f64; 2]) -> [f64; 3] {
    [xy[0] / xy[1], 1.0, (1.0 - xy[0] - xy[1]) / xy[1]]
}

fn invert(m: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    let c =
        |r0: usize, c0: usize, r1: usize, c1: usize| m[r0][c0] * m[r1][c1] - m[r0][c1] * m[r1][c0];
    [
        [
            c(1, 1, 2, 2) / det,
            -c(0, 1, 2, 2) / det,
            c(0, 1, 1, 2) / det,
        ],
        [
            -c(1, 0, 2, 2) / det,
            c(0, 0, 2, 2) / det,
            -c(0, 0, 1, 2) / det,
        ],
        [
            c(1, 0, 2, 1) / det,
            -c(0, 0, 2, 1) / det,
            c(0, 0, 1, 1) / det,
        ],
    ]
}

fn mul(a: [[f64; 3]; 3], b: [[f64; 3]; 3]) -> [[f64; 3]; 3] {
    let mut r = [[0.0; 3]; 3];
    for (i, row) in r.iter_mut().enumerate() {
        for (j, v) in row.iter_mut().enumerate() {
            *v = (0..3).map(|k| a[i][k] * b[k][j]).sum();
        }
    }
    r
}

/// Linear RGB of `p` to CIE XYZ (Y = 1 for white), per SMPTE RP 177.
pub fn rgb_to_xyz(p: Primaries) -> [[f64; 3]; 3] {
    let [r, g, b] = p.xy().map(xyz_of);
    let cols = [[r[0], g[0], b[0]], [r[1], g[1], b[1]], [r[2], g[2], b[2]]];
    let w = xyz_of(D65);
    let inv = invert(cols);
    let s: Vec<f64> = (0..3)
        .map(|i| inv[i][0] * w[0] + inv[i][1] * w[1] + inv[i][2] * w[2])
        .collect();
    let mut m = cols;
    for row in m.iter_mut() {
        for (j, v) in row.iter_mut().enumerate() {
            *v *= s[j];
        }
    }
    m
}

/// The matrix taking linear RGB in `from` primaries to linear RGB in `to`.
pub fn convert_matrix(from: Primaries, to: Primaries) -> Matrix3 {
    if from == to {
        return Matrix3::IDENTITY;
    }
    let m = mul(invert(rgb_to_xyz(to)), rgb_to_xyz(from));
    Matrix3(m.map(|row| row.map(|v| v as f32)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(m: Matrix3, want: [[f32; 3]; 3], tol: f32) {
        for (r, w) in m.0.iter().zip(want) {
            for (a, b) in r.iter().zip(w) {
                assert!((a - b).abs() <= tol, "{m:?} vs {want:?}");
            }
        }
    }

    #[test]
    fn bt709_to_bt2020_is_bt2087s_matrix() {
        // ITU-R BT.2087-0, equation (3), printed to 4 decimals.
        let bt2087 = [
            [0.6274, 0.3293, 0.0433],
            [0.0691, 0.9195, 0.0114],
            [0.0164, 0.0880, 0.8956],
        ];
        close(
            convert_matrix(Primaries::Bt709, Primaries::Bt2020),
            bt2087,
            0.5e-4 + 1e-6,
        );
    }

    #[test]
    fn bt2020_to_bt709_is_bt2407s_matrix_and_the_inverse() {
        // ITU-R BT.2407-0, equation (5), printed to 4 decimals.
        let bt2407 = [
            [1.6605, -0.5876, -0.0728],
            [-0.1246, 1.1329, -0.0083],
            [-0.0182, -0.1006, 1.1187],
        ];
        let back = convert_matrix(Primaries::Bt2020, Primaries::Bt709);
        close(back, bt2407, 0.5e-4 + 1e-6);
        let there = convert_matrix(Primaries::Bt709, Primaries::Bt2020);
        let round = Matrix3(
            mul(
                back.0.map(|r| r.map(f64::from)),
                there.0.map(|r| r.map(f64::from)),
            )
            .map(|r| r.map(|v| v as f32)),
        );
        close(round, Matrix3::IDENTITY.0, 1e-6);
    }

    #[test]
    fn display_p3_to_bt709_and_luminance() {
        // W3C CSS Color 4's linear Display P3 → linear sRGB matrix (7 decimals).
        let p3 = [
            [1.2249401, -0.2249404, 0.0],
            [-0.0420569, 1.0420571, 0.0],
            [-0.0196376, -0.0786361, 1.0982735],
        ];
        close(
            convert_matrix(Primaries::DisplayP3, Primaries::Bt709),
            p3,
            0.5e-4 + 1e-6,
        );
        // The constant weights are rgb_to_xyz's middle rows; BT.2020's and
        // BT.709's are their luma coefficients.
        for p in [Primaries::Bt709, Primaries::Bt2020, Primaries::DisplayP3] {
            let m = rgb_to_xyz(p);
            for (a, b) in p.luminance_weights().iter().zip(m[1]) {
                assert!((*a as f64 - b).abs() < 1e-6, "{p:?}: {a} vs {b}");
            }
        }
        let w = Primaries::Bt2020.luminance_weights();
        for (a, b) in w.iter().zip([0.2627, 0.6780, 0.0593]) {
            assert!((a - b).abs() < 1e-4, "{w:?}");
        }
        let w = Primaries::Bt709.luminance_weights();
        for (a, b) in w.iter().zip([0.2126, 0.7152, 0.0722]) {
            assert!((a - b).abs() < 1e-4, "{w:?}");
        }
    }
}
