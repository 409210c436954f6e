//! Stage 1 for a vessel (a closed Ψ): its columns sampled as one spiral
//! wall over its floor, a raised rim's partial layers above the spiral
//! (paper §4, docs/ALGORITHMS.md §6 and §8). `super::sample_surface`
//! hands a loop here once its columns are laid out.

use super::*;

/// Where a spiral may begin on a loop whose columns' rims are `h`: just
/// past the lowest rim (the first turn then ends where its rise is least,
/// docs/ALGORITHMS.md §8), Ψ's start, then seven more evenly round the
/// loop.
fn spiral_starts(h: &[f64]) -> Vec<usize> {
    let n = h.len();
    let lowest = (0..n).min_by(|&a, &b| h[a].total_cmp(&h[b])).unwrap_or(0);
    let mut starts = vec![(lowest + 1) % n];
    for c in (0..8).map(|m| m * n / 8).filter(|&c| c < n) {
        if !starts.contains(&c) {
            starts.push(c);
        }
    }
    starts
}

/// A vessel's layering whose extruder body meets clay, by the sampling's
/// estimate: at which column, and how high above the nozzle (mm).
type Colliding = (VesselPlan, usize, f64);

/// The layering with the most turns, from `v.turns` down to
/// `v.fewest_turns`, and the first of `starts`, whose first turn fits
/// and whose spiral the extruder body clears; else the one whose first
/// turn fits with the least collision (column, mm above the nozzle), if
/// any first turn fits.
fn clear_layering(
    v: &VesselPlan,
    starts: &[usize],
    near: &crate::vessel::Neighbours,
    heights: &[f64],
    exempt: f64,
    params: &Params,
) -> std::result::Result<VesselPlan, Option<Box<Colliding>>> {
    let mut least: Option<Box<Colliding>> = None;
    for turns in (v.fewest_turns..=v.turns).rev() {
        for &st in starts {
            let w = v.with(turns, st, params);
            if !w.first_fits(params) {
                continue;
            }
            match w.body_violation(near, heights, exempt) {
                None => return Ok(w),
                Some((i, over)) => {
                    if least.as_ref().is_none_or(|l| over < l.2) {
                        least = Some(Box::new((w, i, over)));
                    }
                }
            }
        }
    }
    Err(least)
}

/// The rim's lowest and highest heights, and the largest share f of its
/// spread for which `holds` is true of the heights drawn toward the
/// lowest, lo + f·(h − lo), by bisection over `steps` halvings (0 if
/// none holds): how far a refused rim's heights must come together.
fn largest_share(heights: &[f64], steps: u32, holds: impl Fn(&[f64]) -> bool) -> (f64, f64, f64) {
    let lo = heights.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = heights.iter().copied().fold(0.0, f64::max);
    let (mut ok, mut bad) = (0.0f64, 1.0f64);
    for _ in 0..steps {
        let f = 0.5 * (ok + bad);
        let h: Vec<f64> = heights.iter().map(|&h| lo + f * (h - lo)).collect();
        if holds(&h) {
            ok = f;
        } else {
            bad = f;
        }
    }
    (lo, hi, ok)
}

