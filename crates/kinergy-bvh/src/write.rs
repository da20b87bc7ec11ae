//! The writer: a standard layout, full precision, and atomic file replacement.

use std::fmt::Write as _;
use std::io;
use std::path::Path;

use crate::document::Bvh;
use crate::error::{Error, WriteError};

/// Renders a validated document.
pub(crate) fn render(bvh: &Bvh) -> Result<String, WriteError> {
    bvh.validate()?;
    let estimate = bvh
        .motion
        .len()
        .saturating_mul(12)
        .saturating_add(bvh.joints.len().saturating_mul(96))
        .saturating_add(64);
    let mut out = String::with_capacity(estimate);
    out.push_str("HIERARCHY\n");

    // Joints whose `}` is still to be written, root first.
    let mut open: Vec<usize> = Vec::new();
    for (index, joint) in bvh.joints.iter().enumerate() {
        while let Some(&top) = open.last() {
            if Some(top) == joint.parent {
                break;
            }
            open.pop();
            close(&mut out, open.len());
        }
        let depth = open.len();
        indent(&mut out, depth);
        match (&joint.name, joint.parent) {
            (_, _) if joint.end_site => out.push_str("End Site\n"),
            (Some(name), None) => push_line(&mut out, &["ROOT ", name]),
            (Some(name), Some(_)) => push_line(&mut out, &["JOINT ", name]),
            // validate() guarantees names on joints.
            (None, _) => out.push_str("JOINT\n"),
        }
        indent(&mut out, depth);
        out.push_str("{\n");
        indent(&mut out, depth.saturating_add(1));
        out.push_str("OFFSET");
        for value in joint.offset {
            out.push(' ');
            push_f64(&mut out, value);
        }
        out.push('\n');
        if !joint.end_site {
            indent(&mut out, depth.saturating_add(1));
            let _ = write!(out, "CHANNELS {}", joint.channels.len());
            for channel in &joint.channels {
                out.push(' ');
                out.push_str(channel.name());
            }
            out.push('\n');
        }
        open.push(index);
    }
    while open.pop().is_some() {
        close(&mut out, open.len());
    }

    let _ = writeln!(out, "MOTION\nFrames: {}", bvh.frame_count);
    out.push_str("Frame Time: ");
    push_f64(&mut out, bvh.frame_time);
    out.push('\n');
    let channels = bvh.channel_count();
    if channels > 0 {
        for frame in bvh.motion.chunks(channels) {
            for (k, &value) in frame.iter().enumerate() {
                if k > 0 {
                    out.push(' ');
                }
                push_f64(&mut out, value);
            }
            out.push('\n');
        }
    }
    Ok(out)
}

fn indent(out: &mut String, depth: usize) {
    out.extend(std::iter::repeat_n('\t', depth));
}

fn close(out: &mut String, depth: usize) {
    indent(out, depth);
    out.push_str("}\n");
}

fn push_line(out: &mut String, parts: &[&str]) {
    parts.iter().for_each(|p| out.push_str(p));
    out.push('\n');
}

/// Writes `value` (finite) with the fewest digits that read back as the same `f64`:
/// plain decimals (`0`, `-0`, `93.0864`) from 1e-5 to 1e16, exponent form (`5.1072e-6`,
/// `1e300`, `5e-324`) outside, so tiny and huge values stay short.
pub(crate) fn push_f64(out: &mut String, value: f64) {
    let magnitude = value.abs();
    let _ = if magnitude == 0.0 || (1e-5..1e16).contains(&magnitude) {
        write!(out, "{value}")
    } else {
        write!(out, "{value:e}")
    };
}

/// Validates, renders, and writes to `out`.
pub(crate) fn write_to<W: io::Write>(bvh: &Bvh, mut out: W) -> Result<(), Error> {
    let text = render(bvh).map_err(|source| Error::Invalid { source })?;
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|source| Error::Stream { source })
}

/// Replaces `path` atomically with the rendered document (see [`kinergy_io::write_atomic`]).
pub(crate) fn write_file(path: &Path, bvh: &Bvh) -> Result<(), Error> {
    let text = render(bvh).map_err(|source| Error::Write {
        path: path.to_owned(),
        source,
    })?;
    kinergy_io::write_atomic(path, text.as_bytes()).map_err(|source| Error::Io {
        path: path.to_owned(),
        source,
        reading: false,
    })
}

#[cfg(test)]
mod tests {
    use super::push_f64;

    fn fmt(value: f64) -> String {
        let mut s = String::new();
        push_f64(&mut s, value);
        s
    }

    #[test]
    fn floats_are_short_and_exact() {
        for (value, text) in [
            (0.0, "0"),
            (-0.0, "-0"),
            (1.0, "1"),
            (93.0864, "93.0864"),
            (0.0083333, "0.0083333"),
            (5.1072e-06, "5.1072e-6"),
            (1e-5, "0.00001"),
            (1e16, "1e16"),
            (f64::MIN_POSITIVE / 4.0, "5.562684646268003e-309"),
            (5e-324, "5e-324"),
            (f64::MAX, "1.7976931348623157e308"),
        ] {
            assert_eq!(fmt(value), text);
            assert_eq!(text.parse::<f64>().unwrap().to_bits(), value.to_bits());
        }
    }
}
