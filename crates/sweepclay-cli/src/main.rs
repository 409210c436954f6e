//! The `sweepclay` command: a thin shell over `sweepclay-core` (the
//! pipeline) and `sweepclay-check` (the independent verifier).

use anyhow::{bail, Context, Result};
use clap::{Args, Parser, Subcommand};
use std::io::Write;
use std::path::{Path, PathBuf};
use sweepclay_check::{check_reader, CheckConfig};
use sweepclay_core::{examples, printer::PRESETS, Design, Printer, PrinterRef};
use sweepclay_plan::{plan, printer_check, Cancel, Checked, Job, Unchecked};

mod calibrate;
mod send;

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

#[derive(Args, Debug)]
struct ServeArgs {
    /// Address to listen on (use 0.0.0.0 to let other machines in).
    #[arg(long, default_value = "127.0.0.1")]
    host: String,
    /// Port (0 picks a free one).
    #[arg(long, default_value_t = 8080)]
    port: u16,
    /// Refuse designs with more surface samples than this (estimated).
    #[arg(long, default_value_t = DEFAULT_MAX_SAMPLES)]
    max_samples: u64,
    /// Longest a request may wait for a worker and run (seconds); its
    /// answer must begin within a minute longer.
    #[arg(long, default_value_t = 60)]
    timeout: u64,
    /// Most connections open at once (more wait to be accepted).
    #[arg(long, default_value_t = 256)]
    max_connections: usize,
    /// Longest a client may take to start a request, to send its headers,
    /// or to fall silent while sending its body (seconds); a body must
    /// also arrive at 64 KiB/s or faster on the whole.
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..=3600))]
    read_timeout: u64,
    /// Another name the server answers to in Host, besides loopback, the
    /// address given and (with 0.0.0.0) the machine's own names and any IP
    /// address (repeatable): what keeps other sites' pages out.
    #[arg(long = "allow-host", value_name = "NAME")]
    allow_hosts: Vec<String>,
    /// A secret the page must carry to use the API; on any address but
    /// loopback (0.0.0.0, or one LAN address) one is made up and printed
    /// in the link unless given.
    #[arg(long)]
    token: Option<String>,
}

/// The machine's own names: its host name and that name in `.local`
/// (mDNS), as the studio's other machines reach it.
fn own_names() -> Vec<String> {
    let name = std::fs::read_to_string("/proc/sys/kernel/hostname")
        .or_else(|_| std::fs::read_to_string("/etc/hostname"))
        .map(|n| n.trim().to_string())
        .unwrap_or_default();
    if name.is_empty() || name.len() > 253 {
        return Vec::new();
    }
    let local = format!("{name}.local");
    vec![name, local]
}

/// 128 random bits as hex, from the standard library's per-process
/// random hash keys (no extra crate for one secret).
fn random_token() -> String {
    use std::hash::{BuildHasher, Hasher};
    (0..2)
        .map(|i| {
            let mut h = std::collections::hash_map::RandomState::new().build_hasher();
            h.write_u64(i);
            h.write_u128(
                std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.as_nanos()),
            );
            format!("{:016x}", h.finish())
        })
        .collect()
}

#[derive(Args, Debug)]
struct SliceArgs {
    /// Design file; a vessel mesh (`.stl`, `.obj`), fitted to a design
    /// first (docs/MESHES.md); or a bundled example name (`t1` … `t6`, `vase`, `flower`, `cup`, `slanted-vase`, `pitcher`, `ripple-vase`, `fluted-cup`, `twisted-lobes`, `diamond-vase`).
    design: String,
    /// A mesh's units: multiply its coordinates by this to get
    /// millimetres [default: 1, or 25.4 for a mesh 0.8 to 16 units tall,
    /// which is said].
    #[arg(long)]
    scale: Option<f64>,
    /// A mesh's axis that points up (x, y or z): a Y-up export (Blender's
    /// glTF habit, many CAD tools) stands on its side otherwise.
    #[arg(long, default_value = "z", value_parser = ["x", "y", "z"])]
    up: String,
    /// Also write the surface the G-code prints as STL (its beads'
    /// width), e.g. to compare with a mesh.
    #[arg(long, value_name = "FILE.stl")]
    stl: Option<PathBuf>,
    /// Output G-code file [default: the design's name with .gcode].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Printer preset (cerambot-plus, cerambot-mini, wasp-2040-clay, wasp-40100-clay, eazao-zero, eazao-potter, eazao-m500, eazao-m600, vormvrij-lutum-4.6, generic: `sweepclay printers` lists them with their sources) or a printer JSON file; overrides the design's.
    #[arg(long)]
    printer: Option<String>,
    /// Override a parameter, e.g. `--set layer_height=1.5` (repeatable). Keys: layer_height, max_layer_height, spacing, nozzle_height, width_min, width_max, overlap, max_overhang_deg, feedrate, floor_layers (vessels), even_turn_flow (1 or 0), max_correction_mm, shrinkage_xy, shrinkage_z (firing shrinkage, fractions).
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
    /// Refuse designs with more surface samples than this (estimated
    /// before slicing; the same default as `serve`).
    #[arg(long, default_value_t = DEFAULT_MAX_SAMPLES)]
    max_samples: u64,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
}

