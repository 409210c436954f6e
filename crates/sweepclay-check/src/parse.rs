//! A small G-code reader: comments (`;…` and `(…)`), line numbers (`N…`),
//! checksums (`*NN`, verified), and the words of each line. Every
//! diagnostic carries its 1-based source line. Nothing here panics on any
//! input (fuzzed in the tests).

/// One parsed line: its command letter and number, and its parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Line {
    /// 1-based line number in the file.
    pub line: usize,
    /// Command letter (`G`, `M`, `T`) or `None` for parameter-only lines.
    pub letter: Option<char>,
    /// Command number (`1` for `G1`, `1.1` style sub-codes keep the fraction).
    pub code: f64,
    /// Parameters, upper-case letter and value.
    pub params: Vec<(char, f64)>,
}

impl Line {
    /// The value of parameter `c`, if present.
    pub fn get(&self, c: char) -> Option<f64> {
        self.params.iter().find(|(k, _)| *k == c).map(|(_, v)| *v)
    }

    /// Whether the line is command `letter` `code` (e.g. `G`, 1).
    pub fn is(&self, letter: char, code: f64) -> bool {
        self.letter == Some(letter) && self.code == code
    }
}

/// A problem found while reading or replaying, with its line.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Diagnostic {
    /// 1-based line number.
    pub line: usize,
    /// What is wrong.
    pub message: String,
}

/// Parses a whole file. Lines that cannot be read produce diagnostics and
/// are skipped.
pub fn parse(text: &str, diags: &mut Vec<Diagnostic>) -> Vec<Line> {
    let mut parser = LineParser::default();
    let mut line = Line::empty();
    let mut out = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        if parser.parse(raw, i + 1, diags, &mut line) {
            out.push(line.clone());
        }
    }
    out
}

impl Line {
    /// A line with no command, for [`LineParser::parse`] to fill.
    pub fn empty() -> Line {
        Line {
            line: 0,
            letter: None,
            code: 0.0,
            params: Vec::new(),
        }
    }
}

/// Reads lines one at a time into a [`Line`] it reuses, so reading a file
/// allocates nothing per line once its buffers have grown.
#[derive(Debug, Default)]
pub struct LineParser {
    clean: String,
    /// Whose reading of an exponent (`Z5e-05`) to follow.
    pub firmware: crate::Firmware,
    /// Numbers in exponent form met so far, with the line of the first:
    /// firmwares read them differently, so each is a failure.
    pub ambiguous: crate::Count,
    /// Moves (G0–G3) with a number no firmware reads as written (`X-`,
    /// `X-inf`): Marlin reads 0 and moves there, so each is a failure.
    pub unreadable: crate::Count,
}

/// Whether a line's command, after any `N` line number, is a move: G0,
/// G1, G2 or G3 (`G01` too).
fn is_move(raw: &str) -> bool {
    let s = raw.trim_start();
    let s = match s.strip_prefix(['N', 'n']) {
        Some(rest) => rest
            .trim_start_matches(|c: char| c.is_ascii_digit())
            .trim_start(),
        None => s,
    };
    let Some(rest) = s.strip_prefix(['G', 'g']) else {
        return false;
    };
    let digits: String = rest
        .trim_start()
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    matches!(digits.trim_start_matches('0'), "" | "1" | "2" | "3") && !digits.is_empty()
}

/// Whether `s` from byte `i` on starts an exponent: `e` or `E`, then a
/// digit, or a sign and a digit.
fn exponent_at(s: &[u8], i: usize) -> bool {
    matches!(s.get(i), Some(b'e' | b'E'))
        && match s.get(i + 1) {
            Some(b'+' | b'-') => s.get(i + 2).is_some_and(u8::is_ascii_digit),
            Some(c) => c.is_ascii_digit(),
            None => false,
        }
}

/// The char at byte `i` of `s` and its length.
fn char_at(s: &str, i: usize) -> (char, usize) {
    let b = s.as_bytes()[i];
    if b < 0x80 {
        (b as char, 1)
    } else {
        let c = s[i..].chars().next().unwrap_or('\u{fffd}');
        (c, c.len_utf8())
    }
}

/// The first byte index from `i` on whose char is not `keep` (or the end).
fn skip_while(s: &str, mut i: usize, keep: impl Fn(char) -> bool) -> usize {
    while i < s.len() {
        let (c, cl) = char_at(s, i);
        if !keep(c) {
            break;
        }
        i += cl;
    }
    i
}

