//! The check as a state machine fed one line at a time
//! ([`CheckWriter`]): continuity, bounds, collisions and support from the
//! replayed moves, and the entry points [`check`] and [`check_reader`].

use crate::bead::Bead;
use crate::blocks::Blocks;
use crate::geom::{larger, len2, minmax, overlap_fraction, smaller};
use crate::grid::{settle, BeadGrid};
use crate::parse::{Diagnostic, Line, LineParser};
use crate::replay::{Event, Move, Replayer};
use crate::report::Report;
use crate::support::{follow_support, search_support, Query, Recent, Scratch, Walk};
use crate::tops::TopGrid;
use crate::verdict::verdict;
use crate::CheckConfig;

const EPS_E: f64 = 1e-7;

/// Checks a G-code text. Never panics, whatever the input.
pub fn check(text: &str, cfg: &CheckConfig) -> Report {
    check_with(text, cfg, Walk::Auto)
}

fn check_with(text: &str, cfg: &CheckConfig, walk: Walk) -> Report {
    let mut w = CheckWriter::new(cfg);
    w.checker.walk = walk;
    w.feed(text.as_bytes());
    w.finish()
}

/// [`check`] with the support always found by the full search, never by
/// following the bead below (`follow_support`), and the full search
/// always classifying every bead near the middle: the reference the
/// tests hold the fast path to. The two give the same report.
#[doc(hidden)]
pub fn check_exhaustive(text: &str, cfg: &CheckConfig) -> Report {
    check_with(text, cfg, Walk::Plain)
}

/// [`check_exhaustive`], but with every full search asking blocks of
/// beads however few the beads (`search_pruned`): the tests hold the two
/// to the same report, also on designs too coarse for [`check`] to prune.
#[doc(hidden)]
pub fn check_pruned(text: &str, cfg: &CheckConfig) -> Report {
    check_with(text, cfg, Walk::Pruned)
}

/// Checks G-code read line by line from `input`, holding no more of the
/// text than one line: for files too large to read into memory. Bytes that
/// are not UTF-8 are replaced, as by `String::from_utf8_lossy`.
pub fn check_reader<R: std::io::BufRead>(
    mut input: R,
    cfg: &CheckConfig,
) -> std::io::Result<Report> {
    let mut w = CheckWriter::new(cfg);
    std::io::copy(&mut input, &mut w)?;
    Ok(w.finish())
}

/// Checks G-code as it is written: an `io::Write` that feeds each complete
/// line to the check, so a writer can verify its output in the same pass
/// without keeping it. [`CheckWriter::finish`] gives the report.
pub struct CheckWriter<'a> {
    checker: Checker<'a>,
    partial: Vec<u8>,
}

impl<'a> CheckWriter<'a> {
    /// A check with `cfg`, fed by writing to it.
    pub fn new(cfg: &'a CheckConfig) -> Self {
        Self::with_capacity(cfg, 0)
    }

    /// A check with `cfg` of G-code of about `moves` moves (a writer
    /// knows how many it writes): the per-bead arrays are sized for them
    /// at once instead of growing by doubling, which at millions of moves
    /// holds the old and the new array at once and leaves up to half the
    /// last one unused. More moves than that are fine.
    pub fn with_capacity(cfg: &'a CheckConfig, moves: usize) -> Self {
        let mut checker = Checker::new(cfg);
        checker.reserve(moves);
        CheckWriter {
            checker,
            partial: Vec::new(),
        }
    }

    /// The report on everything written (a last line without a newline
    /// included).
    pub fn finish(mut self) -> Report {
        if !self.partial.is_empty() {
            self.checker.bytes(&self.partial);
        }
        self.checker.finish()
    }

    /// Feeds every complete line of `buf` (after what was left over from
    /// the last write) and keeps the rest.
    fn feed(&mut self, buf: &[u8]) {
        let mut start = 0;
        for nl in memchr::memchr_iter(b'\n', buf) {
            if self.partial.is_empty() {
                self.checker.bytes(&buf[start..nl]);
            } else {
                self.partial.extend_from_slice(&buf[start..nl]);
                self.checker.bytes(&self.partial);
                self.partial.clear();
            }
            start = nl + 1;
        }
        self.partial.extend_from_slice(&buf[start..]);
    }
}

