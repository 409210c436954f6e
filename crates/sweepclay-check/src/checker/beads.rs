//! Bead support: what each new bead rests on (the bed, a bead below,
//! clay at its own height, or air), its width and layer height, its
//! overlap and overhang, and the clay it adds (docs/CHECKER.md, "The bead
//! model", "Footprints", "Layer gaps").

use super::*;

/// At most this many of the run's last beads are asked whether a move
/// climbing from them lies on their fresh clay: work bounded per move.
const FRESH_BEADS: usize = 64;

/// A thin bead fails for its gap only beyond this many times the gap
/// under the beads before it (docs/CHECKER.md, "Layer gaps").
pub(super) const DEEP_GAP: f64 = 1.5;

/// Widths are read only from gaps of at least this many thinnest layers
/// (docs/CHECKER.md, "Numbers").
pub(super) const WIDTH_GAP_LAYERS: f64 = 2.0;

impl Checker<'_> {
    /// Support analysis of an extruding move, then its bead joins the clay.
    pub(super) fn bead(&mut self, m: &Move, len: f64, s_start: f64) {
        let cfg = self.cfg;
        let s = self.s;
        let volume = m.de / cfg.e_per_mm3;
        self.last_bead = (self.r.moves, m.line);
        if let Some(first) = self.unreplayed_since.take() {
            if self.unreplayed_inside.len() < MAX_UNREPLAYED {
                self.unreplayed_inside.push(first);
            }
        }
        if self.lead.print_run.is_none() {
            if let Some(run) = self.lead.runs.last_mut() {
                run.beads += 1;
                run.clay_mm3 += volume;
                run.last_line = m.line;
            }
        }
        let low_z = m.from[2].min(m.to[2]);
        if low_z < cfg.first_layer_min_mm {
            self.record(
                Finding::IntoBed,
                m.line,
                cfg.first_layer_min_mm - low_z,
                false,
            );
        }
        // For each of WEAK_KINDS, whether it was judged, and if so the
        // bead's shortfall.
        let mut weak_bead: [Option<Option<f64>>; 3] = [None; 3];
        // What it rests on, if its support was sought, and the gap
        // above what it rests on.
        let mut rest = None;
        let mut rest_gap = f64::NAN;
        let Checker {
            r,
            beads,
            grid,
            blocks,
            scratch,
            top_z,
            layer_heights,
            support_tops,
            support_settled,
            recent,
            prev_support,
            bed_loop_top,
            walk,
            steepest,
            overhang_near,
            stretch,
            deep,
            prev_stub,
            prev_overlap,
            lead,
            bent_before,
            typical_gap,
            turn: pending_turn,
            last_width,
            ..
        } = self;
        // Its failures, recorded once the borrows below end (at most one
        // each of: no clay below, more clay
        // than fits).
        let mut held = [(Finding::Unsupported, 0.0); 5];
        let mut n_held = 0;
        let mut hold = |kind, v| {
            held[n_held] = (kind, v);
            n_held += 1;
        };
        r.path_length_mm += len;
        r.volume_ml += volume / 1000.0;
        let rise = (m.to[2] - m.from[2]).abs();
        // The plan vector and length, once for every use below.
        let d = [m.to[0] - m.from[0], m.to[1] - m.from[1]];
        let xy = len2(d[0], d[1]);
        let step = xy <= 2.0 * rise;
        let id = beads.len() as u32;
        let mut width = cfg.width_min;
        let mut height = 0.0;
        // The width its clay makes in the gap it fills, where that differs
        // from `width` (a ramp over the loop below, a film): what the
        // under-extrusion rule reads (docs/CHECKER.md, "Ramps").
        let mut flow_width = f64::NAN;
        // The least footprint it leaves: a film's, the clay it lies on.
        let mut footprint = 0.0f64;
        let horizon = s_start - 2.0 * cfg.width_max;
        settle(
            beads,
            support_settled,
            |b| b.s_end < horizon,
            |j, b| {
                support_tops.raise(b);
                recent.settle(j);
            },
        );
        let turn = if step {
            std::f64::consts::PI
        } else {
            recent.turn(d, xy, s_start)
        };
        // Clay no nozzle can lay along this bead: a cross-section beyond
        // OVERFLOW_SECTIONS widest beads of half their width in height
        // (E switched to relative half way, a lost G92).
        let section = volume / len.max(1e-9);
        let overflow = !step
            && section > crate::report::OVERFLOW_SECTIONS * 0.5 * cfg.width_max * cfg.width_max;
        if overflow {
            hold(Finding::ClayOverflow, section);
        }
        let mut on_clay = false;
        if step {
            r.support.steps += 1;
            let t = pending_turn.get_or_insert(Turn {
                line: m.line,
                clay: 0.0,
                rise: 0.0,
                length: 0.0,
                before: *last_width,
            });
            t.clay += volume;
            t.rise += rise;
            t.length += len;
        } else if *deep {
            let mid = [
                0.5 * (m.from[0] + m.to[0]),
                0.5 * (m.from[1] + m.to[1]),
                0.5 * (m.from[2] + m.to[2]),
            ];
            let q = Query {
                m,
                mid,
                s_start,
                cfg,
            };
            // The shortcut needs the clay of the last 2 w_max of path not to
            // be clay below: the bound of `clear_of` says so for most beads;
            // for the rest (reversals, drops) each such bead is asked.
            // The shortcuts: along the pass below (`prev_support`), or on
            // the bare bed (a first layer: nothing below to follow).
            // A ramp starting from a first layer laid at the tallest one
            // (Z 3.000) lies on that loop's clay, the bed under it, until
            // it has risen a thinnest layer over it.
            let near_bed = mid[2] <= cfg.first_layer_max_mm
                || bed_loop_top.is_some_and(|z| mid[2] < z + cfg.min_layer_mm);
            // The largest gap this bead's clay can stand in: as tall as
            // it would then be wide, with the widths' tolerance.
            let gap_limit = (section * (1.0 + WIDTH_TOLERANCE))
                .sqrt()
                .min(cfg.max_gap_mm);
            let fast = (*walk == Walk::Auto
                && (prev_support.is_some() || near_bed)
                && (recent.clear_of(m, mid, cfg.min_layer_mm, turn, xy)
                    || q.none_below(beads, *support_settled)))
            .then(|| match *prev_support {
                Some(j) => follow_support(
                    beads,
                    grid,
                    bent_before,
                    *support_settled,
                    support_tops,
                    j,
                    &q,
                )
                .map(Some),
                None => on_bare_bed(beads, grid, support_tops, &q).then_some(None),
            })
            .flatten();
            r.support.beads += 1;
            let (support, own) = match fast {
                Some(fast) => (fast, None),
                None => search_support(beads, grid, blocks, scratch, &q, *walk),
            };
            *prev_support = support.map(|c| c.id);
            if let Some(crate::support::Own {
                z: z_own,
                width: under,
            }) = own
            {
                // Clay at its own height under its middle: the bead is
                // pressed onto it. Its clay has the gap above that clay to
                // spread in, at most twice the widest bead wide.
                on_clay = true;
                r.support.on_clay += 1;
                // A film on a bead is part of that bead's top, as wide
                // (docs/CHECKER.md, "Films").
                footprint = under;
                let gap = (mid[2] - z_own).max(0.0);
                let room = len * gap * (1.0 + WIDTH_TOLERANCE) * cfg.width_max;
                // The gap at the bead's two ends, over the clay under its
                // middle: a ramp's rise is read the same whether it is one
                // 63 mm move or thirty 2 mm ones (docs/CHECKER.md,
                // "Cutting").
                // Clay at or above the middle leaves no gap there; how far
                // above is not asked (the pruned walk stops at the first
                // such clay), so neither end reads it.
                let z_under = z_own.min(mid[2]);
                let (gap_from, gap_to) =
                    ((m.from[2] - z_under).max(0.0), (m.to[2] - z_under).max(0.0));
                if stretch.length == 0.0 {
                    stretch.first_line = m.line;
                    stretch.first_gap = gap_from;
                } else if gap_from < stretch.last_gap - RAMP_SLACK_MM
                    || m.from[2] < stretch.last_z - RAMP_SLACK_MM
                {
                    stretch.falls = true;
                }
                if gap_to < gap_from - RAMP_SLACK_MM {
                    stretch.falls = true;
                }
                stretch.last_gap = gap_to;
                stretch.last_z = m.to[2];
                stretch.length += len;
                stretch.volume += volume;
                stretch.excess += (volume - room).max(0.0);
                if gap > 0.05 {
                    width = volume / (len * gap);
                    height = gap;
                    // A gap thinner than the thinnest layer gives no width
                    // a person could measure on the print (287 mm for a
                    // 75 mm pot): such a reading is left out of the
                    // report's figures.
                    if gap >= cfg.min_layer_mm {
                        minmax(&mut r.support.width, width, m.line);
                        if width > cfg.width_max * (1.0 + WIDTH_TOLERANCE) {
                            r.support.wide.add(m.line, width);
                        }
                    }
                } else {
                    // No gap to measure it by: as wide as its clay would
                    // be on the thinnest layer, at most the widest bead (a
                    // move carrying next to no clay reads as under-extruded).
                    width = (volume / (len * cfg.min_layer_mm)).min(cfg.width_max);
                    // A ramp climbing from the clay under it: its clay
                    // follows the gap it fills, its first millimetres a few
                    // percent of a bead because that is all the gap holds.
                    // A flat move (a floor's join across the rings) has
                    // no gap growing under it to read.
                    if m.to[2] > m.from[2] && gap > 0.0 {
                        flow_width = volume / (len * gap);
                    }
                }
            }
            // A move climbing from the run's fresh clay across its top (a
            // spiral's first move from a wider first loop out to its wall)
            // lies on clay no search counts (the last 2 w_max of path is
            // the tip's own): its clay is read against the gap over it,
            // as a ramp's is (docs/CHECKER.md, "Ramps").
            if !on_clay && support.is_none() && m.to[2] > m.from[2] {
                let fresh = (0..id as usize)
                    .rev()
                    .take(FRESH_BEADS)
                    .map_while(|k| beads.get(k))
                    .take_while(|b| b.s_end > s_start - 2.0 * cfg.width_max)
                    .filter(|b| !b.step && !crate::support::is_smear(b.width(), cfg))
                    .find_map(|b| {
                        let (d, z, _) = b.closest(mid);
                        let gap = mid[2] - z;
                        (d < b.width() / 2.0 && (0.0..cfg.min_layer_mm).contains(&gap))
                            .then_some(gap)
                    });
                if let Some(gap) = fresh {
                    flow_width = volume / (len * gap.max(crate::support::SAME_HEIGHT_MM));
                }
            }
            rest = Some(match support {
                _ if on_clay => Rest::Clay,
                Some(c) => Rest::Bead(c.id),
                None if near_bed => Rest::Bed,
                None => Rest::Air,
            });
            *bed_loop_top = match rest {
                Some(Rest::Bed) if mid[2] <= cfg.first_layer_max_mm => Some(m.from[2].max(m.to[2])),
                Some(Rest::Bed) => *bed_loop_top,
                _ => None,
            };
            let (dz, overlap, offset, below_h) = match support {
                _ if on_clay => (f64::NAN, f64::NAN, 0.0, 0.0),
                Some(c) => {
                    let dz = mid[2] - c.z;
                    width = volume / (len * dz);
                    // Taller than wide over the clay it rests on: the
                    // bead does not stand (docs/CHECKER.md, "Layer gaps").
                    // A stub (a blob joined to the bead before) carries no
                    // bead of its own; a bead climbing
                    // a thinnest layer or more climbs from the clay it
                    // was just laid on (a finishing pass, a sloping edge).
                    // A thin bead between neighbours at its height (a
                    // floor's narrowed tail) fails only over a gap well
                    // beyond the layers laid so far: clay two layers down;
                    // a thin coil with none beside it fails over any gap
                    // taller than it is wide.
                    if rise < cfg.min_layer_mm {
                        let thin = width < cfg.width_min * (1.0 - WIDTH_TOLERANCE);
                        let deep = *typical_gap == 0.0 || dz > DEEP_GAP * *typical_gap;
                        let over = dz > gap_limit
                            // A smear is the under-extrusion rule's, not a
                            // bead that stands or falls.
                            && !crate::support::is_smear(width, cfg)
                            && (!thin || deep || !crate::support::flanked(beads, grid, &q))
                            && !crate::support::clay_within_gap(beads, grid, &q, gap_limit);
                        if !over {
                            *typical_gap = if *typical_gap == 0.0 {
                                dz
                            } else {
                                0.95 * *typical_gap + 0.05 * dz
                            };
                        }
                        weak_bead[1] = Some(over.then_some(dz));
                    }
                    // A bead thinner than the one below it and wider (a
                    // vase's first turn rising from its flat loop), or
                    // wider than the widest bead, is pressed onto it and
                    // spreads over its shoulders: judged by its core, a
                    // bead as wide as the one it is pressed on.
                    let thinner = dz < 0.95 * c.height;
                    let pressed = width > c.width && thinner;
                    let core = if width > cfg.width_max || pressed {
                        width.min(c.width.max(cfg.width_min))
                    } else {
                        width
                    };
                    // Its lean is how far its edge passes the edge of the
                    // bead below, never more than the centrelines' offset: a
                    // narrower bead leans only where it passes that bead's
                    // edge. One thinner than that bead is as wide as its clay
                    // would lie on a layer as tall (its angle is taken over
                    // that height, below), and no narrower than the nozzle
                    // lays: clay squeezed wider is pressed out, not a lean
                    // (docs/CHECKER.md, "Overhangs").
                    let lean_width = if thinner {
                        core.min((volume / (len * c.height.max(1e-9))).max(cfg.width_min))
                    } else {
                        core
                    };
                    let offset = c.d.min((c.d + 0.5 * (lean_width - c.width)).max(0.0));
                    (dz, overlap_fraction(core, c.width, c.d), offset, c.height)
                }
                None if near_bed => {
                    r.support.on_bed += 1;
                    width = volume / (len * mid[2].max(1e-6));
                    (mid[2], 1.0, 0.0, 0.0)
                }
                None => {
                    hold(Finding::Unsupported, mid[2]);
                    (f64::NAN, f64::NAN, 0.0, 0.0)
                }
            };
            rest_gap = dz;
            // A bead into the bed has no layer height or width to speak of.
            if dz.is_finite() && low_z >= cfg.first_layer_min_mm {
                height = dz;
                layer_heights.add(dz);
                minmax(&mut r.support.layer_height, dz, m.line);
                // A gap under two thinnest layers (a vase ramp's first
                // millimetres) gives a width no one could measure on the
                // print (24 mm for 4.5 mm lines): left out of the figures.
                // Nor does clay that cannot fit under the nozzle (its
                // own failure): a 23 m bead is no figure.
                let measurable = dz >= WIDTH_GAP_LAYERS * cfg.min_layer_mm && !overflow;
                if measurable {
                    minmax(&mut r.support.width, width, m.line);
                }
                if width > cfg.width_max * (1.0 + WIDTH_TOLERANCE) {
                    if measurable {
                        r.support.wide.add(m.line, width);
                    }
                } else if width < cfg.width_min * (1.0 - WIDTH_TOLERANCE) {
                    r.support.thin.add(m.line, cfg.width_min - width);
                }
                {
                    let bin = if overlap < 0.5 {
                        0
                    } else if overlap < 0.6 {
                        1
                    } else if overlap < cfg.overlap_target - 1e-9 {
                        2
                    } else if overlap < 0.9 {
                        3
                    } else {
                        4
                    };
                    r.support.overlap_histogram[bin] += 1;
                    if r.support.min_overlap.is_none_or(|(v, _)| overlap < v) {
                        r.support.min_overlap = Some((overlap, m.line));
                    }
                    // A bead much shorter than it is wide (a slicer's stub at a
                    // layer change) is a blob joined to the bead before: it is
                    // as well supported as that bead, if that one is no stub.
                    let stub = xy < 0.25 * cfg.width_min;
                    let overlap = if stub && !*prev_stub {
                        overlap.max(*prev_overlap)
                    } else {
                        overlap
                    };
                    *prev_stub = stub;
                    *prev_overlap = overlap;
                    weak_bead[0] = Some(
                        (overlap < cfg.overlap_min - 1e-9).then_some(cfg.overlap_min - overlap),
                    );
                    if overlap < cfg.overlap_target - 1e-6 {
                        r.support.under_target += 1;
                    }
                    // The angle against the bead's real geometry: a bead
                    // thinner than the one it rests on leans over that bead's
                    // height, not over its own (a finishing turn 0.3 mm up is
                    // no 80° overhang). An arc tangent only when it can
                    // matter: a new steepest or one near the limit.
                    let ratio = offset / dz.max(below_h);
                    // Judged, and within the limit unless found past it.
                    weak_bead[2] = Some(None);
                    if !(ratio <= *steepest && ratio < *overhang_near) {
                        *steepest = steepest.max(ratio);
                        let angle = ratio.atan().to_degrees();
                        if r.support.max_overhang_deg.is_none_or(|(v, _)| angle > v) {
                            r.support.max_overhang_deg = Some((angle, m.line));
                        }
                        if angle > cfg.max_overhang_deg + cfg.overhang_tolerance_deg {
                            // Climbed to a bead beside it: judged by the
                            // gentlest full-height bead under its middle.
                            let lean = crate::support::gentlest_lean(beads, grid, &q, gap_limit);
                            let angle = angle.min(lean.atan().to_degrees());
                            if angle > cfg.max_overhang_deg + cfg.overhang_tolerance_deg {
                                weak_bead[2] = Some(Some(angle));
                            }
                        }
                    }
                }
            }
        }
        let mut pile = None;
        // The steps before this bead make the end of its layer: they need
        // the half disc of a bead as wide as the wider of the two they join
        // (a thin top-edge bead after a step still ends a wide layer), as
        // high as they climbed.
        if !step {
            let w = if width.is_finite() {
                width.clamp(cfg.width_min, cfg.width_max)
            } else {
                cfg.width_min
            };
            if let Some(t) = pending_turn.take() {
                let w = w.max(t.before);
                let need = std::f64::consts::PI / 8.0 * w * w * t.rise;
                r.support.turn_clay_mm3[0] += t.clay;
                r.support.turn_clay_mm3[1] += need;
                // Steep beads that carry the clay a millimetre of the bead
                // after them (a climb along a sloping top edge) lay a bead,
                // not a pile: only clay beyond both measures piles up.
                let per_mm = volume / len.max(1e-9);
                if t.clay > TURN_FACTOR * need && t.clay > TURN_FACTOR * per_mm * t.length {
                    pile = Some((t.line, t.clay / need));
                }
            }
            *last_width = w;
        }
        // Its footprint: no wider than the widest bead a nozzle can lay,
        // with the widths' tolerance. Clay past that has no room under the
        // nozzle and goes up, not out (docs/CHECKER.md, "Clay on clay"): a
        // first turn pressed 0.3 mm over its flat loop is no 17.6 mm shelf
        // for the turn above to rest on ("Footprints").
        let mut bead = Bead::new(
            m.from,
            m.to,
            if width.is_finite() {
                width
                    .max(footprint)
                    .clamp(0.0, cfg.width_max * (1.0 + WIDTH_TOLERANCE))
            } else {
                cfg.width_min.max(footprint)
            },
            s,
            step,
        );
        bead.set_height(height);
        bead.bent = step || turn > BENT_RAD;
        let full = if *deep { grid.insert(&bead, id) } else { None };
        let low = bead.from32[2].min(bead.to32[2]);
        let heading = (xy > 1e-9 && !step).then(|| [d[0] / xy, d[1] / xy]);
        recent.push(id, heading, s, low, turn);
        // A purge in the air before the print is no clay the carriage can
        // hit (its clay falls off).
        let purge = rest == Some(Rest::Air) && lead.print_run.is_none();
        if !purge {
            *top_z = top_z.max(m.from[2].max(m.to[2]));
        }
        bent_before.push(bent_before.last().copied().unwrap_or(0) + u32::from(bead.bent));
        // The piece's size is kept as it goes: its first beads may be let
        // go before the end (docs/CHECKER.md, "Bounded memory").
        let bounds = match lead.runs.last_mut().filter(|_| lead.print_run.is_none()) {
            Some(run) => &mut run.bounds,
            None => &mut lead.after,
        };
        for p in [bead.from(), bead.to()] {
            for (a, v) in p.into_iter().enumerate() {
                bounds.0[a] = bounds.0[a].min(v);
                bounds.1[a] = bounds.1[a].max(v);
            }
        }
        beads.push(bead);
        // A stub (under a quarter of the narrowest bead in plan: where a
        // move was cut a hair from its end, its middle lies between two
        // beads below) ends a stretch only by climbing out of it onto a
        // bead a thinnest layer or more below: a ramp cut so was read as
        // three short stretches, none rising half a layer
        // (docs/CHECKER.md, "Cutting").
        let on_bead = matches!(rest, Some(Rest::Bead(_)));
        let stub = xy < 0.25 * cfg.width_min && !(on_bead && rest_gap >= cfg.min_layer_mm);
        if !on_clay && !step && !stub {
            self.close_stretch(on_bead.then_some(rest_gap));
        }
        for &(kind, v) in &held[..n_held] {
            self.record(kind, m.line, v, false);
        }
        if let Some(at) = full {
            self.cell_full(m.line, at);
        }
        for (k, judged) in weak_bead.into_iter().enumerate() {
            match judged {
                Some(Some(short)) => {
                    self.weak[k].length += xy;
                    self.weak[k].pending.push((m.line, short));
                    self.flush_weak(k);
                }
                Some(None) => {
                    self.weak[k].length = 0.0;
                    self.weak[k].pending.clear();
                }
                None => {}
            }
        }
        if let Some((line, ratio)) = pile {
            self.record(Finding::TurnPile, line, ratio, false);
        }
        // Less than a quarter of the narrowest bead's clay on a move that
        // is no climbing step: an under-extruded bead, unless nothing but
        // more of them follows (the final taper).
        let width = if flow_width.is_finite() {
            flow_width
        } else {
            width
        };
        if !step && width.is_finite() {
            let least = crate::report::UNDER_EXTRUDED * cfg.width_min;
            if width < least {
                self.under.push((m.line, width, len));
            } else {
                if !self.under.is_empty() {
                    // Flow is judged over a bead's length: a dip shorter
                    // than half `width_min` (a slicer's 0.3 mm layer-change
                    // move at 19 %), with the full beads beside it, over
                    // `width_min` of path; a longer one (a floor's 2.55 mm
                    // join at 5 %) is a flow drop (docs/CHECKER.md, "Short
                    // moves").
                    let dip: f64 = self.under.iter().map(|u| u.2).sum();
                    let clay: f64 = self.under.iter().map(|u| u.1 * u.2).sum();
                    let side = if self.full_width.is_finite() {
                        width.max(self.full_width)
                    } else {
                        width
                    };
                    let averaged = (clay + side * (cfg.width_min - dip)) / cfg.width_min;
                    let under = std::mem::take(&mut self.under);
                    if dip >= 0.5 * cfg.width_min || averaged < least {
                        for (line, w, _) in under {
                            self.record(Finding::UnderExtruded, line, w, false);
                        }
                    }
                }
                self.full_width = width;
            }
        }
        if self.lead.print_run.is_some() {
            return;
        }
        let lead = &mut self.lead;
        match (rest, lead.runs.last_mut()) {
            // Clay laid on an earlier run's bead: that run is the print's.
            (Some(Rest::Bead(j)), _) => {
                let k = lead.runs.partition_point(|r| r.first_bead <= j);
                self.decide(k.saturating_sub(1));
            }
            (Some(Rest::Air), Some(run)) => {
                run.air += 1;
                if lead.air.len() < MAX_HELD {
                    lead.air.push(id);
                }
            }
            (Some(Rest::Bed), Some(run)) => run.on_bed += 1,
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::testkit::*;

    /// A zig-zag wall of 10 layers whose pass 6, between x = 60 and 80,
    /// swerves `off` mm sideways; pass 7 runs straight back over the swerve.
    fn swerving_wall(off: f64) -> G {
        let mut g = G::new([50.0, 50.0, LAYER]);
        for k in 1..=10 {
            let z = LAYER * k as f64;
            let (x0, x1) = if k % 2 == 1 {
                (50.0, 90.0)
            } else {
                (90.0, 50.0)
            };
            if k > 1 {
                g.bead([x0, 50.0, z], W, LAYER);
            }
            if k == 6 {
                g.run([80.0, 50.0, z], W, LAYER);
                g.bead([79.0, 50.0 + off, z], W, LAYER);
                g.run([61.0, 50.0 + off, z], W, LAYER);
                g.bead([60.0, 50.0, z], W, LAYER);
            }
            g.run([x1, 50.0, z], W, LAYER);
        }
        g
    }

    #[test]
    fn a_pass_over_clay_two_layers_down_fails_for_its_layer_gap() {
        // Pass 6 swerves 6 mm off the wall (a bead with nothing below: its
        // own failure); pass 7 runs straight back over the swerve, where the
        // clay below it is pass 5's, two layers (2.4 mm) down: 3.2 mm beads
        // carrying 1.2 mm layers of clay cannot stand 2.4 mm tall. It used to
        // pass with a warning about thin beads.
        let r = verdict(&swerving_wall(6.0).out);
        fails_for(
            &r,
            "farther below than they are wide",
            &["no clay below", "overlapping the bead below", "overhang"],
        );
        let gap = &r.findings[Finding::LayerGap];
        assert!(gap.count >= 15, "{}", r.render());
        let (worst, _) = gap.worst.unwrap();
        assert!((worst - 2.0 * LAYER).abs() < 0.05, "{}", r.render());
        // The same wall with the swerve half a bead wide: pass 6 still under
        // pass 7 everywhere, no layer gap.
        let r = verdict(&swerving_wall(1.0).out);
        assert!(r.printable, "{}", r.render());
        assert_eq!(r.findings[Finding::LayerGap].count, 0);
    }

    #[test]
    fn unsupported_overhang_fails() {
        // Layer 6 shifted 5 mm sideways.
        let mut g = wall(5);
        let z = LAYER * 6.0;
        g.bead([90.0, 55.0, z], W, LAYER);
        g.run([50.0, 55.0, z], W, LAYER);
        let r = verdict(&g.out);
        assert!(!r.printable);
        assert!(
            r.findings[Finding::Unsupported].count + r.findings[Finding::UnderMinOverlap].count
                >= 30,
            "{}",
            r.render()
        );
        assert!(
            r.failures.iter().all(|f| f.contains("overhang")
                || f.contains("overlapping")
                || f.contains("no clay below")),
            "{}",
            r.render()
        );
    }

    #[test]
    fn a_narrow_bead_on_a_wide_one_leans_only_past_its_edge() {
        // Three 6 mm passes, then 3.2 mm beads 1.9 mm to the side: their
        // centrelines lean atan(1.9 / 1.2) = 57.7°, past the limit (every
        // move failed), but their edge passes the wide bead's by 0.5 mm:
        // atan(0.5 / 1.2) = 22.6°. The same passes on 3.2 mm passes still
        // fail.
        let passes = |first: f64| {
            let mut g = G::new([50.0, 50.0, LAYER]);
            for k in 1..=3 {
                let (z, x) = (LAYER * k as f64, if k % 2 == 1 { 90.0 } else { 50.0 });
                if k > 1 {
                    g.bead([g.at[0], 50.0, z], first, LAYER);
                }
                g.run([x, 50.0, z], first, LAYER);
            }
            g.bead([90.0, 50.0, 4.0 * LAYER], W, LAYER);
            g.bead([90.0, 51.9, 4.0 * LAYER], W, LAYER);
            g.run([50.0, 51.9, 4.0 * LAYER], W, LAYER);
            g.bead([50.0, 51.9, 5.0 * LAYER], W, LAYER);
            g.run([90.0, 51.9, 5.0 * LAYER], W, LAYER);
            verdict(&g.out)
        };
        let r = passes(6.0);
        assert!(r.printable, "{}", r.render());
        let (angle, _) = r.support.max_overhang_deg.unwrap();
        assert!((angle - 22.6).abs() < 1.0, "{angle}\n{}", r.render());
        assert!(!passes(W).printable);
    }

    #[test]
    fn a_move_across_the_loop_just_laid_is_read_against_its_gap() {
        // A 6 mm flat loop, then a 2 mm move out across its end to the
        // wall's line, climbing 0.1 mm with the clay of its gap
        // (PrusaSlicer's and Slic3r's first move from a wide first loop),
        // then the wall's spiral. The loop under that move was laid within
        // the last 2 w_max of path, so no search counts it: the move read
        // as a bead on the bed, 1.25 mm tall and 0.13 mm wide,
        // under-extruded. With a fifth of its gap's clay it still is.
        let wall = |share: f64| {
            // The loop and the wall share their angles, as a slicer's
            // vase does: each bead's middle lies over a bead of the loop.
            let (c, r, rw) = ((100.0, 100.0), 20.0, 22.0);
            let per = (std::f64::consts::TAU * rw).round();
            let at = |k: f64, r: f64| {
                let a = std::f64::consts::TAU * k / per;
                (c.0 + r * a.cos(), c.1 + r * a.sin())
            };
            let mut g = G::new([c.0 + r, c.1, LAYER]);
            for k in 1..=per as usize {
                let (x, y) = at(k as f64, r);
                g.bead([x, y, LAYER], 6.0, LAYER);
            }
            // Straight out to the wall's line, 2 mm: longer than a dip the
            // flow is averaged over.
            let (x, y) = at(0.0, rw);
            let start = LAYER + 0.1;
            g.bead([x, y, start], share * W, 0.05);
            for k in 1..=3 * per as usize {
                let (x, y) = at(k as f64, rw);
                g.bead([x, y, start + LAYER * k as f64 / per], W, LAYER);
            }
            verdict(&g.out)
        };
        let r = wall(1.0);
        assert!(r.printable, "{}", r.render());
        fails_for(&wall(0.2), "under-extruded", &[]);
    }

    #[test]
    fn a_thin_finishing_pass_offset_sideways_is_no_steep_overhang() {
        // A wall, then a last pass 0.4 mm up and 1.2 mm to the side: atan(1.2
        // / 0.4) is 72°, but the pass leans over the height of the bead it
        // rests on (atan(1.2 / 1.2) = 45°).
        let mut g = wall(6);
        let z = LAYER * 6.0 + 0.4;
        g.bead([50.0, 51.2, z], W, 0.4);
        g.run([90.0, 51.2, z], W, 0.4);
        let r = verdict(&g.out);
        assert!(r.printable, "{}", r.render());
        let (angle, _) = r.support.max_overhang_deg.unwrap();
        assert!(angle > 40.0 && angle < 50.0, "{angle}\n{}", r.render());
    }

    #[test]
    fn clay_that_cannot_fit_under_the_nozzle_fails() {
        // `M83` half way through an absolute-E file: each move's E, meant as
        // the total so far, is read as that move's clay (beads hundreds of
        // metres wide; it passed with a warning).
        let g = wall(10);
        let lines: Vec<&str> = g.out.lines().collect();
        let mid = lines.len() / 2;
        let text = format!(
            "{}\nM83\n{}\n",
            lines[..mid].join("\n"),
            lines[mid..].join("\n")
        );
        let r = verdict(&text);
        assert!(!r.printable);
        let c = &r.findings[Finding::ClayOverflow];
        assert!(
            c.count > 0 && c.first_line == Some(mid + 2),
            "{:?} {:?}",
            c,
            r.failures
        );
        // A wide bead pressed flat is no overflow: the clean wall passes.
        assert!(verdict(&g.out).printable);
    }

    #[test]
    fn a_first_bead_from_the_bed_fails_as_dragged() {
        // The first pass laid at Z=0: the nozzle drags on the bed.
        let mut g = G::new([50.0, 50.0, 0.0]);
        g.run([90.0, 50.0, 0.0], W, LAYER);
        for k in 1..=3 {
            let z = LAYER * k as f64;
            let (a, b) = if k % 2 == 1 {
                (90.0, 50.0)
            } else {
                (50.0, 90.0)
            };
            g.bead([a, 50.0, z], W, LAYER);
            g.run([b, 50.0, z], W, LAYER);
        }
        let r = verdict(&g.out);
        fails_for(
            &r,
            "into the bed",
            &["overlapping the bead below", "farther below"],
        );
        // Beads into the bed have no layer height or width to report.
        let [(lo, _), _] = r.support.layer_height.unwrap();
        assert!(lo > 0.0, "{}", r.render());
    }
}
