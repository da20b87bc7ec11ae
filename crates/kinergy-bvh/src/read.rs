//! The reader: HIERARCHY with an explicit stack, then MOTION with a tight value loop.

use std::num::NonZeroUsize;

use crate::document::{Bvh, Channel, Joint};
use crate::error::{ParseError, ParseErrorKind};
use crate::options::{FrameCountPolicy, ReadOptions};
use crate::scan::{
    Scanner, Token, is_line_break, is_space, line_breaks_before, parse_count, parse_fast,
    parse_number, shorten,
};

/// The deepest nesting of joints (the root is at depth 1) the reader accepts and the
/// writer produces.
pub const MAX_DEPTH: usize = 1024;

/// The shortest frame time the reader accepts (and the writer writes), seconds: 10 kHz.
pub const MIN_FRAME_TIME: f64 = 1e-4;

/// The longest frame time the reader accepts (and the writer writes), seconds: 0.1 Hz.
pub const MAX_FRAME_TIME: f64 = 10.0;

/// The largest magnitude of an `OFFSET` component or a motion value the reader accepts
/// with [`ReadOptions::bounded_values`](crate::ReadOptions::bounded_values): 1e9, a
/// million kilometers in millimeters, or millions of turns in degrees. No capture holds a
/// length or an angle that large; a file that does is damaged, and its numbers would
/// overflow every distance computed from them.
pub const MAX_VALUE: f64 = 1e9;

/// What a joint body may contain, for error messages.
const BODY: &str = "OFFSET, CHANNELS, JOINT, End Site or `}`";

/// Parses `text` (a leading byte order mark is skipped).
pub(crate) fn parse_str(text: &str, options: &ReadOptions) -> Result<Bvh, ParseError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut parser = Parser {
        scanner: Scanner::new(text),
        joints: Vec::new(),
        channel_count: 0,
        bounded: options.bounded_values,
    };
    parser.hierarchy()?;
    parser.motion(options)
}

/// Parses UTF-8 `bytes`, reporting the position of the first invalid byte otherwise.
pub(crate) fn parse_bytes(bytes: &[u8], options: &ReadOptions) -> Result<Bvh, ParseError> {
    match std::str::from_utf8(bytes) {
        Ok(text) => parse_str(text, options),
        Err(e) => {
            let valid = bytes.get(..e.valid_up_to()).unwrap_or_default();
            // The prefix is valid UTF-8 by construction.
            let text = std::str::from_utf8(valid).unwrap_or_default();
            let text = text.strip_prefix('\u{feff}').unwrap_or(text);
            let (breaks, line_start) = line_breaks_before(text.as_bytes(), text.len());
            Err(ParseError {
                line: breaks.saturating_add(1),
                column: text
                    .get(line_start..)
                    .map_or(1, |s| s.chars().count().saturating_add(1)),
                kind: ParseErrorKind::InvalidUtf8,
            })
        }
    }
}

/// A joint whose `}` has not been read yet.
#[derive(Clone, Copy)]
struct Open {
    joint: usize,
    end_site: bool,
    has_offset: bool,
    has_channels: bool,
    has_children: bool,
}

struct Parser<'a> {
    scanner: Scanner<'a>,
    joints: Vec<Joint>,
    /// Channels of the joints read so far.
    channel_count: usize,
    /// Refuse values beyond ±[`MAX_VALUE`] ([`ReadOptions::bounded_values`]).
    bounded: bool,
}

impl<'a> Parser<'a> {
    fn expected(&self, token: &Token<'_>, expected: &'static str) -> ParseError {
        self.scanner.error_at(
            token,
            ParseErrorKind::Expected {
                expected,
                found: token.found(),
            },
        )
    }

