//! The check as a state machine fed one line at a time
//! ([`CheckWriter`]): continuity, bounds, collisions and support from the
//! replayed moves, and the entry points [`check`] and [`check_reader`].

use crate::bead::Bead;
use crate::blocks::Blocks;
use crate::collide;
use crate::geom::{larger, len2, minmax, overlap_fraction};
use crate::grid::{settle, BeadGrid};
use crate::parse::{Diagnostic, Line, LineParser};
use crate::replay::{Event, Move, Replayer};
use crate::report::{Finding, Report, Segment, TURN_FACTOR};
use crate::support::{follow_support, on_bare_bed, search_support, Query, Recent, Scratch, Walk};
use crate::tops::TopGrid;
use crate::verdict::verdict;
use crate::verdict::WIDTH_TOLERANCE;
use crate::CheckConfig;

const EPS_E: f64 = 1e-7;

/// A turn into a bead over this (10°) marks it bent (`Bead::bent`).
const BENT_RAD: f64 = std::f64::consts::PI / 18.0;

/// Lines longer than this (bytes) are not G-code any firmware reads (Marlin
/// takes 96): one diagnostic, and the line is skipped.
pub const MAX_LINE: usize = 4096;

/// Diagnostics kept in a report; the rest are counted.
const MAX_DIAGNOSTICS: usize = 50;

/// After this many failures the file is not printable beyond doubt: the
/// support and collision analysis stops (a diagnostic says where), so a
/// file whose clay piles up or leaves the bed still checks in linear time.
pub const MAX_FAILURES: usize = 10_000;

