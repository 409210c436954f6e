//! `sweepclay-perf`: the figures of `docs/PERFORMANCE.md`. For each size
//! of the benchmarks' scaling series (`examples::scaled`) it measures the
//! peak heap of slicing and of design → verified G-code with a counting
//! allocator, reads the criterion medians of the same runs from
//! `target/criterion` (run the benchmarks first; `scripts/perf.sh` does
//! both), writes `docs/perf/scaling.csv` and every benchmark's median to
//! `docs/perf/medians.csv`, and plots time and memory against samples into
//! `docs/img/scaling.png`.
//!
//! `cargo run --release -p sweepclay-perf -- [MAX_SAMPLES]`

use anyhow::{Context, Result};
use peak_alloc::PeakAlloc;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use sweepclay_core::examples;

#[global_allocator]
static ALLOC: PeakAlloc = PeakAlloc;

/// One size of the series.
struct Row {
    samples: usize,
    /// Design → G-code: criterion medians of `slice` plus `gcode`.
    slice_ms: Option<f64>,
    verified_ms: Option<f64>,
    slice_peak: usize,
    verified_peak: usize,
}

/// Peak heap (bytes above what was in use before) while `f` runs.
fn peak_of<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = ALLOC.current_usage();
    ALLOC.reset_peak_usage();
    let out = f();
    (out, ALLOC.peak_usage().saturating_sub(base))
}

/// The median of a criterion benchmark, in ms, if it has been run.
fn criterion_median(root: &Path, id: &str) -> Option<f64> {
    let path = root.join(id).join("new/estimates.json");
    let text = std::fs::read_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    Some(v["median"]["point_estimate"].as_f64()? / 1e6)
}

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn main() -> Result<()> {
    let max: usize = match std::env::args().nth(1) {
        Some(v) => v.parse().context("MAX_SAMPLES must be a number")?,
        None => 10_000_000,
    };
    let root = workspace();
    let crit = root.join("target/criterion");
    let mut rows = Vec::new();
    for n in examples::SCALING_SIZES.into_iter().filter(|&n| n <= max) {
        let d = examples::scaled(n);
        let (sliced, slice_peak) = peak_of(|| sweepclay_core::slice(&d));
        let sliced = sliced.context("the benchmark design slices")?;
        let samples = sliced.stats.sample_points;
        drop(sliced);
        let (printable, verified_peak) = peak_of(|| {
            let s = sweepclay_core::slice(&d).expect("it sliced a moment ago");
            sweepclay_plan::verify_into(&s, 0.5, std::io::sink())
                .expect("a sink takes any amount")
                .0
                .printable
        });
        anyhow::ensure!(printable, "the {n}-sample design must verify");
        let row = Row {
            samples,
            // Design → G-code: the pipeline, then the writer.
            slice_ms: criterion_median(&crit, &format!("scaling/slice/{n}"))
                .zip(criterion_median(&crit, &format!("scaling/gcode/{n}")))
                .map(|(a, b)| a + b),
            verified_ms: criterion_median(&crit, &format!("verified_scaling/{n}")),
            slice_peak,
            verified_peak,
        };
        eprintln!(
            "{samples:>9} samples: design → G-code {} ms, verified {} ms; peak {:.0} B/sample sliced, {:.0} B/sample verified",
            row.slice_ms.map_or("-".into(), |v| format!("{v:.1}")),
            row.verified_ms.map_or("-".into(), |v| format!("{v:.1}")),
            slice_peak as f64 / samples as f64,
            verified_peak as f64 / samples as f64,
        );
        rows.push(row);
    }
    let mut csv = String::from(
        "samples,gcode_median_ms,verified_median_ms,slice_peak_bytes,verified_peak_bytes,slice_bytes_per_sample,verified_bytes_per_sample\n",
    );
    let opt = |v: Option<f64>| v.map_or(String::new(), |v| format!("{v:.3}"));
    for r in &rows {
        writeln!(
            csv,
            "{},{},{},{},{},{:.1},{:.1}",
            r.samples,
            opt(r.slice_ms),
            opt(r.verified_ms),
            r.slice_peak,
            r.verified_peak,
            r.slice_peak as f64 / r.samples as f64,
            r.verified_peak as f64 / r.samples as f64
        )?;
    }
    let dir = root.join("docs/perf");
    std::fs::create_dir_all(&dir)?;
    std::fs::write(dir.join("scaling.csv"), csv)?;
    std::fs::write(dir.join("medians.csv"), all_medians(&crit)?)?;
    plot(&rows, &root.join("docs/img/scaling.png"))?;
    eprintln!("wrote docs/perf/scaling.csv and docs/img/scaling.png");
    Ok(())
}

