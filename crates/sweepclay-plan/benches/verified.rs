//! The whole job, design → verified G-code (docs/PERFORMANCE.md): slice, write
//! the G-code and check it in the same pass, through the correction loop
//! as `slice` runs it (`slice_checked`, output discarded), on the examples, on a 44k wall and a 44k vessel, and on the
//! scaling series of
//! `examples::scaled` (10 thousand to 10 million samples).
//!
//! `replan/*`: a vessel planned again after an edit of the printer's flow,
//! its surface sampled afresh or kept (docs/ARCHITECTURE.md, "Stages").
//!
//! `cargo bench -p sweepclay-plan` (all), `-- verified/t1`, `-- verified_scaling`.
//! `SWEEPCLAY_BENCH_MAX=1000000` stops the scaling series at 1 million.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use sweepclay_core::printer::PrinterRef;
use sweepclay_core::{examples, Design};
use sweepclay_plan::{plan, slice_checked, Cancel, Job, Limits, Samples};

/// The allocator the `sweepclay` binary ships with (mimalloc: it keeps
/// freed pages for reuse, where glibc's returns large blocks to the system
/// and faults them in again on the next run), so the figures are the
/// binary's.
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn verified(d: &Design) -> bool {
    match slice_checked(d, 0.5, &Cancel::new(), || Ok(std::io::sink())) {
        Ok(c) => c.report.printable,
        Err(e) => panic!("{e}"),
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("verified");
    for (file, text) in examples::EXAMPLES {
        let d = Design::from_json(text).unwrap();
        assert!(verified(&d), "{file} must verify");
        let n = sweepclay_core::slice(&d).unwrap().stats.sample_points;
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(file.trim_end_matches(".json"), |b| {
            b.iter(|| verified(black_box(&d)))
        });
    }
    // The size of the paper's largest model (43,724 samples).
    let d = examples::scaled(43_724);
    assert!(verified(&d));
    g.throughput(Throughput::Elements(43_724));
    g.bench_function("44k", |b| b.iter(|| verified(black_box(&d))));
    // A vessel of about the same size: the vase at 0.4 mm spacing (45,738
    // path points), floor and spiral (docs/ALGORITHMS.md §8).
    let mut v = Design::from_json(examples::example("vase").unwrap()).unwrap();
    v.params.spacing = 0.4;
    assert!(verified(&v));
    let n = sweepclay_core::slice(&v).unwrap().stats.sample_points;
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("vessel_44k", |b| b.iter(|| verified(black_box(&v))));
    g.finish();
    // An edit that changes only the printer's flow (stage 5): the plan
    // from a fresh sampling, and from the surface the store kept.
    let mut g = c.benchmark_group("replan");
    for name in ["pitcher", "vase"] {
        let d = Design::from_json(examples::example(name).unwrap()).unwrap();
        let mut e = d.clone();
        let mut p = e.printer.resolve().unwrap();
        p.e_per_mm3 *= 1.05;
        e.printer = PrinterRef::Inline(Box::new(p));
        let limits = Limits::default();
        let job = Job::new(e, &limits).unwrap();
        let store = Samples::new();
        store.sampled(&d).unwrap();
        let kept = job.clone().with_samples(&store);
        let run = |j: &Job| {
            plan(j, &Cancel::new(), || Ok(std::io::sink()))
                .unwrap()
                .checked
                .report
                .printable
        };
        assert!(run(&job) && run(&kept));
        g.bench_function(format!("{name}_flow_resampled"), |b| {
            b.iter(|| run(black_box(&job)))
        });
        g.bench_function(format!("{name}_flow_kept"), |b| {
            b.iter(|| run(black_box(&kept)))
        });
    }
    g.finish();
    let max: usize = std::env::var("SWEEPCLAY_BENCH_MAX")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10_000_000);
    let mut g = c.benchmark_group("verified_scaling");
    g.sample_size(10);
    for n in examples::SCALING_SIZES.into_iter().filter(|&n| n <= max) {
        let d = examples::scaled(n);
        g.throughput(Throughput::Elements(n as u64));
        g.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter(|| verified(black_box(&d)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
