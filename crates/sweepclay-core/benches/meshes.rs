//! A vessel mesh cut and fitted (docs/MESHES.md, docs/PERFORMANCE.md): a
//! revolved pot of 1 million triangles (and 100 thousand), and a
//! five-lobed one twisted 40° (whose twist is found), from reading the
//! STL bytes to the fitted design sliced (stages 1–4).
//!
//! `cargo bench -p sweepclay-core --bench meshes`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use std::hint::black_box;
use sweepclay_core::meshfit::{fit, FitOptions};
use sweepclay_core::meshread::TriMesh;

/// A closed revolved pot: `m` points round, `k` rings up, capped; with
/// `twist` (degrees), five lobes turning by it from the floor's top.
fn pot(m: usize, k: usize, twist: f64) -> Vec<u8> {
    let h = 120.0;
    let ring = |i: usize, j: usize| {
        let z = h * i as f64 / k as f64;
        let a = std::f64::consts::TAU * (j % m) as f64 / m as f64;
        let turn = twist.to_radians() * ((z - 2.5) / (h - 2.5)).clamp(0.0, 1.0);
        let lobes = if twist == 0.0 {
            1.0
        } else {
            1.0 + 0.06 * (5.0 * (a - turn)).cos()
        };
        let r = (40.0 + 10.0 * (z / 25.0).sin()) * lobes;
        [r * a.cos(), r * a.sin(), z]
    };
    let mut tris = Vec::with_capacity(2 * m * (k + 1));
    for i in 0..k {
        for j in 0..m {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j + 1),
                ring(i + 1, j),
            );
            tris.push([a, b, c]);
            tris.push([a, c, d]);
        }
    }
    for j in 0..m {
        tris.push([[0.0, 0.0, 0.0], ring(0, j + 1), ring(0, j)]);
        tris.push([[0.0, 0.0, h], ring(k, j), ring(k, j + 1)]);
    }
    let mut out = Vec::new();
    stl_io::write_stl(
        &mut out,
        tris.iter().map(|t| stl_io::Triangle {
            normal: stl_io::Normal::new([0.0; 3]),
            vertices: t.map(|p| stl_io::Vertex::new(p.map(|x| x as f32))),
        }),
    )
    .unwrap();
    out
}

/// Reads, cuts, fits, and slices the fitted design (stages 1–4).
fn cut_and_fit(bytes: &[u8]) -> f64 {
    let mesh = TriMesh::read("pot.stl", bytes).unwrap();
    let f = fit(&mesh, &FitOptions::default()).unwrap();
    let s = sweepclay_core::slice(&f.design).unwrap();
    f.deviation_mm + 0.0 * s.stats.path_length_mm
}

fn meshes(c: &mut Criterion) {
    let mut g = c.benchmark_group("mesh");
    g.sample_size(10);
    for (name, m, k, twist) in [
        ("100k", 500, 100, 0.0),
        ("1M", 1000, 500, 0.0),
        ("1M_twisted", 1000, 500, 40.0),
    ] {
        let bytes = pot(m, k, twist);
        assert!(cut_and_fit(&bytes) < 0.3, "{name} must fit");
        g.throughput(Throughput::Elements((2 * m * (k + 1)) as u64));
        g.bench_function(name, |b| b.iter(|| cut_and_fit(black_box(&bytes))));
    }
    g.finish();
}

criterion_group!(benches, meshes);
criterion_main!(benches);
