//! The `sweepclay` command: a thin shell over `sweepclay-core` (the
//! pipeline) and `sweepclay-check` (the independent verifier).

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use sweepclay_check::{check, CheckConfig};
use sweepclay_core::{examples, gcode, printer::PRESETS, Design, Printer, PrinterRef};

/// Clay 3D printing of sweeping surfaces: design file → one continuous,
/// collision-free, self-supporting G-code path, and a checker that says
/// whether any G-code file prints in clay.
#[derive(Parser, Debug)]
#[command(name = "sweepclay", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Slice a design file (JSON, DESIGN.md §3) into clay G-code.
    ///
    /// Runs the pipeline (sample, correct, zig-zag path, adaptive
    /// extrusion), checks the result with `sweepclay check`, and writes the
    /// G-code only when the check passes. Prints a summary.
    Slice(SliceArgs),
    /// Check any G-code file for clay printability (exit 0 only if printable).
    Check(CheckArgs),
    /// Write the bundled example designs t1–t6 into a directory.
    Examples {
        /// Directory to write into (created if missing).
        dir: PathBuf,
    },
}

#[derive(Args, Debug)]
struct SliceArgs {
    /// Design file; a bundled example name (`t1` … `t6`) also works.
    design: String,
    /// Output G-code file [default: the design's name with .gcode].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Printer preset (cerambot-plus, cerambot-mini, generic) or a printer JSON file; overrides the design's.
    #[arg(long)]
    printer: Option<String>,
    /// Override a parameter, e.g. `--set layer_height=1.5` (repeatable). Keys: layer_height, max_layer_height, spacing, nozzle_height, width_min, width_max, overlap, max_overhang_deg, feedrate.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    sets: Vec<String>,
    /// Refuse the G-code if a bead overlaps the bead below by less than
    /// this fraction of its width (the checker's hard floor).
    #[arg(long, default_value_t = 0.5)]
    min_overlap: f64,
    /// Also write a picture of the toolpath (SVG).
    #[arg(long, value_name = "FILE.svg")]
    preview: Option<PathBuf>,
    /// Write the file even if the printability check fails.
    #[arg(long)]
    force: bool,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
struct CheckArgs {
    /// G-code file to check.
    file: PathBuf,
    /// Printer preset or printer JSON file (build volume, e_per_mm3, nozzle_radius).
    #[arg(long, default_value = "generic")]
    printer: String,
    /// H: extruder body height above the nozzle tip (mm).
    #[arg(long, default_value_t = 30.0)]
    nozzle_height: f64,
    /// Narrowest expected bead (mm).
    #[arg(long, default_value_t = 3.0)]
    width_min: f64,
    /// Widest expected bead (mm).
    #[arg(long, default_value_t = 6.0)]
    width_max: f64,
    /// Target overlap with the bead below (fraction); beads under it are counted.
    #[arg(long, default_value_t = 2.0 / 3.0)]
    overlap: f64,
    /// Overlap under which a bead fails (fraction).
    #[arg(long, default_value_t = 0.5)]
    min_overlap: f64,
    /// Overhang threshold from vertical (degrees).
    #[arg(long, default_value_t = 57.0)]
    max_overhang_deg: f64,
    /// The first bead must start at most this high (mm).
    #[arg(long, default_value_t = 3.0)]
    first_layer_max: f64,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

fn main() {
    let cli = Cli::parse();
    let code = match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            2
        }
    };
    std::process::exit(code);
}

fn run(cli: Cli) -> Result<i32> {
    match cli.command {
        Command::Slice(a) => slice(a),
        Command::Check(a) => check_cmd(a),
        Command::Examples { dir } => {
            std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
            for (name, text) in examples::EXAMPLES {
                let path = dir.join(name);
                write_atomic(&path, text.as_bytes())?;
                println!("wrote {}", path.display());
            }
            Ok(0)
        }
    }
}