/// A plain decimal (`-12.345`, `7`, `.5`) of at most 15 significant
/// digits, read exactly: the digits as an integer divided by a power of
/// ten, both exact in `f64`, so the one rounding gives the same value as
/// `str::parse`. `None` for anything else (exponents, more digits), which
/// `str::parse` then reads.
fn decimal(s: &[u8]) -> Option<f64> {
    match number(s, 0) {
        (v, end) if end == s.len() => v,
        _ => None,
    }
}

fn ends_word(c: char) -> bool {
    c.is_ascii_alphabetic() || c.is_whitespace()
}

impl LineParser {
    /// Parses line `n` (1-based) of a file into `out`. Returns false, with
    /// a diagnostic when it is not just empty, when the line holds no
    /// command.
    pub fn parse(
        &mut self,
        raw: &str,
        n: usize,
        diags: &mut Vec<Diagnostic>,
        out: &mut Line,
    ) -> bool {
        self.parse_bytes(raw.as_bytes(), n, diags, out)
    }

    /// [`LineParser::parse`] of a line as bytes. A plain line is read as
    /// it is; any other is first made text (bytes that are not UTF-8
    /// replaced, as by `String::from_utf8_lossy`).
    pub(crate) fn parse_bytes(
        &mut self,
        raw: &[u8],
        n: usize,
        diags: &mut Vec<Diagnostic>,
        out: &mut Line,
    ) -> bool {
        out.params.clear();
        if !plain_words(raw, &mut out.params) {
            out.params.clear();
            // Borrowed, not copied, when the bytes are UTF-8.
            if !self.words(&String::from_utf8_lossy(raw), n, diags, &mut out.params) {
                return false;
            }
        }
        let words = &mut out.params;
        let mut first = usize::from(words.first().is_some_and(|(c, _)| *c == 'N'));
        let Some(&head) = words.get(first) else {
            words.clear();
            return false;
        };
        let (letter, code) = match head {
            (c @ ('G' | 'M' | 'T'), v) => {
                first += 1;
                (Some(c), v)
            }
            _ => (None, 0.0),
        };
        if first > 0 {
            let n = words.len() - first;
            words.copy_within(first.., 0);
            words.truncate(n);
        }
        out.line = n;
        out.letter = letter;
        out.code = code;
        true
    }