#[derive(Args, Debug)]
struct ImportArgs {
    /// The mesh: `.stl` (binary or ASCII) or `.obj`.
    mesh: PathBuf,
    /// The design file to write [default: the mesh's name with .json].
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Multiply the mesh's coordinates by this to get millimetres
    /// [default: 1, or 25.4 for a mesh 0.8 to 16 units tall, which is said].
    #[arg(long)]
    scale: Option<f64>,
    /// The largest difference from the mesh the design may have (mm).
    #[arg(long, default_value_t = 0.3)]
    tolerance: f64,
    /// The mesh's axis that points up (x, y or z).
    #[arg(long, default_value = "z", value_parser = ["x", "y", "z"])]
    up: String,
    /// Printer preset or printer JSON file for the design.
    #[arg(long)]
    printer: Option<String>,
}

#[derive(Args, Debug)]
struct CheckArgs {
    /// G-code file to check.
    file: PathBuf,
    /// Printer preset or printer JSON file (build volume, bed_min,
    /// e_per_mm3, nozzle_radius) [default: the printer in a sweepclay
    /// file's header, else generic].
    #[arg(long)]
    printer: Option<String>,
    /// Whose reading of the G-code to follow where firmwares differ
    /// (G90/G91 and E; numbers such as Z5e-05): marlin, klipper or reprap.
    #[arg(long, default_value = "marlin")]
    firmware: sweepclay_check::Firmware,
    /// H: extruder body height above the nozzle tip (mm) [default: 30].
    #[arg(long)]
    nozzle_height: Option<f64>,
    /// Narrowest expected bead (mm) [default: 3].
    #[arg(long)]
    width_min: Option<f64>,
    /// Widest expected bead (mm) [default: 6].
    #[arg(long)]
    width_max: Option<f64>,
    /// Target overlap with the bead below (fraction); beads under it are
    /// counted [default: 0.6667].
    #[arg(long)]
    overlap: Option<f64>,
    /// Overlap under which a bead fails (fraction) [default: 0.5].
    #[arg(long)]
    min_overlap: Option<f64>,
    /// Overhang threshold from vertical (degrees) [default: 57].
    #[arg(long)]
    max_overhang_deg: Option<f64>,
    /// The print's first bead must start at most this high (mm) [default: 3].
    #[arg(long)]
    first_layer_max: Option<f64>,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
}

