//! `sweepclay slice` and `sweepclay import`: a design (or a vessel mesh
//! fitted by one, docs/MESHES.md) sliced, checked and written; a thin
//! shell over `sweepclay-plan`.

use super::*;

#[derive(Args, Debug)]
pub(crate) struct SliceArgs {
    /// Design file; a vessel mesh (`.stl`, `.obj`), fitted to a design
    /// first (docs/MESHES.md); or a bundled example name (`t1` … `t6`, `vase`, `flower`, `cup`, `slanted-vase`, `pitcher`, `ripple-vase`, `fluted-cup`, `twisted-lobes`, `diamond-vase`).
    pub(crate) design: String,
    /// A mesh's units: multiply its coordinates by this to get
    /// millimetres [default: 1, or 25.4 for a mesh 0.8 to 16 units tall,
    /// which is said].
    #[arg(long)]
    pub(crate) scale: Option<f64>,
    /// A mesh's axis that points up (x, y or z): a Y-up export (Blender's
    /// glTF habit, many CAD tools) stands on its side otherwise.
    #[arg(long, default_value = "z", value_parser = ["x", "y", "z"])]
    pub(crate) up: String,
    /// Also write the surface the G-code prints as STL (its beads'
    /// width), e.g. to compare with a mesh.
    #[arg(long, value_name = "FILE.stl")]
    pub(crate) stl: Option<PathBuf>,
    /// Output G-code file [default: the design's name with .gcode].
    #[arg(short, long)]
    pub(crate) output: Option<PathBuf>,
    /// Printer preset (cerambot-plus, cerambot-mini, wasp-2040-clay, wasp-40100-clay, eazao-zero, eazao-potter, eazao-m500, eazao-m600, vormvrij-lutum-4.6, generic: `sweepclay printers` lists them with their sources) or a printer JSON file; overrides the design's.
    #[arg(long)]
    pub(crate) printer: Option<String>,
    /// Override a parameter, e.g. `--set layer_height=1.5` (repeatable). Keys: layer_height, max_layer_height, spacing, nozzle_height, width_min, width_max, overlap, max_overhang_deg, feedrate, floor_layers (vessels), even_turn_flow (1 or 0), max_correction_mm, shrinkage_xy, shrinkage_z (firing shrinkage, fractions).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub(crate) sets: Vec<String>,
    /// Refuse the G-code if a bead overlaps the bead below by less than
    /// this fraction of its width (the checker's hard floor).
    #[arg(long, default_value_t = 0.5)]
    pub(crate) min_overlap: f64,
    /// Also write a picture of the toolpath (SVG).
    #[arg(long, value_name = "FILE.svg")]
    pub(crate) preview: Option<PathBuf>,
    /// Write the file even if the printability check fails.
    #[arg(long)]
    pub(crate) force: bool,
    /// Refuse designs with more surface samples than this (estimated
    /// before slicing; the same default as `serve`).
    #[arg(long, default_value_t = DEFAULT_MAX_SAMPLES)]
    pub(crate) max_samples: u64,
    /// Print the summary as JSON.
    #[arg(long)]
    pub(crate) json: bool,
}

#[derive(Args, Debug)]
pub(crate) struct ImportArgs {
    /// The mesh: `.stl` (binary or ASCII) or `.obj`.
    pub(crate) mesh: PathBuf,
    /// The design file to write [default: the mesh's name with .json].
    #[arg(short, long)]
    pub(crate) output: Option<PathBuf>,
    /// Multiply the mesh's coordinates by this to get millimetres
    /// [default: 1, or 25.4 for a mesh 0.8 to 16 units tall, which is said].
    #[arg(long)]
    pub(crate) scale: Option<f64>,
    /// The largest difference from the mesh the design may have (mm).
    #[arg(long, default_value_t = 0.3)]
    pub(crate) tolerance: f64,
    /// The mesh's axis that points up (x, y or z).
    #[arg(long, default_value = "z", value_parser = ["x", "y", "z"])]
    pub(crate) up: String,
    /// Refuse a mesh that is no sweep within the tolerance, instead of
    /// keeping what it has beyond the closest sweep as a relief.
    #[arg(long)]
    pub(crate) sweep_only: bool,
    /// Printer preset or printer JSON file for the design.
    #[arg(long)]
    pub(crate) printer: Option<String>,
    /// Replace the design file if it exists (it may hold edits made since
    /// the last import).
    #[arg(long)]
    pub(crate) force: bool,
}

