//! Messages that quote input: never the whole of it.

use std::borrow::Cow;

/// The most characters of input a message quotes ([`clip_text`]).
pub const MAX_QUOTED_CHARS: usize = 120;

/// `text` as a message may quote it: whole when it has at most `max` characters, else its
/// first `max` characters followed by `… (N more characters)`. A damaged file can hold a
/// string of any size; errors quote it through this, so their length stays bounded.
pub fn clip_text(text: &str, max: usize) -> Cow<'_, str> {
    match text.char_indices().nth(max) {
        None => Cow::Borrowed(text),
        Some((cut, _)) => {
            let rest = text[cut..].chars().count();
            Cow::Owned(format!("{}… ({rest} more characters)", &text[..cut]))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_text_is_quoted_whole() {
        assert_eq!(clip_text("abc", 3), "abc");
        assert_eq!(clip_text("", 0), "");
    }

    #[test]
    fn long_text_is_cut_on_a_character_boundary_and_says_how_much_is_left() {
        assert_eq!(clip_text("abcdef", 2), "ab… (4 more characters)");
        // Multi-byte characters are counted as characters, never split.
        assert_eq!(clip_text("ééééé", 3), "ééé… (2 more characters)");
        let huge = "x".repeat(10_000_000);
        assert!(clip_text(&huge, MAX_QUOTED_CHARS).len() < 200);
    }
}
