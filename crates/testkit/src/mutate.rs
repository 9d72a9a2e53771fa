//! The seeded mutator of the mutation campaign, shared by the in-process campaign
//! (`pdeshape`'s `campaign` tests) and the runs through the binary (`pdeshape-cli`'s `robust`
//! and `campaign` tests); the designs it mutates are [`crate::example_designs`].

use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// Longest acceptable message, in characters.
pub const MAX_MESSAGE: usize = 600;

/// Values a mutant puts in place of a number: extreme, degenerate, of the wrong type.
const VALUES: &[&str] = &[
    "0",
    "-1",
    "1e-320",
    "2.2e-308",
    "1e308",
    "-1e308",
    "99999999999",
    "4294967296",
    "nan",
    "inf",
    "-inf",
    "0.5",
    "1e-7",
    "2e6",
    "1.5",
    "3",
    "\"x\"",
    "true",
    "[]",
    "{}",
    "[1.0, 2.0]",
    "\"((((((((((u))))))))))\"",
    "1e-300",
    "-0.0",
    "65",
    "100000",
    "\"\"",
];

/// One mutant of `text`.
pub fn mutate(text: &str, rng: &mut ChaCha8Rng) -> String {
    let mut t: Vec<char> = text.chars().collect();
    let kind = rng.gen_range(0..10);
    match kind {
        // Syntax damage: delete, insert a character, truncate.
        0 if !t.is_empty() => {
            let i = rng.gen_range(0..t.len());
            t.remove(i);
        }
        1 => {
            let i = rng.gen_range(0..=t.len());
            let c = [
                '\r', '\u{7f}', '=', '[', ']', '"', '{', '}', ',', '\n', '#', '\'', '\0', 'é',
            ];
            t.insert(i, c[rng.gen_range(0..c.len())]);
        }
        2 => {
            let i = rng.gen_range(0..=t.len());
            t.truncate(i);
        }
        // Duplicate or drop a line.
        3 | 4 => {
            let lines: Vec<&str> = text.lines().collect();
            if lines.is_empty() {
                return text.to_string();
            }
            let i = rng.gen_range(0..lines.len());
            let mut out: Vec<&str> = lines.clone();
            if kind == 3 {
                out.insert(i, lines[i]);
            } else {
                out.remove(i);
            }
            return out.join("\n") + "\n";
        }
        // Replace a number (or a quoted value) by an extreme or wrongly typed value.
        _ => {
            let s: String = t.iter().collect();
            let spans = value_spans(&s);
            if spans.is_empty() {
                return s;
            }
            let (a, b) = spans[rng.gen_range(0..spans.len())];
            let v = if rng.gen_range(0..40) == 0 {
                // A huge string or array.
                if rng.gen_bool(0.5) {
                    format!("\"{}\"", "w".repeat(rng.gen_range(5000..200_000)))
                } else {
                    format!("[{}]", vec!["1.0"; rng.gen_range(1000..120_000)].join(","))
                }
            } else {
                VALUES[rng.gen_range(0..VALUES.len())].to_string()
            };
            return format!("{}{}{}", &s[..a], v, &s[b..]);
        }
    }
    t.into_iter().collect()
}

/// Byte spans of numbers and double-quoted strings outside comments.
fn value_spans(s: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    for (start, line) in line_starts(s) {
        let code = line.split('#').next().unwrap_or("");
        let b = code.as_bytes();
        let mut i = 0;
        while i < b.len() {
            let c = b[i];
            let prev_ok = i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
            if c == b'"' {
                let j = code[i + 1..].find('"').map_or(b.len(), |k| i + 1 + k + 1);
                spans.push((start + i, start + j.min(b.len())));
                i = j.max(i + 1);
            } else if prev_ok && (c.is_ascii_digit() || c == b'-') {
                let mut j = i + 1;
                while j < b.len() && (b[j].is_ascii_alphanumeric() || b"._+-".contains(&b[j])) {
                    j += 1;
                }
                spans.push((start + i, start + j));
                i = j;
            } else {
                i += 1;
            }
        }
    }
    spans
}

fn line_starts(s: &str) -> Vec<(usize, &str)> {
    let mut out = Vec::new();
    let mut pos = 0;
    for line in s.split_inclusive('\n') {
        out.push((pos, line.trim_end_matches('\n')));
        pos += line.len();
    }
    out
}

/// Why a message is unclear, if it is.
pub fn unclear(message: &str) -> Option<&'static str> {
    let body = message.rsplit_once(": ").map_or(message, |(_, m)| m);
    if message.trim().is_empty() || body.trim().is_empty() {
        return Some("empty");
    }
    if message.chars().count() > MAX_MESSAGE {
        return Some("over-long");
    }
    if message.contains(".pdeshape-") && message.contains(".tmp") {
        return Some("temporary path");
    }
    for word in message.split(|c: char| !(c.is_alphanumeric() || c == '_')) {
        if matches!(
            word,
            "f64"
                | "f32"
                | "usize"
                | "u64"
                | "u32"
                | "u8"
                | "i64"
                | "i32"
                | "isize"
                | "struct"
                | "enum"
                | "untagged"
                | "FormulaText"
                | "Vec"
                | "Option"
                | "String"
        ) || (word.ends_with("Spec") && word.len() > 4)
        {
            return Some("Rust type name");
        }
    }
    None
}

/// The edge of the operating system a mutant's run meets besides its mutated input: the classes
/// of special files, aliasing outputs and signals between outputs. The campaign through the
/// binary makes the edge in the mutant's directory before the run (or sends the signal during
/// it) and judges what is left.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Edge {
    /// Nothing but the mutated input.
    Plain,
    /// The first output is an existing FIFO: refused, left a FIFO.
    OutputFifo,
    /// The first output is an existing directory: refused, left as it was.
    OutputDirectory,
    /// The first output is a loop of two symbolic links: refused, left as it was.
    OutputLoop,
    /// The second output is a symbolic link to the first: refused before any work.
    OutputsAlias,
    /// The input is a FIFO without a writer: refused, not waited on.
    InputFifo,
    /// SIGTERM after this many milliseconds: the run ends with all its outputs or none.
    Signal(u64),
}

/// The edge of one mutant: three in four runs are plain, the others take one class in turn.
pub fn edge(rng: &mut ChaCha8Rng) -> Edge {
    if rng.gen_range(0..4) != 0 {
        return Edge::Plain;
    }
    match rng.gen_range(0..6) {
        0 => Edge::OutputFifo,
        1 => Edge::OutputDirectory,
        2 => Edge::OutputLoop,
        3 => Edge::OutputsAlias,
        4 => Edge::InputFifo,
        _ => Edge::Signal(rng.gen_range(0..600)),
    }
}
