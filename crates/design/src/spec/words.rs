//! The parser's messages in a designer's words: no Rust type names (`f64`, `usize`, `struct
//! SplineSpec`, `untagged enum FormulaText`), never empty, long quoted values shortened.

/// Longest quoted value kept whole in a message, in characters.
pub const MAX_QUOTED: usize = 60;

/// Longest user-supplied text (a name, a path) printed whole in a message, in characters.
pub const MAX_USER_TEXT: usize = 80;

/// A user-supplied text (a curve or patch name, a key, a path) as a message shows it: as typed,
/// without quotes added or escapes of the programming language, except that control and
/// invisible characters (a byte order mark, zero-width spaces, line breaks) are shown as
/// `<U+FEFF>`; longer than [`MAX_USER_TEXT`] characters, it is cut there with an ellipsis and
/// its length. Messages put it between their own quotes.
pub fn user_text(s: &str) -> String {
    let invisible = |c: char| {
        c.is_control()
            || matches!(c, '\u{200B}'..='\u{200F}' | '\u{2028}'..='\u{202E}' | '\u{2060}'..='\u{2064}' | '\u{FEFF}')
    };
    let n = s.chars().count();
    let mut out = String::new();
    for c in s.chars().take(MAX_USER_TEXT) {
        if invisible(c) {
            out.push_str(&format!("<U+{:04X}>", c as u32));
        } else {
            out.push(c);
        }
    }
    if n > MAX_USER_TEXT {
        out.push_str(&format!("… ({n} characters)"));
    }
    out
}

/// A number as a message shows it: plain for moderate magnitudes, short scientific form
/// otherwise (`1e308`, not 309 digits).
pub fn number(x: f64) -> String {
    crate::check::num(x)
}

/// What a Rust type of the design file is called in a message.
fn type_words(name: &str) -> &'static str {
    match name {
        "f64" | "f32" => "a number",
        "usize" | "u64" | "u32" | "u16" | "u8" => "a whole number ≥ 0",
        "i64" | "i32" | "i16" | "i8" | "isize" => "a whole number",
        "bool" => "true or false",
        "char" | "String" | "str" => "a text",
        "FormulaText" => "a formula (a text) or a number",
        "CurveRef" => "a curve name or an inline curve table",
        _ => "a value of another form (see docs/design-file.md)",
    }
}

/// Rewrites a serde/TOML message in plain words (see the module docs).
pub fn plain(message: &str) -> String {
    let mut s = message.trim().to_string();
    if s.is_empty() {
        return "this is not valid TOML here (an unexpected character or end of file)".to_string();
    }
    // Untagged enums and structs first: their names are Rust names.
    for prefix in [
        "data did not match any variant of untagged enum ",
        "expected struct ",
        "expected tuple struct ",
        "expected enum ",
        "expected unit struct ",
    ] {
        while let Some(i) = s.find(prefix) {
            let rest = &s[i + prefix.len()..];
            let end = rest
                .find(|c: char| !(c.is_alphanumeric() || c == '_'))
                .unwrap_or(rest.len());
            let name = &rest[..end];
            let words = if prefix.starts_with("expected enum") {
                "one of the names allowed here"
            } else if prefix.starts_with("data did not") {
                type_words(name)
            } else {
                match type_words(name) {
                    w if w.starts_with("a value of another") => "a table",
                    w => w,
                }
            };
            s = format!("{}expected {words}{}", &s[..i], &rest[end..]);
        }
    }
    // Primitive type names after "expected".
    for t in [
        "f64", "f32", "usize", "u64", "u32", "u16", "u8", "i64", "i32", "i16", "i8", "isize",
        "bool", "char",
    ] {
        s = replace_word(
            &s,
            &format!("expected {t}"),
            &format!("expected {}", type_words(t)),
        );
    }
    s = s
        .replace("invalid type: map", "invalid type: a table")
        .replace("invalid type: sequence", "invalid type: an array")
        .replace("expected a map", "expected a table")
        .replace("expected a sequence", "expected an array")
        .replace("floating point `", "number `")
        .replace(
            "number too large to fit in target type",
            "the number is too large",
        );
    shorten_quoted(&s)
}