/// The samples of a vessel (docs/ALGORITHMS.md §8): each column's spiral
/// turns and, where the last turn ends half a layer or more below the
/// rim, the rim bead. The floor is not sampled: the path stage fills the
/// first turn's inside.
pub(super) fn sample_vessel(
    design: &Design,
    columns: Vec<Column>,
    length: f64,
    params: Params,
    printer: Printer,
    start: Profile,
    end: Profile,
) -> Result<Surface> {
    let heights: Vec<f64> = columns.iter().map(|c| c.height).collect();
    let floor = params
        .floor_layers
        .unwrap_or(crate::design::DEFAULT_FLOOR_LAYERS);
    let chosen = VesselPlan::choose(&heights, &params, floor);
    let starts = spiral_starts(&heights);
    // The extruder body's reach, and the clay just laid along the loop
    // that it may touch, as the checker counts them; columns where the
    // rim is, where collisions happen (docs/ALGORITHMS.md §8).
    let reach = printer.nozzle_radius + params.width_max / 2.0 + displacement_reach(design);
    let exempt = printer.nozzle_radius + params.width_max;
    let offset = |c: &Column| {
        if design.rim.is_some() {
            return super::continued(&start, c.height);
        }
        let t = 1.0;
        (1.0 - c.lambda) * start.offset(t) + c.lambda * end.offset(t)
    };
    let points: Vec<[f64; 2]> = columns
        .iter()
        .map(|c| {
            let q = c.point(offset(c), 0.0);
            [q[0], q[1]]
        })
        .collect();
    let near = crate::vessel::Neighbours::new(&points, reach);
    // The most turns (the thinnest layers) whose spiral the extruder body
    // clears, from the first start whose seam it clears; where a rim rises
    // and falls, thicker layers keep the turn below out of its way.
    let full = chosen
        .as_ref()
        .ok()
        .map(|v| clear_layering(v, &starts, &near, &heights, exempt, &params));
    // Where no spiral carries the whole rim, the spiral carries it up to
    // a level and the part above is laid as partial layers.
    let mut peaks = None;
    let (v, rim) = 'plan: {
        if !matches!(full, Some(Ok(_))) {
            match raised_arc(&heights, &columns, floor, &near, exempt, &params) {
                Ok(Some(v)) => break 'plan (v, None),
                Ok(None) => {}
                // Two raised parts: the spiral over the whole rim may still
                // print (the replay judges); where it cannot, this says why.
                Err(why) => peaks = Some(why),
            }
        }
        if let (Err(_), Some(why)) = (&chosen, &peaks) {
            return Err(Error::invalid("profile_end", why.clone()));
        }
        // Where the rim is highest and lowest, for a refusal of its spread.
        let places = || {
            let at = |best: fn(f64, f64) -> bool| {
                let i = (0..heights.len())
                    .reduce(|a, b| if best(heights[b], heights[a]) { b } else { a })
                    .unwrap_or(0);
                columns[i].p
            };
            let (hi, lo) = (at(|a, b| a > b), at(|a, b| a < b));
            format!(
                " (the rim is highest near ({:.0}, {:.0}) mm and lowest near ({:.0}, {:.0}) mm; no level of it leaves one raised part above what one spiral carries)",
                hi[0], hi[1], lo[0], lo[1]
            )
        };
        if let Err(Error::Invalid { key, reason }) = &chosen {
            return Err(Error::invalid(key.clone(), format!("{reason}{}", places())));
        }
        chosen?;
        let v = match full.expect("a layering was chosen") {
            Ok(clear) => clear,
            Err(None) => {
                // The most the rim may rise: the largest share of its spread
                // whose first turn fits somewhere (to 1/1000 of it).
                let (lo, hi, ok) = largest_share(&heights, 10, |hs| {
                    VesselPlan::choose(hs, &params, floor).is_ok_and(|v| {
                        (v.fewest_turns..=v.turns).any(|t| {
                            starts
                                .iter()
                                .any(|&st| v.with(t, st, &params).first_fits(&params))
                        })
                    })
                });
                return Err(Error::invalid(
                "params.max_layer_height",
                format!(
                    "the rim's height varies from {lo:.1} to {hi:.1} mm round the loop: the wall's first turn, starting a layer above the floor, would end more than {} mm above it wherever it starts; bring the rim's highest point to {:.1} mm or less, or raise params.max_layer_height{}",
                    params.max_layer_height,
                    lo + ok * (hi - lo),
                    places()
                ),
            ));
            }
            Err(Some(least)) => {
                let (least, i, over) = *least;
                // No layering clears by this estimate: print the thickest and
                // let the replay of the path judge (the checker names where the
                // body meets clay, and `--force` writes it); the estimate says
                // how far the rim's heights must come together.
                // The largest share of today's spread whose spiral clears.
                let (lo, hi, ok) = largest_share(&heights, 12, |h| {
                    VesselPlan::choose(h, &params, floor).is_ok_and(|w| {
                        clear_layering(&w, &starts, &near, h, exempt, &params).is_ok()
                    })
                });
                let c = &columns[i];
                let mut v = least;
                v.uneven = Some(crate::vessel::Uneven {
                    at: [c.p[0], c.p[1]],
                    over_mm: over,
                    spread_mm: hi - lo,
                    most_mm: ok * (hi - lo),
                    peaks,
                });
                v
            }
        };
        let rim = v.rim_beads(&near, &heights, exempt);
        (v, Some(rim))
    };
    Ok(vessel_samples(
        design,
        columns,
        length,
        params,
        printer,
        (start, end),
        v,
        rim,
    ))
}

