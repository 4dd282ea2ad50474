//! Clustered light lists (Olsson, Billeter and Assarsson, "Clustered Deferred and
//! Forward Shading", HPG 2012): the view frustum is cut into screen tiles of
//! [`TILE_PX`] pixels and [`SLICES`] depth slices spaced exponentially from the
//! near to the far plane; every point and spot light is listed in the clusters
//! its bounding sphere touches. A pixel (deferred and light pre-pass light pass)
//! or a fragment (forward) then shades only the lights of its cluster, plus the
//! global lights (directional) that reach everything.
//!
//! This file holds the grid, the lights' footprints on it (the tiles and slices
//! a sphere may touch) and the CPU reference of the binning (tests); the lists
//! themselves are built on the GPU each frame (`cluster_gpu.rs`).
//!
//! Why clusters rather than stencil-marked light volumes: on lavapipe every
//! light-volume draw costs a G-buffer read and a blend per covered pixel, and the
//! volume's front faces also cover every surface behind it; a cluster pass reads
//! the G-buffer once and writes once, whatever the light count, and its lists
//! cull in depth as well as on screen.

use super::cli_names::cli_names;
use glam::{Mat4, Vec3};

/// How the deferred and light pre-pass light passes (and the forward loop) pick
/// the lights a pixel shades.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum LightCulling {
    /// Clustered light lists (tiles × depth slices), one full-screen light pass.
    #[default]
    Clustered,
    /// Seed 001's light volumes: an instanced icosphere or cone per light,
    /// additive (forward loops over every visible light).
    Volumes,
    /// Every visible light at every pixel: the reference the culling is checked
    /// against.
    None,
}

cli_names!(
    LightCulling {
        Clustered => "clustered",
        Volumes => "volumes",
        None => "none",
    },
    parse = "unknown light culling `{}`: expected clustered, volumes or none"
);

/// Tile edge in pixels.
pub(crate) const TILE_PX: u32 = 32;
/// Depth slices between the near and the far plane.
pub(crate) const SLICES: u32 = 24;
/// Most entries (light × cluster) a frame may list: 64 MiB of indices.
pub(crate) const MAX_ENTRIES: usize = 16 << 20;

/// The cluster grid of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ClusterGrid {
    pub tiles_x: u32,
    pub tiles_y: u32,
    pub slices: u32,
    pub tile_px: u32,
    pub near: f32,
    pub far: f32,
    /// `slices / ln(far / near)`: slice = floor(ln(depth / near) × scale).
    pub log_scale: f32,
}

impl ClusterGrid {
    /// The grid for a `width`×`height` frame; `tile_px` 0 means one cluster (every
    /// light everywhere: the reference without culling).
    pub fn new(width: u32, height: u32, near: f32, far: f32, tile_px: u32, slices: u32) -> Self {
        let (tiles_x, tiles_y, slices, tile_px) = if tile_px == 0 {
            (1, 1, 1, width.max(height).max(1))
        } else {
            (
                width.div_ceil(tile_px).max(1),
                height.div_ceil(tile_px).max(1),
                slices.max(1),
                tile_px,
            )
        };
        ClusterGrid {
            tiles_x,
            tiles_y,
            slices,
            tile_px,
            near,
            far,
            log_scale: slices as f32 / (far / near).ln().max(1e-6),
        }
    }

    pub fn count(&self) -> usize {
        (self.tiles_x * self.tiles_y * self.slices) as usize
    }

    /// View depth (positive) where slice `s` starts.
    fn slice_depth(&self, s: u32) -> f32 {
        if s == 0 {
            return self.near;
        }
        if s >= self.slices {
            return self.far;
        }
        self.near * (s as f32 / self.log_scale).exp()
    }

    /// The slice holding view depth `d` (clamped to the grid).
    fn slice_of(&self, d: f32) -> u32 {
        let s = ((d.max(self.near) / self.near).ln() * self.log_scale).floor();
        (s.max(0.0) as u32).min(self.slices - 1)
    }
}

/// The view-depth range of world box `bounds` seen through `view`, clamped to
/// `near..far` and widened by 1 % so that depth-buffer rounding stays inside.
pub(crate) fn depth_range(
    bounds: &crate::scene::Aabb,
    view: &Mat4,
    near: f32,
    far: f32,
) -> (f32, f32) {
    if bounds.is_empty() {
        return (near, far);
    }
    let (mut lo, mut hi) = (f32::MAX, f32::MIN);
    for k in 0..8 {
        let p = Vec3::new(
            if k & 1 == 0 {
                bounds.min.x
            } else {
                bounds.max.x
            },
            if k & 2 == 0 {
                bounds.min.y
            } else {
                bounds.max.y
            },
            if k & 4 == 0 {
                bounds.min.z
            } else {
                bounds.max.z
            },
        );
        let d = -view.transform_point3(p).z;
        lo = lo.min(d);
        hi = hi.max(d);
    }
    let lo = (lo * 0.99).clamp(near, far);
    let hi = (hi * 1.01).clamp(near, far);
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo * 1.0001 {
        return (near, far);
    }
    (lo, hi)
}