    /// The words of any line (checksums, both kinds of comment, a space
    /// between a letter and its number, any number `str::parse` reads) into
    /// `params`. False, with a diagnostic, for a line that cannot be read.
    fn words(
        &mut self,
        raw: &str,
        n: usize,
        diags: &mut Vec<Diagnostic>,
        params: &mut Vec<(char, f64)>,
    ) -> bool {
        // Checksum: XOR of every byte before '*'.
        let mut body = raw;
        if let Some(star) = raw.find('*') {
            let before = &raw[..star];
            if !before.contains(';') {
                let want: u8 = before.bytes().fold(0, |a, b| a ^ b);
                let rest = &raw[star + 1..];
                let end = rest
                    .find(|c: char| !c.is_ascii_digit())
                    .unwrap_or(rest.len());
                match rest[..end].parse::<u16>() {
                    Ok(got) if got == want as u16 => {}
                    _ => diags.push(Diagnostic {
                        line: n,
                        message: format!("checksum mismatch (expected {want})"),
                    }),
                }
                body = before;
            }
        }
        // Strip comments: a `;` comment is a cut, `( )` ones need a copy.
        let s = if body.contains('(') {
            self.clean.clear();
            let mut in_paren = false;
            for c in body.chars() {
                match c {
                    ';' if !in_paren => break,
                    '(' => in_paren = true,
                    ')' if in_paren => in_paren = false,
                    _ if !in_paren => self.clean.push(c),
                    _ => {}
                }
            }
            self.clean.as_str()
        } else {
            body.split_once(';').map_or(body, |(code, _)| code)
        };
        let len = s.len();
        let mut i = 0;
        while i < len {
            let (c, cl) = char_at(s, i);
            if c.is_whitespace() {
                i += cl;
                continue;
            }
            if !c.is_ascii_alphabetic() {
                diags.push(Diagnostic {
                    line: n,
                    message: format!("unexpected character `{c}`"),
                });
                return false;
            }
            let letter = c.to_ascii_uppercase();
            i += 1;
            let start = i;
            i = skip_while(s, start, |c| !ends_word(c));
            // Allow "X 10" (space between letter and number).
            let mut num = &s[start..i];
            let mut num_start = start;
            if num.is_empty() {
                let s2 = skip_while(s, i, char::is_whitespace);
                let j = skip_while(s, s2, |c| !ends_word(c));
                let first = s.as_bytes().get(s2).copied().unwrap_or(b' ');
                if j > s2 && (first.is_ascii_digit() || matches!(first, b'-' | b'+' | b'.')) {
                    num = &s[s2..j];
                    num_start = s2;
                    i = j;
                }
            }
            let digits = num.bytes().any(|b| b.is_ascii_digit())
                && num
                    .bytes()
                    .all(|b| b.is_ascii_digit() || matches!(b, b'.' | b'-' | b'+'));
            if digits && exponent_at(s.as_bytes(), i) {
                let j = skip_while(s, i + 2, |c| c.is_ascii_digit());
                let whole = &s[num_start..j];
                let marlin = whole.trim().parse::<f64>().unwrap_or(f64::NAN);
                let exp = &s[i + 1..j];
                self.ambiguous.add(n, 0.0);
                diags.push(Diagnostic {
                    line: n,
                    message: format!(
                        "`{letter}{}` reads as {letter}{marlin} in Marlin and RepRapFirmware but as {letter}{} E{exp} in Klipper; write plain decimals",
                        whole.trim(),
                        num.trim()
                    ),
                });
                if self.firmware.reads_exponents() {
                    num = whole;
                    i = j;
                }
            }
            let value = if num.is_empty() {
                0.0
            } else if let Some(v) = decimal(num.as_bytes()) {
                v
            } else {
                match num.parse::<f64>() {
                    Ok(v) if v.is_finite() => v,
                    _ => {
                        let on_move = is_move(raw);
                        if on_move {
                            self.unreadable.add(n, 0.0);
                        }
                        diags.push(Diagnostic {
                            line: n,
                            message: if on_move {
                                format!("`{letter}{num}` is not a number: Marlin reads {letter}0 and moves there")
                            } else {
                                format!("`{letter}{num}` is not a number")
                            },
                        });
                        return false;
                    }
                }
            };
            params.push((letter, value));
        }
        true
    }
}

/// ASCII whitespace as `char::is_whitespace` has it (with vertical tab).
fn space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | 0x0b | 0x0c | b'\r')
}

/// The words of a plain line, the kind writers print: ASCII letters each
/// followed by a plain decimal of at most 15 digits, separated by
/// whitespace, up to a `;` comment. False when the line holds anything
/// else (a checksum, a `( )` comment, other bytes or numbers): then
/// [`LineParser::words`] reads it, with the same result for a line this
/// reads. One pass over the bytes.
fn plain_words(raw: &[u8], params: &mut Vec<(char, f64)>) -> bool {
    let mut i = 0;
    while let Some(&b) = raw.get(i) {
        i += 1;
        if space(b) {
            continue;
        }
        if b == b';' {
            return true;
        }
        if !b.is_ascii_alphabetic() {
            return false;
        }
        let (v, end) = number(raw, i);
        let Some(v) = v else { return false };
        if exponent_at(raw, end) {
            return false;
        }
        params.push((char::from(b.to_ascii_uppercase()), v));
        i = end;
    }
    true
}