/// Replaces `from` when it is followed by a non-identifier character (or the end).
fn replace_word(s: &str, from: &str, to: &str) -> String {
    let mut out = String::new();
    let mut rest = s;
    while let Some(i) = rest.find(from) {
        let after = &rest[i + from.len()..];
        let boundary = after
            .chars()
            .next()
            .is_none_or(|c| !(c.is_alphanumeric() || c == '_'));
        out.push_str(&rest[..i]);
        out.push_str(if boundary { to } else { from });
        rest = after;
    }
    out.push_str(rest);
    out
}

/// Shortens values between backticks or double quotes longer than [`MAX_QUOTED`] characters.
pub fn shorten_quoted(s: &str) -> String {
    // A number quoted whole (`100000…0.0`, as the TOML reader quotes 1e308) in short form first.
    let s = &crate::check::short_numbers(s);
    let mut out = String::new();
    let mut chars = s.chars().peekable();
    while let Some(c) = chars.next() {
        out.push(c);
        if c == '`' || c == '"' {
            let mut inner = String::new();
            let mut closed = false;
            for d in chars.by_ref() {
                if d == c {
                    closed = true;
                    break;
                }
                inner.push(d);
            }
            let n = inner.chars().count();
            if n > MAX_QUOTED {
                let head: String = inner.chars().take(MAX_QUOTED).collect();
                out.push_str(&head);
                out.push_str(&format!("… ({n} characters)"));
            } else {
                out.push_str(&inner);
            }
            if closed {
                out.push(c);
            }
        }
    }
    // A very long message without quotes (an echoed line) is cut too.
    if out.chars().count() > 400 {
        let head: String = out.chars().take(400).collect();
        return format!("{head}…");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{number, plain, user_text, MAX_USER_TEXT};

    #[test]
    fn user_text_is_cut_and_shows_invisible_characters() {
        assert_eq!(user_text("rim"), "rim");
        assert_eq!(user_text("\u{feff}rim"), "<U+FEFF>rim");
        assert_eq!(user_text("a\nb"), "a<U+000A>b");
        let long = "r".repeat(4096);
        let cut = user_text(&long);
        assert_eq!(
            cut,
            format!("{}… (4096 characters)", "r".repeat(MAX_USER_TEXT))
        );
        assert_eq!(user_text(&"é".repeat(80)), "é".repeat(80));
        assert_eq!(number(1e308), "1e308");
        assert_eq!(number(2.5), "2.5");
    }

    #[test]
    fn rust_names_become_words() {
        assert_eq!(
            plain("invalid type: string \"x\", expected f64"),
            "invalid type: string \"x\", expected a number"
        );
        assert_eq!(
            plain("invalid value: integer `-1`, expected usize"),
            "invalid value: integer `-1`, expected a whole number ≥ 0"
        );
        assert_eq!(
            plain("data did not match any variant of untagged enum FormulaText"),
            "expected a formula (a text) or a number"
        );
        assert_eq!(
            plain("invalid type: string \"a\", expected struct SplineSpec"),
            "invalid type: string \"a\", expected a table"
        );
        assert_eq!(
            plain("invalid type: map, expected a sequence"),
            "invalid type: a table, expected an array"
        );
        assert_eq!(plain("expected u8s"), "expected u8s");
        assert!(!plain("").is_empty());
    }

    #[test]
    fn long_values_are_shortened() {
        let long = "y".repeat(1_000_000);
        let m = plain(&format!("invalid type: string \"{long}\", expected f64"));
        assert!(m.len() < 200, "{}", m.len());
        assert!(m.contains("… (1000000 characters)\""), "{m}");
    }
}