    /// The next token, or `UnexpectedEof { expected }`.
    fn require(&mut self, expected: &'static str) -> Result<Token<'a>, ParseError> {
        self.scanner.next_token().ok_or_else(|| {
            self.scanner
                .error_here(ParseErrorKind::UnexpectedEof { expected })
        })
    }

    fn hierarchy(&mut self) -> Result<(), ParseError> {
        let token = self.require("HIERARCHY")?;
        if !token.is("HIERARCHY") {
            return Err(self.expected(&token, "HIERARCHY"));
        }
        let token = self.require("ROOT")?;
        if token.is("HIERARCHY") {
            return Err(self
                .scanner
                .error_at(&token, ParseErrorKind::DuplicateHierarchy));
        }
        if !token.is("ROOT") {
            return Err(self.expected(&token, "ROOT"));
        }
        let root = self.named_joint(&token, "ROOT", None)?;
        let mut stack = vec![Open::new(root, false)];

        while let Some(&top) = stack.last() {
            let Some(token) = self.scanner.next_token() else {
                return Err(self.scanner.error_here(ParseErrorKind::UnbalancedBraces {
                    unclosed: stack.len(),
                }));
            };
            if token.is("OFFSET") {
                if top.has_offset {
                    return Err(self
                        .scanner
                        .error_at(&token, ParseErrorKind::Repeated { keyword: "OFFSET" }));
                }
                let offset = self.offset()?;
                if let Some(joint) = self.joints.get_mut(top.joint) {
                    joint.offset = offset;
                }
                set_top(&mut stack, |open| open.has_offset = true);
            } else if token.is("CHANNELS") {
                let kind = if top.end_site {
                    Some(ParseErrorKind::EndSiteChannels)
                } else if top.has_channels {
                    Some(ParseErrorKind::Repeated {
                        keyword: "CHANNELS",
                    })
                } else if top.has_children {
                    Some(ParseErrorKind::ChannelsAfterChild)
                } else {
                    None
                };
                if let Some(kind) = kind {
                    return Err(self.scanner.error_at(&token, kind));
                }
                let channels = self.channels(&token)?;
                self.channel_count =
                    self.channel_count
                        .checked_add(channels.len())
                        .ok_or_else(|| {
                            self.scanner.error_at(
                                &token,
                                ParseErrorKind::BadChannelCount {
                                    found: channels.len().to_string(),
                                },
                            )
                        })?;
                if let Some(joint) = self.joints.get_mut(top.joint) {
                    joint.channels = channels;
                }
                set_top(&mut stack, |open| open.has_channels = true);
            } else if token.is("JOINT") || token.is("End") {
                if top.end_site {
                    return Err(self
                        .scanner
                        .error_at(&token, ParseErrorKind::EndSiteChildren));
                }
                if stack.len() >= MAX_DEPTH {
                    return Err(self
                        .scanner
                        .error_at(&token, ParseErrorKind::TooDeep { max: MAX_DEPTH }));
                }
                set_top(&mut stack, |open| open.has_children = true);
                let end_site = token.is("End");
                let index = if end_site {
                    self.end_site(&token, top.joint)?
                } else {
                    self.named_joint(&token, "JOINT", Some(top.joint))?
                };
                stack.push(Open::new(index, end_site));
            } else if token.text == "}" {
                if !top.has_offset {
                    let joint = self
                        .joints
                        .get(top.joint)
                        .map(|j| shorten(j.display_name()))
                        .unwrap_or_default();
                    return Err(self
                        .scanner
                        .error_at(&token, ParseErrorKind::MissingOffset { joint }));
                }
                stack.pop();
            } else if token.is("HIERARCHY") {
                return Err(self
                    .scanner
                    .error_at(&token, ParseErrorKind::DuplicateHierarchy));
            } else if token.is("MOTION") {
                return Err(self.scanner.error_at(
                    &token,
                    ParseErrorKind::UnbalancedBraces {
                        unclosed: stack.len(),
                    },
                ));
            } else {
                return Err(self.expected(&token, BODY));
            }
        }

        let token = self.require("MOTION")?;
        if token.is("MOTION") {
            Ok(())
        } else if token.text == "}" {
            Err(self
                .scanner
                .error_at(&token, ParseErrorKind::UnbalancedBraces { unclosed: 0 }))
        } else if token.is("ROOT") {
            Err(self.scanner.error_at(&token, ParseErrorKind::MultipleRoots))
        } else if token.is("HIERARCHY") {
            Err(self
                .scanner
                .error_at(&token, ParseErrorKind::DuplicateHierarchy))
        } else {
            Err(self.expected(&token, "MOTION"))
        }
    }

    /// After `ROOT` or `JOINT`: the name on the same line, then `{`.
    fn named_joint(
        &mut self,
        keyword: &Token<'_>,
        keyword_name: &'static str,
        parent: Option<usize>,
    ) -> Result<usize, ParseError> {
        let name = match self.scanner.next_token_inline() {
            Some(name) if name.text != "{" && name.text != "}" => name,
            _ => {
                return Err(self.scanner.error_at(
                    keyword,
                    ParseErrorKind::MissingName {
                        keyword: keyword_name,
                    },
                ));
            }
        };
        if !crate::document::is_valid_name(name.text) {
            return Err(self
                .scanner
                .error_at(&name, ParseErrorKind::InvalidName { name: name.found() }));
        }
        self.push_joint(keyword, Some(name.text.to_owned()), parent)
    }

    /// After `End`: `Site`, then `{`.
    fn end_site(&mut self, keyword: &Token<'_>, parent: usize) -> Result<usize, ParseError> {
        match self.scanner.next_token_inline() {
            Some(site) if site.is("Site") => {}
            Some(other) => return Err(self.expected(&other, "`Site` after `End`")),
            None => {
                return Err(self.scanner.error_here(ParseErrorKind::Expected {
                    expected: "`Site` after `End`",
                    found: String::new(),
                }));
            }
        }
        self.push_joint(keyword, None, Some(parent))
    }

    fn push_joint(
        &mut self,
        keyword: &Token<'_>,
        name: Option<String>,
        parent: Option<usize>,
    ) -> Result<usize, ParseError> {
        let token = self.require("`{`")?;
        if token.text != "{" {
            return Err(self.expected(&token, "`{`"));
        }
        let index = self.joints.len();
        self.joints.push(Joint {
            end_site: name.is_none(),
            name,
            parent,
            offset: [0.0; 3],
            channels: Vec::new(),
            first_channel: self.channel_count,
            line: keyword.line,
        });
        Ok(index)
    }

    /// Three finite numbers after `OFFSET`.
    fn offset(&mut self) -> Result<[f64; 3], ParseError> {
        let mut offset = [0.0; 3];
        for slot in &mut offset {
            *slot = self.finite_number("a number after OFFSET")?;
        }
        Ok(offset)
    }

    fn finite_number(&mut self, expected: &'static str) -> Result<f64, ParseError> {
        let token = self.require(expected)?;
        match parse_number(token.text) {
            Some(value) if value.is_finite() && self.bounded && value.abs() > MAX_VALUE => {
                let joint = match self.joints.last() {
                    Some(j) if j.end_site => {
                        let parent = j.parent.and_then(|p| self.joints.get(p));
                        format!(
                            "the End Site of {}",
                            parent.map_or("?", Joint::display_name)
                        )
                    }
                    Some(j) => j.display_name().to_string(),
                    None => "the root".into(),
                };
                let what = format!("an OFFSET component of {joint}");
                Err(self.scanner.error_at(
                    &token,
                    ParseErrorKind::ValueTooLarge {
                        value: token.found().into(),
                        what: what.into(),
                    },
                ))
            }
            Some(value) if value.is_finite() => Ok(value),
            Some(_) => Err(self.scanner.error_at(
                &token,
                ParseErrorKind::NonFinite {
                    value: token.found(),
                },
            )),
            None => Err(self.expected(&token, expected)),
        }
    }

    /// After `CHANNELS`: a count in `0..=6` and that many distinct names, all on its line.
    fn channels(&mut self, keyword: &Token<'_>) -> Result<Vec<Channel>, ParseError> {
        let declared = match self.scanner.next_token_inline() {
            Some(count) => match parse_count(count.text) {
                Some(n) if n <= 6 => n,
                _ => {
                    return Err(self.scanner.error_at(
                        &count,
                        ParseErrorKind::BadChannelCount {
                            found: count.found(),
                        },
                    ));
                }
            },
            None => {
                return Err(self.scanner.error_here(ParseErrorKind::BadChannelCount {
                    found: String::new(),
                }));
            }
        };
        let mut channels = Vec::with_capacity(declared);
        let mut listed = 0usize;
        while let Some(name) = self.scanner.next_token_inline() {
            let Some(channel) = Channel::from_name(name.text) else {
                return Err(self
                    .scanner
                    .error_at(&name, ParseErrorKind::UnknownChannel(name.found())));
            };
            if channels.contains(&channel) {
                return Err(self
                    .scanner
                    .error_at(&name, ParseErrorKind::DuplicateChannel(channel)));
            }
            channels.push(channel);
            listed = listed.saturating_add(1);
        }
        if listed != declared {
            return Err(self.scanner.error_at(
                keyword,
                ParseErrorKind::ChannelCountMismatch { declared, listed },
            ));
        }
        Ok(channels)
    }

    fn motion(mut self, options: &ReadOptions) -> Result<Bvh, ParseError> {
        self.scanner.label(&["Frames"], "`Frames:`")?;
        let frames_token = self.require("a frame count")?;
        let declared = parse_count(frames_token.text).ok_or_else(|| {
            self.scanner.error_at(
                &frames_token,
                ParseErrorKind::BadFrameCount {
                    found: frames_token.found(),
                },
            )
        })?;

        self.scanner.label(&["Frame", "Time"], "`Frame Time:`")?;
        let time_token = self.require("a frame time")?;
        let frame_time = match parse_number(time_token.text) {
            Some(t) if (MIN_FRAME_TIME..=MAX_FRAME_TIME).contains(&t) => t,
            Some(t) if t.is_finite() && t > 0.0 => {
                return Err(self.scanner.error_at(
                    &time_token,
                    ParseErrorKind::FrameTimeOutOfRange {
                        found: time_token.found(),
                    },
                ));
            }
            _ => {
                return Err(self.scanner.error_at(
                    &time_token,
                    ParseErrorKind::BadFrameTime {
                        found: time_token.found(),
                    },
                ));
            }
        };

        let Some(channels) = NonZeroUsize::new(self.channel_count) else {
            // No values to read: the header's count stands.
            if let Some(token) = self.scanner.next_token() {
                return Err(self.scanner.error_at(
                    &token,
                    ParseErrorKind::TrailingGarbage {
                        found: token.found(),
                    },
                ));
            }
            return Ok(Bvh {
                joints: self.joints,
                frame_time,
                frame_count: declared,
                motion: Vec::new(),
            });
        };

        // Every value is preceded by at least one separator, so the rest of the text holds
        // at most half its length in values. Never allocate more than that.
        let max_values = self.scanner.rest().len() / 2;
        let max_frames = max_values / channels;
        let strict = options.frame_count == FrameCountPolicy::Strict;
        if strict && declared > max_frames {
            return Err(self.scanner.error_at(
                &frames_token,
                ParseErrorKind::TooManyFrames {
                    declared,
                    max_possible: max_frames,
                },
            ));
        }
        let expected_values = declared.saturating_mul(channels.get());
        let mut motion = Vec::with_capacity(expected_values.min(max_values));

        let start = self.scanner.pos();
        let rest = self.scanner.rest();
        let mut i = 0usize;
        let mut last_value = start;
        // One frame per line or not, decided by the first line holding values: then every
        // line must hold one frame, and a line that does not is reported on that line.
        let mut lines = LineCheck::new(channels.get());
        loop {
            while let Some(&b) = rest.get(i) {
                if !is_space(b) {
                    break;
                }
                if is_line_break(rest, i)
                    && let Some((pos, values)) = lines.end_line()
                {
                    return Err(self.line_values(start, pos, values, channels.get()));
                }
                i = i.saturating_add(1);
            }
            let Some(tail) = rest.get(i..).filter(|t| !t.is_empty()) else {
                if let Some((pos, values)) = lines.end_of_text() {
                    return Err(self.line_values(start, pos, values, channels.get()));
                }
                break;
            };
            let token_pos = start.saturating_add(i);
            let value = match parse_fast(tail) {
                Some((value, len)) if tail.get(len).is_none_or(|&b| is_space(b)) => {
                    i = i.saturating_add(len);
                    value
                }
                _ => {
                    let text = self.scanner.token_text_at(token_pos);
                    i = i.saturating_add(text.len());
                    match text.parse::<f64>() {
                        Ok(value) if value.is_finite() => value,
                        Ok(_) => {
                            return Err(self.scanner.error_at_pos(
                                token_pos,
                                ParseErrorKind::NonFinite {
                                    value: shorten(text),
                                },
                            ));
                        }
                        Err(_) => {
                            let at_frame_end = motion.len() % channels == 0;
                            let kind = if text.eq_ignore_ascii_case("HIERARCHY") {
                                ParseErrorKind::DuplicateHierarchy
                            } else if at_frame_end && (!strict || motion.len() >= expected_values) {
                                ParseErrorKind::TrailingGarbage {
                                    found: shorten(text),
                                }
                            } else {
                                ParseErrorKind::Expected {
                                    expected: "a number (motion value)",
                                    found: shorten(text),
                                }
                            };
                            return Err(self.scanner.error_at_pos(token_pos, kind));
                        }
                    }
                }
            };
            if self.bounded && value.abs() > MAX_VALUE {
                let text = self.scanner.token_text_at(token_pos);
                return Err(self.scanner.error_at_pos(
                    token_pos,
                    ParseErrorKind::ValueTooLarge {
                        value: shorten(text).into(),
                        what: self
                            .channel_name(motion.len().checked_rem(channels.get()))
                            .into(),
                    },
                ));
            }
            motion.push(value);
            last_value = token_pos;
            if let Some((pos, values)) = lines.value(token_pos.saturating_sub(start)) {
                return Err(self.line_values(start, pos, values, channels.get()));
            }
        }
        self.scanner.set_pos_untracked(start.saturating_add(i));

        let partial = motion.len() % channels;
        if partial != 0 {
            return Err(self.scanner.error_at_pos(
                last_value,
                ParseErrorKind::PartialFrame {
                    values: partial,
                    channels: channels.get(),
                },
            ));
        }
        let found = motion.len() / channels;
        if strict && found != declared {
            return Err(self.scanner.error_at(
                &frames_token,
                ParseErrorKind::FrameCountMismatch { declared, found },
            ));
        }
        Ok(Bvh {
            joints: self.joints,
            frame_time,
            frame_count: found,
            motion,
        })
    }
}

/// The one-frame-per-line rule of the motion section. Positions are offsets into the
/// motion text.
struct LineCheck {
    channels: usize,
    /// `Some(true)` once the first line holding values held exactly one frame.
    one_per_line: Option<bool>,
    /// Values on the current line so far.
    values: usize,
    /// Where the current line's first surplus value (value `channels + 1`) is, or its last.
    at: usize,
    /// A line with too few values, reported when another value follows it (at the end of
    /// the text it is a partial frame instead).
    short: Option<(usize, usize)>,
}

impl LineCheck {
    fn new(channels: usize) -> Self {
        LineCheck {
            channels,
            one_per_line: None,
            values: 0,
            at: 0,
            short: None,
        }
    }