fn load_printer(spec: &str) -> Result<Printer> {
    if let Some(p) = Printer::preset(spec) {
        return Ok(p);
    }
    let path = Path::new(spec);
    if !path.exists() {
        bail!(
            "--printer: `{spec}` is neither a preset ({}) nor a file",
            PRESETS.join(", ")
        );
    }
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {spec}"))?;
    let r: PrinterRef = serde_json::from_str(&text).with_context(|| spec.to_string())?;
    r.resolve().with_context(|| spec.to_string())
}

/// The checker's defaults with the printer's build volume, calibration and
/// extruder body.
fn printer_check(p: &Printer) -> CheckConfig {
    CheckConfig {
        build_volume: p.build_volume,
        e_per_mm3: p.e_per_mm3,
        nozzle_radius: p.nozzle_radius,
        ..CheckConfig::default()
    }
}

/// The check `slice` runs: the printer's, with the design's parameters.
fn check_config(p: &Printer, params: &sweepclay_core::Params) -> CheckConfig {
    let base = printer_check(p);
    CheckConfig {
        nozzle_height: params.nozzle_height,
        width_min: params.width_min,
        width_max: params.width_max,
        overlap_target: params.overlap,
        max_overhang_deg: params.max_overhang_deg,
        first_layer_max_mm: base.first_layer_max_mm.max(params.max_layer_height + 0.05),
        ..base
    }
}