/// A light to bin: its index in the GPU light array and a view-space bounding
/// sphere of the region it lights.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LocalLight {
    /// (read by the CPU reference `build`: tests)
    #[cfg_attr(not(test), allow(dead_code))]
    pub index: u32,
    pub center: Vec3,
    pub radius: f32,
}

/// The lists of one frame, laid out as the shaders read them: `indices` starts
/// with the `globals` global lights, then each cluster's lights at
/// `ranges[cluster] = (offset, count)`.
#[cfg(test)]
#[derive(Debug, Clone)]
pub(crate) struct ClusterLists {
    pub grid: ClusterGrid,
    pub globals: u32,
    pub ranges: Vec<[u32; 2]>,
    pub indices: Vec<u32>,
    /// The longest cluster list.
    pub max_per_cluster: u32,
}

/// Too many light × cluster entries for one frame.
#[cfg(test)]
#[derive(Debug, Clone, thiserror::Error)]
#[error(
    "{entries} light-cluster entries exceed the limit of {MAX_ENTRIES}: fewer or smaller lights"
)]
pub(crate) struct TooManyEntries {
    pub entries: usize,
}

/// The slopes of the grid's planes for one projection: view x = `ax[t]` × depth
/// on tile column edge t, view y = `ay[t]` × depth on tile row edge t (rows top to
/// bottom), and the depth where each slice starts (`depth[slices]` = far). The
/// GPU builder uploads them as they are, so both compute the same boxes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct GridEdges {
    pub ax: Vec<f32>,
    pub ay: Vec<f32>,
    pub depth: Vec<f32>,
}

/// The tiles and slices a light's sphere may touch (inclusive ranges).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Footprint {
    pub tiles_x: (u32, u32),
    pub tiles_y: (u32, u32),
    pub slices: (u32, u32),
}

impl Footprint {
    /// Clusters inside the footprint: a bound on the light's entries.
    pub fn clusters(&self) -> usize {
        let n = |(a, b): (u32, u32)| (b - a + 1) as usize;
        n(self.tiles_x) * n(self.tiles_y) * n(self.slices)
    }
}

impl ClusterGrid {
    /// The edges of this grid seen through `proj` (a perspective projection
    /// without shear in z, as [`crate::scene::camera::perspective_rh`] makes; an
    /// off-centre frustum is handled through its x/y offsets).
    pub fn edges(&self, proj: &Mat4, width: u32, height: u32) -> GridEdges {
        let (p00, p02) = (proj.x_axis.x, proj.z_axis.x);
        let (p11, p12) = (proj.y_axis.y, proj.z_axis.y);
        let tile_ndc_x = |t: u32| ((t * self.tile_px).min(width) as f32 / width as f32) * 2.0 - 1.0;
        let tile_ndc_y =
            |t: u32| 1.0 - ((t * self.tile_px).min(height) as f32 / height as f32) * 2.0;
        GridEdges {
            ax: (0..=self.tiles_x)
                .map(|t| (tile_ndc_x(t) + p02) / p00)
                .collect(),
            ay: (0..=self.tiles_y)
                .map(|t| (tile_ndc_y(t) + p12) / p11)
                .collect(),
            depth: (0..=self.slices).map(|s| self.slice_depth(s)).collect(),
        }
    }

