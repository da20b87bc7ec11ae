//! A byte scanner over BVH text: whitespace-separated tokens, line tracking, and a fast,
//! exact number parser.
//!
//! Every step uses `get` and saturating or checked arithmetic, so no input can make it
//! panic; positions only ever grow up to `bytes.len()`.

use crate::error::{ParseError, ParseErrorKind};

/// The longest piece of offending text an error message carries.
const MAX_FOUND_CHARS: usize = 40;

/// Token separators: ASCII space, tab, LF, CR, vertical tab and form feed.
#[inline]
pub(crate) fn is_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\n' | b'\r' | 0x0B | 0x0C)
}

/// Separators that do not end a line (a CR does only when no LF follows it).
#[inline]
fn is_inline_space(b: u8) -> bool {
    matches!(b, b' ' | b'\t' | b'\r' | 0x0B | 0x0C)
}

/// Whether the byte at `i` ends a line: an LF, or a CR that no LF follows (old Mac OS
/// files end lines with CR alone; in CRLF the LF ends the line).
#[inline]
pub(crate) fn is_line_break(bytes: &[u8], i: usize) -> bool {
    match bytes.get(i) {
        Some(b'\n') => true,
        Some(b'\r') => bytes.get(i.saturating_add(1)) != Some(&b'\n'),
        _ => false,
    }
}

/// The number of line breaks ([`is_line_break`]) in `bytes[..end]` and the offset just
/// after the last one (0 if none).
pub(crate) fn line_breaks_before(bytes: &[u8], end: usize) -> (usize, usize) {
    let end = end.min(bytes.len());
    let mut count = 0usize;
    let mut line_start = 0usize;
    for i in 0..end {
        if is_line_break(bytes, i) {
            count = count.saturating_add(1);
            line_start = i.saturating_add(1);
        }
    }
    (count, line_start)
}

/// A whitespace-free run of the text and where it starts.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Token<'a> {
    /// The token's text.
    pub text: &'a str,
    /// Byte offset of its first byte.
    pub start: usize,
    /// 1-based line it is on.
    pub line: usize,
    /// Byte offset of the start of that line.
    pub line_start: usize,
}

impl Token<'_> {
    /// Case-insensitive keyword comparison.
    #[inline]
    pub fn is(&self, keyword: &str) -> bool {
        self.text.eq_ignore_ascii_case(keyword)
    }

    /// The token cut to a length fit for an error message.
    pub fn found(&self) -> String {
        shorten(self.text)
    }
}

/// `text` cut to [`MAX_FOUND_CHARS`] characters, with `…` when cut.
pub(crate) fn shorten(text: &str) -> String {
    match text.char_indices().nth(MAX_FOUND_CHARS) {
        Some((cut, _)) => {
            let mut s = text.get(..cut).unwrap_or_default().to_owned();
            s.push('…');
            s
        }
        None => text.to_owned(),
    }
}

/// The scanner's state: a position in the text and the line it is on.
pub(crate) struct Scanner<'a> {
    text: &'a str,
    bytes: &'a [u8],
    pos: usize,
    line: usize,
    line_start: usize,
}

impl<'a> Scanner<'a> {
    pub fn new(text: &'a str) -> Self {
        Scanner {
            text,
            bytes: text.as_bytes(),
            pos: 0,
            line: 1,
            line_start: 0,
        }
    }

