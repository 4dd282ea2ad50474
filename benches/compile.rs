//! Parse + compile + plan of every shipped effect (no GPU).

use criterion::{criterion_group, criterion_main, Criterion};
use fxgraph::graph::plan::{plan, InputDesc, PlanOptions};
use fxgraph::graph::{compile, library, CompileRequest};
use std::hint::black_box;

fn bench(c: &mut Criterion) {
    let mut group = c.benchmark_group("compile+plan");
    for (name, _) in library::builtin_effects() {
        let req = CompileRequest {
            effects: vec![name.clone()],
            ..Default::default()
        };
        let (g, _, _) = compile(&req);
        let input = InputDesc::rgba8_srgb(1920, 1080)
            .with_aux(&fxgraph::render::published_aux(true))
            .with_aux_of(&g.expect("shipped effect compiles"));
        group.bench_function(&name, |b| {
            b.iter(|| {
                let (g, _, _) = compile(black_box(&req));
                let g = g.expect("shipped effect compiles");
                black_box(plan(&g, &input, &PlanOptions::default()).expect("plans"));
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