    /// A value at offset `pos` on the current line: `Some((offset, values))` when a line
    /// with too few values came before it.
    #[inline]
    fn value(&mut self, pos: usize) -> Option<(usize, usize)> {
        if self.short.is_some() {
            return self.short;
        }
        self.values = self.values.saturating_add(1);
        if self.values <= self.channels.saturating_add(1) {
            self.at = pos;
        }
        None
    }

    /// The current line ends: `Some((offset, values))` when it breaks the rule.
    #[inline]
    fn end_line(&mut self) -> Option<(usize, usize)> {
        let values = std::mem::take(&mut self.values);
        if values == 0 {
            return None;
        }
        match self.one_per_line {
            None => {
                self.one_per_line = Some(values == self.channels);
                None
            }
            Some(true) if values > self.channels => Some((self.at, values)),
            Some(true) if values < self.channels => {
                self.short = Some((self.at, values));
                None
            }
            Some(_) => None,
        }
    }

    /// The text ends: a last line with too many values breaks the rule; one with too few
    /// is left to the partial-frame check.
    fn end_of_text(&mut self) -> Option<(usize, usize)> {
        if self.values > self.channels {
            self.end_line()
        } else {
            None
        }
    }
}

impl Parser<'_> {
    /// [`ParseErrorKind::LineValues`] at offset `pos` of the motion text at `start`.
    /// The channel at `k` of a frame, as a message names it: "Hips Xposition".
    fn channel_name(&self, k: Option<usize>) -> String {
        let found = k.and_then(|k| {
            self.joints.iter().find_map(|joint| {
                let at = k.checked_sub(joint.first_channel)?;
                joint
                    .channels
                    .get(at)
                    .map(|c| format!("{} {c}", joint.display_name()))
            })
        });
        found.unwrap_or_else(|| "a motion value".into())
    }

