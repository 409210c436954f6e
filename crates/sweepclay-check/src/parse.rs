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
    const POW10: [f64; 16] = [
        1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    ];
    let (neg, digits) = match s.first()? {
        b'-' => (true, &s[1..]),
        b'+' => (false, &s[1..]),
        _ => (false, s),
    };
    let (mut m, mut n, mut frac, mut dot) = (0u64, 0usize, 0usize, false);
    for &b in digits {
        match b {
            b'0'..=b'9' => {
                m = m * 10 + u64::from(b - b'0');
                n += 1;
                frac += usize::from(dot);
            }
            b'.' if !dot => dot = true,
            _ => return None,
        }
        if n > 15 {
            return None;
        }
    }
    if n == 0 {
        return None;
    }
    let v = m as f64 / POW10[frac];
    Some(if neg { -v } else { v })
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
        out.params.clear();
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
            if num.is_empty() {
                let s2 = skip_while(s, i, char::is_whitespace);
                let j = skip_while(s, s2, |c| !ends_word(c));
                let first = s.as_bytes().get(s2).copied().unwrap_or(b' ');
                if j > s2 && (first.is_ascii_digit() || matches!(first, b'-' | b'+' | b'.')) {
                    num = &s[s2..j];
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
                        diags.push(Diagnostic {
                            line: n,
                            message: format!("`{letter}{num}` is not a number"),
                        });
                        return false;
                    }
                }
            };
            out.params.push((letter, value));
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
            words.drain(..first);
        }
        out.line = n;
        out.letter = letter;
        out.code = code;
        true
    }
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
    fn bad_checksum_and_garbage_are_diagnosed_with_lines() {
        let mut d = vec![];
        let l = parse("N3 T0*58\nG1 X1..2\n#?\n", &mut d);
        assert_eq!(l.len(), 1);
        assert_eq!(d.len(), 3, "{d:?}");
        assert_eq!((d[0].line, d[1].line, d[2].line), (1, 2, 3));
    }
}
