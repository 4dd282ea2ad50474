//! A plan's pipelines built side by side before [`Engine::prepare`] walks its
//! passes one by one: each missing render pipeline of a fragment pass, and under
//! compute execution the compute pipeline that wraps it, is built on a thread of
//! its own (at most one per core), and the engine's caches are filled with what
//! was built, so the walk finds them there. Building a pipeline (the WGSL parsed
//! and validated, the driver's compile) is most of an image job's preparing, and
//! a plan's pipelines do not depend on each other (a wgpu device may be used
//! from several threads, error scopes are per thread).
//!
//! Compute-native passes get theirs too: the compute pipeline of their own entry
//! point, or the render pipeline of their @fragment entry where fragment
//! execution draws them.
//!
//! Only an optimisation: whatever is not built here (a compute-native pass
//! converting into the caller's output, the render pipeline of a compute-native
//! pass writing it, a shader that cannot be wrapped, a pipeline that fails to
//! build) is built, or reported, by the walk as before. On one core, or with one pipeline to build,
//! nothing is done here. The GL backend's device is used from one thread.

use super::compute::{build_compute_pipeline, ComputeKey};
use super::{build_render_pipeline, Engine, Execution, PipelineKey};
use crate::graph::plan::Plan;
use crate::graph::Graph;
use crate::script::types::Sampling;
use crate::script::Diagnostics;
use crate::shader::compute::{wrap_fragment_as_compute, StorageTarget, COMPUTE_ENTRY};
use crate::shader::{LoadedShader, Reflection};
use std::collections::HashSet;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// One pipeline to build, labelled by its pass.
enum Job<'a> {
    Render {
        key: PipelineKey,
        refl: &'a Reflection,
        samplers: Vec<(u32, Sampling, bool)>,
        label: &'a str,
    },
    Compute {
        key: ComputeKey,
        /// A compute-native shader (its own entry point), else a fragment shader
        /// to wrap.
        native: bool,
        st: StorageTarget,
        refl: &'a Reflection,
        samplers: Vec<(u32, Sampling, bool)>,
        label: &'a str,
    },
}

impl<'a> Job<'a> {
    fn compute(
        key: ComputeKey,
        native: bool,
        st: StorageTarget,
        refl: &'a Reflection,
        samplers: Vec<(u32, Sampling, bool)>,
        label: &'a str,
    ) -> Job<'a> {
        Job::Compute {
            key,
            native,
            st,
            refl,
            samplers,
            label,
        }
    }
}

/// What a job built (`None`: it failed, the walk builds it again and reports it).
enum Built {
    Render(PipelineKey, Option<super::CachedPipeline>),
    Compute(ComputeKey, Option<super::compute::CachedCompute>),
}