    /// The bytes not yet consumed.
    #[inline]
    pub fn rest(&self) -> &'a [u8] {
        self.bytes.get(self.pos..).unwrap_or_default()
    }

    /// The current byte offset.
    #[inline]
    pub fn pos(&self) -> usize {
        self.pos
    }

    /// Moves to byte offset `pos` without tracking lines (the motion section, where
    /// lines are only needed for errors and are then recounted).
    #[inline]
    pub fn set_pos_untracked(&mut self, pos: usize) {
        self.pos = pos.min(self.bytes.len());
    }

    /// Skips separators, counting lines.
    pub fn skip_space(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !is_space(b) {
                break;
            }
            let breaks = is_line_break(self.bytes, self.pos);
            self.pos = self.pos.saturating_add(1);
            if breaks {
                self.line = self.line.saturating_add(1);
                self.line_start = self.pos;
            }
        }
    }

    /// Skips separators that do not end the line.
    pub fn skip_inline_space(&mut self) {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !is_inline_space(b) || is_line_break(self.bytes, self.pos) {
                break;
            }
            self.pos = self.pos.saturating_add(1);
        }
    }

    /// The token starting at the current position (which must not be a separator).
    fn take_token(&mut self) -> Token<'a> {
        let start = self.pos;
        let len = self
            .rest()
            .iter()
            .position(|&b| is_space(b))
            .unwrap_or(self.rest().len());
        self.pos = self.pos.saturating_add(len);
        Token {
            // Separators are ASCII, so both ends are character boundaries.
            text: self.text.get(start..self.pos).unwrap_or_default(),
            start,
            line: self.line,
            line_start: self.line_start,
        }
    }

    /// The next token on any line.
    pub fn next_token(&mut self) -> Option<Token<'a>> {
        self.skip_space();
        if self.pos >= self.bytes.len() {
            return None;
        }
        Some(self.take_token())
    }

    /// The next token if there is one before the end of the current line.
    pub fn next_token_inline(&mut self) -> Option<Token<'a>> {
        self.skip_inline_space();
        match self.bytes.get(self.pos) {
            None => None,
            Some(_) if is_line_break(self.bytes, self.pos) => None,
            Some(_) => Some(self.take_token()),
        }
    }

    /// Consumes `words` (case-insensitively, separated by spaces or tabs) and then an
    /// optional `:`, as in `Frames:` or `Frame Time :`. Each word must end at a
    /// separator, a `:` or the end of the text.
    pub fn label(&mut self, words: &[&str], expected: &'static str) -> Result<(), ParseError> {
        self.skip_space();
        let start = (self.pos, self.line, self.line_start);
        for (k, word) in words.iter().enumerate() {
            if k > 0 {
                self.skip_inline_space();
            }
            let end = self.pos.saturating_add(word.len());
            let matches = self
                .bytes
                .get(self.pos..end)
                .is_some_and(|b| b.eq_ignore_ascii_case(word.as_bytes()));
            let boundary = match self.bytes.get(end) {
                None | Some(b':') => true,
                Some(&b) => is_space(b),
            };
            if !(matches && boundary) {
                (self.pos, self.line, self.line_start) = start;
                return Err(match self.next_token() {
                    Some(token) => self.error_at(
                        &token,
                        ParseErrorKind::Expected {
                            expected,
                            found: token.found(),
                        },
                    ),
                    None => self.error_here(ParseErrorKind::UnexpectedEof { expected }),
                });
            }
            self.pos = end;
        }
        self.skip_inline_space();
        if self.bytes.get(self.pos) == Some(&b':') {
            self.pos = self.pos.saturating_add(1);
        }
        Ok(())
    }

    /// An error at `token`.
    pub fn error_at(&self, token: &Token<'_>, kind: ParseErrorKind) -> ParseError {
        ParseError {
            line: token.line,
            column: self.column(token.line_start, token.start),
            kind,
        }
    }

    /// An error at the current position (after the last token consumed).
    pub fn error_here(&self, kind: ParseErrorKind) -> ParseError {
        ParseError {
            line: self.line,
            column: self.column(self.line_start, self.pos),
            kind,
        }
    }

    /// An error at byte offset `pos`, counting lines from the start of the text. Only for
    /// the motion section, where lines are not tracked while scanning.
    pub fn error_at_pos(&self, pos: usize, kind: ParseErrorKind) -> ParseError {
        let (newlines, line_start) = line_breaks_before(self.bytes, pos);
        ParseError {
            line: newlines.saturating_add(1),
            column: self.column(line_start, pos),
            kind,
        }
    }

    /// A token read at byte offset `pos` (a non-separator) for an error message.
    pub fn token_text_at(&self, pos: usize) -> &'a str {
        let rest = self.bytes.get(pos..).unwrap_or_default();
        let len = rest.iter().position(|&b| is_space(b)).unwrap_or(rest.len());
        self.text
            .get(pos..pos.saturating_add(len))
            .unwrap_or_default()
    }

    /// 1-based column, in characters, of byte `pos` on the line starting at `line_start`.
    fn column(&self, line_start: usize, pos: usize) -> usize {
        self.text
            .get(line_start..pos)
            .map_or(1, |s| s.chars().count().saturating_add(1))
    }
}

