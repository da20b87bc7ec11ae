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

/// The first `max` of `items` joined by ", ", followed by `, … (N more)` when there are more:
/// a message naming a list (DoF names, parameter names) read from a file stays bounded however
/// long the file's list is (a params file of 780,000 DoF names echoed 6.2 MB to stderr).
pub fn list_some<S: AsRef<str>>(items: &[S], max: usize) -> String {
    let mut out = items
        .iter()
        .take(max)
        .map(|s| clip_text(s.as_ref(), MAX_QUOTED_CHARS))
        .collect::<Vec<_>>()
        .join(", ");
    if items.len() > max {
        out.push_str(&format!(", … ({} more)", items.len() - max));
    }
    out
}

/// A number as a message quotes it: as Rust prints it (shortest exact digits) in the usual
/// range, in scientific notation when tiny or huge (`1e-300`, `1e300`: never 300 digits).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Num(pub f64);

impl std::fmt::Display for Num {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let v = self.0;
        if v.is_finite() && v != 0.0 && !(1e-5..1e16).contains(&v.abs()) {
            write!(f, "{v:e}")
        } else {
            write!(f, "{v}")
        }
    }
}

/// Any number as a message quotes it ([`Num`] for the floats that print long): integers and
/// short floats as they print, `1e300` rather than 301 digits.
pub fn quote_number<T: std::fmt::Display>(v: T) -> String {
    let text = v.to_string();
    match text.parse::<f64>() {
        Ok(x) if text.len() > 24 => Num(x).to_string(),
        _ => text,
    }
}

/// A length for a message: meters with two decimals, or in scientific notation when huge
/// (never a 309-digit number: `1e308` is `1.000e308 m`).
pub fn meters(v: f64) -> String {
    if v.abs() < 1e6 {
        format!("{v:.2} m")
    } else {
        format!("{v:.3e} m")
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn numbers_are_quoted_short_whatever_their_size() {
        assert_eq!(Num(1e-300).to_string(), "1e-300");
        assert_eq!(Num(1e300).to_string(), "1e300");
        assert_eq!(Num(-1.5e-7).to_string(), "-1.5e-7");
        assert_eq!(Num(0.2).to_string(), "0.2");
        assert_eq!(Num(50.0).to_string(), "50");
        assert_eq!(Num(0.0).to_string(), "0");
        assert_eq!(Num(f64::NAN).to_string(), "NaN");
        for v in [1e-300, 1e300, 1e308, 5e-324, 0.123456789] {
            assert!(Num(v).to_string().len() < 25, "{v}");
            assert_eq!(Num(v).to_string().parse::<f64>().unwrap(), v);
        }
    }
    use super::*;

    #[test]
    fn a_long_list_names_its_first_items_and_counts_the_rest() {
        assert_eq!(list_some(&["a", "b"], 8), "a, b");
        assert_eq!(list_some(&["a", "b", "c"], 2), "a, b, … (1 more)");
        let many: Vec<String> = (0..780_000).map(|i| format!("dof_{i}")).collect();
        let text = list_some(&many, 8);
        assert!(text.len() < 200, "{text}");
        assert!(text.ends_with("(779992 more)"), "{text}");
    }

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