/// Runs before the print, and findings held back while it is not yet
/// known whether they are in it, at most.
const MAX_LEAD_RUNS: usize = 64;
const MAX_HELD: usize = 100_000;

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
    /// The partial line is over [`MAX_LINE`]: the rest of it is dropped.
    overlong: bool,
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
            overlong: false,
        }
    }

    /// The report on everything written (a last line without a newline
    /// included).
    pub fn finish(mut self) -> Report {
        if self.overlong {
            self.checker.overlong(&self.partial);
        } else if !self.partial.is_empty() {
            self.checker.bytes(&self.partial);
        }
        self.checker.finish()
    }

    /// Feeds every complete line of `buf` (after what was left over from
    /// the last write) and keeps the rest.
    fn feed(&mut self, buf: &[u8]) {
        let mut start = 0;
        for nl in memchr::memchr_iter(b'\n', buf) {
            if self.partial.is_empty() && !self.overlong {
                self.checker.bytes(&buf[start..nl]);
            } else {
                self.keep(&buf[start..nl]);
                if self.overlong {
                    self.checker.overlong(&self.partial);
                } else {
                    self.checker.bytes(&self.partial);
                }
                self.partial.clear();
                self.overlong = false;
            }
            start = nl + 1;
        }
        self.keep(&buf[start..]);
    }

    /// Keeps the start of a line that goes on in the next write, up to
    /// [`MAX_LINE`] bytes (the command before a long comment is in them):
    /// memory never grows with a line's length.
    fn keep(&mut self, part: &[u8]) {
        let room = MAX_LINE.saturating_sub(self.partial.len());
        if part.len() > room {
            self.overlong = true;
        }
        self.partial
            .extend_from_slice(&part[..part.len().min(room)]);
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

/// A finding held back while the checker does not yet know whether it is
/// in the print or in the start code: `run` is the run it belongs to, or,
/// with `gap`, the run it comes before.
struct Held {
    run: usize,
    gap: bool,
    kind: Finding,
    line: usize,
    v: f64,
}

/// An extrusion run before the print is known to have begun.
struct LeadRun {
    first_bead: u32,
    line: usize,
    last_line: usize,
    /// Moves replayed before it.
    moves_before: usize,
    /// Height of its first bead.
    z: f64,
    clay_mm3: f64,
    beads: usize,
    /// Beads with nothing under them and far from the bed: a purge in the
    /// air.
    air: usize,
    /// Beads resting on the bed.
    on_bed: usize,
}

/// Where the print begins (docs/CHECKER.md, "Start and end code"): the
/// first run that clay is laid on. Runs before it that nothing rests on
/// (a skirt or purge line on the bed, a purge in the air, a stationary
/// prime) are start code. Until a bead rests on an earlier run, what the
/// runs so far did is held here.
#[derive(Default)]
struct Lead {
    /// The print's first run, once known.
    print_run: Option<usize>,
    runs: Vec<LeadRun>,
    held: Vec<Held>,
    /// Beads of the air purges (their clay falls off; it is no obstacle).
    air: Vec<u32>,
    /// What the start code holds, once decided.
    start: Segment,
}

/// What a bead was found to rest on.
#[derive(Clone, Copy, PartialEq)]
enum Rest {
    /// An earlier bead (its index).
    Bead(u32),
    /// Clay at its own height (it is pressed onto it).
    Clay,
    /// The bed.
    Bed,
    /// Nothing, far from the bed: a purge in the air, or a fault.
    Air,
}

/// Consecutive beads overlapping the bead below by less than the least
/// overlap, resting over a layer gap, or leaning past the overhang limit
/// ([`WEAK_KINDS`]). Shorter in all than [`Checker::weak_length`], they
/// are held up by the clay on either side (a slicer's seam bead a
/// millimetre long, the end of a pass over the slope the pass below
/// climbed); longer, each is a failure (docs/CHECKER.md, "Overlap",
/// "Layer gaps", "Overhangs").
#[derive(Default)]
struct Weak {
    /// Their length in plan (mm).
    length: f64,
    /// The beads not yet recorded: line and value.
    pending: Vec<(usize, f64)>,
}

/// The findings judged by stretches of [`Weak`] beads.
const WEAK_KINDS: [Finding; 3] = [
    Finding::UnderMinOverlap,
    Finding::LayerGap,
    Finding::Overhang,
];

/// A thin bead fails for its gap only beyond this many times the gap
/// under the beads before it (docs/CHECKER.md, "Layer gaps").
const DEEP_GAP: f64 = 1.5;

/// Widths are read only from gaps of at least this many thinnest layers
/// (docs/CHECKER.md, "Numbers").
const WIDTH_GAP_LAYERS: f64 = 2.0;

/// How much a ramp's gap or height may dip from one bead to the next
/// (rounding in the file) and still rise (mm).
const RAMP_SLACK_MM: f64 = 0.02;

/// A stretch of consecutive beads laid on clay at their own height: their
/// clay and the part of it that has no room (docs/CHECKER.md, "Clay on
/// clay").
#[derive(Default)]
struct Stretch {
    first_line: usize,
    length: f64,
    volume: f64,
    excess: f64,
    /// The gap at the start of its first bead and the end of its last
    /// (mm).
    first_gap: f64,
    last_gap: f64,
    /// Whether some bead of it lies lower than the one before, or on a
    /// thinner gap: then it is no ramp.
    falls: bool,
    /// Height of its last bead's end (mm).
    last_z: f64,
}

/// Turnaround steps since the last bead: the first one's line, their
/// clay (mm³) and rise (mm), and the width of the bead before them (mm).
struct Turn {
    line: usize,
    clay: f64,
    rise: f64,
    /// Path length of the steps (mm).
    length: f64,
    before: f64,
}

/// The check as a state machine fed one line at a time, in one pass: what
/// happens after a bead is held back until the next bead proves it was
/// not after the last one.
struct Checker<'a> {
    cfg: &'a CheckConfig,
    parser: LineParser,
    line: Line,
    replayer: Replayer,
    diags: Vec<Diagnostic>,
    diags_dropped: usize,
    r: Report,
    /// A bead has been laid.
    started: bool,
    in_run: bool,
    /// Runs begun so far (start code included).
    runs: usize,
    /// Findings that only count if a bead follows them (travel,
    /// retractions, pauses, blobs and collisions between two beads; after
    /// the last they are the end code), with their line and value.
    pending: Vec<(Finding, usize, f64)>,
    lead: Lead,
    /// Moves and line of the last bead, for the end code.
    last_bead: (usize, usize),
    /// Cross-section (mm²) under which a move whose E rises is a travel
    /// carrying a rounding residue of E, not a bead.
    min_area: f64,
    /// Failures recorded so far (held ones included), and whether beads
    /// are still analysed for support and collisions (see
    /// [`MAX_FAILURES`]).
    failures: usize,
    deep: bool,
    /// Turnaround steps since the last bead, judged with the bead after
    /// them (docs/CHECKER.md, "Turns").
    turn: Option<Turn>,
    /// The width of the last bead that was no step (mm, within
    /// [w_min, w_max]).
    last_width: f64,
    stretch: Stretch,
    /// The last judged bead was a stub, and its overlap.
    prev_stub: bool,
    prev_overlap: f64,
    /// Consecutive beads under the least overlap, and over a layer gap,
    /// not yet recorded.
    weak: [Weak; 3],
    /// Under-extruded moves since the last full bead (line, width, plan
    /// length): a failure once a bead follows them, the final taper if
    /// none does and they are no longer than two widest beads.
    under: Vec<(usize, f64, f64)>,
    /// The feedrate of the last move (mm/min): how long a dwell is
    /// against the bead it holds up.
    last_feed: f64,
    /// The gap under the beads judged for it so far, a running mean
    /// (mm; 0 before the first): the layers the print lays.
    typical_gap: f64,
    beads: Vec<Bead>,
    /// `bent_before[k + 1]`: how many of beads `0..=k` are bent (a
    /// prefix count, so "any bent bead in this stretch?" is two loads).
    bent_before: Vec<u32>,
    grid: BeadGrid,
    /// Bounds of blocks of consecutive beads, for the full search.
    blocks: Blocks,
    scratch: Scratch,
    s: f64,
    top_z: f64,
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
        let mut parser = LineParser::default();
        parser.firmware = cfg.firmware;
        let mut replayer = Replayer::default();
        replayer.firmware = cfg.firmware;
        // A round bed is a delta's: G28 takes it up to the top, centred.
        replayer.delta_home = cfg.bed_diameter.map(|_| {
            [
                cfg.bed_min[0] + 0.5 * cfg.build_volume[0],
                cfg.bed_min[1] + 0.5 * cfg.build_volume[1],
                cfg.bed_min[2] + cfg.build_volume[2],
            ]
        });
        Checker {
            cfg,
            parser,
            line: Line::empty(),
            replayer,
            diags: Vec::new(),
            diags_dropped: 0,
            r: Report::default(),
            started: false,
            in_run: false,
            runs: 0,
            pending: Vec::new(),
            lead: Lead::default(),
            last_bead: (0, 0),
            min_area: 0.01 * cfg.width_min * cfg.min_layer_mm,
            failures: 0,
            deep: true,
            turn: None,
            last_width: 0.0,
            stretch: Stretch::default(),
            prev_stub: false,
            prev_overlap: 0.0,
            weak: Default::default(),
            under: Vec::new(),
            last_feed: 0.0,
            typical_gap: 0.0,
            beads: Vec::new(),
            bent_before: vec![0],
            grid: BeadGrid::new(cfg),
            blocks: Blocks::default(),
            scratch: Scratch::default(),
            s: 0.0,
            top_z: f64::MIN,
            layer_heights: Vec::new(),
            support_tops: TopGrid::layered(
                [cfg.build_volume[0], cfg.build_volume[1]],
                2.0,
                cfg.min_layer_mm,
            ),
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
        let _ = self.bent_before.try_reserve_exact(moves);
        let _ = self.layer_heights.try_reserve_exact(moves);
        self.blocks.reserve(moves);
    }

    /// A line over [`MAX_LINE`] bytes, of which `head` is the start.
    /// Firmware drops a comment whatever its length, so a command before a
    /// `;` in the head is judged as it stands; a longer command is
    /// counted, noted and skipped (no firmware reads it).
    fn overlong(&mut self, head: &[u8]) {
        if let Some(cut) = memchr::memchr(b';', &head[..head.len().min(MAX_LINE)]) {
            return self.bytes(&head[..cut]);
        }
        self.r.lines += 1;
        self.diagnose(Diagnostic {
            line: self.r.lines,
            message: format!("line longer than {MAX_LINE} bytes skipped (no firmware reads it)"),
        });
    }

    fn diagnose(&mut self, d: Diagnostic) {
        self.diags.push(d);
        self.trim_diagnostics();
    }

    /// Keeps the first [`MAX_DIAGNOSTICS`], counting the rest.
    fn trim_diagnostics(&mut self) {
        if self.diags.len() > MAX_DIAGNOSTICS {
            self.diags_dropped += self.diags.len() - MAX_DIAGNOSTICS;
            self.diags.truncate(MAX_DIAGNOSTICS);
        }
    }

    /// A line as bytes, without its `\n`: a `\r` before it is dropped.
    fn bytes(&mut self, mut raw: &[u8]) {
        if raw.len() > MAX_LINE {
            return self.overlong(raw);
        }
        if raw.last() == Some(&b'\r') {
            raw = &raw[..raw.len() - 1];
        }
        self.r.lines += 1;
        let n = self.r.lines;
        let parsed = self
            .parser
            .parse_bytes(raw, n, &mut self.diags, &mut self.line);
        let event = if parsed {
            self.replayer.feed(&self.line, &mut self.diags)
        } else {
            None
        };
        self.trim_diagnostics();
        match event {
            Some(Event::Pause(line)) => {
                self.pending.push(((Finding::Pause), line, 0.0));
                self.in_run = false;
            }
            // A dwell is a pause when clay pools in it: longer than laying
            // a narrowest bead's length of clay takes at the feed in force
            // (docs/CHECKER.md, "Firmwares").
            Some(Event::Dwell(line, seconds)) => {
                let feed_mm_s = (self.last_feed / 60.0).max(1.0);
                if seconds > self.cfg.width_min / feed_mm_s {
                    self.pending.push(((Finding::Pause), line, seconds));
                    self.in_run = false;
                }
            }
            Some(Event::Retract(line)) => {
                self.pending.push(((Finding::Retraction), line, 0.0));
                self.in_run = false;
            }
            Some(Event::Move(m)) => {
                self.framed(m);
                // The rest of an arc's segments.
                while let Some(m) = self.replayer.next_segment() {
                    self.framed(m);
                }
            }
            None => {}
        }
    }

    /// A move into the box's own frame (its lowest corner at 0), then
    /// judged.
    fn framed(&mut self, mut m: crate::replay::Move) {
        if m.feed > 0.0 {
            self.last_feed = m.feed;
        }
        let b = self.cfg.bed_min;
        if b != [0.0; 3] {
            for p in [&mut m.from, &mut m.to] {
                for (v, o) in p.iter_mut().zip(b) {
                    *v -= o;
                }
            }
        }
        self.step(&m)
    }

    /// Records a finding: at once in the print, held back while it is not
    /// yet known whether the print has begun.
    fn record(&mut self, kind: Finding, line: usize, v: f64, gap: bool) {
        self.failures += 1;
        if self.lead.print_run.is_some() {
            self.r.findings[kind].add(line, v);
            return;
        }
        if self.lead.held.len() >= MAX_HELD {
            // So much before anything rests on anything: all of it is the
            // print.
            self.decide(0);
            self.r.findings[kind].add(line, v);
            return;
        }
        let run = if gap {
            self.runs
        } else {
            self.runs.saturating_sub(1)
        };
        self.lead.held.push(Held {
            run,
            gap,
            kind,
            line,
            v,
        });
    }

    fn defer_or_add(&mut self, extruding: bool, kind: Finding, line: usize, v: f64) {
        if extruding {
            self.record(kind, line, v, false);
        } else {
            self.pending.push((kind, line, v));
        }
    }

    /// The print begins at run `k`: what was held for runs before it (and
    /// in the gap before it) is start code, the rest counts.
    fn decide(&mut self, k: usize) {
        let lead = &mut self.lead;
        if lead.print_run.is_some() {
            return;
        }
        lead.print_run = Some(k);
        let cfg = self.cfg;
        let first = lead.runs.get(k);
        let first_z = first.map(|r| r.z);
        let high = first_z.filter(|&z| z > cfg.first_layer_max_mm);
        let start = &mut lead.start;
        for h in std::mem::take(&mut lead.held) {
            if h.run > k || (h.run == k && !h.gap) {
                // A first layer too high is one finding, not a bead with no
                // clay below for every bead of it.
                if h.kind == Finding::Unsupported
                    && high.is_some_and(|z| h.v <= z + cfg.min_layer_mm)
                {
                    continue;
                }
                self.r.findings[h.kind].add(h.line, h.v);
            } else {
                start.cover(h.line);
                if h.kind == Finding::ExtrusionWithoutMotion {
                    start.clay_ml += h.v / cfg.e_per_mm3 / 1000.0;
                }
                start.note(match h.kind {
                    Finding::ExtrusionWithoutMotion => {
                        format!("prime without motion (line {})", h.line)
                    }
                    Finding::Retraction => format!("retraction (line {})", h.line),
                    Finding::TravelMove => "travel moves".to_string(),
                    Finding::Pause => format!("pause (line {})", h.line),
                    Finding::Unsupported => "purge in the air (its clay is no obstacle)".into(),
                    other => format!("{} (line {})", other.label(), h.line),
                });
            }
        }
        for run in &lead.runs[..k.min(lead.runs.len())] {
            start.cover(run.line);
            start.cover(run.last_line);
            start.clay_ml += run.clay_mm3 / 1000.0;
            let what = if run.air * 2 > run.beads {
                "purge in the air"
            } else if run.on_bed * 2 > run.beads {
                "clay on the bed beside the part (skirt or purge line)"
            } else {
                "clay that nothing rests on"
            };
            start.note(format!(
                "{what}: {} bead(s), lines {}-{}",
                run.beads, run.line, run.last_line
            ));
        }
        // The start code runs from its first item to the print's first
        // bead (the report leaves it out if it holds nothing).
        if let Some(run) = first {
            start.moves = run.moves_before;
            if run.moves_before > 0 {
                start.note("homing and moves to the start".into());
            }
            start.lines = [start.lines[0].max(1), run.line.saturating_sub(1)];
        }
        // Clay purged into the air falls off: it is no obstacle to the
        // print (a height no question reaches).
        let first_bead = first.map_or(u32::MAX, |r| r.first_bead);
        for &id in &lead.air {
            if id < first_bead {
                if let Some(b) = self.beads.get_mut(id as usize) {
                    b.from32[2] = f32::NEG_INFINITY;
                    b.to32[2] = f32::NEG_INFINITY;
                }
            }
        }
        lead.air = Vec::new();
        if let Some(z) = first_z {
            self.r.first_layer_z = Some(z);
        }
        if let (Some(z), Some(run)) = (high, first) {
            self.r.findings[Finding::FirstLayerHigh].add(run.line, z);
        }
        self.r.run_starts = lead.runs[k.min(lead.runs.len())..]
            .iter()
            .map(|r| r.line)
            .take(20)
            .collect();
    }

    fn step(&mut self, m: &Move) {
        let cfg = self.cfg;
        let len = m.length();
        // A move whose E rises by a rounding residue is a travel.
        let is_extruding =
            m.de > EPS_E && (len == 0.0 || m.de / cfg.e_per_mm3 >= self.min_area * len);
        let bead = is_extruding && len > 0.0;
        // Continuity.
        self.r.moves += 1;
        if m.de < -EPS_E {
            self.pending.push(((Finding::Retraction), m.line, -m.de));
            self.in_run = false;
        } else if is_extruding && len == 0.0 {
            self.pending
                .push(((Finding::ExtrusionWithoutMotion), m.line, m.de));
            self.in_run = false;
        } else if bead {
            self.started = true;
            self.r.extruding_moves += 1;
            // Whatever happened since the last bead was between beads: in
            // the gap before the run this bead begins or goes on.
            for (kind, line, v) in std::mem::take(&mut self.pending) {
                self.record(kind, line, v, true);
            }
            if !self.in_run {
                self.new_run(m);
            }
            self.in_run = true;
        } else if len > 0.0 {
            if self.started {
                self.pending.push(((Finding::TravelMove), m.line, len));
            }
            self.in_run = false;
        }
        // Bounds (the machine cannot go there, start code or not).
        let mut out =
            m.to.iter()
                .zip(cfg.build_volume)
                .fold(0.0f64, |o, (&v, lim)| larger(larger(o, -v), v - lim));
        if let Some(d) = cfg.bed_diameter {
            let c = [cfg.build_volume[0] / 2.0, cfg.build_volume[1] / 2.0];
            out = larger(out, (m.to[0] - c[0]).hypot(m.to[1] - c[1]) - d / 2.0);
        }
        if out > 1e-3 {
            self.failures += 1;
            self.r.findings[Finding::OutOfBounds].add(m.line, out);
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
        if self.deep && self.failures > MAX_FAILURES {
            self.deep = false;
            self.diagnose(Diagnostic {
                line: m.line,
                message: format!(
                    "over {MAX_FAILURES} failures: support and collisions are not analysed from here on"
                ),
            });
        }
        if self.deep {
            self.probe(m, len, s_start, bead);
        }
        if bead {
            self.bead(m, len, s_start);
        }
    }

    /// A bead begins a new extrusion run.
    fn new_run(&mut self, m: &Move) {
        self.runs += 1;
        if self.lead.runs.len() >= MAX_LEAD_RUNS {
            // Run after run and nothing laid on any: all of it counts.
            self.decide(0);
        }
        if self.lead.print_run.is_some() {
            if self.r.run_starts.len() < 20 {
                self.r.run_starts.push(m.line);
            }
            return;
        }
        self.lead.runs.push(LeadRun {
            first_bead: self.beads.len() as u32,
            line: m.line,
            last_line: m.line,
            moves_before: self.r.moves - 1,
            z: m.from[2].max(m.to[2]),
            clay_mm3: 0.0,
            beads: 0,
            air: 0,
            on_bed: 0,
        });
    }

    /// Collisions along a move ([`collide::probe`]): counted at once for a
    /// bead, held back for a travel (they count only if a bead follows).
    fn probe(&mut self, m: &Move, len: f64, s_start: f64, is_extruding: bool) {
        let mut hits = Vec::new();
        collide::probe(
            &mut self.grid,
            &self.beads,
            self.top_z,
            self.cfg,
            (m, len, s_start, self.s),
            |kind, v| hits.push((kind, v)),
        );
        for (kind, v) in hits {
            self.defer_or_add(is_extruding, kind, m.line, v);
        }
    }

    /// Records the beads of a stretch of [`Weak`] beads of kind `k`, if it
    /// is long enough to fail: half the narrowest bead.
    /// How long a stretch of weak beads of kind `k` must be to fail: half
    /// the narrowest bead for too little overlap and a layer gap (a bead
    /// shorter than that is a blob on its neighbours); the narrowest
    /// bead's width for an overhang, the shortest length of bead that can
    /// sag on its own: a shorter one leans no farther than the supported
    /// clay it joins at both ends holds it (docs/CHECKER.md, "Overhangs").
    fn weak_length(&self, k: usize) -> f64 {
        match WEAK_KINDS[k] {
            Finding::Overhang => self.cfg.width_min,
            _ => 0.5 * self.cfg.width_min,
        }
    }

    fn flush_weak(&mut self, k: usize) {
        if self.weak[k].length < self.weak_length(k) {
            return;
        }
        let mut pending = std::mem::take(&mut self.weak[k].pending);
        for &(line, v) in &pending {
            self.record(WEAK_KINDS[k], line, v, false);
        }
        pending.clear();
        self.weak[k].pending = pending;
    }

    /// The share of a stretch's clay on clay at its own height that may have
    /// no room before it fails: half. A bead under the nozzle a gap g above
    /// clay is at most 1.25 w_max wide (the widths' tolerance), so it holds
    /// 1.25 w_max g a millimetre; past twice that, more clay is pushed out
    /// than the bead keeps (docs/CHECKER.md, "Clay on clay").
    const SQUISH_EXCESS: f64 = 0.5;

    /// Ends a stretch of beads on clay at their own height: a failure if
    /// most of its clay had no room, it is at least 3/4 `w_min` long (more
    /// than a seam's last bead) and its excess is a bead's clay (more
    /// than a `w_min`-wide bead of `min_layer_mm` a millimetre, over at
    /// least `w_min`): a pass laid again, or the step from one ring of a
    /// floor to the next laid as a full bead over both (docs/CHECKER.md,
    /// "Clay on clay"). A move carrying next to no clay across them fails
    /// as under-extruded instead (docs/CHECKER.md, "Under-extruded moves").
    ///
    /// A *ramp* is neither: a stretch whose gap only grows, by at least
    /// half the thinnest layer, and that the path leaves by a bead resting
    /// on the clay below at least a thinnest layer up, a vase's first turn
    /// rising from its flat loop, at any slope, width or lean (`climbs_out`:
    /// the gap under the bead that ended the stretch, if it rests on clay).
    fn close_stretch(&mut self, climbs_out: Option<f64>) {
        if self.stretch.length == 0.0 {
            return;
        }
        let st = std::mem::take(&mut self.stretch);
        let cfg = self.cfg;
        let ramp = !st.falls
            && st.last_gap - st.first_gap >= 0.5 * cfg.min_layer_mm
            && climbs_out
                .is_some_and(|g| g >= cfg.min_layer_mm && g <= st.last_gap + cfg.min_layer_mm);
        if ramp {
            return;
        }
        // Either way its excess must be a bead's clay: a move with next
        // to no clay is judged as under-extruded, not here.
        let bead = cfg.width_min * cfg.min_layer_mm * st.length.max(cfg.width_min);
        if st.excess > Self::SQUISH_EXCESS * st.volume
            && st.excess > bead
            && st.length >= 0.75 * cfg.width_min
        {
            self.record(Finding::DoubleDeposition, st.first_line, st.excess, false);
        }
    }

    /// Support analysis of an extruding move, then its bead joins the clay.
    fn bead(&mut self, m: &Move, len: f64, s_start: f64) {
        let cfg = self.cfg;
        let s = self.s;
        let volume = m.de / cfg.e_per_mm3;
        self.last_bead = (self.r.moves, m.line);
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
            let near_bed = mid[2] <= cfg.first_layer_max_mm;
            // The largest gap this bead's clay can stand in: as tall as
            // it would then be wide, with the widths' tolerance.
            let gap_limit = (section * (1.0 + WIDTH_TOLERANCE))
                .sqrt()
                .min(cfg.max_gap_mm);
            let fast = (*walk == Walk::Auto
                && (prev_support.is_some() || near_bed)
                && (recent.clear_of(m, mid, cfg.min_layer_mm, turn, xy)
                    || q.none_below(&beads[*support_settled..], *support_settled)))
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
            if let Some(z_own) = own {
                // Clay at its own height under its middle: the bead is
                // pressed onto it. Its clay has the gap above that clay to
                // spread in, at most twice the widest bead wide.
                on_clay = true;
                r.support.on_clay += 1;
                let gap = (mid[2] - z_own).max(0.0);
                let room = len * gap * (1.0 + WIDTH_TOLERANCE) * cfg.width_max;
                // The gap at the bead's two ends, over the clay under its
                // middle: a ramp's rise is read the same whether it is one
                // 63 mm move or thirty 2 mm ones (docs/CHECKER.md,
                // "Cutting").
                let (gap_from, gap_to) = ((m.from[2] - z_own).max(0.0), (m.to[2] - z_own).max(0.0));
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
                }
            }
            rest = Some(match support {
                _ if on_clay => Rest::Clay,
                Some(c) => Rest::Bead(c.id),
                None if near_bed => Rest::Bed,
                None => Rest::Air,
            });
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
                    // A thin bead (a floor's narrowed tail between its
                    // neighbours) fails only over a gap well beyond the
                    // layers laid so far: clay two layers down.
                    if rise < cfg.min_layer_mm {
                        let thin = width < cfg.width_min * (1.0 - WIDTH_TOLERANCE);
                        let deep = *typical_gap == 0.0 || dz > DEEP_GAP * *typical_gap;
                        let over = dz > gap_limit
                            && (!thin || deep)
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
                    let pressed = width > c.width && dz < 0.95 * c.height;
                    let core = if width > cfg.width_max || pressed {
                        width.min(c.width.max(cfg.width_min))
                    } else {
                        width
                    };
                    (dz, overlap_fraction(core, c.width, c.d), c.d, c.height)
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
                layer_heights.push(dz);
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
                width.clamp(0.0, cfg.width_max * (1.0 + WIDTH_TOLERANCE))
            } else {
                cfg.width_min
            },
            s,
            step,
        );
        bead.set_height(height);
        bead.bent = step || turn > BENT_RAD;
        if *deep {
            grid.insert(&bead, id);
        }
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
        if !step && width.is_finite() {
            if width < crate::report::UNDER_EXTRUDED * cfg.width_min {
                self.under.push((m.line, width, len));
            } else if !self.under.is_empty() {
                for (line, w, _) in std::mem::take(&mut self.under) {
                    self.record(Finding::UnderExtruded, line, w, false);
                }
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

    fn finish(mut self) -> Report {
        self.close_stretch(None);
        // A taper at the rim is a few millimetres; a whole layer or more
        // of too little clay at the end is under-extruded all the same.
        let tail: f64 = self.under.iter().map(|u| u.2).sum();
        if tail > 2.0 * self.cfg.width_max {
            for (line, w, _) in std::mem::take(&mut self.under) {
                self.record(Finding::UnderExtruded, line, w, false);
            }
        }
        for k in 0..WEAK_KINDS.len() {
            self.flush_weak(k);
        }
        if self.lead.print_run.is_none() {
            // Nothing rests on anything (a single layer): the print begins
            // at the first run that is not a purge in the air.
            let runs = &self.lead.runs;
            let k = runs.iter().position(|r| r.air * 2 <= r.beads).unwrap_or(0);
            self.decide(k);
        }
        let start = std::mem::take(&mut self.lead.start);
        self.r.start_code = (!start.items.is_empty()).then_some(start);
        self.r.extrusion_runs = self.runs.saturating_sub(self.lead.print_run.unwrap_or(0));
        // What follows the last bead is the end code.
        let (moves_at, line_at) = self.last_bead;
        if self.started && (self.r.moves > moves_at || !self.pending.is_empty()) {
            let mut end = Segment {
                lines: [line_at + 1, self.r.lines],
                moves: self.r.moves - moves_at,
                ..Segment::default()
            };
            for &(kind, line, v) in &self.pending {
                end.note(match kind {
                    Finding::Retraction => format!("end retraction (line {line})"),
                    Finding::TravelMove => "lifting off and travel".into(),
                    Finding::Pause => format!("pause (line {line})"),
                    // Not printing, but into the piece just printed: a
                    // crash like any other (an end code's `G1 Z+30` read
                    // as Z30 from above the rim).
                    Finding::NozzleCollision | Finding::CarriageCollision
                        if !self.replayer.homing_lines.contains(&line) =>
                    {
                        self.r.findings[kind].add(line, v);
                        format!("drives the nozzle into the printed piece (line {line})")
                    }
                    Finding::NozzleCollision | Finding::CarriageCollision => {
                        "homing through the clay after the print (where the endstops are is the printer's), not judged".into()
                    }
                    _ => "moves after the print, not judged".into(),
                });
            }
            if end.items.is_empty() {
                end.note("moves after the last bead".into());
            }
            self.r.end_code = Some(end);
        }
        let r = &mut self.r;
        let ambiguous = &self.parser.ambiguous;
        if ambiguous.count > 0 {
            r.findings[Finding::AmbiguousNumber] = ambiguous.clone();
        }
        let unreadable = &self.parser.unreadable;
        if unreadable.count > 0 {
            r.findings[Finding::UnreadableNumber] = unreadable.clone();
        }
        // The size of the piece a person measures: the print's beads,
        // not a purge line or skirt of the start code beside it.
        let first = self
            .lead
            .print_run
            .and_then(|k| self.lead.runs.get(k))
            .map_or(0, |run| run.first_bead as usize);
        let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
        for b in self.beads.get(first..).unwrap_or_default() {
            for p in [b.from(), b.to()] {
                for a in 0..3 {
                    lo[a] = lo[a].min(p[a]);
                    hi[a] = hi[a].max(p[a]);
                }
            }
        }
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
        r.diagnostics_total = self.diags.len() + self.diags_dropped;
        r.diagnostics = self.diags;
        r.printer = self.cfg.printer.clone();
        r.firmware = self.cfg.firmware.name().to_string();
        r.cannot_judge = self
            .replayer
            .cannot_judge
            .take()
            .map(|(line, message)| Diagnostic { line, message });
        verdict(r, self.cfg);
        self.r
    }
}
