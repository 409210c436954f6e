//! The preview's answer as the page reads it (docs/MODELER.md, "The
//! preview"): the layering, the surface's samples, the path with its bead
//! widths and stability map, the printer, the curves as printed, and the
//! binary form that ships them without JSON's cost.

use super::*;

/// The layering the path follows.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PlanView {
    /// K: passes.
    pub passes: u32,
    /// N': passes of the lower (tilted) stage; passes above it are the
    /// upper stage.
    pub lower_passes: u32,
    /// 1 or 2.
    pub stages: u8,
    /// Layer height at the tall end in the lower stage (mm).
    pub lower_layer_mm: f64,
    /// Layer height of the upper stage (mm).
    pub upper_layer_mm: f64,
}

/// The surface samples, column by column: the page zips adjacent columns
/// into triangles as [`mesh::surface_triangles`] does (sending the
/// triangles would triple the answer's size).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SurfaceView {
    /// x, y, z of each sample, flat, in mm relative to `o` (0.01 mm).
    pub positions: Vec<f32>,
    /// First sample and sample count of each transition curve, flat.
    pub columns: Vec<u32>,
    /// Samples that a correction moved by more than 0.05 mm.
    pub moved: Vec<u32>,
    /// Number of transition curves.
    pub curves: usize,
}

/// The toolpath over the surface's samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PathView {
    /// The sample each path point visits, in print order (a vessel's floor
    /// beads: their positions, after the samples').
    pub order: Vec<u32>,
    /// Bead width per path point (mm, 0.01).
    pub width: Vec<f32>,
    /// Pass per path point (1-based).
    pub pass: Vec<u32>,
    /// Path points that are top-edge beads of returning turns.
    pub top: Vec<u32>,
    /// How well each bead sits (overlap, overhang, layer height, the
    /// extruder body's clearance): the stability map.
    pub beads: sweepclay_core::beads::BeadMap,
    /// How much of the texture each path point keeps, 0–1 (1 where it
    /// is whole; empty without textures: docs/ALGORITHMS.md §11).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub texture_kept: Vec<f32>,
}

/// The printer's box and body, for the preview's build volume.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct PrinterView {
    /// Profile name.
    pub name: String,
    /// Build volume `[x, y, z]` (mm).
    pub build_volume: [f64; 3],
    /// The box's lowest corner in the printer's coordinates (mm).
    pub bed_min: [f64; 3],
    /// A round bed's diameter (mm), if round.
    pub bed_diameter: Option<f64>,
    /// Radius of the extruder body (mm).
    pub nozzle_radius: f64,
}

/// Everything the preview shows for one design.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SliceView {
    /// The Table-1 statistics.
    pub stats: sweepclay_core::Stats,
    /// The layering.
    pub plan: PlanView,
    /// The corrected surface.
    pub surface: SurfaceView,
    /// The toolpath.
    pub path: PathView,
    /// One line per correction (which curve, where, by how much).
    pub corrections: Vec<String>,
    /// Things the designer should know that are not errors.
    pub warnings: Vec<String>,
    /// Where the design's `o` lands on the bed (mm): positions + origin =
    /// bed coordinates, as in `stats.bounds_mm`.
    pub origin: [f64; 2],
    /// Time spent slicing on the server (ms).
    pub slice_ms: f64,
    /// The printer's box and body.
    pub printer: PrinterView,
    /// Set when the print leaves the printer's build volume: the preview
    /// shows it, but it cannot be printed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit_error: Option<FitError>,
    /// The curves as printed, where the corrections moved them: the
    /// editors draw them beside the drawn ones.
    pub printed: PrintedCurves,
    /// The check of the G-code this preview is (none for a print that
    /// leaves the build volume).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub verdict: Option<Verdict>,
}

