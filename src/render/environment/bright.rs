//! The brightest parts of a map (a sun, a studio's soft boxes, street lamps)
//! taken out of the prefiltered maps and shaded exactly (issue 29, point 2).
//!
//! The split sum and the lobe model read a lobe's radiance from prefiltered
//! levels whose lobes only approximate the glTF BRDF's at n ≠ v. Where a few
//! texels are thousands of times brighter than the rest, every pixel's value
//! is decided by the lobe's shape where it meets them, and the approximation
//! misses by 10–60 % (gold under the corpus' studio, sunrise and night maps).
//! So the map is split in two:
//! - the **residual**: every texel of a chosen cell clamped to [`CAP`] times
//!   the map's mean luminance. It is what the specular levels from roughness
//!   [`LEVEL_ROUGHNESS`](super::LEVEL_ROUGHNESS)`[1]` on are prefiltered from:
//!   its dynamic range is what the lobe model handles well;
//! - the **cells**: the excess over the cap, summed per cell of a
//!   [`GRID_WIDTH`] × [`GRID_WIDTH`]/2 grid over the map (1.4° cells), at most
//!   [`MAX_CELLS`] (the most energetic; the others stay in the residual). Each
//!   is a small source of light: its energy-weighted direction, its angular
//!   radius and its radiance × solid angle. environment.wgsl sums the glTF
//!   BRDF over them per pixel (`fx_env_bright_specular`), the lobe widened by
//!   the cell's size.
//!
//! The cells were 2.8° (a 128-wide grid, 64 cells) until smooth metals were
//! measured: on gold at roughness 0.1 under studio.exr the widened lobes' GGX
//! tails lit the dark around the soft boxes (+18 % on facing pixels, 19.7 %
//! mean error). Halving the cells' size quarters the widening: 9.9 %. Shading
//! a cell as its map rectangle instead (a representative point with a flat
//! top, or the lobe's share of the rectangle) was tried and lost 10–12 % of
//! the light at roughness 0.15–0.3, or broke at grazing view.
//!
//! Level 0 of the specular map (a mirror) and the irradiance keep the whole
//! map. Between roughness 0 and the first filtered level the shader weighs the
//! cells by the fraction of that level in its trilinear read, so the two halves
//! add up to the map at every roughness. Measured on the CPU model against the
//! brute-force integral (tests/environment.rs): gold at roughness 0.3 under
//! studio.exr 22 % → 2.3 %, sunrise 9.3 % → 3.0 %.
//!
//! Written here, not taken from a crate: the split is a property of this
//! renderer's prefiltering (no IBL crate exposes one).

use crate::scene::environment::{uv_to_direction, Equirect};
use glam::Vec3;

/// Texels brighter than this many times the map's mean luminance (over the
/// sphere) are clamped to it in the residual.
pub const CAP: f32 = 8.0;
/// Cells across the map's width (1.4° each).
pub const GRID_WIDTH: u32 = 256;
/// At most this many cells are taken out (a pixel sums them all).
pub const MAX_CELLS: usize = 128;

/// One cell: `BrightCell` of environment.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct BrightCell {
    /// Unit direction in the map's frame (xyz) and the cell's angular radius
    /// in radians (w).
    pub direction_radius: [f32; 4],
    /// The excess radiance integrated over the cell (radiance × solid angle,
    /// rgb), and the solid angle of its texels over the cap (w).
    pub power_omega: [f32; 4],
}

/// A map split into its residual and its bright cells.
#[derive(Debug, Clone, PartialEq)]
pub struct BrightSplit {
    pub residual: Equirect,
    pub cells: Vec<BrightCell>,
}

/// The normalisation of environment.wgsl's `fx_env_bright_lobe` at roughness
/// i / 15: ∫ D(n·h) G1(n·l) / 4 dω over the hemisphere about n (the weight of
/// a prefiltered level's lobe at n = v = r; below 1 for rough lobes, whose
/// mirrored samples fall under the horizon), by importance sampling with 4,096
/// Hammersley points (the GGX samples' density of l is D / 4 there). Computed
/// once per process.
pub fn lobe_norms() -> &'static [f32; 16] {
    static NORMS: std::sync::OnceLock<[f32; 16]> = std::sync::OnceLock::new();
    NORMS.get_or_init(integrate_lobe_norms)
}

