//! The renderer benchmark (a test helper over the public API, moved out of the
//! library): frame time of each technique against the number of
//! random point lights on `builtin:bench` (run by `bench/renderer.sh`).
//!
//! Each configuration renders `warmup` frames (pipelines are created then), then
//! `frames` frames; a frame's time is the sum of its GPU pass times when the device
//! has timestamp queries, else the CPU wall time from encoding to the device being
//! idle. The median is reported.

use fxgraph::gpu::context::{GpuContext, GpuTimer};
use fxgraph::render::renderer::{
    RenderError, Renderer, RendererOptions, Technique, GBUFFER_BYTES_COMPRESSED,
    GBUFFER_BYTES_TRADITIONAL,
};
use fxgraph::scene::Scene;
use std::fmt;
use std::time::Instant;

/// What to measure.
#[derive(Debug, Clone)]
pub struct BenchConfig {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub light_counts: Vec<usize>,
    pub techniques: Vec<Technique>,
    pub warmup: usize,
    pub frames: usize,
    pub seed: u64,
    /// Light radius range as fractions of the scene diagonal.
    pub radius: (f32, f32),
}

impl Default for BenchConfig {
    /// 1920×1080, `builtin:bench`, 1…1024 lights, all techniques, 1 + 3 frames,
    /// radii 2–5 % of the scene diagonal (about 0.6–1.5 sphere spacings).
    fn default() -> Self {
        BenchConfig {
            scene: "builtin:bench".into(),
            width: 1920,
            height: 1080,
            light_counts: vec![1, 8, 32, 128, 512, 1024],
            techniques: Technique::ALL.to_vec(),
            warmup: 1,
            frames: 3,
            seed: 4,
            radius: (0.02, 0.05),
        }
    }
}

/// One measured configuration.
#[derive(Debug, Clone)]
pub struct BenchRow {
    pub technique: Technique,
    pub lights: usize,
    /// Lights left after frustum culling.
    pub visible: usize,
    /// Median frame time, milliseconds.
    pub ms: f64,
    /// Whether `ms` comes from GPU timestamps (else CPU wall time).
    pub gpu_timed: bool,
    /// Median per pass (GPU timestamps only).
    pub passes: Vec<(String, f64)>,
}

/// The benchmark result; `Display` prints a Markdown table.
#[derive(Debug, Clone)]
pub struct BenchReport {
    pub config: BenchConfig,
    pub adapter: String,
    pub triangles: usize,
    pub rows: Vec<BenchRow>,
}

/// The upper median of `v` (sorted in place); NaN when it is empty.
pub fn median(v: &mut [f64]) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        f64::NAN
    } else {
        v[v.len() / 2]
    }
}

/// Runs the benchmark; `progress` is called after each configuration.
pub fn run_benchmark(
    ctx: &GpuContext,
    config: &BenchConfig,
    mut progress: impl FnMut(&BenchRow),
) -> Result<BenchReport, RenderError> {
    let base = Scene::load(&config.scene)?;
    let camera = base.default_camera();
    let mut renderer = Renderer::new(ctx, &base, &RendererOptions::default())?;
    let timer = GpuTimer::new(ctx, 16);
    let mut rows = Vec::new();
    for &n in &config.light_counts {
        let mut scene = base.clone();
        scene.add_random_point_lights_sized(n, config.seed, config.radius.0, config.radius.1);
        renderer.set_lights(scene.lights.clone());
        for &technique in &config.techniques {
            let mut times = Vec::new();
            let mut passes: Vec<Vec<(String, f64)>> = Vec::new();
            let mut visible = 0;
            for i in 0..config.warmup + config.frames {
                let start = Instant::now();
                let (_, stats) = renderer.render(
                    ctx,
                    &camera,
                    config.width,
                    config.height,
                    technique,
                    timer.as_ref(),
                )?;
                ctx.wait_idle()?;
                let wall = start.elapsed().as_secs_f64() * 1e3;
                visible = stats.lights_visible;
                if i >= config.warmup {
                    times.push(stats.gpu_ms.unwrap_or(wall));
                    passes.push(stats.pass_ms);
                }
            }
            let pass_names: Vec<String> = passes
                .first()
                .map(|p| p.iter().map(|(n, _)| n.clone()).collect())
                .unwrap_or_default();
            let pass_medians = pass_names
                .iter()
                .enumerate()
                .map(|(k, name)| {
                    let mut v: Vec<f64> = passes
                        .iter()
                        .filter_map(|p| p.get(k).map(|x| x.1))
                        .collect();
                    (name.clone(), median(&mut v))
                })
                .collect();
            let row = BenchRow {
                technique,
                lights: n,
                visible,
                ms: median(&mut times),
                gpu_timed: timer.is_some(),
                passes: pass_medians,
            };
            log::info!("{technique} {n} lights: {:.2} ms", row.ms);
            progress(&row);
            rows.push(row);
        }
    }
    Ok(BenchReport {
        config: config.clone(),
        adapter: format!("{} ({})", ctx.info.name, ctx.info.backend),
        triangles: base.triangle_count(),
        rows,
    })
}