/// The design's curves as the corrections left them (design units: the
/// firing scale taken out), each only where it differs from the drawing
/// by more than 0.05 mm: C_s and C_t as `[offset, height]` along their
/// transition curves, Ψ as the columns' points (docs/ALGORITHMS.md §4).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PrintedCurves {
    /// C_s as printed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profile_start: Option<Vec<[f32; 2]>>,
    /// C_t as printed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profile_end: Option<Vec<[f32; 2]>>,
    /// Ψ as printed (its corners rounded).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub trajectory: Option<Vec<[f32; 2]>>,
}

/// The printed curves of a corrected surface against the sampled one.
pub(super) fn printed_curves(drawn: &surface::Surface, s: &surface::Surface) -> PrintedCurves {
    let [kx, kz] = s.params.print_scale();
    let n = s.columns.len();
    if n == 0 || drawn.columns.len() != n {
        return PrintedCurves::default();
    }
    // C_t lies where λ is largest (the last column of a wall, half way
    // round a vessel's default interpolation).
    let end = (0..n)
        .max_by(|&a, &b| s.columns[a].lambda.total_cmp(&s.columns[b].lambda))
        .unwrap_or(n - 1);
    let profile = |c: usize| {
        let col = &s.columns[c];
        let moved = col
            .samples()
            .any(|i| (s.samples[i].xi - drawn.samples[i].xi).abs() > 0.05);
        moved.then(|| {
            col.samples()
                .map(|i| [(s.samples[i].xi / kx) as f32, (s.samples[i].z / kz) as f32])
                .collect()
        })
    };
    PrintedCurves {
        profile_start: profile(0),
        profile_end: profile(end),
        trajectory: (!s.corners.is_empty()).then(|| {
            s.columns
                .iter()
                .map(|c| [(c.p[0] / kx) as f32, (c.p[1] / kx) as f32])
                .collect()
        }),
    }
}

impl SliceView {
    /// The same answer in a compact binary form the page reads without
    /// parsing: `SWCL`, a u32 length and that many bytes of JSON (every
    /// field but the arrays, padded with spaces to 4 bytes), then the
    /// arrays, each a u32 count and its little-endian values, in this
    /// order: surface positions (f32), columns (u32), moved (u32), path
    /// order (u32), width (f32), pass (u32), top (u32), then the bead
    /// map's overlap, overhang, layer height and clearance (f32), then
    /// the texture kept per path point (f32; none without textures).
    pub fn to_binary(&self) -> Vec<u8> {
        let mut json = serde_json::to_vec(&serde_json::json!({
            "stats": self.stats,
            "plan": self.plan,
            "curves": self.surface.curves,
            "corrections": self.corrections,
            "warnings": self.warnings,
            "origin": self.origin,
            "slice_ms": self.slice_ms,
            "printer": self.printer,
            "fit_error": self.fit_error,
            "printed": self.printed,
            "verdict": self.verdict,
        }))
        .expect("plain data serialises");
        while !json.len().is_multiple_of(4) {
            json.push(b' ');
        }
        let s = &self.surface;
        let p = &self.path;
        let words = s.positions.len()
            + s.columns.len()
            + s.moved.len()
            + 7 * p.order.len()
            + p.top.len()
            + p.texture_kept.len()
            + 12;
        let mut out = Vec::with_capacity(8 + json.len() + 4 * words);
        out.extend_from_slice(b"SWCL");
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(&json);
        fn floats(out: &mut Vec<u8>, v: &[f32]) {
            out.extend_from_slice(&(v.len() as u32).to_le_bytes());
            v.iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
        }
        fn ints(out: &mut Vec<u8>, v: &[u32]) {
            out.extend_from_slice(&(v.len() as u32).to_le_bytes());
            v.iter()
                .for_each(|x| out.extend_from_slice(&x.to_le_bytes()));
        }
        floats(&mut out, &s.positions);
        ints(&mut out, &s.columns);
        ints(&mut out, &s.moved);
        ints(&mut out, &p.order);
        floats(&mut out, &p.width);
        ints(&mut out, &p.pass);
        ints(&mut out, &p.top);
        for v in [
            &p.beads.overlap,
            &p.beads.overhang_deg,
            &p.beads.layer_height,
            &p.beads.clearance,
            &p.texture_kept,
        ] {
            floats(&mut out, v);
        }
        out
    }
}

