//! From error paths back to lines and columns of the design file.

use crate::{Error, Result};
use toml_edit::{ImDocument, Item, Value};

/// Refuses NaN and infinite numbers anywhere in a parsed TOML value; the error names the path.
/// (The paths are spelled out only when there is an error to report.)
pub(crate) fn check_finite(value: &toml::Value, place: &str) -> Result<()> {
    if all_finite(value) {
        return Ok(());
    }
    find_not_finite(value, place)
}

/// Refuses an array of the file longer than what was read from it (`read`, the spec written
/// back as TOML): the reader takes a fixed-size array (a point's three coordinates, an edge's
/// two tangents) from the first items and would drop the rest unseen. Tables are compared on
/// the keys both have, arrays of equal length item by item; values read into another form (a
/// string for a table) are not compared. The error names the path.
pub(crate) fn check_lengths(file: &toml::Value, read: &toml::Value, place: &str) -> Result<()> {
    match (file, read) {
        (toml::Value::Array(a), toml::Value::Array(b)) => {
            if a.len() > b.len() {
                return Err(Error::invalid(format!(
                    "{} items where {} are expected",
                    a.len(),
                    b.len()
                ))
                .at(place));
            }
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                check_lengths(x, y, &format!("{place}[{i}]"))?;
            }
            Ok(())
        }
        (toml::Value::Table(a), toml::Value::Table(b)) => {
            for (k, x) in a {
                if let Some(y) = b.get(k) {
                    let p = if place.is_empty() {
                        key_path(k)
                    } else {
                        format!("{place}.{}", key_path(k))
                    };
                    check_lengths(x, y, &p)?;
                }
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Whether every number in the tree is finite.
fn all_finite(value: &toml::Value) -> bool {
    match value {
        toml::Value::Float(x) => x.is_finite(),
        toml::Value::Array(items) => items.iter().all(all_finite),
        toml::Value::Table(t) => t.values().all(all_finite),
        _ => true,
    }
}

/// [`check_finite`]'s walk, naming the path of the first number that is not finite.
fn find_not_finite(value: &toml::Value, place: &str) -> Result<()> {
    match value {
        toml::Value::Float(x) if !x.is_finite() => {
            Err(Error::invalid(format!("must be finite (got {x})")).at(place))
        }
        toml::Value::Array(items) => {
            for (i, item) in items.iter().enumerate() {
                find_not_finite(item, &format!("{place}[{i}]"))?;
            }
            Ok(())
        }
        toml::Value::Table(t) => {
            for (k, item) in t {
                let p = if place.is_empty() {
                    key_path(k)
                } else {
                    format!("{place}.{}", key_path(k))
                };
                find_not_finite(item, &p)?;
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// One step of a path such as `curves."my rim".center[1]`.
#[derive(Debug, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
}

fn parse_path(path: &str) -> Option<Vec<Step>> {
    let mut steps = Vec::new();
    let mut chars = path.chars().peekable();
    while let Some(&c) = chars.peek() {
        match c {
            '.' => {
                chars.next();
            }
            '[' => {
                chars.next();
                let mut digits = String::new();
                for d in chars.by_ref() {
                    if d == ']' {
                        break;
                    }
                    digits.push(d);
                }
                steps.push(Step::Index(digits.trim().parse().ok()?));
            }
            '"' => {
                chars.next();
                let mut key = String::new();
                while let Some(d) = chars.next() {
                    match d {
                        '"' => break,
                        '\\' => match chars.next()? {
                            e @ ('u' | 'U') => {
                                let n = if e == 'u' { 4 } else { 8 };
                                let hex: String = chars.by_ref().take(n).collect();
                                key.push(char::from_u32(u32::from_str_radix(&hex, 16).ok()?)?);
                            }
                            other => key.push(other),
                        },
                        _ => key.push(d),
                    }
                }
                steps.push(Step::Key(key));
            }
            _ => {
                let mut key = String::new();
                while let Some(&d) = chars.peek() {
                    if d == '.' || d == '[' {
                        break;
                    }
                    key.push(d);
                    chars.next();
                }
                steps.push(Step::Key(key));
            }
        }
    }
    Some(steps)
}

/// The 1-based line and column of the deepest part of `path` (e.g. `conditions[2].curve`) that
/// exists in the TOML `text`; `None` if the text does not parse or not even the first step exists.
pub fn locate(text: &str, path: &str) -> Option<(usize, usize)> {
    let doc = ImDocument::parse(text).ok()?;
    let steps = parse_path(path)?;
    walk_table(doc.as_table(), &steps, None).map(|r| line_col(text, r.start))
}

type Span = Option<std::ops::Range<usize>>;

/// Follows `steps` inside a table; returns the span of the deepest part found.
fn walk_table(table: &toml_edit::Table, steps: &[Step], best: Span) -> Span {
    let Some((Step::Key(k), rest)) = steps.split_first() else {
        return best;
    };
    let Some((key, next)) = table.get_key_value(k) else {
        return best;
    };
    let best = key.span().or_else(|| next.span()).or(best);
    match next {
        Item::Value(v) => walk_value(v, rest, best),
        Item::Table(t) => walk_table(t, rest, best),
        Item::ArrayOfTables(a) => match rest.split_first() {
            Some((Step::Index(i), rest)) => match a.get(*i) {
                Some(t) => walk_table(t, rest, t.span().or(best)),
                None => best,
            },
            _ => best,
        },
        Item::None => best,
    }
}

/// Follows `steps` inside a value (inline tables and arrays).
fn walk_value(mut value: &Value, steps: &[Step], mut best: Span) -> Span {
    for step in steps {
        match step {
            Step::Key(k) => {
                let Some((key, next)) = value
                    .as_inline_table()
                    .and_then(|t| Some((t.key(k)?, t.get(k)?)))
                else {
                    return best;
                };
                best = key.span().or_else(|| next.span()).or(best);
                value = next;
            }
            Step::Index(i) => {
                let Some(next) = value.as_array().and_then(|a| a.get(*i)) else {
                    return best;
                };
                best = next.span().or(best);
                value = next;
            }
        }
    }
    best
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// `file:line:col: place: message` for an error about the design file `text` named `file`. The
/// position comes from the error's place, or, for a TOML syntax error, from the parser.
pub fn describe_error(file: &str, text: &str, err: &Error) -> String {
    let position = if err.place().is_empty() {
        match toml::from_str::<toml::Table>(text) {
            Err(e) => e.span().map(|r| line_col(text, r.start)),
            Ok(_) => None,
        }
    } else {
        locate(text, err.place())
    };
    match position {
        Some((line, col)) => format!("{file}:{line}:{col}: {err}"),
        None => format!("{file}: {err}"),
    }
}

/// A TOML key as it appears in a path: bare if it can be, quoted otherwise.
pub fn key_path(key: &str) -> String {
    if !key.is_empty()
        && key
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        key.to_string()
    } else {
        // A TOML basic string (what the design file itself would write, and what
        // [`parse_path`] reads back): quotes and backslashes escaped, invisible characters as
        // `\uXXXX`. Not Rust's debug quoting (`\u{feff}` is not TOML).
        let mut out = String::from("\"");
        for c in key.chars() {
            match c {
                '"' => out.push_str("\\\""),
                '\\' => out.push_str("\\\\"),
                c if invisible(c) => {
                    let n = c as u32;
                    if n > 0xFFFF {
                        out.push_str(&format!("\\U{n:08X}"));
                    } else {
                        out.push_str(&format!("\\u{n:04X}"));
                    }
                }
                c => out.push(c),
            }
        }
        out.push('"');
        out
    }
}

/// Characters a key shows escaped: controls, line and paragraph separators, zero-width and
/// direction marks, the byte order mark.
fn invisible(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{00AD}' | '\u{200B}'..='\u{200F}' | '\u{2028}'..='\u{202E}' | '\u{2060}'..='\u{2064}' | '\u{FEFF}')
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed-size array written longer than it is (a point of four coordinates, an edge of
    /// three tangents) is refused with its place, where the reader would keep its first items;
    /// the same file with the right lengths is read.
    #[test]
    fn arrays_longer_than_their_fields_are_refused_with_their_place() {
        let layout = |point: &str, tangents: &str| {
            format!(
                "[[patchwork]]\nname = \"p\"\npoints = [{point}, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]\n\
                 normals = [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]\nedges = [\n\
                 {{ ends = [0, 1], tangents = {tangents} }},\n\
                 {{ ends = [1, 2], tangents = [[-1.0, 1.0, 0.0], [-1.0, 1.0, 0.0]] }},\n\
                 {{ ends = [0, 2], tangents = [[0.0, 1.0, 0.0], [0.0, 1.0, 0.0]] }},\n]\n\
                 faces = [[0, 1, 2]]\n"
            )
        };
        let good = "[[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]";
        let spec = crate::spec::parse_design(&layout("[0.0, 0.0, 0.0]", good)).unwrap();
        assert_eq!(spec.patchwork[0].points[0], [0.0, 0.0, 0.0]);
        let e = crate::spec::parse_design(&layout("[9.0, 0.0, 0.0, 0.0]", good)).unwrap_err();
        assert!(
            e.to_string()
                .contains("patchwork[0].points[0]: 4 items where 3 are expected"),
            "{e}"
        );
        let three = "[[1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]]";
        let e = crate::spec::parse_design(&layout("[0.0, 0.0, 0.0]", three)).unwrap_err();
        assert!(
            e.to_string()
                .contains("patchwork[0].edges[0].tangents: 3 items where 2 are expected"),
            "{e}"
        );
    }

    #[test]
    fn keys_with_invisible_characters_are_quoted_as_toml_and_read_back() {
        for (key, shown) in [
            ("\u{feff}rim", "\"\\uFEFFrim\""),
            ("my \"rim\"", "\"my \\\"rim\\\"\""),
            ("a\\b\n", "\"a\\\\b\\u000A\""),
        ] {
            let path = key_path(key);
            assert_eq!(path, shown);
            assert!(!path.contains("\\u{"), "{path}");
            // What the design file would write, and what the locator reads back.
            let toml_text = format!("{path} = 1\n");
            let table: toml::Table = toml::from_str(&toml_text).unwrap();
            assert!(table.contains_key(key), "{toml_text}");
            assert_eq!(
                parse_path(&format!("curves.{path}.radius")).unwrap(),
                vec![
                    Step::Key("curves".into()),
                    Step::Key(key.into()),
                    Step::Key("radius".into())
                ]
            );
        }
    }

    #[test]
    fn paths_parse() {
        assert_eq!(
            parse_path("curves.\"my rim\".center[1]").unwrap(),
            vec![
                Step::Key("curves".into()),
                Step::Key("my rim".into()),
                Step::Key("center".into()),
                Step::Index(1)
            ]
        );
    }

    #[test]
    fn locates_keys_values_and_array_tables() {
        let text = "title = \"x\"\n[curves.rim]\ntype = \"circle\"\ncenter = [0, 0, 1]\nradius = -1\n\
                    conditions = [\n  { u = 0.0, curve = \"a\" },\n  { u = 1.0, curve = \"rimm\" },\n]\n";
        assert_eq!(locate(text, "curves.rim.radius"), Some((5, 1)));
        assert_eq!(locate(text, "curves.rim.center[2]"), Some((4, 17)));
        assert_eq!(locate(text, "curves.rim.nothing"), Some((2, 9)));
        let text2 = "[[patches]]\nname = \"a\"\n[[patches]]\nname = \"b\"\nconditions = [ { u = 2.0, curve = \"x\" } ]\n";
        assert_eq!(locate(text2, "patches[1].conditions[0].u"), Some((5, 18)));
        assert_eq!(locate(text2, "patches[1].name"), Some((4, 1)));
    }
}
