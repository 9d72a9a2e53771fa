//! "Did you mean …": the nearest of the names accepted at a place to a name that is not
//! accepted there (a misspelt key, curve name, subcommand or flag), by the optimal string
//! alignment distance (Damerau–Levenshtein without repeated edits of a substring, from the
//! `strsim` crate).

/// The accepted name nearest to `word`, when it is near enough to be a likely typo: at most
/// one edit (an insertion, deletion, substitution or swap of neighbours) for names of up to four
/// characters, two up to eight, three beyond; a name that differs only in case always is. Ties
/// go to the first candidate.
pub fn nearest<'a>(word: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let lower = word.to_lowercase();
    let allowed = match word.chars().count() {
        0 => return None,
        1..=4 => 1,
        5..=8 => 2,
        _ => 3,
    };
    let mut best: Option<(usize, &str)> = None;
    for c in candidates {
        if c == word {
            continue;
        }
        let d = strsim::osa_distance(&lower, &c.to_lowercase());
        if d <= allowed && best.is_none_or(|(b, _)| d < b) {
            best = Some((d, c));
        }
    }
    best.map(|(_, c)| c)
}

/// A parser message with a suggestion added: for "unknown field `X`, expected one of `a`, `b`"
/// and "unknown variant `X`, expected …" (serde's words, with the design file's "(or one of
/// c, d)" for keys every curve accepts), the nearest accepted name as "; did you mean `a`?".
/// Other messages are returned unchanged.
pub fn with_suggestion(message: &str) -> String {
    let Some((word, rest)) = ["unknown field `", "unknown variant `"]
        .iter()
        .find_map(|p| message.find(p).map(|i| &message[i + p.len()..]))
        .and_then(|s| s.split_once('`'))
    else {
        return message.to_string();
    };
    let mut candidates: Vec<&str> = rest.split('`').skip(1).step_by(2).collect();
    if let Some(i) = rest.find("(or one of ") {
        let list = &rest[i + "(or one of ".len()..];
        let list = list.split(')').next().unwrap_or("");
        candidates.extend(list.split(", ").map(str::trim));
    }
    match nearest(word, candidates) {
        Some(c) => format!("{message}; did you mean `{c}`?"),
        None => message.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn typos_find_their_name_and_strangers_none() {
        let keys = ["radius", "center", "normal", "type"];
        assert_eq!(nearest("radus", keys), Some("radius"));
        assert_eq!(nearest("raidus", keys), Some("radius"));
        assert_eq!(nearest("centre", keys), Some("center"));
        assert_eq!(nearest("Normal", keys), Some("normal"));
        assert_eq!(nearest("typ", keys), Some("type"));
        assert_eq!(nearest("colour", ["color", "cols"]), Some("color"));
        assert_eq!(
            nearest("surfce", ["surface", "render", "check"]),
            Some("surface")
        );
        assert_eq!(nearest("height", keys), None);
        assert_eq!(nearest("xy", keys), None);
        assert_eq!(nearest("", keys), None);
        // The nearer of two candidates wins.
        assert_eq!(nearest("radiux", ["radii", "radius"]), Some("radius"));
    }

    #[test]
    fn serde_messages_get_the_nearest_name() {
        let m = "unknown field `radus`, expected one of `center`, `radius`, `normal`";
        assert_eq!(with_suggestion(m), format!("{m}; did you mean `radius`?"));
        let m = "unknown field `v_orign`, expected `radius` (or one of transform, v_origin, arc_length)";
        assert!(
            with_suggestion(m).ends_with("did you mean `v_origin`?"),
            "{}",
            with_suggestion(m)
        );
        let m = "unknown variant `circel`, expected one of `circle`, `ellipse`";
        assert!(with_suggestion(m).ends_with("did you mean `circle`?"));
        let m = "unknown field `zzzzzz`, expected one of `center`, `radius`";
        assert_eq!(with_suggestion(m), m);
        assert_eq!(
            with_suggestion("invalid type: a table"),
            "invalid type: a table"
        );
    }
}
