//! Replays parsed G-code into a list of moves in absolute millimetres and
//! absolute E: G0/G1 with any subset of X Y Z E F, G2/G3 arcs in the XY
//! plane (`I J` or `R`, split into segments of at most 1 mm as Marlin and
//! Klipper do), G90/G91, M82/M83, G92 (the machine's position kept apart
//! from the file's), G20/G21, G28; M0, M1 and M600 are pauses, G4 a dwell
//! of its length, a bare G10 a firmware retraction, M221 a flow factor;
//! M200 D makes the file one it cannot judge; any other command is either
//! on the list of those that change nothing clay sees, a pause or stop
//! ([`PAUSES_M`], [`word_command`]), or [`Event::Unreplayed`], which the
//! checker judges by where it stands in the file. An arc this does
//! not replay as firmware would (another plane, no centre, a radius too
//! short for its chord) makes the file one it cannot judge.

/// The name of `M92 E` (steps per millimetre of E) as an
/// [`Event::Unreplayed`]: the checker says so in the start code.
pub(crate) const M92_E: &str = "M92 E (steps per millimetre of E)";

use crate::parse::{Diagnostic, Line};

/// One linear move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Move {
    /// Source line.
    pub line: usize,
    /// Start position (mm).
    pub from: [f64; 3],
    /// End position (mm).
    pub to: [f64; 3],
    /// E change of the move (E units; negative = retraction).
    pub de: f64,
    /// Feedrate in force (mm/min).
    pub feed: f64,
}

impl Move {
    /// 3D length (mm).
    pub fn length(&self) -> f64 {
        let d = sub(self.to, self.from);
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
    }