/// The most bytes of a mesh file read: a binary STL of the triangle cap.
pub(crate) const MAX_MESH_BYTES: usize = 84 + 50 * sweepclay_core::meshread::MAX_TRIANGLES;

/// Reads a mesh file and fits it by a design (named after the file),
/// saying what was assumed and how close the fit is.
pub(crate) fn mesh_design(
    path: &Path,
    scale: Option<f64>,
    tolerance: f64,
    up: &str,
    relief: bool,
) -> Result<Design> {
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
        relief,
        ..meshfit::FitOptions::default()
    };
    let m = meshfit::import(&shown, &bytes, up, scale, &opts).with_context(|| shown.clone())?;
    if let Some(n) = m.units_note {
        eprintln!("note: {shown}: {n}");
    }
    if let Some(n) = &m.fitted.absorbed {
        eprintln!("note: {shown}: {n}");
    }
    if let Some(n) = &m.fitted.inside {
        eprintln!("note: {shown}: {n}");
    }
    let f = m.fitted;
    // A twist and ribs found in the mesh are the design's own twist and
    // texture (docs/MESHES.md).
    let mut twist = if f.design.twist_deg == 0.0 {
        String::new()
    } else {
        format!(", twisted {}°", f.design.twist_deg)
    };
    for t in &f.design.texture {
        twist += &format!(
            ", a {} texture of {} ribs",
            t.label(),
            t.count.unwrap_or(0.0)
        );
    }
    if let (Some((dev, at)), Some(r)) = (f.sweep, &f.design.relief) {
        say!(
            "{shown}: {} triangles, a {}; no sweep of one loop within {tolerance} mm (the closest, {}{twist}, differs by {dev:.2} mm at ({:.1}, {:.1}, {:.1}) mm): printed as the mesh is, that sweep and a relief of {} heights × {} places over it, within {:.2} mm of its {} sections; its foot's centre moved to o (editing its curves reshapes the sweep under the relief; --sweep-only refuses such a mesh)",
            m.triangles,
            if f.kind == "shell" { "wall with its thickness (its outside kept)" } else { "solid (its outside kept)" },
            if f.design.profile_end.is_some() { "two profiles blended round one loop" } else { "one profile round one loop" },
            at[0],
            at[1],
            at[2],
            r.z.len(),
            r.u.len(),
            f.deviation_mm,
            f.sections
        );
        return Ok(f.design);
    }
    say!(
        "{shown}: {} triangles, a {}; fitted by a design (one loop, {}{twist}) within {:.2} mm of its {} sections (largest at ({:.1}, {:.1}, {:.1}) mm); its foot's centre moved to o",
        m.triangles,
        if f.kind == "shell" { "wall with its thickness (its outside kept)" } else { "solid (its outside kept)" },
        if f.design.profile_end.is_some() { "two profiles blended round it" } else { "one profile" },
        f.deviation_mm,
        f.sections,
        f.at[0],
        f.at[1],
        f.at[2]
    );
    Ok(f.design)
}

pub(crate) fn is_mesh(path: &str) -> bool {
    let lower = path.to_ascii_lowercase();
    lower.ends_with(".stl") || lower.ends_with(".obj")
}

pub(crate) fn import_cmd(a: ImportArgs) -> Result<i32> {
    if !(a.tolerance.is_finite() && a.tolerance > 0.0) {
        bail!(
            "--tolerance: must be a length above 0 mm (got {})",
            a.tolerance
        );
    }
    let mut design = mesh_design(&a.mesh, a.scale, a.tolerance, &a.up, !a.sweep_only)?;
    if let Some(p) = &a.printer {
        design.printer = PrinterRef::Inline(Box::new(load_printer(p)?));
    }
    let out = a
        .output
        .clone()
        .unwrap_or_else(|| a.mesh.with_extension("json"));
    let out = output_target(&out)?;
    let printer_file = a.printer.as_deref().map(Path::new);
    let inputs: Vec<&Path> = std::iter::once(a.mesh.as_path())
        .chain(printer_file)
        .collect();
    not_an_input("-o", &out, &inputs)?;
    if out.exists() && !a.force {
        bail!(
            "{} exists (it may hold edits made since it was imported); refusing to replace it: give -o another name, or --force to replace it",
            out.display()
        );
    }
    write_atomic(&out, design.to_json().as_bytes())?;
    say!("wrote {}", out.display());
    Ok(0)
}