pub(super) fn round2(x: f64) -> f32 {
    ((x * 100.0).round() / 100.0) as f32
}

/// Why a sliced design cannot be printed on its printer (it leaves the
/// build volume), as an API error's message and key.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct FitError {
    /// The message.
    pub error: String,
    /// The design key it concerns.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub key: Option<String>,
}

pub(super) fn view(
    s: &Sliced,
    moved: Vec<u32>,
    slice_ms: f64,
    fit_error: Option<FitError>,
) -> SliceView {
    let surf = &s.corrected.surface;
    let mut positions = Vec::with_capacity(3 * surf.samples.len());
    for (c, col) in surf.columns.iter().enumerate() {
        for si in col.samples() {
            positions.extend(surf.position(c, si).map(round2));
        }
    }
    let columns = surf
        .columns
        .iter()
        .flat_map(|c| [c.first, c.len() as u32])
        .collect();
    let pts = &s.toolpath.points;
    // A vessel's floor beads are not surface samples: their positions
    // follow the samples', in print order.
    let mut extra = surf.samples.len() as u32;
    let order: Vec<u32> = pts
        .iter()
        .map(|p| match mesh::sample_of_point(surf, p) {
            Some(i) => i as u32,
            None => {
                positions.extend(p.pos.map(round2));
                extra += 1;
                extra - 1
            }
        })
        .collect();
    // A floor bead's index is past the samples: it keeps no texture.
    let kept = &s.corrected.kept;
    let texture_kept = if kept.is_empty() {
        Vec::new()
    } else {
        order
            .iter()
            .map(|&i| kept.get(i as usize).map_or(1.0, |&k| round2(k)))
            .collect()
    };
    let path = PathView {
        order,
        width: s.extrusion.width.iter().map(|&w| round2(w)).collect(),
        pass: pts.iter().map(|p| p.pass).collect(),
        top: (0..pts.len() as u32)
            .filter(|&i| pts[i as usize].kind == PointKind::Top)
            .collect(),
        beads: sweepclay_core::beads::bead_map(
            &s.toolpath,
            &s.extrusion,
            surf.printer.nozzle_radius,
            surf.params.nozzle_height,
        ),
        texture_kept,
    };
    let plan = &surf.plan;
    let mut warnings = Vec::new();
    if s.toolpath.stages == 2 {
        warnings.push(format!(
            "two stages: the ends differ by more than the extruder allows in one tilted stage; the upper {} passes climb the top edge with {} returning turns, so the rim is a sawtooth of up to one layer",
            plan.passes - plan.lower_passes,
            s.toolpath.returning_points
        ));
    }
    warnings.extend(s.stats.warnings.iter().cloned());
    let pr = &surf.printer;
    let b = &s.stats.bounds_mm;
    let fill = (0..3)
        .map(|a| (b[1][a] - b[0][a]) / pr.build_volume[a])
        .fold(0.0, f64::max);
    if fill > 0.9 {
        warnings.push(format!(
            "the print fills {:.0} % of printer `{}`'s build volume along one axis",
            100.0 * fill,
            pr.name
        ));
    }
    SliceView {
        stats: s.stats.clone(),
        plan: PlanView {
            passes: plan.passes,
            lower_passes: plan.lower_passes,
            stages: s.toolpath.stages,
            lower_layer_mm: plan.lower_layer_mm,
            upper_layer_mm: plan.upper_layer_mm,
        },
        surface: SurfaceView {
            positions,
            columns,
            moved,
            curves: surf.columns.len(),
        },
        path,
        corrections: s.corrected.report.summary(),
        warnings,
        origin: pr.origin,
        slice_ms,
        printer: PrinterView {
            name: pr.name.clone(),
            build_volume: pr.build_volume,
            bed_min: pr.bed_min,
            bed_diameter: pr.bed_diameter,
            nozzle_radius: pr.nozzle_radius,
        },
        fit_error,
        printed: PrintedCurves::default(),
        verdict: None,
    }
}