    /// Horizontal length (mm). A square root, not `f64::hypot`, whose
    /// guard against overflow costs more than the check can pay per move.
    pub fn xy_length(&self) -> f64 {
        let (dx, dy) = (self.to[0] - self.from[0], self.to[1] - self.from[1]);
        (dx * dx + dy * dy).sqrt()
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// An event in print order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Event {
    /// A move.
    Move(Move),
    /// A pause (M0, M1, M600) at a line.
    Pause(usize),
    /// A dwell (`G4`) at a line, of so many seconds: a pause if clay
    /// pools in it (the checker judges its length).
    Dwell(usize, f64),
    /// A firmware retraction (a bare `G10`, Marlin's `G10 S1`) at a line.
    Retract(usize),
    /// A command this does not replay and that is not on the list of
    /// those that change nothing clay sees ([`HARMLESS_M`]): fine in start
    /// and end code, "cannot judge" inside the print (its line and name).
    Unreplayed(usize, &'static str),
}

/// M-codes that change nothing the clay sees, anywhere in a file
/// (docs/CHECKER.md, "Commands"): temperatures (M104, M109, M140, M190,
/// M141, M191), fans (M106, M107), messages and reports (M105, M110, M114,
/// M115, M117, M118, M300 a beep), progress (M73), motion limits and the
/// speed factor (M201, M203, M204, M205, M220: time, not place or clay),
/// waiting for moves (M400) and pressure advance (Marlin's M900,
/// RepRapFirmware's M572: when the clay comes, not how much). Object
/// labels (M486 with S or A only) are matched apart.
pub const HARMLESS_M: [f64; 24] = [
    73.0, 104.0, 105.0, 106.0, 107.0, 109.0, 110.0, 114.0, 115.0, 117.0, 118.0, 140.0, 141.0,
    190.0, 191.0, 201.0, 203.0, 204.0, 205.0, 220.0, 300.0, 400.0, 572.0, 900.0,
];

/// Pauses and stops in every dialect (docs/CHECKER.md, "Commands"): M0,
/// M1, M25 (pause an SD print), M125 (park), M226 (wait for a pin), M600
/// (filament change), M601 (Prusa's pause), M112 (emergency stop), M410
/// (quick stop). Klipper's `PAUSE` and OctoPrint's `@pause` are read from
/// their words ([`word_command`]).
pub const PAUSES_M: [f64; 9] = [0.0, 1.0, 25.0, 125.0, 226.0, 600.0, 601.0, 112.0, 410.0];

/// A line that is one of the word commands firmwares and hosts take
/// (Klipper's extended G-code `SET_GCODE_OFFSET Z=1`, OctoPrint's
/// `@pause`), at line `n`: `None` for a line of G-code letters and numbers
/// (to be parsed), else what the word does — a pause or stop, nothing
/// clay sees (`Some(None)`), or a command not replayed. Cheap for G-code
/// lines: two bytes decide, before any text is made.
pub fn word_command(raw: &[u8], n: usize) -> Option<Option<Event>> {
    let mut b = raw.iter().skip_while(|c| c.is_ascii_whitespace());
    let host = match (b.next(), b.next()) {
        (Some(b'@'), _) => true,
        // Two letters, or a letter and `_`: `G1`, `M104`, `N12` are not.
        (Some(a), Some(c))
            if a.is_ascii_alphabetic() && (c.is_ascii_alphabetic() || *c == b'_') =>
        {
            false
        }
        _ => return None,
    };
    let text = String::from_utf8_lossy(raw);
    let head = text
        .split(';')
        .next()
        .unwrap_or("")
        .split_whitespace()
        .next()
        .unwrap_or("");
    let upper = head.trim_start_matches('@').to_ascii_uppercase();
    let pause = [
        "PAUSE",
        "CANCEL_PRINT",
        "SDCARD_RESET_FILE",
        "FIRMWARE_RESTART",
        "RESTART",
        "ABORT",
    ];
    // OctoPrint's `@abort` and `@cancel` stop the job it streams.
    let host_stop = host && upper == "CANCEL";
    if pause.contains(&upper.as_str()) || host_stop {
        return Some(Some(Event::Pause(n)));
    }
    // Klipper's own commands that change nothing clay sees: messages,
    // temperatures, fans, limits, pressure advance, object labels.
    const HARMLESS: [&str; 13] = [
        "RESPOND",
        "SET_DISPLAY_TEXT",
        "SET_HEATER_TEMPERATURE",
        "TEMPERATURE_WAIT",
        "SET_FAN_SPEED",
        "SET_VELOCITY_LIMIT",
        "SET_PRESSURE_ADVANCE",
        "SET_PRINT_STATS_INFO",
        "EXCLUDE_OBJECT_START",
        "EXCLUDE_OBJECT_END",
        "EXCLUDE_OBJECT_DEFINE",
        "SET_IDLE_TIMEOUT",
        "UPDATE_DELAYED_GCODE",
    ];
    if HARMLESS.contains(&upper.as_str()) {
        return Some(None);
    }
    let name = if host {
        "a host command (@…)"
    } else {
        "an extended command"
    };
    Some(Some(Event::Unreplayed(n, name)))
}

/// Replays the lines. Returns the events; diagnostics are appended.
pub fn replay(lines: &[Line], diags: &mut Vec<Diagnostic>) -> Vec<Event> {
    let mut r = Replayer::default();
    let mut out = Vec::new();
    for l in lines {
        if let Some(ev) = r.feed(l, diags) {
            out.push(ev);
            while let Some(m) = r.next_segment() {
                out.push(Event::Move(m));
            }
        }
    }
    out
}

/// The machine state of a replay, fed one line at a time.
#[derive(Debug)]
pub struct Replayer {
    /// Where the nozzle is, in the file's coordinates (after `G92`).
    pos: [f64; 3],
    /// The machine's position minus the file's, per axis: what `G92`
    /// declared (Marlin's position shift, Klipper's and RepRapFirmware's
    /// alike); homing an axis clears it.
    shift: [f64; 3],
    e: f64,
    abs_xyz: bool,
    abs_e: bool,
    scale: f64,
    feed: f64,
    unknown_reported: std::collections::BTreeSet<String>,
    /// Whose reading of `G90`/`G91` to follow (they switch E in Marlin).
    pub firmware: crate::Firmware,
    /// The plane arcs turn in: 17 (XY), 18 (ZX) or 19 (YZ).
    plane: u8,
    /// The segments of the last arc after the one `feed` returned, last
    /// first (taken by [`Replayer::next_segment`]).
    segments: Vec<Move>,
    /// The first line the replay cannot follow as firmware would, and why.
    pub cannot_judge: Option<(usize, String)>,
    /// Where `G28` takes a delta printer (its towers home up: the centre,
    /// at the top of the build volume); `None` homes to 0 as a Cartesian
    /// printer's endstops do.
    pub delta_home: Option<[f64; 3]>,
    /// The lines of the first 64 `G28` moves.
    pub homing_lines: Vec<usize>,
    /// The flow override `M221 S` sets, as a factor on every E (1: none).
    flow: f64,
    /// Segments the arcs so far split into.
    arc_segments: usize,
    /// The first `M92 E` (steps per mm of E): the machine's calibration,
    /// which the printer's E per mm³ states.
    steps_e: Option<f64>,
    /// A later `M92 E` over the first: the clay each E now lays, relative.
    steps_factor: f64,
}

/// Most segments a file's arcs may split into in all: 10 km of arcs in
/// 1 mm segments. Each arc is capped at 65,536; 709 KB of arcs 20 m
/// across split into 1.25 billion and took 65 s (docs/CHECKER.md,
/// "Bounded cost").
pub const MAX_ARC_SEGMENTS: usize = 10_000_000;

/// Longest segment an arc is split into (mm): Marlin's
/// `MM_PER_ARC_SEGMENT` and about Klipper's `resolution`.
pub const ARC_SEGMENT_MM: f64 = 1.0;

impl Default for Replayer {
    fn default() -> Self {
        Replayer {
            pos: [0.0; 3],
            shift: [0.0; 3],
            e: 0.0,
            abs_xyz: true,
            abs_e: true,
            scale: 1.0,
            feed: 0.0,
            unknown_reported: Default::default(),
            firmware: crate::Firmware::Marlin,
            plane: 17,
            steps_e: None,
            steps_factor: 1.0,
            segments: Vec::new(),
            cannot_judge: None,
            delta_home: None,
            homing_lines: Vec::new(),
            flow: 1.0,
            arc_segments: 0,
        }
    }
}

impl Replayer {
    /// The next segment of the arc the last [`Replayer::feed`] began, if
    /// any is left.
    pub fn next_segment(&mut self) -> Option<Move> {
        self.segments.pop()
    }

    /// A position in the file's coordinates as the machine has it.
    fn machine(&self, p: [f64; 3]) -> [f64; 3] {
        [
            p[0] + self.shift[0],
            p[1] + self.shift[1],
            p[2] + self.shift[2],
        ]
    }

    /// Where a move's X Y Z take the nozzle (absolute or relative).
    fn target(&self, l: &Line) -> [f64; 3] {
        let mut to = self.pos;
        for (a, k) in ['X', 'Y', 'Z'].into_iter().enumerate() {
            if let Some(v) = l.get(k) {
                to[a] = if self.abs_xyz {
                    v * self.scale
                } else {
                    self.pos[a] + v * self.scale
                };
            }
        }
        to
    }

    /// A move's E change (absolute or relative E); its feedrate is kept.
    fn take_e_and_feed(&mut self, l: &Line) -> f64 {
        let mut de = 0.0;
        if let Some(v) = l.get('E') {
            let v = v * self.scale;
            de = if self.abs_e { v - self.e } else { v };
            self.e += de;
        }
        // `M221 S50` halves the clay of every E that follows.
        de *= self.flow * self.steps_factor;
        if let Some(f) = l.get('F') {
            self.feed = f * self.scale;
        }
        de
    }

    /// Notes the first line the replay cannot follow.
    fn cannot(&mut self, line: usize, why: String) {
        self.cannot_judge.get_or_insert((line, why));
    }

    /// An arc (`clockwise` for G2) from the current position, as firmware
    /// splits it: the first segment, the rest left for
    /// [`Replayer::next_segment`].
    fn arc(&mut self, l: &Line, clockwise: bool, diags: &mut Vec<Diagnostic>) -> Option<Event> {
        let scale = self.scale;
        if self.plane != 17 {
            self.cannot(
                l.line,
                format!(
                    "an arc in the G{} plane (only G17, XY, is replayed)",
                    self.plane
                ),
            );
            return None;
        }
        let to = self.target(l);
        let (p1, q1, p2, q2) = (self.pos[0], self.pos[1], to[0], to[1]);
        let centre = match (l.get('I'), l.get('J'), l.get('R')) {
            (i, j, _) if i.is_some() || j.is_some() => {
                [p1 + i.unwrap_or(0.0) * scale, q1 + j.unwrap_or(0.0) * scale]
            }
            (_, _, Some(r)) => {
                let r = r * scale;
                let (dx, dy) = (p2 - p1, q2 - q1);
                let d = dx.hypot(dy);
                if d == 0.0 || r.abs() < 0.5 * d - 1e-9 {
                    self.cannot(
                        l.line,
                        format!(
                            "an arc of radius {} mm between points {d:.3} mm apart",
                            r.abs()
                        ),
                    );
                    return None;
                }
                // Marlin's pivot: on the chord's bisector, on the side the
                // direction and the radius's sign choose.
                let e = if clockwise ^ (r < 0.0) { -1.0 } else { 1.0 };
                let h = (r * r - 0.25 * d * d).max(0.0).sqrt();
                [
                    0.5 * (p1 + p2) - e * h * dy / d,
                    0.5 * (q1 + q2) + e * h * dx / d,
                ]
            }
            _ => {
                self.cannot(l.line, "an arc with neither I J nor R".into());
                return None;
            }
        };
        let (rp, rq) = (p1 - centre[0], q1 - centre[1]);
        let (tp, tq) = (p2 - centre[0], q2 - centre[1]);
        let radius = rp.hypot(rq);
        let mut travel = (rp * tq - rq * tp).atan2(rp * tp + rq * tq);
        if travel < 0.0 {
            travel += std::f64::consts::TAU;
        }
        if clockwise {
            travel -= std::f64::consts::TAU;
        }
        if travel == 0.0 && p1 == p2 && q1 == q2 {
            travel = std::f64::consts::TAU;
        }
        let de = self.take_e_and_feed(l);
        let length = (travel * radius).hypot(to[2] - self.pos[2]);
        if !length.is_finite() || radius > 1e6 {
            self.cannot(l.line, "an arc whose centre is not a number".into());
            return None;
        }
        // Firmware moves the last segment to the target itself.
        let n = ((length / ARC_SEGMENT_MM).ceil() as usize).clamp(1, 1 << 16);
        self.arc_segments += n;
        if self.arc_segments > MAX_ARC_SEGMENTS {
            self.cannot(
                l.line,
                format!(
                    "arcs that split into more than {MAX_ARC_SEGMENTS} segments of {ARC_SEGMENT_MM} mm in all (the cap on the work one file may ask)"
                ),
            );
            return None;
        }
        let start = self.pos;
        let a0 = rq.atan2(rp);
        let at = |k: usize| -> [f64; 3] {
            if k == n {
                return to;
            }
            let f = k as f64 / n as f64;
            let a = a0 + travel * f;
            [
                centre[0] + radius * a.cos(),
                centre[1] + radius * a.sin(),
                start[2] + (to[2] - start[2]) * f,
            ]
        };
        self.segments.clear();
        for k in (1..=n).rev() {
            self.segments.push(Move {
                line: l.line,
                from: self.machine(at(k - 1)),
                to: self.machine(at(k)),
                de: de / n as f64,
                feed: self.feed,
            });
        }
        if (to[0] - at(n - 1)[0]).hypot(to[1] - at(n - 1)[1]) > 2.0 * ARC_SEGMENT_MM + 1e-6 && n > 1
        {
            diags.push(Diagnostic {
                line: l.line,
                message: "the arc's end is not on its circle; firmware jumps to it".into(),
            });
        }
        self.pos = to;
        self.segments.pop().map(Event::Move)
    }

    /// Applies one line; returns the move or pause it makes, if any.
    pub fn feed(&mut self, l: &Line, diags: &mut Vec<Diagnostic>) -> Option<Event> {
        let Some(letter) = l.letter else {
            diags.push(Diagnostic {
                line: l.line,
                message: "parameters without a command".into(),
            });
            return None;
        };
        let scale = self.scale;
        match (letter, l.code) {
            ('G', c) if c == 0.0 || c == 1.0 => {
                let to = self.target(l);
                let de = self.take_e_and_feed(l);
                let m = Move {
                    line: l.line,
                    from: self.machine(self.pos),
                    to: self.machine(to),
                    de,
                    feed: self.feed,
                };
                self.pos = to;
                return Some(Event::Move(m));
            }
            ('G', 2.0) | ('G', 3.0) => return self.arc(l, l.code == 2.0, diags),
            ('G', 17.0) => self.plane = 17,
            ('G', 18.0) => self.plane = 18,
            ('G', 19.0) => self.plane = 19,
            ('M', c) if PAUSES_M.contains(&c) => return Some(Event::Pause(l.line)),
            // A dwell: `P` milliseconds, `S` seconds (all three firmwares);
            // none, a wait for the moves to finish.
            ('G', 4.0) => {
                let s = l.get('S').unwrap_or(0.0) + l.get('P').unwrap_or(0.0) / 1000.0;
                return Some(Event::Dwell(l.line, s.max(0.0)));
            }
            // Firmware retraction (Marlin's FWRETRACT, Klipper's
            // `[firmware_retraction]`, RepRapFirmware): a bare `G10`
            // retracts, `G11` primes again. With parameters `G10` sets tool
            // offsets and temperatures in RepRapFirmware; Marlin's `S1` is a
            // swap retraction; anything else is read by no firmware the
            // same way.
            ('G', 10.0) => {
                let bare = l.params.is_empty();
                let swap = l.get('S') == Some(1.0) && l.params.len() == 1;
                match self.firmware {
                    _ if bare => return Some(Event::Retract(l.line)),
                    crate::Firmware::Marlin if swap => return Some(Event::Retract(l.line)),
                    crate::Firmware::Reprap => {}
                    _ => self.cannot(
                        l.line,
                        "G10 with parameters: a tool offset or temperature to RepRapFirmware, no firmware retraction elsewhere (give --firmware reprap if the file is for it)".into(),
                    ),
                }
            }
            ('G', 11.0) => {}
            // Flow overrides: the clay of every E after them.
            ('M', 221.0) => {
                if let Some(s) = l.get('S') {
                    self.flow = (s / 100.0).max(0.0);
                }
            }
            ('M', 200.0) => {
                if l.get('D').is_some_and(|d| d != 0.0) {
                    self.cannot(
                        l.line,
                        "M200 D switches E to cubic millimetres of a filament's diameter: E per mm³ is no longer the printer's".into(),
                    );
                }
            }
            ('G', 20.0) => self.scale = 25.4,
            ('G', 21.0) => self.scale = 1.0,
            ('G', 28.0) => {
                let any = ['X', 'Y', 'Z'].iter().any(|k| l.get(*k).is_some());
                let from = self.machine(self.pos);
                let mut to = from;
                if let Some(home) = self.delta_home {
                    // A delta homes all three towers at once.
                    to = home;
                    self.shift = [0.0; 3];
                } else {
                    for (a, k) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                        if !any || l.get(k).is_some() {
                            to[a] = 0.0;
                            // Homing an axis clears what G92 declared.
                            self.shift[a] = 0.0;
                        }
                    }
                }
                if self.homing_lines.len() < 64 {
                    self.homing_lines.push(l.line);
                }
                let m = Move {
                    line: l.line,
                    from,
                    to,
                    de: 0.0,
                    feed: self.feed,
                };
                self.pos = [
                    to[0] - self.shift[0],
                    to[1] - self.shift[1],
                    to[2] - self.shift[2],
                ];
                return Some(Event::Move(m));
            }
            ('G', 90.0) => {
                self.abs_xyz = true;
                if self.firmware.g91_moves_e() {
                    self.abs_e = true;
                }
            }
            ('G', 91.0) => {
                self.abs_xyz = false;
                if self.firmware.g91_moves_e() {
                    self.abs_e = false;
                }
            }
            ('G', 92.0) => {
                // The machine stays where it is; the file's coordinates
                // of that place change (an end code's `G92 Z0`, then
                // `G1 Z10`, lifts 10 mm).
                let here = self.machine(self.pos);
                let all = l.params.is_empty();
                if all {
                    self.e = 0.0;
                }
                for (a, k) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                    let v = if all { Some(0.0) } else { l.get(k) };
                    if let Some(v) = v {
                        self.pos[a] = v * scale;
                        self.shift[a] = here[a] - self.pos[a];
                    }
                }
                if let Some(v) = l.get('E') {
                    self.e = v * scale;
                }
            }
            ('M', 82.0) => self.abs_e = true,
            ('M', 83.0) => self.abs_e = false,
            // Commands that change nothing clay sees, anywhere.
            ('M', c) if HARMLESS_M.contains(&c) => {}
            ('M', 486.0) if l.params.iter().all(|(k, _)| matches!(k, 'S' | 'A')) => {}
            // `M92` without values reports the steps; with them it is the
            // machine's calibration ([`Event::Unreplayed`] to the checker,
            // which judges it by where it stands).
            ('M', 92.0) if l.params.is_empty() => {}
            // A later `M92 E` scales E by its ratio to the first one's.
            ('M', 92.0) if l.params.iter().all(|(k, _)| *k == 'E') => {
                let v = l.get('E').unwrap_or(0.0);
                match self.steps_e {
                    Some(base) if base > 0.0 && v > 0.0 && v.is_finite() => {
                        self.steps_factor = v / base;
                    }
                    _ => {
                        self.steps_e = Some(v);
                        return Some(Event::Unreplayed(l.line, M92_E));
                    }
                }
            }
            (k, c) => {
                let name = known_name(k, c).unwrap_or_else(|| {
                    // One note a command this knows nothing of, for the
                    // first 64 distinct ones.
                    if self.unknown_reported.len() < 64
                        && self.unknown_reported.insert(format!("{k}{c}"))
                    {
                        diags.push(Diagnostic {
                            line: l.line,
                            message: format!("unknown command {k}{c} ignored"),
                        });
                    }
                    match k {
                        'G' => "an unknown G command",
                        'M' => "an unknown M command",
                        _ => "an unknown command",
                    }
                });
                return Some(Event::Unreplayed(l.line, name));
            }
        }
        None
    }
}

