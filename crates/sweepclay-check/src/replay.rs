//! Replays parsed G-code into a list of moves in absolute millimetres and
//! absolute E: G0/G1 with any subset of X Y Z E F, G90/G91, M82/M83, G92,
//! G20/G21, G28; G4, M0, M1 and M600 are pauses; unknown commands are
//! reported, not fatal.

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
    /// A pause (G4, M0, M1, M600) at a line.
    Pause(usize),
}

/// Replays the lines. Returns the events; diagnostics are appended.
pub fn replay(lines: &[Line], diags: &mut Vec<Diagnostic>) -> Vec<Event> {
    let mut r = Replayer::default();
    let mut out = Vec::new();
    for l in lines {
        if let Some(ev) = r.feed(l, diags) {
            out.push(ev);
        }
    }
    out
}

/// The machine state of a replay, fed one line at a time.
#[derive(Debug)]
pub struct Replayer {
    pos: [f64; 3],
    e: f64,
    abs_xyz: bool,
    abs_e: bool,
    scale: f64,
    feed: f64,
    unknown_reported: std::collections::BTreeSet<String>,
    /// Whose reading of `G90`/`G91` to follow (they switch E in Marlin).
    pub firmware: crate::Firmware,
}

impl Default for Replayer {
    fn default() -> Self {
        Replayer {
            pos: [0.0; 3],
            e: 0.0,
            abs_xyz: true,
            abs_e: true,
            scale: 1.0,
            feed: 0.0,
            unknown_reported: Default::default(),
            firmware: crate::Firmware::Marlin,
        }
    }
}

impl Replayer {
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
                let mut to = self.pos;
                for (a, k) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                    if let Some(v) = l.get(k) {
                        to[a] = if self.abs_xyz {
                            v * scale
                        } else {
                            self.pos[a] + v * scale
                        };
                    }
                }
                let mut de = 0.0;
                if let Some(v) = l.get('E') {
                    let v = v * scale;
                    de = if self.abs_e { v - self.e } else { v };
                    self.e += de;
                }
                if let Some(f) = l.get('F') {
                    self.feed = f * scale;
                }
                let m = Move {
                    line: l.line,
                    from: self.pos,
                    to,
                    de,
                    feed: self.feed,
                };
                self.pos = to;
                return Some(Event::Move(m));
            }
            ('G', 2.0) | ('G', 3.0) => diags.push(Diagnostic {
                line: l.line,
                message: "arc moves (G2/G3) are not replayed".into(),
            }),
            ('G', 4.0) | ('M', 0.0) | ('M', 1.0) | ('M', 600.0) => {
                return Some(Event::Pause(l.line))
            }
            ('G', 20.0) => self.scale = 25.4,
            ('G', 21.0) => self.scale = 1.0,
            ('G', 28.0) => {
                let any = ['X', 'Y', 'Z'].iter().any(|k| l.get(*k).is_some());
                let mut to = self.pos;
                for (a, k) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                    if !any || l.get(k).is_some() {
                        to[a] = 0.0;
                    }
                }
                let m = Move {
                    line: l.line,
                    from: self.pos,
                    to,
                    de: 0.0,
                    feed: self.feed,
                };
                self.pos = to;
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
                if l.params.is_empty() {
                    self.pos = [0.0; 3];
                    self.e = 0.0;
                }
                for (a, k) in ['X', 'Y', 'Z'].into_iter().enumerate() {
                    if let Some(v) = l.get(k) {
                        self.pos[a] = v * scale;
                    }
                }
                if let Some(v) = l.get('E') {
                    self.e = v * scale;
                }
            }
            ('M', 82.0) => self.abs_e = true,
            ('M', 83.0) => self.abs_e = false,
            // Known commands with no effect on the deposition.
            ('M', c)
                if [
                    17.0, 18.0, 84.0, 104.0, 105.0, 106.0, 107.0, 109.0, 110.0, 114.0, 115.0,
                    117.0, 140.0, 190.0, 201.0, 203.0, 204.0, 205.0, 220.0, 221.0, 400.0, 73.0,
                    107.0,
                ]
                .contains(&c) => {}
            ('G', c) if [29.0, 17.0, 80.0].contains(&c) => {}
            ('T', _) => {}
            (k, c) => {
                // One note a command, for the first 64 distinct ones.
                if self.unknown_reported.len() < 64
                    && self.unknown_reported.insert(format!("{k}{c}"))
                {
                    diags.push(Diagnostic {
                        line: l.line,
                        message: format!("unknown command {k}{c} ignored"),
                    });
                }
            }
        }
        None
    }
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
                Event::Pause(_) => None,
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
                Event::Pause(_) => unreachable!(),
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
        assert!(matches!(ev[0], Event::Pause(1)));
        assert!(matches!(ev[1], Event::Pause(2)));
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].line, 3);
    }
}