impl std::io::Write for CheckWriter<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        self.feed(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// A count whose occurrences only count if an extrusion follows them
/// (travel, pauses and collisions between two beads, not after the last).
#[derive(Clone, Copy)]
enum Deferred {
    Travel,
    Pause,
    Nozzle,
    Carriage,
}

/// The check as a state machine fed one line at a time, in one pass: what
/// happens after the first bead is held back until the next bead proves it
/// was not after the last one.
struct Checker<'a> {
    cfg: &'a CheckConfig,
    parser: LineParser,
    line: Line,
    replayer: Replayer,
    diags: Vec<Diagnostic>,
    r: Report,
    /// An extruding move has been seen.
    started: bool,
    in_run: bool,
    pending: Vec<(Deferred, usize, f64)>,
    beads: Vec<Bead>,
    grid: BeadGrid,
    /// Bounds of blocks of consecutive beads, for the full search.
    blocks: Blocks,
    scratch: Scratch,
    s: f64,
    top_z: f64,
    lo: [f64; 3],
    hi: [f64; 3],
    layer_heights: Vec<f64>,
    /// Clay tops of the beads laid more than 2 w_max of path back, in
    /// finer cells, for the support's fast path (`follow_support`).
    support_tops: TopGrid,
    /// Beads `..support_settled` are in `support_tops`.
    support_settled: usize,
    /// The beads laid since (their lowest point, the path's turning).
    recent: Recent,
    /// The bead the last bead rests on.
    prev_support: Option<u32>,
    /// Offset / layer height of the steepest overhang so far, and a ratio
    /// just under the overhang limit's.
    steepest: f64,
    overhang_near: f64,
    /// How supports are found (tests compare the ways).
    walk: Walk,
}

impl<'a> Checker<'a> {
    fn new(cfg: &'a CheckConfig) -> Self {
        Checker {
            cfg,
            parser: LineParser::default(),
            line: Line::empty(),
            replayer: Replayer::default(),
            diags: Vec::new(),
            r: Report::default(),
            started: false,
            in_run: false,
            pending: Vec::new(),
            beads: Vec::new(),
            grid: BeadGrid::new(cfg),
            blocks: Blocks::default(),
            scratch: Scratch::default(),
            s: 0.0,
            top_z: f64::MIN,
            lo: [f64::MAX; 3],
            hi: [f64::MIN; 3],
            layer_heights: Vec::new(),
            support_tops: TopGrid::new([cfg.build_volume[0], cfg.build_volume[1]], 2.0),
            support_settled: 0,
            recent: Recent::default(),
            prev_support: None,
            steepest: f64::NEG_INFINITY,
            overhang_near: 0.999
                * (cfg.max_overhang_deg + cfg.overhang_tolerance_deg)
                    .to_radians()
                    .tan(),
            walk: Walk::Auto,
        }
    }

    /// Room for `moves` beads in every per-bead array, as far as memory
    /// allows (an array that gets none grows as it would have). The bead
    /// lists grow as they go: they hold a run of beads an entry, from
    /// 9 entries a bead (long beads across many cells) down to 0.04
    /// (3 million samples), too wide a range to guess.
    fn reserve(&mut self, moves: usize) {
        // A failed reservation only leaves the growing to `push`.
        let _ = self.beads.try_reserve_exact(moves);
        let _ = self.layer_heights.try_reserve_exact(moves);
        self.blocks.reserve(moves);
    }

    /// A line as bytes, without its `\n`: a `\r` before it is dropped.
    fn bytes(&mut self, mut raw: &[u8]) {
        if raw.last() == Some(&b'\r') {
            raw = &raw[..raw.len() - 1];
        }
        self.r.lines += 1;
        let n = self.r.lines;
        if !self
            .parser
            .parse_bytes(raw, n, &mut self.diags, &mut self.line)
        {
            return;
        }
        match self.replayer.feed(&self.line, &mut self.diags) {
            Some(Event::Pause(line)) if self.started => {
                self.pending.push((Deferred::Pause, line, 0.0));
                self.in_run = false;
            }
            Some(Event::Move(m)) => self.step(&m),
            Some(Event::Pause(_)) | None => {}
        }
    }

    fn defer_or_add(&mut self, extruding: bool, kind: Deferred, line: usize, v: f64) {
        if extruding {
            self.count(kind).add(line, v);
        } else {
            self.pending.push((kind, line, v));
        }
    }

    fn count(&mut self, kind: Deferred) -> &mut crate::report::Count {
        match kind {
            Deferred::Travel => &mut self.r.travel_moves,
            Deferred::Pause => &mut self.r.pauses,
            Deferred::Nozzle => &mut self.r.nozzle_collisions,
            Deferred::Carriage => &mut self.r.carriage_collisions,
        }
    }