    /// The tiles and slices light `l` may touch: its slices, and the tile
    /// rectangle of its sphere's projected box (all tiles when the box reaches
    /// behind the near plane); `None` when it misses the grid. A one-cluster grid
    /// lists every light.
    pub fn footprint(
        &self,
        proj: &Mat4,
        width: u32,
        height: u32,
        l: &LocalLight,
    ) -> Option<Footprint> {
        if self.count() == 1 {
            return Some(Footprint {
                tiles_x: (0, 0),
                tiles_y: (0, 0),
                slices: (0, 0),
            });
        }
        let (p00, p02) = (proj.x_axis.x, proj.z_axis.x);
        let (p11, p12) = (proj.y_axis.y, proj.z_axis.y);
        let (c, r) = (l.center, l.radius);
        let (dmin, dmax) = (-c.z - r, -c.z + r);
        if dmax < self.near || dmin > self.far {
            return None;
        }
        let slices = (self.slice_of(dmin), self.slice_of(dmax));
        let all = Footprint {
            tiles_x: (0, self.tiles_x - 1),
            tiles_y: (0, self.tiles_y - 1),
            slices,
        };
        if dmin <= self.near * 0.5 {
            return Some(all);
        }
        // The projected corners of the sphere's box bound its projection when
        // the box is in front of the near plane.
        let (mut x0, mut x1, mut y0, mut y1) = (f32::MAX, f32::MIN, f32::MAX, f32::MIN);
        for k in 0..8 {
            let p = c + Vec3::new(
                if k & 1 == 0 { -r } else { r },
                if k & 2 == 0 { -r } else { r },
                if k & 4 == 0 { -r } else { r },
            );
            let d = -p.z;
            let (nx, ny) = (p.x * p00 / d - p02, p.y * p11 / d - p12);
            x0 = x0.min(nx);
            x1 = x1.max(nx);
            y0 = y0.min(ny);
            y1 = y1.max(ny);
        }
        if x1 < -1.0 || x0 > 1.0 || y1 < -1.0 || y0 > 1.0 {
            return None;
        }
        let px = |n: f32| ((n.clamp(-1.0, 1.0) + 1.0) * 0.5 * width as f32) as u32;
        let py = |n: f32| ((1.0 - n.clamp(-1.0, 1.0)) * 0.5 * height as f32) as u32;
        Some(Footprint {
            tiles_x: (
                (px(x0) / self.tile_px).min(self.tiles_x - 1),
                (px(x1) / self.tile_px).min(self.tiles_x - 1),
            ),
            tiles_y: (
                (py(y1) / self.tile_px).min(self.tiles_y - 1),
                (py(y0) / self.tile_px).min(self.tiles_y - 1),
            ),
            slices,
        })
    }
}

/// Bins `locals` into `grid` for projection `proj` on the CPU: the reference
/// the GPU lists (`cluster_gpu.rs`) are tested against, test for test.
#[cfg(test)]
pub(crate) fn build(
    grid: ClusterGrid,
    proj: &Mat4,
    width: u32,
    height: u32,
    globals: &[u32],
    locals: &[LocalLight],
) -> Result<ClusterLists, TooManyEntries> {
    let edges = grid.edges(proj, width, height);
    let (ax, ay, depth) = (&edges.ax, &edges.ay, &edges.depth);
    let one = grid.count() == 1;
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    for l in locals {
        let (c, r) = (l.center, l.radius);
        if one {
            pairs.push((0, l.index));
            continue;
        }
        let Some(f) = grid.footprint(proj, width, height, l) else {
            continue;
        };
        let r2 = r * r;
        for s in f.slices.0..=f.slices.1 {
            let (dn, df) = (depth[s as usize], depth[s as usize + 1]);
            // distance² along z from the centre to the slab
            let dz = (-c.z).clamp(dn, df) + c.z;
            let dz2 = dz * dz;
            if dz2 > r2 {
                continue;
            }
            for ty in f.tiles_y.0..=f.tiles_y.1 {
                // the tile's view-space y extent over the slab
                let (top, bottom) = (ay[ty as usize], ay[ty as usize + 1]);
                let ymax = top * if top > 0.0 { df } else { dn };
                let ymin = bottom * if bottom < 0.0 { df } else { dn };
                let dy = c.y.clamp(ymin, ymax) - c.y;
                let dyz2 = dz2 + dy * dy;
                if dyz2 > r2 {
                    continue;
                }
                for tx in f.tiles_x.0..=f.tiles_x.1 {
                    let (left, right) = (ax[tx as usize], ax[tx as usize + 1]);
                    let xmin = left * if left < 0.0 { df } else { dn };
                    let xmax = right * if right > 0.0 { df } else { dn };
                    let dx = c.x.clamp(xmin, xmax) - c.x;
                    if dyz2 + dx * dx <= r2 {
                        let cluster = (s * grid.tiles_y + ty) * grid.tiles_x + tx;
                        pairs.push((cluster, l.index));
                    }
                }
            }
        }
        if pairs.len() > MAX_ENTRIES {
            return Err(TooManyEntries {
                entries: pairs.len(),
            });
        }
    }
    Ok(sort_by_cluster(grid, globals, pairs))
}