fn slice(a: SliceArgs) -> Result<i32> {
    let (text, source) = match std::fs::read_to_string(&a.design) {
        Ok(t) => (t, a.design.clone()),
        Err(e) => match examples::example(&a.design) {
            Some(t) if !Path::new(&a.design).exists() => {
                (t.to_string(), format!("bundled example {}", a.design))
            }
            _ => return Err(e).with_context(|| format!("reading {}", a.design)),
        },
    };
    let mut design = Design::from_json(&text).with_context(|| source.clone())?;
    if let Some(p) = &a.printer {
        design.printer = PrinterRef::Inline(load_printer(p)?);
    }
    for s in &a.sets {
        let (k, v) = s
            .split_once('=')
            .with_context(|| format!("--set `{s}`: expected KEY=VALUE"))?;
        let k = k.trim().trim_start_matches("params.");
        let v: f64 = v
            .trim()
            .parse()
            .with_context(|| format!("--set {k}: `{v}` is not a number"))?;
        design.params.set(k, v)?;
    }
    let sliced = sweepclay_core::slice(&design).with_context(|| source.clone())?;
    let (text, point_lines) = gcode::to_string_with_lines(&sliced);
    let printer = &sliced.corrected.surface.printer;
    let cfg = CheckConfig {
        overlap_min: a.min_overlap,
        ..check_config(printer, &sliced.corrected.surface.params)
    };
    let report = check(&text, &cfg);
    let out = a.output.clone().unwrap_or_else(|| {
        let stem = Path::new(&a.design)
            .file_stem()
            .map(|s| s.to_owned())
            .unwrap_or_else(|| "out".into());
        PathBuf::from(stem).with_extension("gcode")
    });
    if let Some(p) = &a.preview {
        write_atomic(p, sweepclay_core::preview::svg(&sliced).as_bytes())?;
    }
    let st = &sliced.stats;
    if a.json {
        let v = serde_json::json!({
            "output": out, "stats": st, "corrections": sliced.corrected.report,
            "check": report, "written": report.printable || a.force,
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let name = &sliced.corrected.surface.name;
        println!(
            "{} → {}",
            if name.is_empty() { &source } else { name },
            out.display()
        );
        println!("  printer            {}", printer.name);
        println!(
            "  size               {:.1} × {:.1} × {:.1} mm",
            st.size_mm[0], st.size_mm[1], st.size_mm[2]
        );
        println!(
            "  sample points      {} on {} transition curves",
            st.sample_points, st.curves
        );
        println!(
            "  passes             {} ({} stage{}, {} returning turns)",
            st.passes,
            st.stages,
            if st.stages == 1 { "" } else { "s" },
            st.returning_points
        );
        println!("  path length        {:.1} m", st.path_length_mm / 1000.0);
        println!("  clay volume        {:.1} ml", st.volume_ml);
        println!("  estimated time     {:.1} min", st.time_min);
        let corr = sliced.corrected.report.summary();
        if corr.is_empty() {
            println!("  corrections        none");
        }
        for c in corr {
            println!("  correction         {c}");
        }
        println!(
            "  check              {}",
            if report.printable {
                "printable".to_string()
            } else {
                format!("NOT printable: {}", report.failures.join("; "))
            }
        );
        for line in failure_lines(&report).into_iter().take(5) {
            if let Some(at) = locate(&sliced, &point_lines, line) {
                println!("  where              {at}");
            }
        }
    }
    if !report.printable && !a.force {
        eprintln!("error: the G-code fails the clay printability check; nothing written (use --force to write it anyway)");
        return Ok(1);
    }
    if !report.printable {
        eprintln!("warning: writing G-code that FAILS the printability check (--force)");
    }
    write_atomic(&out, text.as_bytes())?;
    Ok(if report.printable { 0 } else { 1 })
}

/// The first line of each kind of failure in a report.
fn failure_lines(r: &sweepclay_check::Report) -> Vec<usize> {
    let sp = &r.support;
    let mut v: Vec<usize> = [
        &r.travel_moves,
        &r.retractions,
        &r.pauses,
        &r.extrusion_without_motion,
        &r.out_of_bounds,
        &r.nozzle_collisions,
        &r.carriage_collisions,
        &sp.unsupported,
        &sp.double_deposition,
        &sp.under_min,
        &sp.overhang,
    ]
    .iter()
    .filter_map(|c| c.first_line)
    .collect();
    v.sort_unstable();
    v.dedup();
    v
}

/// Where in the design a G-code line of our own output is.
fn locate(s: &sweepclay_core::Sliced, lines: &[usize], line: usize) -> Option<String> {
    let i = lines.partition_point(|&l| l < line);
    if lines.get(i) != Some(&line) {
        return None;
    }
    let p = &s.toolpath.points[i];
    let col = &s.corrected.surface.columns[p.column as usize];
    let top = if p.kind == sweepclay_core::toolpath::PointKind::Top {
        ", top-edge bead"
    } else {
        ""
    };
    Some(format!(
        "line {line}: pass {}, transition curve {} (u = {:.3}), z = {:.2} mm{top}",
        p.pass, p.column, col.u, p.pos[2]
    ))
}

fn check_cmd(a: CheckArgs) -> Result<i32> {
    let text = std::fs::read(&a.file).with_context(|| format!("reading {}", a.file.display()))?;
    let text = String::from_utf8_lossy(&text);
    let p = load_printer(&a.printer)?;
    let cfg = CheckConfig {
        nozzle_height: a.nozzle_height,
        width_min: a.width_min,
        width_max: a.width_max,
        overlap_target: a.overlap,
        overlap_min: a.min_overlap,
        max_overhang_deg: a.max_overhang_deg,
        first_layer_max_mm: a.first_layer_max,
        ..printer_check(&p)
    };
    let report = check(&text, &cfg);
    if a.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!("{}", report.render());
    }
    Ok(if report.printable { 0 } else { 1 })
}

/// Writes through a temporary file in the same directory and renames it,
/// so a crash never leaves a half-written file.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let mut tmp = tempfile::NamedTempFile::new_in(dir)
        .with_context(|| format!("creating a temporary file in {}", dir.display()))?;
    tmp.write_all(bytes)?;
    // Temporary files are private (0600); the result is an ordinary file.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(0o644))?;
    }
    tmp.as_file().sync_all()?;
    tmp.persist(path)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(())
}
