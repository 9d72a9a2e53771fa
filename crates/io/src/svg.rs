//! Text placed in SVG documents: the plots of dynamic-curve runs, of animations' measures and
//! of fits' bytes against distance.

/// `text` with the characters XML reserves (`&`, `<`, `>`, `"`) written as entities, for an
/// element's text or an attribute's value.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    #[test]
    fn reserved_characters_become_entities() {
        assert_eq!(
            super::escape(r#"a < b & "c" > d"#),
            "a &lt; b &amp; &quot;c&quot; &gt; d"
        );
        // `&` first: an entity is not escaped twice.
        assert_eq!(super::escape("&lt;"), "&amp;lt;");
    }
}