/// The lists from (cluster, light) pairs: the global lights first, then each
/// cluster's lights (counting sort by cluster, each cluster's lights in light
/// order).
#[cfg(test)]
fn sort_by_cluster(grid: ClusterGrid, globals: &[u32], pairs: Vec<(u32, u32)>) -> ClusterLists {
    let mut counts = vec![0u32; grid.count()];
    for &(c, _) in &pairs {
        counts[c as usize] += 1;
    }
    let mut ranges = Vec::with_capacity(grid.count());
    let mut offset = globals.len() as u32;
    let mut max_per_cluster = 0;
    for &n in &counts {
        ranges.push([offset, 0]);
        offset += n;
        max_per_cluster = max_per_cluster.max(n);
    }
    let mut indices = vec![0u32; offset as usize];
    indices[..globals.len()].copy_from_slice(globals);
    for (c, light) in pairs {
        let r = &mut ranges[c as usize];
        indices[(r[0] + r[1]) as usize] = light;
        r[1] += 1;
    }
    ClusterLists {
        grid,
        globals: globals.len() as u32,
        ranges,
        indices,
        max_per_cluster,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::camera::perspective_rh;

    /// The cluster a view-space point falls in, as the shaders compute it.
    fn cluster_of(grid: &ClusterGrid, proj: &Mat4, w: u32, h: u32, p: Vec3) -> Option<u32> {
        let clip = *proj * p.extend(1.0);
        let (nx, ny) = (clip.x / clip.w, clip.y / clip.w);
        if nx.abs() >= 1.0 || ny.abs() >= 1.0 || -p.z < grid.near || -p.z > grid.far {
            return None;
        }
        let px = (nx + 1.0) * 0.5 * w as f32;
        let py = (1.0 - ny) * 0.5 * h as f32;
        let tx = (px as u32 / grid.tile_px).min(grid.tiles_x - 1);
        let ty = (py as u32 / grid.tile_px).min(grid.tiles_y - 1);
        let s = grid.slice_of(-p.z);
        Some((s * grid.tiles_y + ty) * grid.tiles_x + tx)
    }

    /// Every visible point inside a light's sphere finds that light in its
    /// cluster (the lists are conservative), for lights in front of, around and
    /// behind the camera.
    #[test]
    fn every_lit_point_finds_its_light() {
        let (w, h) = (200, 120);
        let proj = perspective_rh(1.0, w as f32 / h as f32, 0.1, 50.0);
        let grid = ClusterGrid::new(w, h, 0.1, 50.0, 16, 12);
        let locals = [
            LocalLight {
                index: 0,
                center: Vec3::new(0.5, -0.3, -4.0),
                radius: 1.0,
            },
            LocalLight {
                index: 1,
                center: Vec3::new(0.0, 0.0, 0.2),
                radius: 2.0,
            },
            LocalLight {
                index: 2,
                center: Vec3::new(-3.0, 1.0, -20.0),
                radius: 0.3,
            },
            LocalLight {
                index: 3,
                center: Vec3::new(0.0, 0.0, 5.0),
                radius: 1.0,
            },
        ];
        let lists = build(grid, &proj, w, h, &[7], &locals).unwrap();
        assert_eq!(lists.indices[0], 7);
        let mut state = 12345u64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f32 / (1u64 << 53) as f32
        };
        let mut checked = 0;
        for l in &locals {
            for _ in 0..4000 {
                let dir = Vec3::new(rnd() - 0.5, rnd() - 0.5, rnd() - 0.5).normalize_or_zero();
                let p = l.center + dir * l.radius * rnd().cbrt() * 0.999;
                let Some(c) = cluster_of(&grid, &proj, w, h, p) else {
                    continue;
                };
                let [o, n] = lists.ranges[c as usize];
                let list = &lists.indices[o as usize..(o + n) as usize];
                assert!(list.contains(&l.index), "light {} missing at {p}", l.index);
                checked += 1;
            }
        }
        assert!(checked > 3000, "too few visible samples: {checked}");
        // the light behind the camera is listed nowhere
        assert!(!lists.indices[1..].contains(&3));
    }

    /// The lists cull: a small light far from most clusters is listed in few.
    #[test]
    fn small_lights_touch_few_clusters() {
        let (w, h) = (1920, 1080);
        let proj = perspective_rh(0.9, w as f32 / h as f32, 0.1, 100.0);
        let grid = ClusterGrid::new(w, h, 0.1, 100.0, TILE_PX, SLICES);
        let locals = [LocalLight {
            index: 0,
            center: Vec3::new(0.0, 0.0, -10.0),
            radius: 0.5,
        }];
        let lists = build(grid, &proj, w, h, &[], &locals).unwrap();
        let listed = lists.ranges.iter().filter(|r| r[1] > 0).count();
        // the sphere spans about 1/10 of the screen height and two slices
        assert!(listed > 0 && listed < 200, "{listed} clusters");
        assert_eq!(lists.max_per_cluster, 1);
    }

    #[test]
    fn one_cluster_lists_every_light() {
        let proj = perspective_rh(1.0, 1.0, 0.1, 10.0);
        let grid = ClusterGrid::new(64, 64, 0.1, 10.0, 0, 1);
        let locals: Vec<LocalLight> = (0..5)
            .map(|i| LocalLight {
                index: i,
                center: Vec3::new(0.0, 0.0, 100.0),
                radius: 1.0,
            })
            .collect();
        let lists = build(grid, &proj, 64, 64, &[9], &locals).unwrap();
        assert_eq!(lists.ranges, vec![[1, 5]]);
        assert_eq!(lists.indices, vec![9, 0, 1, 2, 3, 4]);
    }
}