    fn line_values(&self, start: usize, pos: usize, values: usize, channels: usize) -> ParseError {
        self.scanner.error_at_pos(
            start.saturating_add(pos),
            ParseErrorKind::LineValues { values, channels },
        )
    }
}

impl Open {
    fn new(joint: usize, end_site: bool) -> Self {
        Open {
            joint,
            end_site,
            has_offset: false,
            has_channels: false,
            has_children: false,
        }
    }
}

fn set_top(stack: &mut [Open], f: impl FnOnce(&mut Open)) {
    if let Some(top) = stack.last_mut() {
        f(top);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A root with 6 channels and a joint with 3: 9 values a frame, motion from line 14.
    fn text(frames: &[&str], frame_time: &str) -> String {
        let mut t = String::from(
            "HIERARCHY\nROOT Hips\n{\n\tOFFSET 0 0 0\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n\tJOINT Spine\n\t{\n\t\tOFFSET 0 10 0\n\t\tCHANNELS 3 Zrotation Yrotation Xrotation\n\t\tEnd Site\n\t\t{\n\t\t\tOFFSET 0 5 0\n\t\t}\n\t}\n}\nMOTION\n",
        );
        t.push_str(&format!(
            "Frames: {}\nFrame Time: {frame_time}\n",
            frames.len()
        ));
        for f in frames {
            t.push_str(f);
            t.push('\n');
        }
        t
    }

    const FRAME: &str = "0 90 0 0 0 0 1 2 3";

    fn error(text: &str) -> ParseError {
        parse_str(text, &ReadOptions::default()).unwrap_err()
    }

    #[test]
    fn cr_only_line_endings_read_as_the_lf_file() {
        let lf = text(&[FRAME, FRAME, FRAME], "0.0333333");
        let cr = lf.replace('\n', "\r");
        let crlf = lf.replace('\n', "\r\n");
        let want = parse_str(&lf, &ReadOptions::default()).unwrap();
        for other in [&cr, &crlf] {
            let got = parse_str(other, &ReadOptions::default()).unwrap();
            assert!(got.same_content(&want));
            assert_eq!(
                got.joints.iter().map(|j| j.line).collect::<Vec<_>>(),
                want.joints.iter().map(|j| j.line).collect::<Vec<_>>()
            );
        }
    }

    #[test]
    fn cr_only_errors_name_the_same_line_as_lf() {
        let lf = text(&[FRAME, "0 90 0 0 0 x 1 2 3", FRAME], "0.0333333");
        let e = error(&lf);
        assert_eq!(e.line, 20);
        assert_eq!(error(&lf.replace('\n', "\r")), e);
        let bad_name = lf.replace("JOINT Spine", "JOINT");
        assert_eq!(error(&bad_name.replace('\n', "\r")), error(&bad_name));
    }

    #[test]
    fn a_surplus_value_is_reported_on_its_line() {
        let e = error(&text(
            &[FRAME, FRAME, "0 90 0 0 0 0 1 2 3 4", FRAME],
            "0.0333333",
        ));
        assert_eq!(e.line, 21);
        assert_eq!(
            e.kind,
            ParseErrorKind::LineValues {
                values: 10,
                channels: 9
            }
        );
        assert_eq!(e.column, 20, "at the surplus value");
        // On the last line too, and on a line one short then one long (which would
        // otherwise read as two shifted frames).
        let e = error(&text(&[FRAME, "0 90 0 0 0 0 1 2 3 4"], "0.0333333"));
        assert_eq!(
            (e.line, e.kind.clone()),
            (
                20,
                ParseErrorKind::LineValues {
                    values: 10,
                    channels: 9
                }
            )
        );
        let e = error(&text(
            &[FRAME, "0 90 0 0 0 0 1 2", "0 90 0 0 0 0 1 2 3 4"],
            "0.0333333",
        ));
        assert_eq!(
            (e.line, e.kind),
            (
                20,
                ParseErrorKind::LineValues {
                    values: 8,
                    channels: 9
                }
            )
        );
    }

    #[test]
    fn wrapped_and_several_frames_per_line_still_read() {
        let wrapped = text(
            &["0 90 0 0", "0 0 1 2 3 0 90 0", "0 0 0 1 2 3"],
            "0.0333333",
        );
        let wrapped = wrapped.replace("Frames: 3", "Frames: 2");
        assert_eq!(
            parse_str(&wrapped, &ReadOptions::default())
                .unwrap()
                .frame_count,
            2
        );
        let two = format!("{FRAME} {FRAME}");
        let both = text(&[&two], "0.0333333").replace("Frames: 1", "Frames: 2");
        assert_eq!(
            parse_str(&both, &ReadOptions::default())
                .unwrap()
                .frame_count,
            2
        );
    }

    #[test]
    fn frame_times_outside_the_range_are_refused_on_their_line() {
        for t in ["1e-300", "0.00009", "11", "1e300"] {
            let e = error(&text(&[FRAME], t));
            assert_eq!(e.line, 18, "{t}");
            assert_eq!(
                e.kind,
                ParseErrorKind::FrameTimeOutOfRange { found: t.into() }
            );
        }
        for t in ["0.0001", "10", "0.0083333"] {
            assert!(
                parse_str(&text(&[FRAME], t), &ReadOptions::default()).is_ok(),
                "{t}"
            );
        }
        assert!(matches!(
            error(&text(&[FRAME], "0")).kind,
            ParseErrorKind::BadFrameTime { .. }
        ));
    }
}