/// The surface of a vessel laid out by `v` (docs/ALGORITHMS.md §8): each
/// column's spiral turns, its rim bead (where `rim` says, or, with a
/// raised arc, on every column: at its rim or the arc's level, half a
/// layer above the last turn at least), and a raised arc's passes and
/// top beads above.
#[allow(clippy::too_many_arguments)]
fn vessel_samples(
    design: &Design,
    mut columns: Vec<Column>,
    length: f64,
    params: Params,
    printer: Printer,
    (start, end): (Profile, Profile),
    v: VesselPlan,
    rim: Option<Vec<bool>>,
) -> Surface {
    let n = columns.len();
    let layers = v.turns;
    let plan = LayerPlan {
        passes: layers + 1,
        lower_passes: layers + 1,
        lower_layer_mm: v.turn_mm[0],
        upper_layer_mm: v.turn_mm[1],
        spread_mm: 0.0,
        first_toward_tall: true,
        min_top_bead_mm: 0.0,
    };
    let mut surface = Surface {
        name: design.name.clone(),
        columns: Vec::new(),
        samples: Vec::with_capacity(n * (layers as usize + 1)),
        plan,
        vessel: None,
        tall_at_end: true,
        start,
        end,
        trajectory_length: length,
        spacing: length / n as f64,
        params,
        printer,
        corners: Vec::new(),
        texture: Vec::new(),
        texture_label: (String::new(), 0.0),
        relief: design.relief.clone(),
        rim_continues: design.rim.is_some(),
    };
    // Each arc column's place in the arc.
    let mut in_arc = vec![usize::MAX; n];
    if let Some(a) = &v.arc {
        for (j, &c) in a.columns.iter().enumerate() {
            in_arc[c] = j;
        }
    }
    let half = 0.5 * v.base_layer_mm;
    for (i, col) in columns.iter_mut().enumerate() {
        col.first = surface.samples.len() as u32;
        col.passes = layers;
        let h = v.heights[i];
        let last = v.spiral_z(v.turns, i, n, h);
        let (rim_z, arc_z): (Option<f64>, Vec<f64>) = match (&v.arc, &rim) {
            (Some(a), _) if in_arc[i] != usize::MAX => {
                let j = in_arc[i];
                let passes = (1..=a.passes[j]).map(|k| a.level_mm + f64::from(k) * a.layer_mm);
                let top = a.has_top(j).then_some(a.top_z[j]);
                (Some(a.rim[j]), passes.chain(top).collect())
            }
            (Some(_), _) => (Some(col.height.max(last + half)), Vec::new()),
            (None, Some(r)) => (r[i].then_some(col.height), Vec::new()),
            (None, None) => (None, Vec::new()),
        };
        col.top = rim_z.is_some();
        col.extra = arc_z.len() as u32;
        let spiral = (1..=v.turns).map(|k| v.spiral_z(k, i, n, h));
        for z in spiral.chain(rim_z).chain(arc_z) {
            let xi = surface.design_offset(col, z, 1.0);
            surface.samples.push(Sample { z, xi });
        }
    }
    surface.columns = columns;
    surface.vessel = Some(v);
    surface
}