/// Powers of ten that are exact in `f64`.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// The largest integer below which every integer is exact in `f64`.
const MAX_EXACT_MANTISSA: u64 = 1 << 53;

/// Parses the decimal number at the start of `bytes`, returning the value and the number
/// of bytes it took, when the result can be computed exactly with one IEEE operation
/// (Clinger's fast path: at most 19 significant digits, mantissa at most 2^53, decimal
/// exponent within ±22). The result is then the correctly rounded value, identical to
/// `str::parse::<f64>`. Returns `None` for anything else, which the caller hands to
/// `str::parse`.
#[inline]
pub(crate) fn parse_fast(bytes: &[u8]) -> Option<(f64, usize)> {
    let mut i = 0usize;
    let negative = match bytes.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    let mut mantissa: u64 = 0;
    let mut significant: u32 = 0;
    let mut any_digit = false;
    let mut exponent: i32 = 0;

    while let Some(&b) = bytes.get(i) {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        any_digit = true;
        if mantissa != 0 || d != 0 {
            significant = significant.saturating_add(1);
            if significant > 19 {
                return None;
            }
            mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
        }
        i = i.saturating_add(1);
    }
    if bytes.get(i) == Some(&b'.') {
        i = i.saturating_add(1);
        while let Some(&b) = bytes.get(i) {
            let d = b.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            any_digit = true;
            if mantissa != 0 || d != 0 {
                significant = significant.saturating_add(1);
                if significant > 19 {
                    return None;
                }
                mantissa = mantissa.wrapping_mul(10).wrapping_add(u64::from(d));
            }
            exponent = exponent.saturating_sub(1);
            i = i.saturating_add(1);
        }
    }
    if !any_digit {
        return None;
    }
    if let Some(b'e' | b'E') = bytes.get(i) {
        i = i.saturating_add(1);
        let exp_negative = match bytes.get(i) {
            Some(b'-') => {
                i = i.saturating_add(1);
                true
            }
            Some(b'+') => {
                i = i.saturating_add(1);
                false
            }
            _ => false,
        };
        let mut e: i32 = 0;
        let mut any = false;
        while let Some(&b) = bytes.get(i) {
            let d = b.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            any = true;
            e = e.saturating_mul(10).saturating_add(i32::from(d));
            i = i.saturating_add(1);
        }
        if !any {
            return None;
        }
        exponent = if exp_negative {
            exponent.saturating_sub(e)
        } else {
            exponent.saturating_add(e)
        };
    }
    let magnitude = if mantissa == 0 {
        0.0
    } else {
        if mantissa > MAX_EXACT_MANTISSA {
            return None;
        }
        // Exact conversion: mantissa <= 2^53.
        let m = mantissa as f64;
        let scale = *POW10.get(exponent.unsigned_abs() as usize)?;
        if exponent < 0 { m / scale } else { m * scale }
    };
    Some((if negative { -magnitude } else { magnitude }, i))
}

/// Parses a whole token as a number: the fast path, then `str::parse` for the rest
/// (long mantissas, large exponents, `inf`, `nan`). `Ok` values may be non-finite.
#[inline]
pub(crate) fn parse_number(token: &str) -> Option<f64> {
    match parse_fast(token.as_bytes()) {
        Some((value, len)) if len == token.len() => Some(value),
        _ => token.parse::<f64>().ok(),
    }
}