fn integrate_lobe_norms() -> [f32; 16] {
    const N: u32 = 4096;
    std::array::from_fn(|i| {
        let roughness = i as f32 / 15.0;
        let alpha = (roughness * roughness).max(1e-3);
        let a2 = alpha * alpha;
        let mut sum = 0.0f64;
        for k in 0..N {
            let xi = k.reverse_bits() as f32 * 2.328_306_4e-10;
            let cos_h2 = (1.0 - xi) / (1.0 + (a2 - 1.0) * xi);
            let ndl = 2.0 * cos_h2 - 1.0;
            if ndl > 0.0 {
                let c2 = ndl * ndl;
                sum += f64::from(2.0 / (1.0 + (1.0 + a2 * (1.0 - c2) / c2).sqrt()));
            }
        }
        (sum / f64::from(N)) as f32
    })
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// Splits `map` (see the module's text). A map without texels over the cap
/// gives no cells and itself as the residual.
pub fn split(map: &Equirect) -> BrightSplit {
    let cap = CAP * mean_luminance(map);
    let grid = Grid::of(map);
    let energy = excess_energy(map, &grid, cap);
    let chosen = most_energetic(&energy, MAX_CELLS);
    let mut residual = map.clone();
    let mut sums = vec![CellSum::default(); energy.len()];
    for y in 0..map.height {
        let omega = map.texel_solid_angle(y);
        for x in 0..map.width {
            let cell = grid.cell(x, y);
            let i = (y * map.width + x) as usize;
            let le = map.texels[i];
            let l = luminance(le);
            if !chosen[cell] || l <= cap {
                continue;
            }
            let keep = le * (cap / l);
            residual.texels[i] = keep;
            sums[cell].add(texel_direction(map, x, y), le - keep, omega);
        }
    }
    let cells = sums
        .iter()
        .enumerate()
        .filter(|(c, s)| chosen[*c] && s.energy > 0.0)
        .map(|(_, s)| s.cell())
        .collect();
    BrightSplit { residual, cells }
}

/// The map's mean luminance over the sphere.
fn mean_luminance(map: &Equirect) -> f32 {
    let mut sum = 0.0f64;
    for y in 0..map.height {
        let omega = f64::from(map.texel_solid_angle(y));
        let row = &map.texels[(y * map.width) as usize..((y + 1) * map.width) as usize];
        sum += row.iter().map(|t| f64::from(luminance(*t))).sum::<f64>() * omega;
    }
    (sum / (4.0 * std::f64::consts::PI)) as f32
}

fn texel_direction(map: &Equirect, x: u32, y: u32) -> Vec3 {
    uv_to_direction(
        (x as f32 + 0.5) / map.width as f32,
        (y as f32 + 0.5) / map.height as f32,
    )
}

/// The cell grid over a map: `texels` × `texels` map texels per cell.
struct Grid {
    width: u32,
    texels: u32,
}

impl Grid {
    fn of(map: &Equirect) -> Grid {
        let width = GRID_WIDTH.min(map.width).max(1);
        Grid {
            width,
            texels: (map.width / width).max(1),
        }
    }

    fn cells(&self, map: &Equirect) -> usize {
        (self.width * map.height.div_ceil(self.texels)) as usize
    }

    fn cell(&self, x: u32, y: u32) -> usize {
        ((y / self.texels) * self.width + (x / self.texels).min(self.width - 1)) as usize
    }
}

/// Per cell, the luminance over the cap integrated over its texels.
fn excess_energy(map: &Equirect, grid: &Grid, cap: f32) -> Vec<f32> {
    let mut energy = vec![0.0f32; grid.cells(map)];
    for y in 0..map.height {
        let omega = map.texel_solid_angle(y);
        for x in 0..map.width {
            let l = luminance(map.at(x, y));
            if l > cap {
                energy[grid.cell(x, y)] += (l - cap) * omega;
            }
        }
    }
    energy
}

/// Which cells are among the `n` with the most (non-zero) energy.
fn most_energetic(energy: &[f32], n: usize) -> Vec<bool> {
    let mut order: Vec<usize> = (0..energy.len()).filter(|&c| energy[c] > 0.0).collect();
    order.sort_by(|a, b| energy[*b].total_cmp(&energy[*a]));
    let mut chosen = vec![false; energy.len()];
    for &c in order.iter().take(n) {
        chosen[c] = true;
    }
    chosen
}

/// What a cell gathers: its excess power and its energy-weighted direction.
#[derive(Debug, Clone, Copy, Default)]
struct CellSum {
    direction: Vec3,
    power: Vec3,
    energy: f32,
    /// The solid angle of its texels over the cap.
    omega: f32,
}

impl CellSum {
    fn add(&mut self, d: Vec3, excess: Vec3, omega: f32) {
        let e = luminance(excess) * omega;
        self.direction += d * e;
        self.power += excess * omega;
        self.energy += e;
        self.omega += omega;
    }

    fn cell(&self) -> BrightCell {
        let d = self.direction.normalize();
        let omega = self.omega;
        // the radius of a disc of the solid angle of the cell's bright texels
        let radius = (omega / std::f32::consts::PI).sqrt();
        BrightCell {
            direction_radius: [d.x, d.y, d.z, radius],
            power_omega: [self.power.x, self.power.y, self.power.z, omega],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sun_map() -> Equirect {
        let sun = Vec3::new(0.3, 0.8, 0.5).normalize();
        Equirect::from_fn(256, |d| {
            if d.dot(sun) > 0.9995 {
                Vec3::splat(5.0e4)
            } else {
                Vec3::new(0.2, 0.3, 0.5)
            }
        })
    }

    /// Power over the sphere: residual + cells equals the map.
    #[test]
    fn the_split_keeps_the_power_and_the_sun() {
        let map = sun_map();
        let s = split(&map);
        assert!(!s.cells.is_empty() && s.cells.len() <= MAX_CELLS);
        let power = |m: &Equirect| -> Vec3 {
            (0..m.height)
                .flat_map(|y| (0..m.width).map(move |x| (x, y)))
                .map(|(x, y)| m.at(x, y) * m.texel_solid_angle(y))
                .sum()
        };
        let cells: Vec3 = s
            .cells
            .iter()
            .map(|c| Vec3::from_slice(&c.power_omega[..3]))
            .sum();
        let (whole, parts) = (power(&map), power(&s.residual) + cells);
        assert!(
            ((parts - whole) / whole).abs().max_element() < 1e-4,
            "{whole} != {parts}"
        );
        // the residual's brightest texel is at the cap
        let mean = mean_luminance(&map);
        let top = s
            .residual
            .texels
            .iter()
            .map(|t| luminance(*t))
            .fold(0.0, f32::max);
        assert!(top <= CAP * mean * 1.0001, "{top} > {}", CAP * mean);
        // the cells point at the sun
        let sun = Vec3::new(0.3, 0.8, 0.5).normalize();
        for c in &s.cells {
            let d = Vec3::from_slice(&c.direction_radius[..3]);
            assert!(d.dot(sun) > 0.999, "{d}");
        }
    }

    #[test]
    fn lobe_norms_fall_from_one_as_lobes_widen() {
        let z = lobe_norms();
        assert!((z[0] - 1.0).abs() < 1e-3, "{z:?}");
        assert!(z.windows(2).all(|w| w[1] <= w[0] + 1e-4), "{z:?}");
        assert!(z[15] > 0.3 && z[15] < 0.9, "{z:?}");
    }

    #[test]
    fn a_flat_map_has_no_cells() {
        let map = Equirect::from_fn(64, |d| Vec3::splat(1.0 + 0.5 * d.y));
        let s = split(&map);
        assert!(s.cells.is_empty());
        assert_eq!(s.residual, map);
    }
}