/// Every criterion benchmark under `root` with its median: `id,median_ms`,
/// sorted by id.
fn all_medians(root: &Path) -> Result<String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
        for e in std::fs::read_dir(dir)? {
            let p = e?.path();
            if p.is_dir() {
                if p.file_name().is_some_and(|n| n == "new") {
                    if p.join("estimates.json").exists() {
                        out.push(p);
                    }
                } else if p.file_name().is_none_or(|n| n != "base" && n != "report") {
                    walk(&p, out)?;
                }
            }
        }
        Ok(())
    }
    let mut found = Vec::new();
    if root.exists() {
        walk(root, &mut found).context("reading target/criterion")?;
    }
    let mut rows: Vec<(String, f64)> = found
        .iter()
        .filter_map(|p| {
            let id = p
                .parent()?
                .strip_prefix(root)
                .ok()?
                .to_string_lossy()
                .into_owned();
            Some((id.clone(), criterion_median(root, &id)?))
        })
        .collect();
    rows.sort_by(|a, b| a.0.cmp(&b.0));
    let mut out = String::from("id,median_ms\n");
    for (id, ms) in rows {
        writeln!(out, "{id},{ms:.4}")?;
    }
    Ok(out)
}

const FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

fn plot(rows: &[Row], out: &Path) -> Result<()> {
    let bytes = std::fs::read(FONT)
        .with_context(|| format!("reading {FONT} (Debian: fonts-dejavu-core)"))?;
    plotters::style::register_font("sans-serif", FontStyle::Normal, Box::leak(bytes.into()))
        .map_err(|_| anyhow::anyhow!("{FONT} is not a font"))?;
    let root = BitMapBackend::new(out, (1200, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let (left, right) = root.split_horizontally(620);
    let xs = |r: &Row| r.samples as f64;
    let (x0, x1) = (
        rows.iter().map(xs).fold(f64::MAX, f64::min) * 0.8,
        rows.iter().map(xs).fold(0.0, f64::max) * 1.25,
    );
    // Time against samples, log–log, with the paper's 5 s and a line of
    // slope 1 (linear cost) through the first verified point.
    let times: Vec<f64> = rows
        .iter()
        .flat_map(|r| [r.slice_ms, r.verified_ms])
        .flatten()
        .collect();
    let (t0, t1) = (
        times.iter().copied().fold(f64::MAX, f64::min).min(1.0) * 0.5,
        times.iter().copied().fold(0.0, f64::max).max(5000.0) * 2.0,
    );
    let mut chart = ChartBuilder::on(&left)
        .caption("time (criterion median, one core)", ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0..x1).log_scale(), (t0..t1).log_scale())?;
    chart
        .configure_mesh()
        .x_desc("surface samples")
        .y_desc("ms")
        .x_label_formatter(&|v| human(*v))
        .draw()?;
    let series = |f: fn(&Row) -> Option<f64>| -> Vec<(f64, f64)> {
        rows.iter().filter_map(|r| Some((xs(r), f(r)?))).collect()
    };
    for (name, pts, colour) in [
        ("design → G-code", series(|r| r.slice_ms), BLUE),
        ("design → verified G-code", series(|r| r.verified_ms), RED),
    ] {
        if pts.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
    }
    if let Some(&(xa, ya)) = series(|r| r.verified_ms).first() {
        chart
            .draw_series(LineSeries::new(
                [(xa, ya), (x1, ya * x1 / xa)],
                BLACK.mix(0.3),
            ))?
            .label("linear from the first point")
            .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], BLACK.mix(0.3)));
    }
    chart
        .draw_series(LineSeries::new([(x0, 5000.0), (x1, 5000.0)], GREEN))?
        .label("paper: < 5 s for 43,724 samples")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], GREEN));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 15))
        .draw()?;

    // Peak heap per sample.
    let per = |r: &Row, v: usize| v as f64 / r.samples as f64;
    let m1 = rows
        .iter()
        .map(|r| per(r, r.verified_peak))
        .fold(250.0, f64::max)
        * 1.15;
    let mut chart = ChartBuilder::on(&right)
        .caption("peak heap per sample", ("sans-serif", 22))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d((x0..x1).log_scale(), 0.0..m1)?;
    chart
        .configure_mesh()
        .x_desc("surface samples")
        .y_desc("bytes / sample")
        .x_label_formatter(&|v| human(*v))
        .draw()?;
    for (name, f, colour) in [
        (
            "slice (no G-code text)",
            (|r: &Row| r.slice_peak) as fn(&Row) -> usize,
            BLUE,
        ),
        ("design → verified G-code", |r: &Row| r.verified_peak, RED),
    ] {
        let pts: Vec<(f64, f64)> = rows.iter().map(|r| (xs(r), per(r, f(r)))).collect();
        chart
            .draw_series(LineSeries::new(pts.clone(), colour.stroke_width(2)))?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour));
        chart.draw_series(pts.iter().map(|&p| Circle::new(p, 4, colour.filled())))?;
    }
    chart
        .draw_series(LineSeries::new([(x0, 200.0), (x1, 200.0)], GREEN))?
        .label("target: 200 B/sample")
        .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], GREEN));
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.3))
        .label_font(("sans-serif", 15))
        .draw()?;
    root.present()?;
    Ok(())
}

fn human(v: f64) -> String {
    if v >= 1e6 {
        format!("{}M", v / 1e6)
    } else if v >= 1e3 {
        format!("{}k", v / 1e3)
    } else {
        format!("{v}")
    }
}