    fn step(&mut self, m: &Move) {
        let cfg = self.cfg;
        let is_extruding = m.de > EPS_E;
        let len = m.length();
        // Continuity.
        self.r.moves += 1;
        if m.de < -EPS_E {
            if self.started {
                self.r.retractions.add(m.line, -m.de);
            }
            self.in_run = false;
        } else if is_extruding {
            self.started = true;
            // Whatever happened since the last bead was between beads.
            for (kind, line, v) in std::mem::take(&mut self.pending) {
                self.count(kind).add(line, v);
            }
            self.r.extruding_moves += 1;
            if len == 0.0 {
                self.r.extrusion_without_motion.add(m.line, m.de);
            }
            if !self.in_run {
                self.r.extrusion_runs += 1;
                if self.r.run_starts.len() < 20 {
                    self.r.run_starts.push(m.line);
                }
            }
            self.in_run = true;
        } else if len > 0.0 {
            if self.started {
                self.pending.push((Deferred::Travel, m.line, len));
            }
            self.in_run = false;
        }
        // Bounds.
        let out =
            m.to.iter()
                .zip(cfg.build_volume)
                .fold(0.0f64, |o, (&v, lim)| larger(larger(o, -v), v - lim));
        if out > 1e-3 {
            self.r.out_of_bounds.add(m.line, out);
        }

        // Deposition replay: support and collisions.
        let s_start = self.s;
        self.s += len;
        if m.feed > 0.0 {
            self.r.time_min += len / m.feed;
        }
        if !self.started {
            return;
        }
        let recent_nozzle = cfg.nozzle_radius + cfg.width_max;
        let reach = cfg.nozzle_radius + cfg.width_max / 2.0;
        // Collisions at points every r/2 mm of path (at most 200 a move).
        let every = (cfg.nozzle_radius / 2.0).max(0.5);
        // Path distances are ≥ 0, where truncation is the floor (and no
        // library call).
        let floor = |v: f64| (v as i64) as f64;
        let (first, last) = (floor(s_start / every) + 1.0, floor(self.s / every));
        let probes = (last - first + 1.0).clamp(0.0, 200.0) as usize;
        for k in 0..probes {
            let t = if probes < 200 {
                ((first + k as f64) * every - s_start) / len
            } else {
                (k + 1) as f64 / probes as f64
            };
            let p = [
                m.from[0] + t * (m.to[0] - m.from[0]),
                m.from[1] + t * (m.to[1] - m.from[1]),
                m.from[2] + t * (m.to[2] - m.from[2]),
            ];
            let sp = s_start + t * len;
            // Beads the nozzle has left behind count for collisions.
            self.grid
                .settle(&self.beads, |b| b.s_end <= sp - recent_nozzle);
            if self.top_z > p[2] + cfg.nozzle_height + cfg.collision_tolerance_mm {
                let v = self.top_z - p[2] - cfg.nozzle_height;
                self.defer_or_add(is_extruding, Deferred::Carriage, m.line, v);
            }
            let mut worst: f64 = 0.0;
            let zlo = p[2] + cfg.collision_tolerance_mm;
            let beads = &self.beads;
            self.grid
                .settled_near(beads, p, reach, zlo, p[2] + cfg.nozzle_height, |id| {
                    let b = &beads[id as usize];
                    if b.s_end > sp - recent_nozzle {
                        return;
                    }
                    let (d, z, _) = b.closest(p);
                    if z > zlo && d < cfg.nozzle_radius + b.width() / 2.0 {
                        worst = worst.max(z - p[2]);
                    }
                });
            if worst > 0.0 {
                self.defer_or_add(is_extruding, Deferred::Nozzle, m.line, worst);
            }
        }
        if !is_extruding || len == 0.0 {
            return;
        }
        self.bead(m, len, s_start);
    }