/// Parses a token of ASCII digits as a count; `None` if it is anything else or overflows.
pub(crate) fn parse_count(token: &str) -> Option<usize> {
    if token.is_empty() {
        return None;
    }
    token.bytes().try_fold(0usize, |acc, b| {
        let d = b.wrapping_sub(b'0');
        if d > 9 {
            return None;
        }
        acc.checked_mul(10)?.checked_add(usize::from(d))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn fast_path_handles_the_forms_real_files_use() {
        for (text, value) in [
            ("0", 0.0f64),
            ("-0", -0.0),
            ("+1", 1.0),
            (".5", 0.5),
            ("5.", 5.0),
            ("5.1072e-06", 5.1072e-06),
            ("1E+2", 100.0),
            (".0083333", 0.0083333),
            ("-0.000016", -0.000016),
            ("105.214226", 105.214226),
        ] {
            let (parsed, len) = parse_fast(text.as_bytes()).unwrap();
            assert_eq!(len, text.len(), "{text}");
            assert_eq!(parsed.to_bits(), value.to_bits(), "{text}");
        }
    }

    #[test]
    fn fast_path_declines_what_it_cannot_do_exactly() {
        for text in [
            "",
            "-",
            ".",
            "e5",
            "1e",
            "1e+",
            "12345678901234567890",
            "1e23",
            "9007199254740993",
        ] {
            assert!(parse_fast(text.as_bytes()).is_none(), "{text}");
        }
    }

    #[test]
    fn parse_number_rejects_junk_and_flags_non_finite() {
        assert_eq!(parse_number("abc"), None);
        assert_eq!(parse_number("1.5x"), None);
        assert!(parse_number("nan").unwrap().is_nan());
        assert!(parse_number("1e999").unwrap().is_infinite());
        assert_eq!(parse_number("1e-400"), Some(0.0));
    }

    #[test]
    fn counts_are_digits_only_and_checked() {
        assert_eq!(parse_count("0"), Some(0));
        assert_eq!(parse_count("524"), Some(524));
        assert_eq!(parse_count("-1"), None);
        assert_eq!(parse_count("+1"), None);
        assert_eq!(parse_count(""), None);
        assert_eq!(parse_count("99999999999999999999999"), None);
    }

    #[test]
    fn shorten_cuts_long_text_on_a_character_boundary() {
        let long = "é".repeat(100);
        let cut = shorten(&long);
        assert_eq!(cut.chars().count(), MAX_FOUND_CHARS + 1);
        assert!(cut.ends_with('…'));
        assert_eq!(shorten("abc"), "abc");
    }

    proptest! {
        #[test]
        fn fast_path_agrees_with_std_bit_for_bit(
            sign in prop::sample::select(vec!["", "-", "+"]),
            int in "[0-9]{0,12}",
            frac in prop::option::of("[0-9]{0,12}"),
            exp in prop::option::of((prop::sample::select(vec!["e", "E"]), prop::sample::select(vec!["", "-", "+"]), 0u32..40)),
        ) {
            let mut text = format!("{sign}{int}");
            if let Some(frac) = frac {
                text.push('.');
                text.push_str(&frac);
            }
            if let Some((e, s, n)) = exp {
                text.push_str(&format!("{e}{s}{n}"));
            }
            let std = text.parse::<f64>().ok();
            if let Some((fast, len)) = parse_fast(text.as_bytes()) {
                prop_assert_eq!(len, text.len());
                prop_assert_eq!(Some(fast.to_bits()), std.map(f64::to_bits), "{}", text);
            }
            prop_assert_eq!(parse_number(&text).map(f64::to_bits), std.map(f64::to_bits));
        }

        #[test]
        fn fast_path_agrees_with_std_on_formatted_floats(bits in any::<u64>()) {
            let value = f64::from_bits(bits);
            prop_assume!(value.is_finite());
            for text in [format!("{value}"), format!("{value:e}"), format!("{value:?}")] {
                prop_assert_eq!(parse_number(&text).map(f64::to_bits), Some(value.to_bits()), "{}", text);
            }
        }
    }
}
