//! The pipeline's stages, each on its own (paper §4–5; docs/PERFORMANCE.md):
//! on the six bundled examples, and on a scaling series of one design
//! (`examples::scaled`) from 10 thousand to 10 million samples; and the
//! G-code writer next to a bare fixed-point formatting loop over the same
//! numbers (its floor).
//!
//! `cargo bench -p sweepclay-core` (all), or with a filter:
//! `cargo bench -p sweepclay-core -- stages/t1`, `-- scaling`, `-- gcode_floor`,
//! `-- bspline` (B-spline evaluation from 10 to 100,000 control points),
//! `-- textures` (a 44k-sample vase, plain, with ripple and flutes, and
//! twisted too: docs/ALGORITHMS.md §11), `-- floor` (the floor spiral in
//! circles and ovals of growing size: docs/ALGORITHMS.md §8).
//! `SWEEPCLAY_BENCH_MAX=1000000` stops the scaling series at 1 million.

use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use sweepclay_core::{correct, examples, extrude, finish, gcode, surface, toolpath, Design};

/// The allocator the `sweepclay` binary ships with (mimalloc: it keeps
/// freed pages for reuse, where glibc's returns large blocks to the system
/// and faults them in again on the next run), so the figures are the
/// binary's.
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The scaling series: 10k, 30k, 100k, … up to 10M (or `SWEEPCLAY_BENCH_MAX`).
fn sizes() -> Vec<usize> {
    let max: usize = std::env::var("SWEEPCLAY_BENCH_MAX")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(10_000_000);
    examples::SCALING_SIZES
        .into_iter()
        .filter(|&n| n <= max)
        .collect()
}

fn stages(c: &mut Criterion, group: &str, name: &str, d: &Design, samples: u64) {
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(samples));
    if samples > 200_000 {
        g.sample_size(10);
    }
    let surf = surface::sample_surface(d).unwrap();
    let corrected = correct::correct(&surf).unwrap();
    let path = toolpath::plan_path(&corrected);
    let sliced = finish(corrected.clone()).unwrap();
    let mut out = Vec::with_capacity(gcode::size_hint(&sliced));
    g.bench_function(BenchmarkId::new("sample", name), |b| {
        b.iter(|| surface::sample_surface(black_box(d)).unwrap())
    });
    g.bench_function(BenchmarkId::new("correct", name), |b| {
        b.iter(|| correct::correct(black_box(&surf)).unwrap())
    });
    g.bench_function(BenchmarkId::new("path", name), |b| {
        b.iter(|| toolpath::plan_path(black_box(&corrected)))
    });
    g.bench_function(BenchmarkId::new("extrusion", name), |b| {
        b.iter(|| {
            extrude::plan_extrusion(
                black_box(&path),
                &corrected.surface.params,
                corrected.surface.printer.origin,
            )
        })
    });
    g.bench_function(BenchmarkId::new("gcode", name), |b| {
        b.iter(|| {
            out.clear();
            gcode::emit(black_box(&sliced), &mut out).unwrap()
        })
    });
    g.bench_function(BenchmarkId::new("slice", name), |b| {
        b.iter(|| sweepclay_core::slice(black_box(d)).unwrap())
    });
    g.finish();
}

fn examples_bench(c: &mut Criterion) {
    for (file, text) in examples::EXAMPLES {
        let d = Design::from_json(text).unwrap();
        let n = sweepclay_core::slice(&d).unwrap().stats.sample_points as u64;
        stages(c, "stages", file.trim_end_matches(".json"), &d, n);
    }
    // The size of the paper's largest model (43,724 samples).
    let d = examples::scaled(43_724);
    let n = sweepclay_core::slice(&d).unwrap().stats.sample_points as u64;
    stages(c, "stages", "44k", &d, n);
}

fn scaling_bench(c: &mut Criterion) {
    for n in sizes() {
        let d = examples::scaled(n);
        stages(c, "scaling", &n.to_string(), &d, n as u64);
    }
}

/// The floor: the same numbers (x, y, z with 3 decimals, E with 5) written
/// as `G1 X… Y… Z… E…` lines by a bare loop over precomputed values, with
/// the same fixed-point writer; and the standard formatter for contrast.
fn gcode_floor(c: &mut Criterion) {
    let d = Design::from_json(examples::example("t1").unwrap()).unwrap();
    let s = sweepclay_core::slice(&d).unwrap();
    let o = s.corrected.surface.printer.origin;
    let e_per = s.corrected.surface.printer.e_per_mm3;
    let mut e = 0.0;
    let nums: Vec<[f64; 4]> = s
        .toolpath
        .points
        .iter()
        .zip(&s.extrusion.volume)
        .map(|(p, v)| {
            e += v * e_per;
            [p.pos[0] + o[0], p.pos[1] + o[1], p.pos[2], e]
        })
        .collect();
    let mut g = c.benchmark_group("gcode_floor");
    g.throughput(Throughput::Elements(nums.len() as u64));
    let mut out: Vec<u8> = Vec::with_capacity(nums.len() * 48);
    g.bench_function("emit_t1", |b| {
        b.iter_batched_ref(
            Vec::new,
            |v: &mut Vec<u8>| gcode::emit(black_box(&s), v).unwrap(),
            BatchSize::LargeInput,
        )
    });
    g.bench_function("fixed_point_loop_t1", |b| {
        b.iter(|| {
            out.clear();
            for n in black_box(&nums) {
                out.extend_from_slice(b"G1 X");
                gcode::push_fixed(&mut out, n[0], 3);
                out.extend_from_slice(b" Y");
                gcode::push_fixed(&mut out, n[1], 3);
                out.extend_from_slice(b" Z");
                gcode::push_fixed(&mut out, n[2], 3);
                out.extend_from_slice(b" E");
                gcode::push_fixed(&mut out, n[3], 5);
                out.push(b'\n');
            }
            out.len()
        })
    });
    g.bench_function("std_format_loop_t1", |b| {
        use std::io::Write;
        b.iter(|| {
            out.clear();
            for n in black_box(&nums) {
                writeln!(
                    out,
                    "G1 X{:.3} Y{:.3} Z{:.3} E{:.5}",
                    n[0], n[1], n[2], n[3]
                )
                .unwrap();
            }
            out.len()
        })
    });
    g.finish();
}