    /// Support analysis of an extruding move, then its bead joins the clay.
    fn bead(&mut self, m: &Move, len: f64, s_start: f64) {
        let cfg = self.cfg;
        let s = self.s;
        let Checker {
            r,
            beads,
            grid,
            blocks,
            scratch,
            top_z,
            lo,
            hi,
            layer_heights,
            support_tops,
            support_settled,
            recent,
            prev_support,
            walk,
            steepest,
            overhang_near,
            ..
        } = self;
        r.path_length_mm += len;
        let volume = m.de / cfg.e_per_mm3;
        r.volume_ml += volume / 1000.0;
        for p in [m.from, m.to] {
            for a in 0..3 {
                lo[a] = smaller(lo[a], p[a]);
                hi[a] = larger(hi[a], p[a]);
            }
        }
        if r.first_layer_z.is_none() {
            r.first_layer_z = Some(m.from[2].max(m.to[2]));
        }
        let rise = (m.to[2] - m.from[2]).abs();
        // The plan vector and length, once for every use below.
        let d = [m.to[0] - m.from[0], m.to[1] - m.from[1]];
        let xy = len2(d[0], d[1]);
        let step = xy <= 2.0 * rise;
        let id = beads.len() as u32;
        let mut width = cfg.width_min;
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
        if step {
            r.support.steps += 1;
        } else {
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
            let fast = prev_support
                .filter(|_| {
                    *walk == Walk::Auto
                        && (recent.clear_of(m, mid, cfg.min_layer_mm, turn, xy)
                            || q.none_below(&beads[*support_settled..], *support_settled))
                })
                .and_then(|j| follow_support(beads, *support_settled, support_tops, j, &q));
            r.support.beads += 1;
            let support = if fast.is_some() {
                fast
            } else {
                let (support, double) = search_support(beads, grid, blocks, scratch, &q, *walk);
                if double {
                    r.support.double_deposition.add(m.line, 0.0);
                }
                support
            };
            *prev_support = support.map(|c| c.id);
            let (dz, overlap, offset) = match support {
                Some(c) => {
                    let dz = mid[2] - c.z;
                    width = volume / (len * dz);
                    (dz, overlap_fraction(width, c.width, c.d), c.d)
                }
                None if mid[2] <= cfg.first_layer_max_mm => {
                    r.support.on_bed += 1;
                    width = volume / (len * mid[2].max(1e-6));
                    (mid[2], 1.0, 0.0)
                }
                None => {
                    r.support.unsupported.add(m.line, mid[2]);
                    (f64::NAN, f64::NAN, 0.0)
                }
            };
            if dz.is_finite() {
                layer_heights.push(dz);
                minmax(&mut r.support.layer_height, dz, m.line);
                minmax(&mut r.support.width, width, m.line);
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
                if overlap < cfg.overlap_min - 1e-9 {
                    r.support.under_min.add(m.line, cfg.overlap_min - overlap);
                }
                if overlap < cfg.overlap_target - 1e-6 {
                    r.support.under_target += 1;
                }
                // The angle (an arc tangent) only when it can matter: a
                // new steepest or one near the limit.
                let ratio = offset / dz;
                if !(ratio <= *steepest && ratio < *overhang_near) {
                    *steepest = steepest.max(ratio);
                    let angle = ratio.atan().to_degrees();
                    if r.support.max_overhang_deg.is_none_or(|(v, _)| angle > v) {
                        r.support.max_overhang_deg = Some((angle, m.line));
                    }
                    if angle > cfg.max_overhang_deg + cfg.overhang_tolerance_deg {
                        r.support.overhang.add(m.line, angle);
                    }
                }
            }
        }
        let bead = Bead::new(
            m.from,
            m.to,
            if width.is_finite() {
                width.clamp(0.0, 1e3)
            } else {
                cfg.width_min
            },
            s,
            step,
        );
        grid.insert(&bead, id);
        let low = bead.from32[2].min(bead.to32[2]);
        let heading = (xy > 1e-9 && !step).then(|| [d[0] / xy, d[1] / xy]);
        recent.push(id, heading, s, low, turn);
        *top_z = top_z.max(m.from[2].max(m.to[2]));
        beads.push(bead);
    }

    fn finish(mut self) -> Report {
        let r = &mut self.r;
        let (lo, hi) = (self.lo, self.hi);
        if r.extruding_moves > 0 {
            r.size_mm = [hi[0] - lo[0], hi[1] - lo[1], hi[2].max(0.0)];
        }
        if !self.layer_heights.is_empty() {
            // The element a sort would put in the middle, in linear time
            // (a total order: the same value as sorting).
            let mid = self.layer_heights.len() / 2;
            let (_, &mut median, _) = self
                .layer_heights
                .select_nth_unstable_by(mid, f64::total_cmp);
            if median > 0.0 {
                r.layers = (hi[2] / median).round() as usize;
            }
        }
        self.diags.sort_by_key(|d| d.line);
        self.diags.truncate(50);
        r.diagnostics = self.diags;
        verdict(r, self.cfg);
        self.r
    }
}