pub(crate) fn slice(a: SliceArgs) -> Result<i32> {
    if is_mesh(&a.design) {
        let design = mesh_design(Path::new(&a.design), a.scale, 0.3, &a.up, true)?;
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
pub(crate) fn slice_design(a: SliceArgs, text: String, source: String) -> Result<i32> {
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
    // The temporary file is made when the G-code starts to stream, after
    // the sampling and planning that take the memory: a run that dies
    // there (killed, out of memory) leaves nothing beside the output.
    let mut made: Option<(tempfile::NamedTempFile, std::fs::File)> = None;
    let _ticker = Ticker::start(&source);
    let planned = plan(&job, &Cancel::new(), || {
        use std::io::{Seek, SeekFrom};
        if made.is_none() {
            let tmp = temp_beside(&out).map_err(std::io::Error::other)?;
            let file = tmp.reopen()?;
            made = Some((tmp, file));
        }
        let (_, file) = made.as_ref().expect("made above");
        let mut f = file.try_clone()?;
        f.set_len(0)?;
        f.seek(SeekFrom::Start(0))?;
        Ok(std::io::BufWriter::with_capacity(1 << 16, f))
    });
    let checked = match planned {
        Ok(p) => p.checked,
        Err(Unchecked::Design(e)) => return Err(e).with_context(|| source.clone()),
        Err(Unchecked::Io(e)) => {
            return Err(e).with_context(|| format!("writing beside {}", out.display()))
        }
    };
    let (tmp, _) = made.context("the plan wrote no G-code")?;
    let advice = checked.advice();
    let Checked {
        sliced,
        out: written,
        report,
        locations,
        point_lines,
        most_twist: _,
        most_rise: _,
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
        const LISTED: usize = 10;
        for r in st.refills.iter().take(LISTED) {
            say!(
                "  refill             after {:.0} ml: layer {}, {:.1} mm up, {:.0} % of the path",
                r.after_ml,
                r.pass,
                r.z_mm,
                r.share * 100.0
            );
        }
        if let (Some(c), true) = (printer.cartridge_ml, st.refills.len() > LISTED) {
            let more = (st.volume_ml / c).ceil() - 1.0 - LISTED as f64;
            say!(
                "  refill             … and {more:.0} more (see --json for the first {})",
                st.refills.len()
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

/// Says on a terminal that a long slice is still working, after 3 s and
/// every 5 s then, with the time so far (Ctrl+C stops it and leaves no
/// file behind); stops when dropped.
struct Ticker(Option<(std::sync::mpsc::Sender<()>, std::thread::JoinHandle<()>)>);

impl Ticker {
    fn start(what: &str) -> Ticker {
        use std::io::IsTerminal;
        if !std::io::stderr().is_terminal() {
            return Ticker(None);
        }
        let (tx, rx) = std::sync::mpsc::channel::<()>();
        let what = what.to_string();
        let t0 = std::time::Instant::now();
        let handle = std::thread::spawn(move || {
            let mut wait = std::time::Duration::from_secs(3);
            while let Err(std::sync::mpsc::RecvTimeoutError::Timeout) = rx.recv_timeout(wait) {
                eprintln!(
                    "{what}: still slicing and checking, {:.0} s so far (Ctrl+C stops it)",
                    t0.elapsed().as_secs_f64()
                );
                wait = std::time::Duration::from_secs(5);
            }
        });
        Ticker(Some((tx, handle)))
    }
}

impl Drop for Ticker {
    fn drop(&mut self) {
        if let Some((tx, handle)) = self.0.take() {
            drop(tx);
            let _ = handle.join();
        }
    }
}