/// The layering of a vessel whose rim rises above what one spiral
/// carries: the highest level H (in steps of a quarter layer, at most
/// 200) at which the spiral over the rim cut at H clears the extruder
/// body by the sampling's estimate and the rim above H is one raised arc
/// ([`crate::vessel::RaisedArc`]); the spiral then starts just past the
/// arc, so that its rim turn ends at the arc's end. `None` where no level
/// serves; why not, where the rim rises in two or more places above
/// every level the spiral carries (one continuous path reaches only one).
fn raised_arc(
    h: &[f64],
    columns: &[Column],
    floor: u32,
    near: &crate::vessel::Neighbours,
    exempt: f64,
    params: &Params,
) -> std::result::Result<Option<VesselPlan>, String> {
    let n = h.len();
    let da = params.layer_height.min(0.5 * params.max_layer_height);
    let half = 0.5 * params.layer_height;
    let lo = h.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = h.iter().copied().fold(0.0, f64::max);
    if hi - lo < da {
        return Ok(None);
    }
    // Why a level does not serve, where the rim rises twice there: which
    // rise to lower, and to what.
    let attempt = |level: f64| -> std::result::Result<VesselPlan, Option<String>> {
        let runs = raised_runs(h, level + 0.5 * da);
        if runs.is_empty() {
            return Err(None);
        }
        let hp: Vec<f64> = h.iter().map(|&x| x.min(level)).collect();
        let w = VesselPlan::choose(&hp, params, floor).map_err(|_| None)?;
        if runs.len() > 1 {
            return Err(Some(several_rises(h, columns, level, da, runs)));
        }
        let (a, len) = runs[0];
        let end = (a + len - 1) % n;
        let mut plan =
            clear_layering(&w, &[(end + 1) % n], near, &hp, exempt, params).map_err(|_| None)?;
        let cols: Vec<usize> = (0..len).map(|j| (a + j) % n).collect();
        let last: Vec<f64> = cols
            .iter()
            .map(|&i| plan.spiral_z(plan.turns, i, n, hp[i]))
            .collect();
        let rims: Vec<f64> = cols.iter().map(|&i| h[i]).collect();
        let arc = crate::vessel::RaisedArc::new(level, da, cols, &rims, &last, half).map_err(
            |(j, most)| {
                let i = (a + j) % n;
                Some(format!(
                    "the rim rises twice above the {level:.1} mm one spiral carries round the loop, and one continuous path can print only one raised part: near ({:.0}, {:.0}) mm it rises again, to {:.1} mm; lower it there to {most:.1} mm or less",
                    columns[i].p[0], columns[i].p[1], h[i]
                ))
            },
        )?;
        // The rim turn, every column's bead as `vessel_samples` lays it,
        // must pass under no clay: a lower level flattens the rim the
        // spiral carries.
        let mut rim: Vec<f64> = (0..n)
            .map(|i| h[i].max(plan.spiral_z(plan.turns, i, n, hp[i]) + half))
            .collect();
        for (j, &c) in arc.columns.iter().enumerate() {
            rim[c] = arc.rim[j];
        }
        if !plan.rim_turn_clears(near, &hp, &rim, exempt) || !arc.body_clears(near, exempt) {
            return Err(None);
        }
        plan.arc = Some(arc);
        Ok(plan)
    };
    // From the top down in steps of two layers, then the quarter layers
    // above the first that serves (each level costs a layering's body
    // check; 200 quarter layers took 33 ms on a pitcher).
    let fine = (0.25 * da).max((hi - lo) / 200.0);
    let coarse = 8.0 * fine;
    let top = hi - 0.5 * da;
    let mut why: Option<String> = None;
    let mut level = top;
    loop {
        level -= coarse;
        if level < lo {
            break;
        }
        match attempt(level) {
            Ok(plan) => {
                let mut finer = (level + coarse - fine).min(top - fine);
                while finer > level + 0.5 * fine {
                    if let Ok(better) = attempt(finer) {
                        return Ok(Some(better));
                    }
                    finer -= fine;
                }
                return Ok(Some(plan));
            }
            Err(Some(w)) => why = Some(w),
            Err(None) => {}
        }
    }
    // The quarter layers under the lowest two-layer step, down to the
    // lowest rim, where the spiral's rim is nearly level.
    level += coarse;
    loop {
        level -= fine;
        if level < lo {
            break;
        }
        match attempt(level) {
            Ok(plan) => return Ok(Some(plan)),
            Err(Some(w)) => why = Some(w),
            Err(None) => {}
        }
    }
    why.map_or(Ok(None), Err)
}

/// Why a rim that rises above `level` in the `runs` of columns does not
/// print as one raised part: the second highest, and the most it may
/// rise (`da`: the passes' layer).
fn several_rises(
    h: &[f64],
    columns: &[Column],
    level: f64,
    da: f64,
    mut runs: Vec<(usize, usize)>,
) -> String {
    let n = h.len();
    let peak = |&(a, len): &(usize, usize)| {
        (0..len)
            .map(|j| (a + j) % n)
            .max_by(|&x, &y| h[x].total_cmp(&h[y]))
            .unwrap_or(a)
    };
    runs.sort_by(|x, y| h[peak(y)].total_cmp(&h[peak(x)]));
    let second = peak(&runs[1]);
    let c = &columns[second];
    format!(
        "the rim rises in {} places above the {level:.1} mm one spiral carries round the loop, and one continuous path can print only one raised part: the second, near ({:.0}, {:.0}) mm, rises to {:.1} mm; lower it to {:.1} mm or less, or raise the rim between the raised parts above {level:.1} mm so that they become one",
        runs.len(),
        c.p[0],
        c.p[1],
        h[second],
        level + 0.5 * da
    )
}

/// The runs of columns (first, count) round a loop whose rims `h` stand
/// above `above`.
fn raised_runs(h: &[f64], above: f64) -> Vec<(usize, usize)> {
    let n = h.len();
    let up: Vec<bool> = h.iter().map(|&x| x > above).collect();
    let Some(low) = up.iter().position(|&u| !u) else {
        return vec![(0, n)];
    };
    let mut runs = Vec::new();
    let mut m = 0;
    while m < n {
        let i = (low + m) % n;
        if up[i] {
            let first = i;
            let mut len = 0;
            while m < n && up[(low + m) % n] {
                len += 1;
                m += 1;
            }
            runs.push((first, len));
        } else {
            m += 1;
        }
    }
    runs
}
