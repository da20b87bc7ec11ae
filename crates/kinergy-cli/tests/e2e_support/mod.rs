//! What the end-to-end tests share (`e2e.rs`, `e2e_input.rs`): running the binary, reading
//! what it wrote, a fresh synthetic set, and picture formats.
// Each of the two test binaries uses a part of it.
#![allow(dead_code, unused_imports)]

pub use super::common::{json, kinergy, repo, stderr, stdout, text};

pub use std::collections::BTreeSet;
pub use std::path::{Path, PathBuf};
pub use std::process::{Command, Output};

pub use kinergy_motion::{Clip, ImportOptions, LengthUnit, UnitChoice};

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

pub fn utf8(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Runs `kinergy` with `args`, `set` added to and `unset` removed from the environment.
pub fn kinergy_env(args: &[&str], set: &[(&str, &str)], unset: &[&str]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_kinergy"));
    c.args(args);
    for name in unset {
        c.env_remove(name);
    }
    for (name, value) in set {
        c.env(name, value);
    }
    c.output().expect("run kinergy")
}

/// What a progress bar or colour would leave on a captured stream.
pub fn terminal_remnants(s: &str) -> Vec<&'static str> {
    let mut found = Vec::new();
    if s.contains("\x1b[") {
        found.push("an ANSI escape");
    }
    if s.contains('\r') {
        found.push("a carriage return");
    }
    if s.contains("=>") || s.contains("evaluations  best") {
        found.push("a progress bar");
    }
    found
}

/// Asserts exit code 0 and a stderr without progress-bar or colour remnants.
#[track_caller]
pub fn succeed(o: &Output, what: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(0), "{what}: {err}");
    let remnants = terminal_remnants(&err);
    assert!(
        remnants.is_empty(),
        "{what}: {remnants:?} on stderr: {err:?}"
    );
}

/// Reads a BVH file the way the library does (SI units, radians), guessing its unit.
pub fn read_clip(path: &Path) -> Clip {
    read_clip_in(path, UnitChoice::Auto)
}

pub fn read_clip_in(path: &Path, unit: UnitChoice) -> Clip {
    let options = ImportOptions {
        unit,
        ..Default::default()
    };
    kinergy_motion::read_clip(path, &options)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// The names of the entries of `dir`, sorted.
pub fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A fresh synthetic set, `--persons 1 --reaches 3 --seed 5`, in `DIR/set`.
pub struct Set {
    pub dir: tempfile::TempDir,
    pub root: PathBuf,
    /// The clips the manifest lists, in its order.
    pub clips: Vec<PathBuf>,
    /// Each clip's `frames` column.
    pub manifest_frames: Vec<usize>,
}

pub fn synth_set() -> Set {
    let dir = tempfile::tempdir().expect("tempdir");
    let root = dir.path().join("set");
    let o = kinergy(&[
        "synth",
        "-o",
        utf8(&root),
        "--persons",
        "1",
        "--reaches",
        "3",
        "--seed",
        "5",
    ]);
    succeed(&o, "synth");
    let manifest = std::fs::read_to_string(root.join("manifest.csv")).expect("manifest.csv");
    let mut lines = manifest.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("manifest.csv has no `{name}` column: {header:?}"))
    };
    let (clip_col, frames_col) = (col("clip"), col("frames"));
    let (mut clips, mut manifest_frames) = (Vec::new(), Vec::new());
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len(), "ragged manifest row {line}");
        clips.push(root.join(cells[clip_col]));
        manifest_frames.push(cells[frames_col].parse().expect("frames"));
    }
    Set {
        dir,
        root,
        clips,
        manifest_frames,
    }
}

/// Every `.bvh` file under `dir`, sorted.
pub fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("read_dir") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "bvh") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// A PNG's width and height from its IHDR chunk, after checking the signature and that the
/// file ends with the IEND chunk (a complete file).
#[track_caller]
pub fn png_size(b: &[u8]) -> (u32, u32) {
    assert!(b.len() > 33 + 12, "too short for a PNG: {} bytes", b.len());
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&b[12..16], b"IHDR", "IHDR first");
    assert_eq!(
        &b[b.len() - 12..],
        b"\0\0\0\0IEND\xaeB`\x82",
        "the PNG does not end with IEND"
    );
    let be = |at: usize| u32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
    (be(16), be(20))
}

/// A GIF's logical screen size and its number of images (frames), walking its blocks.
#[track_caller]
pub fn gif_frames(b: &[u8]) -> (u16, u16, usize) {
    assert_eq!(&b[..6], b"GIF89a", "GIF signature");
    let u16_le = |at: usize| u16::from_le_bytes([b[at], b[at + 1]]);
    let skip_sub_blocks = |mut at: usize| loop {
        let n = usize::from(b[at]);
        at += 1 + n;
        if n == 0 {
            return at;
        }
    };
    let packed = b[10];
    let mut at = 13;
    if packed & 0x80 != 0 {
        at += 3 << ((packed & 7) + 1);
    }
    let mut images = 0;
    loop {
        match b[at] {
            0x21 => at = skip_sub_blocks(at + 2),
            0x2C => {
                let local = b[at + 9];
                at += 10;
                if local & 0x80 != 0 {
                    at += 3 << ((local & 7) + 1);
                }
                at = skip_sub_blocks(at + 1);
                images += 1;
            }
            0x3B => {
                assert_eq!(at + 1, b.len(), "bytes after the GIF trailer");
                return (u16_le(6), u16_le(8), images);
            }
            other => panic!("unexpected GIF block {other:#04x} at byte {at}"),
        }
    }
}

/// The text of every `<text>` element of an SVG, trimmed, after checking it is one complete
/// `<svg>` element of `size` (when given).
#[track_caller]
pub fn svg_texts(svg: &str, size: Option<(u32, u32)>) -> Vec<String> {
    assert!(
        svg.starts_with("<svg"),
        "not an SVG: {}",
        &svg[..svg.len().min(80)]
    );
    assert!(svg.trim_end().ends_with("</svg>"), "the SVG is not closed");
    assert_eq!(
        svg.matches("<text").count(),
        svg.matches("</text>").count(),
        "unbalanced <text> elements"
    );
    if let Some((w, h)) = size {
        let want = format!(r#"<svg width="{w}" height="{h}""#);
        assert!(svg.starts_with(&want), "the SVG is not {w}×{h}");
    }
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find("<text") {
        let element = &rest[i..];
        let open = element.find('>').expect("<text …>") + 1;
        let close = element.find("</text>").expect("</text>");
        out.push(element[open..close].trim().to_string());
        rest = &element[close + "</text>".len()..];
    }
    out
}

/// Reads a float out of a JSON value.
#[track_caller]
pub fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}