impl Engine {
    /// Build the missing pipelines of `plan`'s passes side by side and cache them.
    pub(super) fn prewarm(&mut self, graph: &Graph, plan: &Plan, shaders: &[Option<LoadedShader>]) {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        if self.is_gl() || cores < 2 {
            return;
        }
        let jobs = self.prewarm_jobs(graph, plan, shaders);
        if jobs.len() < 2 {
            return;
        }
        let threads = jobs.len().min(cores);
        let next = AtomicUsize::new(0);
        let (ctx, vs) = (&self.ctx, &self.vs);
        let work = || {
            let mut built = Vec::new();
            loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(job) = jobs.get(i) else {
                    return built;
                };
                built.push(match job {
                    Job::Render {
                        key,
                        refl,
                        samplers,
                        label,
                    } => Built::Render(
                        key.clone(),
                        build_render_pipeline(ctx, vs, key, refl, samplers, label).ok(),
                    ),
                    Job::Compute {
                        key,
                        native,
                        st,
                        refl,
                        samplers,
                        label,
                    } => {
                        // A shader that cannot be wrapped is left to the walk (which
                        // says why).
                        let source = if *native {
                            Some((key.base.wgsl.to_string(), key.base.entry.clone()))
                        } else {
                            wrap_fragment_as_compute(
                                &key.base.wgsl,
                                &key.base.entry,
                                st,
                                &key.mipmapped,
                            )
                            .ok()
                            .map(|wgsl| (wgsl, COMPUTE_ENTRY.to_string()))
                        };
                        let built = source.and_then(|(wgsl, entry)| {
                            let shader = (wgsl.as_str(), entry.as_str());
                            build_compute_pipeline(ctx, key, shader, st, (refl, samplers), label)
                                .ok()
                        });
                        Built::Compute(key.clone(), built)
                    }
                });
            }
        };
        let built: Vec<Built> = std::thread::scope(|s| {
            let helpers: Vec<_> = (1..threads)
                .filter_map(|i| {
                    std::thread::Builder::new()
                        .name(format!("fxgraph pipelines {i}"))
                        .spawn_scoped(s, work)
                        .ok()
                })
                .collect();
            let mut all = work();
            for h in helpers {
                // A panicking helper's pipelines are built by the walk.
                all.extend(h.join().unwrap_or_default());
            }
            all
        });
        for b in built {
            match b {
                Built::Render(key, Some(p)) => {
                    self.pipelines_created += 1;
                    self.pipelines.insert(key, Arc::new(p));
                }
                Built::Compute(key, Some(p)) => self.insert_compute_pipeline(key, p),
                Built::Render(_, None) | Built::Compute(_, None) => {}
            }
        }
    }

    /// The pipelines of `plan`'s fragment passes that the engine does not have
    /// yet, each once: the render pipeline, and under compute execution the
    /// wrapping compute pipeline, with the keys the walk will look them up by.
    fn prewarm_jobs<'a>(
        &self,
        graph: &Graph,
        plan: &'a Plan,
        shaders: &'a [Option<LoadedShader>],
    ) -> Vec<Job<'a>> {
        let mut jobs = Vec::new();
        let mut render_seen = HashSet::new();
        let mut compute_seen = HashSet::new();
        for (p, loaded) in plan.passes.iter().zip(shaders) {
            let Some(loaded) = loaded else { continue };
            let refl = &loaded.reflection;
            let Ok(target) = self.check_target(p) else {
                continue;
            };
            let mut scratch = Diagnostics::default();
            let Some(bindings) = self.pass_bindings(graph, p, refl, &mut scratch) else {
                continue;
            };
            let key = PipelineKey {
                wgsl: loaded.wgsl.clone(),
                entry: refl.entry_point.clone(),
                target,
                filterable: bindings.filterable.clone(),
            };
            if let Some(native) = &refl.compute {
                // A compute-native pass: its @fragment entry's render pipeline
                // where fragment execution draws it, else its compute pipeline
                // (a conversion into the caller's output is left to the walk).
                let drawn = native.fragment.as_ref().filter(|_| {
                    self.execution == Execution::Fragment && native.drawn_under_fragment_execution()
                });
                if let Some(entry) = drawn {
                    let key = PipelineKey {
                        entry: entry.clone(),
                        ..key
                    };
                    if !self.pipelines.contains_key(&key) && render_seen.insert(key.clone()) {
                        jobs.push(Job::Render {
                            key,
                            refl,
                            samplers: bindings.samplers,
                            label: &p.path,
                        });
                    }
                } else if let Some((ckey, st)) = self.native_key(p, &key, native) {
                    if !self.has_compute_pipeline(&ckey) && compute_seen.insert(ckey.clone()) {
                        jobs.push(Job::compute(
                            ckey,
                            true,
                            st,
                            refl,
                            bindings.samplers,
                            &p.path,
                        ));
                    }
                }
                continue;
            }
            if self.execution == Execution::Compute {
                if let Some((ckey, st)) = self.wrapped_key(p, &key, refl) {
                    if !self.has_compute_pipeline(&ckey) && compute_seen.insert(ckey.clone()) {
                        let samplers = bindings.samplers.clone();
                        jobs.push(Job::compute(ckey, false, st, refl, samplers, &p.path));
                    }
                }
            }
            if !self.pipelines.contains_key(&key) && render_seen.insert(key.clone()) {
                jobs.push(Job::Render {
                    key,
                    refl,
                    samplers: bindings.samplers,
                    label: &p.path,
                });
            }
        }
        jobs
    }
}
