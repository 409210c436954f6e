//! The check as a state machine fed one line at a time
//! ([`CheckWriter`]): continuity, bounds, collisions and support from the
//! replayed moves, and the entry points [`check`] and [`check_reader`].
//!
//! One rule a file: `runs` (which run is the print, start and end code),
//! `stretches` (beads judged by the stretch they belong to, and turns),
//! `beads` (what each bead rests on), `finish` (the end of the file and
//! the verdict). This file reads the lines and replays the moves.

use crate::bead::{Bead, Beads};
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

mod beads;
mod finish;
mod memory;
mod runs;
mod stretches;

use runs::{Held, Lead, Rest, MAX_HELD};
use stretches::{Stretch, Turn, Weak, RAMP_SLACK_MM, WEAK_KINDS};

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

/// [`check`] keeping at most about `kept_beads` beads in memory (the
/// default is [`memory::KEPT_BEADS`]): the tests' way to see what letting
/// old clay go changes on small files (docs/CHECKER.md, "Bounded memory").
#[doc(hidden)]
pub fn check_kept(text: &str, cfg: &CheckConfig, kept_beads: usize) -> Report {
    let mut w = CheckWriter::new(cfg);
    w.checker.memory = memory::Memory::new(cfg, kept_beads);
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
    /// The width of the last bead laid at full flow (not under-extruded).
    full_width: f64,
    /// Path without clay since the last bead (mm): shorter than a bead
    /// inside a run, it joins the run (docs/CHECKER.md, "Short moves").
    dry_len: f64,
    /// The feedrate of the last move (mm/min): how long a dwell is
    /// against the bead it holds up.
    last_feed: f64,
    /// The gap under the beads judged for it so far, a running mean
    /// (mm; 0 before the first): the layers the print lays.
    typical_gap: f64,
    beads: Beads,
    /// `bent_before[k + 1]`: how many of beads `0..=k` are bent (a
    /// prefix count, so "any bent bead in this stretch?" is two loads).
    bent_before: Vec<u32>,
    grid: BeadGrid,
    /// Bounds of blocks of consecutive beads, for the full search.
    blocks: Blocks,
    scratch: Scratch,
    s: f64,
    top_z: f64,
    /// The beads' layer heights, counted to the micrometre: their median
    /// says how many layers the print has, in memory that does not grow
    /// with the moves.
    layer_heights: finish::Heights,
    /// Clay tops of the beads laid more than 2 w_max of path back, in
    /// finer cells, for the support's fast path (`follow_support`).
    support_tops: TopGrid,
    /// Beads `..support_settled` are in `support_tops`.
    support_settled: usize,
    /// The beads laid since (their lowest point, the path's turning).
    recent: Recent,
    /// The bead the last bead rests on.
    prev_support: Option<u32>,
    /// The top of the first layer the last bead rested on the bed at, if
    /// it did: a ramp climbing from that loop lies on the bed until it
    /// has risen a thinnest layer (docs/CHECKER.md, "Ramps").
    bed_loop_top: Option<f64>,
    /// Offset / layer height of the steepest overhang so far, and a ratio
    /// just under the overhang limit's.
    steepest: f64,
    overhang_near: f64,
    /// How supports are found (tests compare the ways).
    walk: Walk,
    /// Letting old clay go ([`memory`]).
    memory: memory::Memory,
    /// The first command not replayed since the last bead (line, name):
    /// inside the print once a bead follows it. Only the first of a gap
    /// counts: a gap lies wholly before the print's first bead or after.
    unreplayed_since: Option<(usize, &'static str)>,
    /// The first command not replayed of each gap between two beads (the
    /// first [`MAX_UNREPLAYED`] gaps).
    unreplayed_inside: Vec<(usize, &'static str)>,
}

/// Most gaps between beads whose first command not replayed is kept.
const MAX_UNREPLAYED: usize = 64;

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
            lead: Lead {
                after: runs::EMPTY,
                ..Lead::default()
            },
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
            full_width: f64::NAN,
            dry_len: 0.0,
            last_feed: 0.0,
            typical_gap: 0.0,
            beads: Beads::default(),
            bent_before: vec![0],
            grid: BeadGrid::new(cfg),
            blocks: Blocks::default(),
            scratch: Scratch::default(),
            s: 0.0,
            top_z: f64::MIN,
            layer_heights: finish::Heights::default(),
            support_tops: TopGrid::layered(
                [cfg.build_volume[0], cfg.build_volume[1]],
                2.0,
                cfg.min_layer_mm,
            ),
            support_settled: 0,
            recent: Recent::default(),
            prev_support: None,
            bed_loop_top: None,
            steepest: f64::NEG_INFINITY,
            overhang_near: 0.999
                * (cfg.max_overhang_deg + cfg.overhang_tolerance_deg)
                    .to_radians()
                    .tan(),
            walk: Walk::Auto,
            memory: memory::Memory::new(cfg, memory::KEPT_BEADS),
            unreplayed_since: None,
            unreplayed_inside: Vec::new(),
        }
    }

    /// Room for `moves` beads in every per-bead array, as far as memory
    /// allows (an array that gets none grows as it would have). The bead
    /// lists grow as they go: they hold a run of beads an entry, from
    /// 9 entries a bead (long beads across many cells) down to 0.04
    /// (3 million samples), too wide a range to guess.
    fn reserve(&mut self, moves: usize) {
        // A failed reservation only leaves the growing to `push`.
        let _ = self.bent_before.try_reserve_exact(moves);
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
        // Klipper's `PAUSE`, `SET_GCODE_OFFSET Z=1`, OctoPrint's `@pause`
        // are read as words; every other line as letters and numbers.
        let event = match crate::replay::word_command(raw, n) {
            Some(word) => word,
            None => {
                let parsed = self
                    .parser
                    .parse_bytes(raw, n, &mut self.diags, &mut self.line);
                if parsed {
                    self.replayer.feed(&self.line, &mut self.diags)
                } else {
                    None
                }
            }
        };
        self.trim_diagnostics();
        match event {
            Some(Event::Pause(line)) => {
                self.break_run(line);
                self.pending.push(((Finding::Pause), line, 0.0));
            }
            // A dwell is a pause when clay pools in it: longer than laying
            // a narrowest bead's length of clay takes at the feed in force
            // (docs/CHECKER.md, "Firmwares").
            Some(Event::Dwell(line, seconds)) => {
                let feed_mm_s = (self.last_feed / 60.0).max(1.0);
                if seconds > self.cfg.width_min / feed_mm_s {
                    self.break_run(line);
                    self.pending.push(((Finding::Pause), line, seconds));
                }
            }
            // Before the first bead, start code; after the last, end code;
            // between two beads, a command the replay cannot follow.
            Some(Event::Unreplayed(line, name)) if self.started => {
                self.unreplayed_since.get_or_insert((line, name));
            }
            // `M92 E` before any bead: the machine's E calibration, which
            // the printer's E per mm³ states; said in the start code
            // (docs/CHECKER.md, "Commands").
            Some(Event::Unreplayed(line, crate::replay::M92_E)) => {
                self.lead.start.cover(line);
                self.lead.start.note(format!(
                    "E steps set (`M92`, line {line}): the machine's calibration, read as the printer's {} E per mm³",
                    self.cfg.e_per_mm3
                ));
            }
            Some(Event::Unreplayed(..)) => {}
            Some(Event::Retract(line)) => {
                self.break_run(line);
                self.pending.push(((Finding::Retraction), line, 0.0));
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

    /// Ends the extrusion run: the dry moves it had taken in (shorter
    /// than a bead so far) were a travel after all.
    fn break_run(&mut self, line: usize) {
        if self.in_run && self.started && self.dry_len > 0.0 {
            self.pending.push((Finding::TravelMove, line, self.dry_len));
        }
        self.in_run = false;
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
            self.break_run(m.line);
            self.pending.push(((Finding::Retraction), m.line, -m.de));
        } else if is_extruding && len == 0.0 {
            self.break_run(m.line);
            self.pending
                .push(((Finding::ExtrusionWithoutMotion), m.line, m.de));
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
            self.dry_len = 0.0;
        } else if len > 0.0 {
            // A move without clay shorter than a bead inside a run (a
            // slicer's ramp start rounded to E0.000) joins it: no clay
            // extruder stops and starts within a bead's length.
            let joins = self.in_run && self.dry_len + len < cfg.width_min;
            if !joins {
                self.break_run(m.line);
                if self.started {
                    self.pending.push(((Finding::TravelMove), m.line, len));
                }
            }
            self.dry_len += len;
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
        if self.deep && self.memory.reaches_let_go(m) {
            self.cannot_follow(m);
        }
        if self.deep {
            self.probe(m, len, s_start, bead);
        }
        if bead {
            self.bead(m, len, s_start);
            self.let_go(m);
        }
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
}