impl BenchReport {
    /// The row for `technique` with `lights` lights.
    pub fn get(&self, technique: Technique, lights: usize) -> Option<&BenchRow> {
        self.rows
            .iter()
            .find(|r| r.technique == technique && r.lights == lights)
    }
}

impl fmt::Display for BenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let c = &self.config;
        let timing = if self.rows.first().is_some_and(|r| r.gpu_timed) {
            "GPU timestamps"
        } else {
            "CPU wall time to idle"
        };
        writeln!(
            f,
            "{} {}x{}, {} triangles, {} ({timing}, median of {} frames after {} warm-up)",
            c.scene, c.width, c.height, self.triangles, self.adapter, c.frames, c.warmup
        )?;
        writeln!(f)?;
        write!(f, "| lights | visible |")?;
        for t in &c.techniques {
            write!(f, " {t} ms |")?;
        }
        writeln!(f, " forward / deferred |")?;
        write!(f, "|---:|---:|")?;
        for _ in &c.techniques {
            write!(f, "---:|")?;
        }
        writeln!(f, "---:|")?;
        for &n in &c.light_counts {
            let visible = self
                .rows
                .iter()
                .find(|r| r.lights == n)
                .map_or(0, |r| r.visible);
            write!(f, "| {n} | {visible} |")?;
            for &t in &c.techniques {
                match self.get(t, n) {
                    Some(r) => write!(f, " {:.1} |", r.ms)?,
                    None => write!(f, " - |")?,
                }
            }
            match (
                self.get(Technique::Forward, n),
                self.get(Technique::Deferred, n),
            ) {
                (Some(fw), Some(d)) => writeln!(f, " {:.1}x |", fw.ms / d.ms)?,
                _ => writeln!(f, " - |")?,
            }
        }
        let first = c.light_counts.first().copied();
        let last = c.light_counts.last().copied();
        if let (Some(a), Some(b)) = (first, last) {
            if let (Some(d1), Some(dn)) = (
                self.get(Technique::Deferred, a),
                self.get(Technique::Deferred, b),
            ) {
                writeln!(
                    f,
                    "\ndeferred {b} lights / {a} light: {:.2}x",
                    dn.ms / d1.ms
                )?;
            }
        }
        writeln!(
            f,
            "G-buffer bytes per pixel: compressed {GBUFFER_BYTES_COMPRESSED} (RGBA8 diffuse+material id, RGB10A2 normal+roughness, RGBA8 specular+model id, D32 depth) vs traditional {GBUFFER_BYTES_TRADITIONAL} (RGBA16F colour+specular, RGBA16F normal, RGBA16F position, D32/D24S8 depth): {:.0} % less",
            100.0 * (1.0 - f64::from(GBUFFER_BYTES_COMPRESSED) / f64::from(GBUFFER_BYTES_TRADITIONAL))
        )?;
        let with_passes: Vec<&BenchRow> =
            self.rows.iter().filter(|r| !r.passes.is_empty()).collect();
        if !with_passes.is_empty() {
            writeln!(f, "\nper-pass GPU ms (median):")?;
            for r in with_passes {
                let parts: Vec<String> = r
                    .passes
                    .iter()
                    .map(|(n, ms)| format!("{n} {ms:.1}"))
                    .collect();
                writeln!(
                    f,
                    "  {} {} lights: {}",
                    r.technique,
                    r.lights,
                    parts.join(", ")
                )?;
            }
        }
        Ok(())
    }
}