/// B-spline evaluation from 10 to 100,000 control points, 20 points a
/// span: the time a point must not grow with the number of points
/// (throughput in points).
fn bspline_bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("bspline");
    for n in [10usize, 1_000, 100_000] {
        let pts: Vec<[f64; 2]> = (0..n)
            .map(|i| [i as f64, ((i * 7919) % 13) as f64])
            .collect();
        let curve = sweepclay_core::bspline::BSpline::clamped(pts).expect("two points or more");
        let evals = 20 * curve.spans();
        g.throughput(Throughput::Elements(evals as u64));
        g.bench_function(BenchmarkId::new("flatten", n), |b| {
            b.iter(|| curve.flatten(black_box(20)))
        });
    }
    g.finish();
}

/// A vase of about 44k samples, plain, textured (a ripple and flutes
/// whose sampling needs the plain one's spacing and layers already meet)
/// and textured and twisted: the textures' cost in sampling and
/// correcting.
fn textures_bench(c: &mut Criterion) {
    let mut plain = Design::from_json(examples::example("vase").unwrap()).unwrap();
    plain.params.layer_height = 0.7;
    plain.params.max_layer_height = 1.0;
    plain.params.spacing = 0.65;
    let mut textured = plain.clone();
    textured.texture = serde_json::from_str(
        r#"[{"kind": "ripple", "amplitude": 1.2, "period": 12, "fade_in": 6},
            {"kind": "flute", "amplitude": 0.8, "count": 12, "fade_out": 6}]"#,
    )
    .unwrap();
    let mut twisted = textured.clone();
    twisted.twist_deg = 20.0;
    let mut g = c.benchmark_group("textures");
    for (name, d) in [
        ("plain", &plain),
        ("textured", &textured),
        ("twisted", &twisted),
    ] {
        // The extruder body's reach grows with the texture, so the
        // vessel's layering (and its sample count) may differ: compare
        // per sample.
        let n = sweepclay_core::slice(d).unwrap().stats.sample_points;
        g.throughput(Throughput::Elements(n as u64));
        let surf = surface::sample_surface(d).unwrap();
        g.bench_function(BenchmarkId::new("sample", name), |b| {
            b.iter(|| surface::sample_surface(black_box(d)).unwrap())
        });
        g.bench_function(BenchmarkId::new("correct", name), |b| {
            b.iter(|| correct::correct(black_box(&surf)).unwrap())
        });
        g.bench_function(BenchmarkId::new("slice", name), |b| {
            b.iter(|| sweepclay_core::slice(black_box(d)).unwrap())
        });
    }
    g.finish();
}

/// The floor spiral alone (docs/ALGORITHMS.md §8) inside circles and
/// 10:7 ovals of growing size, points 1.1 mm apart: its cost against the
/// area over the pitch (the throughput is that, in mm² / pitch).
fn floor_bench(c: &mut Criterion) {
    use sweepclay_core::floor::{spiral_floor, FloorBeads};
    let beads = FloorBeads {
        width: 3.0,
        spacing: 1.1,
        widest: 6.0,
    };
    let mut g = c.benchmark_group("floor");
    for (name, a, b) in [
        ("circle_25", 25.0, 25.0),
        ("circle_50", 50.0, 50.0),
        ("circle_100", 100.0, 100.0),
        ("oval_50x35", 50.0, 35.0),
        ("oval_100x70", 100.0, 70.0),
    ] {
        let n = (std::f64::consts::PI * (a + b) / 1.1) as usize;
        let ring: Vec<[f64; 2]> = (0..n)
            .map(|i| {
                let t = std::f64::consts::TAU * i as f64 / n as f64;
                [a * t.cos(), b * t.sin()]
            })
            .collect();
        let area_over_pitch = std::f64::consts::PI * a * b / beads.pitch();
        g.throughput(Throughput::Elements(area_over_pitch as u64));
        g.bench_function(name, |bch| {
            bch.iter(|| spiral_floor(black_box(&ring), beads).unwrap())
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    floor_bench,
    textures_bench,
    examples_bench,
    gcode_floor,
    scaling_bench,
    bspline_bench
);
criterion_main!(benches);