/// The flag that sets a field of the check's configuration, for messages.
fn check_flag(field: &str) -> String {
    match field {
        "nozzle_height" => "--nozzle-height".into(),
        "width_min" => "--width-min".into(),
        "width_max" => "--width-max".into(),
        "overlap_target" => "--overlap".into(),
        "overlap_min" => "--min-overlap".into(),
        "max_overhang_deg" => "--max-overhang-deg".into(),
        "first_layer_max_mm" => "--first-layer-max".into(),
        other => format!("the printer's `{other}`"),
    }
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

/// `println!` through [`say`], in a function returning [`Result`].
macro_rules! say {
    ($($t:tt)*) => { say(format_args!("{}\n", format_args!($($t)*)))? };
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

/// Reads a file of at most `cap` bytes, refusing a larger one before
/// reading it whole.
fn read_capped(path: &Path, cap: usize) -> std::result::Result<Vec<u8>, String> {
    use std::io::Read;
    // A FIFO or a device would block or never end: only regular files.
    match std::fs::metadata(path) {
        Ok(m) if !m.is_file() => {
            return Err(format!(
                "{}: not a regular file (a directory, device or FIFO)",
                path.display()
            ))
        }
        _ => {}
    }
    let f = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut bytes = Vec::new();
    f.take(cap as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if bytes.len() > cap {
        return Err(format!("{} is over the cap of {cap} bytes", path.display()));
    }
    Ok(bytes)
}

/// The most bytes of a mesh file read: a binary STL of the triangle cap.
const MAX_MESH_BYTES: usize = 84 + 50 * sweepclay_core::meshread::MAX_TRIANGLES;

/// Reads a mesh file and fits it by a design (named after the file),
/// saying what was assumed and how close the fit is.
fn mesh_design(path: &Path, scale: Option<f64>, tolerance: f64, up: &str) -> Result<Design> {
    use sweepclay_core::meshfit;
    let shown = path.display().to_string();
    let bytes = read_capped(path, MAX_MESH_BYTES).map_err(|e| anyhow::anyhow!("{shown}: {e}"))?;
    let up = match up {
        "x" => 0,
        "y" => 1,
        _ => 2,
    };
    let opts = meshfit::FitOptions {
        tolerance_mm: tolerance,
        ..meshfit::FitOptions::default()
    };
    let m = meshfit::import(&shown, &bytes, up, scale, &opts).with_context(|| shown.clone())?;
    if let Some(n) = m.units_note {
        eprintln!("note: {shown}: {n}");
    }
    let f = m.fitted;
    say!(
        "{shown}: {} triangles, a {}; fitted by a design (one loop, {}) within {:.2} mm of its {} sections (largest at ({:.1}, {:.1}, {:.1}) mm); its foot's centre moved to o",
        m.triangles,
        if f.kind == "shell" { "wall with its thickness (fitted at its middle)" } else { "solid (fitted at its outside)" },
        if f.design.profile_end.is_some() { "two profiles blended round it" } else { "one profile" },
        f.deviation_mm,
        f.sections,
        f.at[0],
        f.at[1],
        f.at[2]
    );
    Ok(f.design)
}

fn is_mesh(path: &str) -> bool {
    let lower = path.to_ascii_lowercase();
    lower.ends_with(".stl") || lower.ends_with(".obj")
}

fn import_cmd(a: ImportArgs) -> Result<i32> {
    if !(a.tolerance.is_finite() && a.tolerance > 0.0) {
        bail!(
            "--tolerance: must be a length above 0 mm (got {})",
            a.tolerance
        );
    }
    let mut design = mesh_design(&a.mesh, a.scale, a.tolerance, &a.up)?;
    if let Some(p) = &a.printer {
        design.printer = PrinterRef::Inline(Box::new(load_printer(p)?));
    }
    let out = a
        .output
        .clone()
        .unwrap_or_else(|| a.mesh.with_extension("json"));
    let out = output_target(&out)?;
    if std::fs::canonicalize(&out).ok() == std::fs::canonicalize(&a.mesh).ok() {
        bail!(
            "-o {}: that is the mesh; refusing to write over it",
            out.display()
        );
    }
    write_atomic(&out, design.to_json().as_bytes())?;
    say!("wrote {}", out.display());
    Ok(0)
}

fn slice(a: SliceArgs) -> Result<i32> {
    if is_mesh(&a.design) {
        let design = mesh_design(Path::new(&a.design), a.scale, 0.3, &a.up)?;
        return slice_design(a, design.to_json(), String::new());
    }
    if a.scale.is_some() || a.up != "z" {
        bail!("--scale, --up: only a mesh (.stl, .obj) is scaled or turned; a design's sizes are millimetres, z up");
    }
    let (text, source) = match std::fs::read_to_string(&a.design) {
        Ok(t) => (t, a.design.clone()),
        Err(e) => match examples::example(&a.design) {
            Some(t) if !Path::new(&a.design).exists() => {
                (t.to_string(), format!("bundled example {}", a.design))
            }
            _ => return Err(e).with_context(|| format!("reading {}", a.design)),
        },
    };
    slice_design(a, text, source)
}

/// Slices design text (`source` names it in messages; empty: the file).
fn slice_design(a: SliceArgs, text: String, source: String) -> Result<i32> {
    let source = if source.is_empty() {
        a.design.clone()
    } else {
        source
    };
    if !(0.0..=1.0).contains(&a.min_overlap) {
        bail!(
            "--min-overlap: must be a fraction from 0 to 1 (got {})",
            a.min_overlap
        );
    }
    let mut design = Design::from_json(&text).with_context(|| source.clone())?;
    // An image texture's `path` is relative to the design file.
    let folder = Path::new(&a.design)
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default();
    // Every file read, so that no output replaces one of them.
    let mut inputs: Vec<PathBuf> = std::fs::canonicalize(&a.design).into_iter().collect();
    design
        .load_images(|p| {
            let path = folder.join(p);
            inputs.extend(std::fs::canonicalize(&path));
            read_capped(&path, sweepclay_core::texture::MAX_IMAGE_BYTES)
        })
        .with_context(|| source.clone())?;
    if let Some(p) = &a.printer {
        design.printer = PrinterRef::Inline(Box::new(load_printer(p)?));
        if Printer::preset(p).is_none() {
            inputs.extend(std::fs::canonicalize(p));
        }
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
    // Validated once, before anything is sampled, as the server does.
    let limits = sweepclay_plan::Limits {
        min_overlap: a.min_overlap,
        max_samples: a.max_samples as f64,
        must_fit: true,
    };
    let job = Job::new(design, &limits).with_context(|| source.clone())?;
    let out = a.output.clone().unwrap_or_else(|| {
        let stem = Path::new(&a.design)
            .file_stem()
            .map(|s| s.to_owned())
            .unwrap_or_else(|| "out".into());
        PathBuf::from(stem).with_extension("gcode")
    });
    // The G-code streams into a temporary file beside the output and
    // through the checker in one pass, again for each round of the
    // correction loop; it becomes the output only if it passes (or with
    // --force).
    let out = output_target(&out)?;
    let preview = a.preview.as_deref().map(output_target).transpose()?;
    let stl = a.stl.as_deref().map(output_target).transpose()?;
    // `slice t4.json -o t4.json` would replace the design by its G-code,
    // `--preview d.json` by an SVG, `-o pic.png` a texture's picture.
    for (flag, target) in [
        ("-o", Some(&out)),
        ("--preview", preview.as_ref()),
        ("--stl", stl.as_ref()),
    ] {
        let Some(target) = target else { continue };
        let resolved = std::fs::canonicalize(target).unwrap_or_else(|_| target.clone());
        if let Some(input) = inputs.iter().find(|i| **i == resolved) {
            bail!(
                "{flag} {}: that is an input ({}); refusing to write over it",
                target.display(),
                input.display()
            );
        }
    }
    let tmp = temp_beside(&out)?;
    let file = tmp
        .reopen()
        .with_context(|| format!("opening {}", tmp.path().display()))?;
    let checked = match plan(&job, &Cancel::new(), || {
        use std::io::{Seek, SeekFrom};
        let mut f = &file;
        f.set_len(0)?;
        f.seek(SeekFrom::Start(0))?;
        Ok(std::io::BufWriter::with_capacity(1 << 16, f))
    }) {
        Ok(p) => p.checked,
        Err(Unchecked::Design(e)) => return Err(e).with_context(|| source.clone()),
        Err(Unchecked::Io(e)) => {
            return Err(e).with_context(|| format!("writing {}", tmp.path().display()))
        }
    };
    let advice = checked.advice();
    let Checked {
        sliced,
        out: written,
        report,
        locations,
        point_lines,
        most_twist: _,
    } = checked;
    drop((written, point_lines));
    let reshaped = sliced.corrected.reshaped();
    let printer = &sliced.corrected.surface.printer;
    if let Some(p) = &a.preview {
        write_atomic(p, sweepclay_core::preview::svg(&sliced).as_bytes())?;
    }
    if let Some(p) = &stl {
        let mut bytes = Vec::new();
        sweepclay_core::mesh::write_stl(&sliced, &mut bytes)?;
        write_atomic(p, &bytes)?;
    }
    let st = &sliced.stats;
    if a.json {
        let v = serde_json::json!({
            "output": out, "stats": st, "corrections": sliced.corrected.report,
            "check": report, "written": report.printable || a.force,
            "reshaped": reshaped, "advice": advice,
        });
        say!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        let name = &sliced.corrected.surface.name;
        say!(
            "{} → {}",
            if name.is_empty() { &source } else { name },
            out.display()
        );
        say!("  printer            {}", printer.name);
        say!(
            "  size               {:.1} × {:.1} × {:.1} mm",
            st.size_mm[0],
            st.size_mm[1],
            st.size_mm[2]
        );
        say!(
            "  sample points      {} on {} transition curves",
            st.sample_points,
            st.curves
        );
        if let Some(v) = &st.vessel {
            if v.floor_layers > 0 {
                say!(
                    "  floor              {} layer{}, each one spiral of {} turns ({:.1} cm², {:.1} % covered)",
                    v.floor_layers,
                    if v.floor_layers == 1 { "" } else { "s" },
                    v.floor_turns,
                    v.floor_area_cm2,
                    v.floor_cover_pct
                );
            } else {
                say!("  floor              none (bottomless)");
            }
            say!(
                "  wall               {} spiral turns and a rim turn, one continuous path",
                v.wall_turns
            );
            if let Some(r) = &v.raised {
                say!(
                    "  raised rim         above {:.1} mm, {:.0} % of the way round: {} partial layers back and forth, {} returning turns",
                    r.level_mm,
                    r.span_pct,
                    r.passes,
                    r.returning
                );
            }
        } else {
            say!(
                "  passes             {} ({} stage{}, {} returning turns)",
                st.passes,
                st.stages,
                if st.stages == 1 { "" } else { "s" },
                st.returning_points
            );
        }
        say!(
            "  layer heights      {} (layer_height {})",
            st.layers.summary(),
            sliced.corrected.surface.params.layer_height
        );
        if let Some(why) = &st.layers.thicker_because {
            say!("                     thicker than asked because {why}");
        }
        say!("  path length        {:.1} m", st.path_length_mm / 1000.0);
        let cartridges = match (st.cartridges, printer.cartridge_ml) {
            (Some(n), Some(c)) => format!(
                "; {n} cartridge{} of {c:.0} ml",
                if n == 1 { "" } else { "s" }
            ),
            _ => String::new(),
        };
        say!(
            "  clay               {:.1} ml, {:.0} g{cartridges}",
            st.volume_ml,
            st.clay_g
        );
        for r in &st.refills {
            say!(
                "  refill             after {:.0} ml: layer {}, {:.1} mm up, {:.0} % of the path",
                r.after_ml,
                r.pass,
                r.z_mm,
                r.share * 100.0
            );
        }
        if st.print_scale != [1.0, 1.0] {
            say!(
                "  firing shrinkage   printed {:.1} % larger across and {:.1} % taller, so the fired piece has the designed size",
                (st.print_scale[0] - 1.0) * 100.0,
                (st.print_scale[1] - 1.0) * 100.0
            );
        }
        if st.turn_steps > 0 {
            say!(
                "  clay at turns      {:.2} ml at {} turnaround steps, each the rounded end of its layer ({:.2} ml as cuboids)",
                st.turn_clay_ml,
                st.turn_steps,
                st.turn_clay_cuboid_ml
            );
        }
        say!("  estimated time     {:.1} min", st.time_min);
        for w in &st.warnings {
            say!("  warning            {w}");
        }
        let corr = sliced.corrected.report.summary();
        if corr.is_empty() {
            say!("  corrections        none");
        }
        for c in corr {
            say!("  correction         {c}");
        }
        say!(
            "  check              {}",
            if let (true, Some(r)) = (report.printable, &reshaped) {
                format!("printable, but reshaped: {r}")
            } else if report.printable {
                "printable".to_string()
            } else {
                format!("NOT printable: {}", report.failures.join("; "))
            }
        );
        for at in &locations {
            say!("  where              {at}");
        }
    }
    if !report.printable && !a.force {
        eprintln!("error: {source}: the design does not print in clay as drawn, and the corrections could not fix it; nothing written (--force writes it anyway). Change the design:");
        for line in &advice {
            eprintln!("  - {line}");
        }
        return Ok(1);
    }
    if !report.printable {
        eprintln!("warning: writing G-code that FAILS the printability check (--force)");
    }
    persist(tmp, &out)?;
    Ok(if report.printable { 0 } else { 1 })
}

fn serve(a: ServeArgs) -> Result<i32> {
    let rt = tokio::runtime::Runtime::new().context("starting the async runtime")?;
    rt.block_on(async {
        eprintln!(
            "sweepclay {VERSION}: starting the modeler on {}:{} ...",
            a.host, a.port
        );
        let listener = tokio::net::TcpListener::bind((a.host.as_str(), a.port))
            .await
            .with_context(|| format!("listening on {}:{}", a.host, a.port))?;
        let addr = listener.local_addr()?;
        let host = if addr.ip().is_unspecified() {
            "127.0.0.1".to_string()
        } else {
            addr.ip().to_string()
        };
        let lan = addr.ip().is_unspecified();
        let token = a
            .token
            .clone()
            .or_else(|| token_required(addr.ip()).then(random_token));
        if token.as_ref().is_some_and(|t| {
            t.is_empty()
                || !t
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        }) {
            bail!("--token: letters, digits, - and _ only, not empty");
        }
        let link = |h: &str| match &token {
            Some(t) => format!("http://{h}:{}/?token={t}", addr.port()),
            None => format!("http://{h}:{}/", addr.port()),
        };
        say!("sweepclay modeler: {}  (Ctrl+C to stop)", link(&host));
        if lan {
            for name in own_names().iter().take(1) {
                say!("  from the studio's other machines: {}", link(name));
            }
        }
        let defaults = sweepclay_web::api::Limits::default();
        let mut limits = sweepclay_web::api::Limits {
            max_samples: a.max_samples as f64,
            request_timeout: std::time::Duration::from_secs(a.timeout),
            // A client has --read-timeout to send; an answer may take a
            // minute more than the longest request.
            connections: sweepclay_web::conn::Connections {
                max: a.max_connections,
                read: std::time::Duration::from_secs(a.read_timeout),
                answer: std::time::Duration::from_secs(a.timeout + 60),
            },
            ..defaults
        };
        // Loopback's names, the address given, --allow-host; bound to every
        // interface on purpose (LAN mode), also the machine's names and any
        // IP address — never any name, which let DNS rebinding in.
        let mut names = a.allow_hosts.clone();
        if lan {
            names.extend(own_names());
        } else {
            names.push(a.host.clone());
        }
        for n in names {
            if !limits.hosts.iter().any(|h| h.eq_ignore_ascii_case(&n)) {
                limits.hosts.push(n);
            }
        }
        limits.lan = lan;
        limits.token = token;
        sweepclay_web::run(listener, limits).await?;
        Ok(0)
    })
}

/// Whether a server bound to `ip` must want a token: any address other
/// machines can reach — every interface, or one LAN address such as
/// `192.168.1.20` (it let the whole network in without one) — not
/// loopback.
fn token_required(ip: std::net::IpAddr) -> bool {
    !ip.is_loopback()
}

/// The check's configuration for `file`: the printer named, else the one
/// a sweepclay file's header names, else generic.
fn base_check_config(file: &Path, printer: Option<&str>) -> Result<CheckConfig> {
    let open = || std::fs::File::open(file).with_context(|| format!("reading {}", file.display()));
    Ok(match printer {
        Some(name) => {
            let p = load_printer(name)?;
            CheckConfig {
                printer: format!("{} (--printer)", p.name),
                ..printer_check(&p)
            }
        }
        None => {
            // Our own files name their printer and parameters in the header.
            use std::io::{BufRead, Read};
            let mut head = String::new();
            for line in std::io::BufReader::new(open()?.take(1 << 16))
                .lines()
                .take(sweepclay_check::header::HEADER_LINES)
            {
                let Ok(line) = line else { break };
                head.push_str(&line);
                head.push('\n');
            }
            sweepclay_check::header::config_from_header(&head, &CheckConfig::default())
                .unwrap_or_else(|| CheckConfig {
                    printer:
                        "generic (assumed: the file names no sweepclay printer; pass --printer)"
                            .into(),
                    ..CheckConfig::default()
                })
        }
    })
}

fn check_cmd(a: CheckArgs) -> Result<i32> {
    let open =
        || std::fs::File::open(&a.file).with_context(|| format!("reading {}", a.file.display()));
    let base = base_check_config(&a.file, a.printer.as_deref())?;
    let cfg = CheckConfig {
        firmware: a.firmware,
        nozzle_height: a.nozzle_height.unwrap_or(base.nozzle_height),
        width_min: a.width_min.unwrap_or(base.width_min),
        width_max: a.width_max.unwrap_or(base.width_max),
        overlap_target: a.overlap.unwrap_or(base.overlap_target),
        overlap_min: a.min_overlap.unwrap_or(base.overlap_min),
        max_overhang_deg: a.max_overhang_deg.unwrap_or(base.max_overhang_deg),
        first_layer_max_mm: a.first_layer_max.unwrap_or(base.first_layer_max_mm),
        ..base
    };
    cfg.validate()
        .map_err(|e| anyhow::anyhow!("{}: {}", check_flag(e.field), e.reason))?;
    let report = check_reader(std::io::BufReader::with_capacity(1 << 16, open()?), &cfg)
        .with_context(|| format!("reading {}", a.file.display()))?;
    if a.json {
        say!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        say(format_args!("{}", report.render()))?;
    }
    Ok(if report.cannot_judge.is_some() {
        3
    } else if report.printable {
        0
    } else {
        1
    })
}

/// The file an output path names: itself if missing, its target if it is
/// a symbolic link to a regular file; anything that is not a regular file
/// (a directory, a device, a FIFO) is refused, never replaced.
fn output_target(path: &Path) -> Result<PathBuf> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {
            std::fs::canonicalize(path).with_context(|| format!("resolving {}", path.display()))
        }
        Ok(_) => bail!(
            "{}: not a regular file (a directory, device or FIFO); refusing to replace it",
            path.display()
        ),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            if std::fs::symlink_metadata(path).is_ok() {
                bail!(
                    "{}: a symbolic link to nothing; refusing to follow it",
                    path.display()
                );
            }
            Ok(path.to_path_buf())
        }
        Err(e) => Err(e).with_context(|| format!("checking {}", path.display())),
    }
}

/// The prefix of our temporary files: `.sweepclay-tmp-NAME.` and random
/// letters, beside the file NAME they will replace.
const TMP_PREFIX: &str = ".sweepclay-tmp-";

/// A temporary file older than this (seconds) beside the output is a
/// run's leftover (a kill -9 runs no clean-up) and is removed.
const STALE_TMP_S: u64 = 600;

/// An empty temporary file in the directory of `path`, to be renamed over
/// it by [`persist`] (deleted if dropped or if the command is interrupted).
/// It is named for `path`, so the next run finds a killed run's leftover
/// and removes it (once it is [`STALE_TMP_S`] old, so a run still going
/// keeps its own).
fn temp_beside(path: &Path) -> Result<tempfile::NamedTempFile> {
    let dir = path
        .parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!("{TMP_PREFIX}{name}.");
    remove_stale(dir, &prefix);
    let tmp = tempfile::Builder::new()
        .prefix(&prefix)
        .tempfile_in(dir)
        .with_context(|| format!("creating a temporary file in {}", dir.display()))?;
    if let Ok(mut live) = LIVE.lock() {
        live.push(tmp.path().to_path_buf());
    }
    Ok(tmp)
}

/// Removes our leftover temporary files for one output (`prefix`) in
/// `dir` that are older than [`STALE_TMP_S`]; what cannot be removed is
/// left.
fn remove_stale(dir: &Path, prefix: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for e in entries.flatten() {
        let old = e
            .metadata()
            .ok()
            .filter(|m| m.is_file())
            .and_then(|m| m.modified().ok())
            .and_then(|t| t.elapsed().ok())
            .is_some_and(|age| age.as_secs() >= STALE_TMP_S);
        if old && e.file_name().to_string_lossy().starts_with(prefix) {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

/// Makes a finished temporary file `path`: an ordinary file with the mode
/// of the file it replaces (0644 for a new one; temporary files are
/// private, 0600), synced, then renamed, so a crash never leaves a
/// half-written file.
fn persist(tmp: tempfile::NamedTempFile, path: &Path) -> Result<()> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path).map_or(0o644, |m| m.permissions().mode() & 0o7777);
        tmp.as_file()
            .set_permissions(std::fs::Permissions::from_mode(mode))?;
    }
    tmp.as_file().sync_all()?;
    let name = tmp.path().to_path_buf();
    let done = tmp
        .persist(path)
        .with_context(|| format!("writing {}", path.display()));
    if let Ok(mut live) = LIVE.lock() {
        live.retain(|p| *p != name);
    }
    done.map(|_| ())
}

/// Writes through a temporary file in the same directory and renames it.
fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let path = output_target(path)?;
    let mut tmp = temp_beside(&path)?;
    tmp.write_all(bytes)?;
    persist(tmp, &path)
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
