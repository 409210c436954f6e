//! The `sweepclay` command: a thin shell over `sweepclay-core` (the
//! pipeline) and `sweepclay-check` (the independent verifier).

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use sweepclay_check::{check_reader, CheckConfig};
use sweepclay_core::{examples, printer::PRESETS, Design, Printer, PrinterRef};
use sweepclay_plan::{plan, printer_check, Cancel, Checked, Job, Unchecked};

/// `println!` through [`say`], in a function returning [`Result`].
macro_rules! say {
    ($($t:tt)*) => { say(format_args!("{}\n", format_args!($($t)*)))? };
}

mod calibrate;
mod check;
mod files;
mod send;
mod serve;
mod slice;

use check::*;
use files::*;
use serve::*;
use slice::*;

/// mimalloc keeps freed pages for reuse; glibc's allocator returns large
/// blocks to the system and faults them in again, which cost a third of
/// the time of slicing a 44k-sample design (docs/PERFORMANCE.md).
#[global_allocator]
static ALLOC: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The most surface samples `slice` and `serve` take by default.
const DEFAULT_MAX_SAMPLES: u64 = sweepclay_plan::job::DEFAULT_MAX_SAMPLES;

/// The version and the commit the binary was built from (`build.rs`).
const VERSION: &str = concat!(
    env!("CARGO_PKG_VERSION"),
    " (commit ",
    env!("SWEEPCLAY_COMMIT"),
    ")"
);

/// Clay 3D printing of sweeping surfaces: design file → one continuous,
/// collision-free, self-supporting G-code path, and a checker that says
/// whether any G-code file prints in clay.
#[derive(Parser, Debug)]
#[command(name = "sweepclay", version = VERSION, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Slice a design file (JSON, docs/FORMATS.md) into clay G-code.
    ///
    /// Runs the pipeline (sample, correct, zig-zag path, adaptive
    /// extrusion), checks the result with `sweepclay check`, and writes the
    /// G-code only when the check passes. Prints a summary.
    Slice(SliceArgs),
    /// Check any G-code file for clay printability (exit 0 only if printable).
    Check(CheckArgs),
    /// Turn a vessel mesh (STL or OBJ) into an editable design file:
    /// cut into sections and fitted by one loop and one or two profiles
    /// (docs/MESHES.md). Prints how close the fit is and where.
    Import(ImportArgs),
    /// Write the bundled example designs (walls t1–t6, vessels vase, flower, cup) into a directory.
    Examples {
        /// Directory to write into (created if missing).
        dir: PathBuf,
    },
    /// Start the modeler: a local web page to draw, preview and print
    /// designs. Prints its URL; Ctrl+C stops it.
    Serve(ServeArgs),
    /// Send a G-code file to the printer's print host (OctoPrint,
    /// Moonraker or a Duet), after checking it; optionally start it and
    /// follow the print (docs/PRINTING.md).
    Send(send::SendArgs),
    /// Write a calibration print, or compute E per mm³ from the walls
    /// measured on it and save it to the printer profile
    /// (docs/CALIBRATION.md).
    Calibrate(calibrate::CalibrateArgs),
    /// List the printer presets: build volume, bed, extruder body,
    /// motion limits and cartridge (`--json` for every value).
    Printers {
        /// Every preset as JSON (the keys a design's `printer` takes).
        #[arg(long)]
        json: bool,
    },
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

/// Prints a line to stdout. A reader that has gone (`| head`) is not an
/// error: the command goes on with its work (writing its files) and says
/// nothing more; any other failure to write is.
fn say(args: std::fmt::Arguments) -> Result<()> {
    use std::sync::atomic::{AtomicBool, Ordering};
    static GONE: AtomicBool = AtomicBool::new(false);
    if GONE.load(Ordering::Relaxed) {
        return Ok(());
    }
    match std::io::stdout().lock().write_fmt(args) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => {
            GONE.store(true, Ordering::Relaxed);
            Ok(())
        }
        r => r.context("writing to standard output"),
    }
}

/// Temporary files not yet renamed into place: removed if the command is
/// interrupted (Ctrl+C, SIGTERM), so no hidden partial file is left.
static LIVE: std::sync::Mutex<Vec<PathBuf>> = std::sync::Mutex::new(Vec::new());

/// Removes the live temporary files when the command is interrupted.
fn clean_up_on_signal() {
    let _ = ctrlc::set_handler(|| {
        if let Ok(live) = LIVE.lock() {
            for p in live.iter() {
                let _ = std::fs::remove_file(p);
            }
        }
        eprintln!("interrupted: nothing written");
        std::process::exit(130);
    });
}

fn run(cli: Cli) -> Result<i32> {
    if matches!(cli.command, Command::Slice(_) | Command::Examples { .. }) {
        clean_up_on_signal();
    }
    match cli.command {
        Command::Slice(a) => slice(a),
        Command::Check(a) => check_cmd(a),
        Command::Import(a) => import_cmd(a),
        Command::Serve(a) => serve(a),
        Command::Send(a) => send::run(a),
        Command::Calibrate(a) => calibrate::run(a),
        Command::Printers { json } => {
            let all: Vec<Printer> = PRESETS.iter().filter_map(|n| Printer::preset(n)).collect();
            if json {
                say!("{}", serde_json::to_string_pretty(&all)?);
                return Ok(0);
            }
            for p in &all {
                let bed = match p.bed_diameter {
                    Some(d) => format!("round, Ø {d:.0} mm, {:.0} mm high", p.build_volume[2]),
                    None => format!(
                        "{:.0} × {:.0} × {:.0} mm",
                        p.build_volume[0], p.build_volume[1], p.build_volume[2]
                    ),
                };
                say!(
                    "{:<18} {bed}; o at ({}, {}), box from ({}, {}, {}); body r {} mm; {:.0} mm/s², corners {:.3} mm{}{}",
                    p.name,
                    p.origin[0],
                    p.origin[1],
                    p.bed_min[0],
                    p.bed_min[1],
                    p.bed_min[2],
                    p.nozzle_radius,
                    p.acceleration_mm_s2,
                    p.junction_deviation_mm,
                    p.max_flow_mm3_s
                        .map(|f| format!("; extruder ≤ {f} mm³/s"))
                        .unwrap_or_default(),
                    p.cartridge_ml
                        .map(|c| format!("; cartridge {c:.0} ml"))
                        .unwrap_or_default(),
                );
                if let Some(src) = sweepclay_core::printer::preset_source(&p.name) {
                    say!("{:<18} source: {src}", "");
                }
            }
            Ok(0)
        }
        Command::Examples { dir } => {
            std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
            for (name, text) in examples::EXAMPLES {
                let path = dir.join(name);
                write_atomic(&path, text.as_bytes())?;
                say!("wrote {}", path.display());
            }
            Ok(0)
        }
    }
}

/// A preset by name, or a printer JSON file.
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

#[cfg(test)]
mod tests {
    use super::token_required;

    #[test]
    fn every_bind_but_loopback_wants_a_token() {
        for ip in [
            "192.168.1.20",
            "10.0.0.7",
            "0.0.0.0",
            "::",
            "fe80::1",
            "203.0.113.9",
        ] {
            assert!(token_required(ip.parse().unwrap()), "{ip}");
        }
        for ip in ["127.0.0.1", "127.0.0.2", "::1"] {
            assert!(!token_required(ip.parse().unwrap()), "{ip}");
        }
    }
}