/// A plain decimal in `s` from byte `i` on (sign, digits, at most one
/// `.`), up to a letter, whitespace, `;` or the end: the value (`None` if
/// there were no digits, more than 15, or another byte) and the index of
/// the byte after it.
fn number(s: &[u8], mut i: usize) -> (Option<f64>, usize) {
    const POW10: [f64; 16] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    ];
    let neg = s.get(i) == Some(&b'-');
    if matches!(s.get(i), Some(b'-' | b'+')) {
        i += 1;
    }
    let start = i;
    // The index of the `.`; `usize::MAX` when there is none (cheaper than
    // an `Option`: docs/PERFORMANCE.md, "The checker's micro-choices").
    let mut dot = usize::MAX;
    let mut m = 0u64;
    while let Some(&c) = s.get(i) {
        let d = c.wrapping_sub(b'0');
        if d < 10 {
            // Wraps only past 19 digits, which are rejected below.
            m = m.wrapping_mul(10).wrapping_add(u64::from(d));
        } else if c == b'.' && dot == usize::MAX {
            dot = i;
        } else {
            break;
        }
        i += 1;
    }
    let (n, frac) = if dot == usize::MAX {
        (i - start, 0)
    } else {
        (i - start - 1, i - dot - 1)
    };
    let ends = s
        .get(i)
        .is_none_or(|&c| c.is_ascii_alphabetic() || space(c) || c == b';');
    if n == 0 || n > 15 || !ends {
        return (None, i);
    }
    let v = m as f64 / POW10[frac];
    (Some(if neg { -v } else { v }), i)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_words_comments_numbers_and_checksums() {
        let mut d = vec![];
        let text = "; header\nN10 G1 X1.5 Y-2 E0.1 ; move\nG1 (inline) Z3\nN3 T0*57\nM82\n";
        let l = parse(text, &mut d);
        assert_eq!(l.len(), 4, "{l:?}");
        assert!(l[0].is('G', 1.0));
        assert_eq!(l[0].get('X'), Some(1.5));
        assert_eq!(l[0].get('Y'), Some(-2.0));
        assert_eq!(l[0].line, 2);
        assert_eq!(l[1].get('Z'), Some(3.0));
        assert!(l[3].is('M', 82.0));
        // "N3 T0" XOR = 57.
        assert!(d.is_empty(), "{d:?}");
    }

    #[test]
    fn decimals_read_as_str_parse_reads_them() {
        for t in [
            "0",
            "-0",
            "7",
            "+7",
            ".5",
            "5.",
            "-12.345",
            "123.45678",
            "0.1",
            "0.30000",
            "199.999",
            "-0.00001",
            "999999999999999",
            "1234567.89012345",
        ] {
            let want: f64 = t.parse().unwrap();
            assert_eq!(
                decimal(t.as_bytes()).map(f64::to_bits),
                Some(want.to_bits()),
                "{t}"
            );
        }
        for t in [
            "",
            "-",
            ".",
            "1e5",
            "1.2.3",
            "12a",
            "1234567890123456",
            "--1",
        ] {
            assert_eq!(decimal(t.as_bytes()), None, "{t}");
        }
        // Every value the G-code writer prints (3 and 5 decimals) agrees.
        for k in (0..2_000_000u64).step_by(7) {
            for t in [
                format!("{:.3}", k as f64 / 1000.0),
                format!("{:.5}", k as f64 / 1e5),
            ] {
                let want: f64 = t.parse().unwrap();
                assert_eq!(decimal(t.as_bytes()), Some(want), "{t}");
            }
        }
    }

    #[test]
    fn plain_lines_read_as_the_general_reader_reads_them() {
        // Lines from pieces, and random byte strings over G-code's alphabet.
        let pieces = [
            "G1", " X12.5", " Y-3", "E0.00001", " ;c", "\t", "N7 ", "x.5", " Z", "F", "1e3", "*",
            "(p)", "é", " 2", "\u{b}", "--1", "M82", ";a*(", "1.2.3", "G0",
        ];
        let alphabet = b"GXYZEFNMT gxe0123456789.-+;*()\t\x0b\r";
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rand = move |n: usize| (crate::xorshift(&mut seed) % n as u64) as usize;
        let mut plain = 0;
        for k in 0..40_000 {
            let line: String = if k % 2 == 0 {
                (0..rand(6)).map(|_| pieces[rand(pieces.len())]).collect()
            } else {
                (0..rand(24))
                    .map(|_| char::from(alphabet[rand(alphabet.len())]))
                    .collect()
            };
            let mut fast = Vec::new();
            if plain_words(line.as_bytes(), &mut fast) {
                plain += 1;
                let (mut general, mut d) = (Vec::new(), Vec::new());
                assert!(LineParser::default().words(&line, 1, &mut d, &mut general));
                assert_eq!(fast, general, "{line:?}");
                assert!(d.is_empty(), "{line:?}: {d:?}");
            }
        }
        // Both kinds are met often.
        assert!(plain > 8_000 && plain < 32_000, "{plain}");
    }

    #[test]
    fn bad_checksum_and_garbage_are_diagnosed_with_lines() {
        let mut d = vec![];
        let l = parse("N3 T0*58\nG1 X1..2\n#?\n", &mut d);
        assert_eq!(l.len(), 1);
        assert_eq!(d.len(), 3, "{d:?}");
        assert_eq!((d[0].line, d[1].line, d[2].line), (1, 2, 3));
    }
}
