//! How long `check` takes on large files: a meandering clay wall of about
//! 44 thousand and about 1 million moves (0.5 mm moves, 0.9 mm layers);
//! and clay stacked at one height (one ring laid 320 and 640 times at one
//! Z, and the same rising 1e-9 mm a move; one 20 mm line laid back and
//! forth 100,000 and 200,000 times at one Z), whose ratios show the cost
//! is linear there too. Run with `cargo bench -p sweepclay-check`.

use criterion::{criterion_group, criterion_main, Criterion};
use std::fmt::Write;
use sweepclay_check::{check, CheckConfig};

/// The allocator the `sweepclay` binary ships with (mimalloc: it keeps
/// freed pages for reuse, where glibc's returns large blocks to the system
/// and faults them in again on the next run), so the figures are the
/// binary's.
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// A meander of `lines` parallel runs 14 mm apart, `layers` layers of
/// alternating direction, as absolute-E G-code.
fn meander(lines: usize, layers: usize) -> (String, usize) {
    let (step, h, w, len) = (0.5, 0.9, 3.0, 180.0);
    let mut pts = Vec::new();
    for i in 0..lines {
        let y = 10.0 + 14.0 * i as f64;
        let (a, b) = if i % 2 == 0 {
            (10.0, 10.0 + len)
        } else {
            (10.0 + len, 10.0)
        };
        let n = (len / step) as usize;
        for k in 0..=n {
            pts.push((a + (b - a) * k as f64 / n as f64, y));
        }
    }
    let mut g = String::from("G21\nG90\nM82\n");
    let mut e = 0.0;
    let mut moves = 0;
    let mut last = (pts[0].0, pts[0].1, h);
    writeln!(g, "G0 X{:.3} Y{:.3} Z{:.3}", last.0, last.1, last.2).unwrap();
    for layer in 1..=layers {
        let z = h * layer as f64;
        let order: Box<dyn Iterator<Item = &(f64, f64)>> = if layer % 2 == 1 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &(x, y) in order {
            let l = ((x - last.0).powi(2) + (y - last.1).powi(2) + (z - last.2).powi(2)).sqrt();
            if l == 0.0 {
                continue;
            }
            e += l * w * h * 0.13;
            writeln!(g, "G1 X{x:.3} Y{y:.3} Z{z:.3} E{e:.5}").unwrap();
            last = (x, y, z);
            moves += 1;
        }
    }
    (g, moves)
}

/// One ring of radius 30 mm in 90 beads, laid `repeats` times from Z 1.2,
/// each move `rise` mm higher than the last.
fn stacked(repeats: usize, rise: f64) -> String {
    let mut g = String::from("G21\nG90\nM82\nG92 E0\nG0 X130 Y100 Z1.2\n");
    let (mut e, mut z) = (0.0, 1.2);
    for _ in 0..repeats {
        for i in 1..=90 {
            let a = std::f64::consts::TAU * i as f64 / 90.0;
            e += 2.09 * 3.2 * 1.2 * 0.13;
            z += rise;
            let (x, y) = (100.0 + 30.0 * a.cos(), 100.0 + 30.0 * a.sin());
            writeln!(g, "G1 X{x:.3} Y{y:.3} Z{z:.9} E{e:.4}").unwrap();
        }
    }
    g
}

/// One 20 mm line laid back and forth `passes` times at one Z.
fn back_and_forth(passes: usize) -> String {
    let mut g = String::from("G21\nG90\nM82\nG92 E0\nG0 X90 Y100 Z1.2\n");
    let mut e = 0.0;
    for i in 0..passes {
        e += 20.0 * 3.2 * 1.2 * 0.13;
        let x = if i % 2 == 0 { 110 } else { 90 };
        writeln!(g, "G1 X{x} Y100 Z1.2 E{e:.3}").unwrap();
    }
    g
}

fn bench(c: &mut Criterion) {
    let cfg = CheckConfig::default();
    let mut group = c.benchmark_group("check");
    group.sample_size(10);
    for (name, lines, layers) in [("44k_moves", 13, 10), ("1M_moves", 13, 214)] {
        let (text, moves) = meander(lines, layers);
        let r = check(&text, &cfg);
        assert!(
            r.printable,
            "the benchmark file must be a clean print:\n{}",
            r.render()
        );
        eprintln!("{name}: {moves} moves, {} MB", text.len() / 1_000_000);
        group.bench_function(name, |b| {
            b.iter(|| check(std::hint::black_box(&text), &cfg))
        });
    }
    for (name, rise) in [("stacked", 0.0), ("rising", 1e-9)] {
        for repeats in [320, 640] {
            let text = stacked(repeats, rise);
            assert!(!check(&text, &cfg).printable, "a stack is clay on clay");
            group.bench_function(format!("{name}_{repeats}"), |b| {
                b.iter(|| check(std::hint::black_box(&text), &cfg))
            });
        }
    }
    for passes in [100_000, 200_000] {
        let text = back_and_forth(passes);
        assert!(!check(&text, &cfg).printable, "a stack is clay on clay");
        group.bench_function(format!("back_and_forth_{passes}"), |b| {
            b.iter(|| check(std::hint::black_box(&text), &cfg))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
