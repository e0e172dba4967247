//! Text shown to people: values quoted in error messages are kept short, and strings that
//! come from outside (a board's name, a file's contents) never reach the terminal with their
//! control characters, so they cannot move the cursor or change its colours.

/// The most characters of a value an error message quotes.
pub const MAX_QUOTED_CHARS: usize = 80;

/// `value` in backquotes for an error message, with control characters escaped and cut to
/// [`MAX_QUOTED_CHARS`] characters (saying how long the whole was).
pub fn quote_value(value: &str) -> String {
    let total = value.chars().count();
    let shown: String = value.chars().take(MAX_QUOTED_CHARS).collect();
    if total > MAX_QUOTED_CHARS {
        format!("`{}…` ({total} characters)", escape_control(&shown))
    } else {
        format!("`{}`", escape_control(&shown))
    }
}

/// `text` with every control character (C0, DEL and C1, which terminals act on) written as
/// a Rust-style escape: `\n`, `\t`, `\u{1b}`. Printable text, including any other Unicode, is
/// kept as is.
pub fn escape_control(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '\n' => out.push_str("\\n"),
            '\r' => out.push_str("\\r"),
            '\t' => out.push_str("\\t"),
            c if c.is_control() => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(
            escape_control("a\u{1b}[31mred\u{7}"),
            "a\\u{1b}[31mred\\u{7}"
        );
        assert_eq!(escape_control("x\ny\u{9b}z"), "x\\ny\\u{9b}z");
        assert_eq!(escape_control("Zürich ✓"), "Zürich ✓");
    }

    #[test]
    fn long_values_are_cut() {
        let q = quote_value(&"a".repeat(10_000_000));
        assert!(q.chars().count() < 120, "{q}");
        assert!(q.contains("10000000 characters"));
        assert_eq!(quote_value("12x"), "`12x`");
    }
}