/// The name of a known command not replayed, for the "cannot judge" line;
/// `None` for one this knows nothing of.
fn known_name(k: char, c: f64) -> Option<&'static str> {
    Some(match (k, c) {
        ('M', 92.0) => "M92 (steps per millimetre)",
        ('M', 17.0) | ('M', 18.0) | ('M', 84.0) => "a motor switch (M17/M18/M84)",
        ('M', 206.0) | ('M', 290.0) => "an offset of Z (M206/M290)",
        ('G', 29.0) | ('G', 80.0) => "bed probing (G29/G80)",
        ('G', 53.0) => "machine coordinates (G53)",
        ('G', 38.0) => "a probing move (G38)",
        ('G', 12.0) => "a nozzle cleaning move (G12)",
        ('T', _) => "a tool change (T)",
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parse::parse;

    fn moves(text: &str) -> Vec<Move> {
        let mut d = vec![];
        replay(&parse(text, &mut d), &mut d)
            .into_iter()
            .filter_map(|e| match e {
                Event::Move(m) => Some(m),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn absolute_and_relative_modes() {
        let m = moves("G90\nM82\nG1 X10 E1\nG1 X20 E3\nM83\nG1 X30 E2\nG91\nG1 X5 E1\n");
        assert_eq!(m.len(), 4);
        assert_eq!((m[0].de, m[1].de, m[2].de, m[3].de), (1.0, 2.0, 2.0, 1.0));
        assert_eq!(m[3].to[0], 35.0);
    }

    #[test]
    fn g91_switches_e_in_marlin_only() {
        let text = "M82\nG1 X10 E1\nG91\nG1 X5 E1\n";
        let mut d = vec![];
        let lines = parse(text, &mut d);
        let mut de = |fw| {
            let mut r = Replayer {
                firmware: fw,
                ..Replayer::default()
            };
            let ev: Vec<_> = lines.iter().filter_map(|l| r.feed(l, &mut d)).collect();
            match ev[1] {
                Event::Move(m) => (m.to[0], m.de),
                _ => unreachable!(),
            }
        };
        // Marlin: G91 makes E relative too (E1 is one more); Klipper and
        // RepRapFirmware: E stays absolute (E1 is where it already is).
        assert_eq!(de(crate::Firmware::Marlin), (15.0, 1.0));
        assert_eq!(de(crate::Firmware::Klipper), (15.0, 0.0));
        assert_eq!(de(crate::Firmware::Reprap), (15.0, 0.0));
    }

    #[test]
    fn g92_and_inches() {
        let m = moves("G1 X1 E5\nG92 E0\nG1 X2 E1\nG20\nG1 X1\n");
        assert_eq!(m[1].de, 1.0);
        assert!((m[2].to[0] - 25.4).abs() < 1e-12);
    }

    #[test]
    fn pauses_and_unknowns() {
        let mut d = vec![];
        let ev = replay(&parse("G4 P100\nM600\nM999\nG1 X1\n", &mut d), &mut d);
        assert_eq!(ev[0], Event::Dwell(1, 0.1));
        assert!(matches!(ev[1], Event::Pause(2)));
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].line, 3);
    }

    #[test]
    fn g92_keeps_the_machine_where_it_is() {
        // 30 mm up, then `G92 Z0` and `G1 Z10`: the nozzle ends at 40.
        let m = moves("G1 Z30\nG92 Z0\nG1 Z10\nG28 Z\nG1 Z5\n");
        assert_eq!(m[1].from[2], 30.0);
        assert_eq!(m[1].to[2], 40.0);
        // Homing clears the shift: Z5 is 5 mm above the bed again.
        assert_eq!(m[3].to[2], 5.0);
    }

    #[test]
    fn flow_overrides_scale_e() {
        let m = moves("M83\nG1 X1 E1\nM221 S50\nG1 X2 E1\n");
        assert_eq!((m[0].de, m[1].de), (1.0, 0.5));
    }

    #[test]
    fn arcs_are_split_as_firmware_splits_them() {
        // A full circle of radius 10 (I J, back to its start): 63 segments
        // of at most 1 mm, 2π·10 long but for the chords' sag, E shared
        // out evenly, ending where it began.
        let m = moves("G1 X20 Y10 Z1 F600\nG2 X20 Y10 I-10 J0 E6.25\n");
        let arc = &m[1..];
        assert_eq!(arc.len(), 63);
        let len: f64 = arc.iter().map(Move::length).sum();
        let closed_form = std::f64::consts::TAU * 10.0;
        assert!((len - closed_form).abs() < 0.01 * closed_form, "{len}");
        let e: f64 = arc.iter().map(|m| m.de).sum();
        assert!((e - 6.25).abs() < 1e-9);
        assert_eq!(arc.last().unwrap().to, [20.0, 10.0, 1.0]);
        // Clockwise: the first segment heads down (−y) from (20, 10).
        assert!(arc[0].to[1] < 10.0, "{:?}", arc[0].to);
        // R form, counter-clockwise, a half circle from (0, 0) to (20, 0)
        // through (10, −10): 10π long.
        let m = moves("G1 X0 Y0 Z1\nG3 X20 Y0 R10 E1\n");
        let len: f64 = m[1..].iter().map(Move::length).sum();
        assert!((len - 10.0 * std::f64::consts::PI).abs() < 0.05, "{len}");
        assert!(m[1..].iter().all(|m| m.to[1] <= 1e-9), "{:?}", m[5].to);
    }

    #[test]
    fn arcs_past_the_total_cap_are_not_judged_and_say_so() {
        // 200 full circles 20 m across: 62,832 segments of 1 mm each, 12.6
        // million in all; the 160th passes the 10 million a file may ask.
        let mut text = String::from("G1 X0 Y0 Z1\n");
        for _ in 0..200 {
            text.push_str("G2 X0 Y0 I10000 J0 E1\n");
        }
        let mut r = Replayer::default();
        let mut d = Vec::new();
        let mut segments = 0usize;
        for l in parse(&text, &mut d) {
            if r.feed(&l, &mut d).is_some() {
                segments += 1;
                while r.next_segment().is_some() {
                    segments += 1;
                }
            }
            if r.cannot_judge.is_some() {
                break;
            }
        }
        let (line, msg) = r.cannot_judge.expect("the cap");
        assert!(msg.contains("10000000 segments"), "{msg}");
        assert_eq!(line, 161, "the arc that passes the cap");
        assert!(segments <= MAX_ARC_SEGMENTS + 1, "{segments}");
    }

    #[test]
    fn arcs_firmware_would_not_run_as_written_are_not_judged() {
        for (text, why) in [
            ("G18\nG2 X10 Z5 I5 K0\n", "G18 plane"),
            ("G1 X0 Y0\nG2 X10 Y0\n", "neither I J nor R"),
            ("G1 X0 Y0\nG2 X10 Y0 R2\n", "radius 2 mm"),
        ] {
            let mut r = Replayer::default();
            let mut d = Vec::new();
            for l in parse(text, &mut d) {
                r.feed(&l, &mut d);
            }
            let (_, msg) = r.cannot_judge.expect(why);
            assert!(msg.contains(why), "{msg}");
        }
    }
}
