//! The segments file: written then read gives the same rows; every bad input is an error that
//! names the file and the line.

use std::path::{Path, PathBuf};

use kinergy_motion::segment::Label;
use kinergy_motion::{ImportOptions, Side, read_clip};
use kinergy_train::segments_file::{RowTempo, SegmentRow, SegmentsFile, SegmentsFileError};

/// A folder with two persons' clips (empty files: reading a segments file does not read clips).
fn folder() -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = tempfile::tempdir().expect("tempdir");
    let (a, b) = (dir.path().join("ann"), dir.path().join("bob"));
    for (folder, clip) in [(&a, "r1.bvh"), (&a, "r2.bvh"), (&b, "r1.bvh")] {
        std::fs::create_dir_all(folder).expect("folder");
        std::fs::write(folder.join(clip), "").expect("clip");
    }
    (dir, a, b)
}

#[test]
fn written_then_read_gives_the_same_rows() {
    let (dir, ann, bob) = folder();
    let out = dir.path().join("out");
    std::fs::create_dir_all(&out).expect("out");
    let rows = vec![
        SegmentRow::new(ann.join("r1.bvh"), 0..12, Side::Left, Label::Reach),
        SegmentRow::new(ann.join("r1.bvh"), 12..37, Side::Left, Label::Return),
        SegmentRow {
            person: "Bob, the second".into(), // a comma: quoted
            ..SegmentRow::new(bob.join("r1.bvh"), 5..80, Side::Right, Label::Other)
        },
    ];
    let path = out.join("segments.csv");
    let written = SegmentsFile::new(&path, rows.clone());
    written.write().expect("write");
    let text = std::fs::read_to_string(&path).expect("read");
    eprintln!("{text}");
    assert!(
        text.starts_with("# kinergy segments: frames onset..end"),
        "{text}"
    );
    assert!(text.contains("clip,onset,end,arm,label,person\n"), "{text}");
    // Clips are written relative to the file's folder.
    assert!(
        text.contains("../ann/r1.bvh,0,12,left,reach,ann\n"),
        "{text}"
    );

    let read = SegmentsFile::read(&path).expect("read back");
    assert_eq!(read.rows().len(), rows.len());
    for (i, (r, w)) in read.rows().iter().zip(&rows).enumerate() {
        assert_eq!(
            std::fs::canonicalize(&r.clip).expect("clip"),
            std::fs::canonicalize(&w.clip).expect("clip")
        );
        assert_eq!(
            (&r.frames, r.arm, r.label, &r.person),
            (&w.frames, w.arm, w.label, &w.person)
        );
        // The comment is line 1, the header line 2.
        assert_eq!(r.line, Some(i + 3));
    }
    assert_eq!(read.rows_for(&ann.join("r1.bvh")).count(), 2);
    assert_eq!(read.rows_for(&ann.join("r2.bvh")).count(), 0);
    // And writing what was read gives the same text.
    assert_eq!(
        SegmentsFile::new(&path, read.rows().to_vec()).to_csv(),
        text
    );
}

#[test]
fn a_hand_written_file_takes_defaults_comments_and_any_column_order() {
    let (dir, _, _) = folder();
    let path = dir.path().join("mine.csv");
    std::fs::write(
        &path,
        "# my reaches\n\narm , end,onset,clip\nright,40,3,ann/r1.bvh\n# not this one\nL, 9 ,1,bob/r1.bvh\n",
    )
    .expect("write");
    let m = SegmentsFile::read(&path).expect("read");
    let rows = m.rows();
    assert_eq!(rows.len(), 2);
    assert_eq!((rows[0].frames.clone(), rows[0].arm), (3..40, Side::Right));
    assert_eq!((rows[1].frames.clone(), rows[1].arm), (1..9, Side::Left));
    assert_eq!(rows[0].label, Label::Reach);
    assert_eq!(
        (rows[0].person.as_str(), rows[1].person.as_str()),
        ("ann", "bob")
    );
    assert_eq!((rows[0].line, rows[1].line), (Some(4), Some(6)));
}

/// Reads `text` as `segments.csv` in a folder with the clips `ann/r1.bvh` and `bob/r1.bvh`.
fn error(text: &str) -> (SegmentsFileError, PathBuf) {
    let (dir, _, _) = folder();
    let path = dir.path().join("segments.csv");
    std::fs::write(&path, text).expect("write");
    let e = SegmentsFile::read(&path).expect_err(text);
    // Keep the folder until here.
    drop(dir);
    (e, path)
}

fn assert_error(text: &str, line: Option<usize>, needle: &str) {
    let (e, path) = error(text);
    let msg = e.to_string();
    assert_eq!(e.line, line, "{msg}");
    assert_eq!(e.path, path);
    assert!(msg.starts_with(&path.display().to_string()), "{msg}");
    if let Some(line) = line {
        assert!(msg.contains(&format!("line {line}: ")), "{msg}");
    }
    assert!(msg.contains(needle), "`{msg}` does not say {needle}");
}

const HEADER: &str = "clip,onset,end,arm,label,person\n";

#[test]
fn every_bad_row_names_the_file_and_the_line() {
    let bad_rows = [
        (
            "nobody/r9.bvh,0,10,left,reach,x",
            "clip `nobody/r9.bvh`: no such file",
        ),
        (",0,10,left,reach,x", "empty `clip`"),
        (
            "ann/r1.bvh,a,10,left,reach,x",
            "onset `a` is not a frame number",
        ),
        (
            "ann/r1.bvh,0,-3,left,reach,x",
            "end `-3` is not a frame number",
        ),
        (
            "ann/r1.bvh,0,1.5,left,reach,x",
            "end `1.5` is not a frame number",
        ),
        ("ann/r1.bvh,10,10,left,reach,x", "frames 10..10 are empty"),
        ("ann/r1.bvh,12,10,left,reach,x", "frames 12..10 are empty"),
        (
            "ann/r1.bvh,0,10,middle,reach,x",
            "arm `middle`: expected right or left",
        ),
        (
            "ann/r1.bvh,0,10,left,wave,x",
            "label `wave`: expected reach, return or other",
        ),
        (
            "ann/r1.bvh,0,10,left,reach",
            "5 fields where the header has 6",
        ),
    ];
    for (row, needle) in bad_rows {
        // The bad row is line 3, after the header and a good row.
        let text = format!("{HEADER}bob/r1.bvh,0,5,right,reach,bob\n{row}\n");
        assert_error(&text, Some(3), needle);
    }
}

/// The target's columns: written only when a row has a target (empty cells for the others),
/// read back to the same numbers, all three or none, finite; bad cells name the line.
#[test]
fn targets_round_trip_and_bad_ones_name_the_line() {
    let (dir, ann, bob) = folder();
    let path = dir.path().join("segments.csv");
    let target = [-0.1314983289625152, 0.9911083172219668, 0.34385613501691664];
    let rows = vec![
        SegmentRow::new(ann.join("r1.bvh"), 0..12, Side::Left, Label::Reach).with_target(target),
        SegmentRow::new(bob.join("r1.bvh"), 5..80, Side::Right, Label::Reach),
    ];
    let written = SegmentsFile::new(&path, rows);
    written.write().expect("write");
    let text = std::fs::read_to_string(&path).expect("read");
    assert!(
        text.contains("clip,onset,end,arm,label,person,target_x,target_y,target_z\n"),
        "{text}"
    );
    assert!(
        text.contains("bob/r1.bvh,5,80,right,reach,bob,,,\n"),
        "{text}"
    );
    let read = SegmentsFile::read(&path).expect("read back");
    assert_eq!(read.rows()[0].target, Some(target));
    assert_eq!(read.rows()[1].target, None);
    assert_eq!(
        SegmentsFile::new(&path, read.rows().to_vec()).to_csv(),
        text
    );

    let header = "clip,onset,end,arm,target_x,target_y,target_z\n";
    for (row, needle) in [
        (
            "ann/r1.bvh,0,10,left,0.1,x,0.3",
            "target_y `x` is not a finite number",
        ),
        (
            "ann/r1.bvh,0,10,left,0.1,,0.3",
            "target_y `` is not a finite number",
        ),
        (
            "ann/r1.bvh,0,10,left,0.1,inf,0.3",
            "target_y `inf` is not a finite",
        ),
    ] {
        assert_error(&format!("{header}{row}\n"), Some(2), needle);
    }
    assert_error(
        "clip,onset,end,arm,target_x,target_y\nann/r1.bvh,0,10,left,0.1,0.2\n",
        Some(1),
        "target_x, target_y and target_z",
    );
}

/// The tempo's columns (what `synth --params` records of the controller that made a motion):
/// written only when a row has one, read back to the same numbers, both or none, positive and
/// finite; bad cells name the line.
#[test]
fn tempos_round_trip_and_bad_ones_name_the_line() {
    let (dir, ann, bob) = folder();
    let path = dir.path().join("segments.csv");
    let tempo = RowTempo {
        peak_speed_m_s: 1.187_5,
        duration_s: 0.987_187_478_487_449_9,
    };
    let rows = vec![
        SegmentRow::new(ann.join("r1.bvh"), 0..12, Side::Left, Label::Reach).with_tempo(tempo),
        SegmentRow::new(bob.join("r1.bvh"), 5..80, Side::Right, Label::Reach),
    ];
    SegmentsFile::new(&path, rows).write().expect("write");
    let text = std::fs::read_to_string(&path).expect("read");
    assert!(
        text.contains("clip,onset,end,arm,label,person,peak_speed_m_s,duration_s\n"),
        "{text}"
    );
    assert!(
        text.contains("bob/r1.bvh,5,80,right,reach,bob,,\n"),
        "{text}"
    );
    let read = SegmentsFile::read(&path).expect("read back");
    assert_eq!(read.rows()[0].tempo, Some(tempo));
    assert_eq!(read.rows()[1].tempo, None);
    assert_eq!(
        SegmentsFile::new(&path, read.rows().to_vec()).to_csv(),
        text
    );

    let header = "clip,onset,end,arm,peak_speed_m_s,duration_s\n";
    for (row, needle) in [
        (
            "ann/r1.bvh,0,10,left,1.2,x",
            "duration_s `x` is not a positive number",
        ),
        (
            "ann/r1.bvh,0,10,left,,0.8",
            "peak_speed_m_s `` is not a positive number",
        ),
        (
            "ann/r1.bvh,0,10,left,-1,0.8",
            "peak_speed_m_s `-1` is not a positive number",
        ),
        (
            "ann/r1.bvh,0,10,left,1.2,0",
            "duration_s `0` is not a positive number",
        ),
        (
            "ann/r1.bvh,0,10,left,NaN,0.8",
            "peak_speed_m_s `NaN` is not a positive",
        ),
    ] {
        assert_error(&format!("{header}{row}\n"), Some(2), needle);
    }
    assert_error(
        "clip,onset,end,arm,duration_s\nann/r1.bvh,0,10,left,0.8\n",
        Some(1),
        "peak_speed_m_s and duration_s",
    );
}

#[test]
fn a_row_twice_is_an_error_naming_both_lines() {
    let text = format!(
        "{HEADER}ann/r1.bvh,0,10,left,reach,ann\nbob/r1.bvh,0,10,left,reach,bob\n\
         ann/r1.bvh,0,10,left,return,someone\n"
    );
    assert_error(&text, Some(4), "repeats line 2");
    // The same frames on the other arm are another segment.
    let (dir, _, _) = folder();
    let path = dir.path().join("ok.csv");
    std::fs::write(
        &path,
        format!("{HEADER}ann/r1.bvh,0,10,left,reach,a\nann/r1.bvh,0,10,right,reach,a\n"),
    )
    .expect("write");
    assert_eq!(SegmentsFile::read(&path).expect("read").rows().len(), 2);
}

#[test]
fn a_bad_header_names_the_file_and_its_line() {
    assert_error(
        "clip,onset,end\nann/r1.bvh,0,10\n",
        Some(1),
        "no `arm` column",
    );
    assert_error(
        "# comment\nclip,onset,end,arm,perosn\n",
        Some(2),
        "unknown column `perosn`",
    );
    assert_error(
        "clip,onset,end,arm,clip\n",
        Some(1),
        "column `clip` appears twice",
    );
    assert_error("", None, "no header");
    assert_error("# only a comment\n\n", None, "no header");
}

#[test]
fn a_missing_file_is_an_error_naming_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("none.csv");
    let e = SegmentsFile::read(&path).expect_err("missing");
    assert_eq!((e.path.as_path(), e.line), (path.as_path(), None));
    assert!(e.to_string().starts_with(&path.display().to_string()));
}

// The frames are checked against the clip when the row is resolved: inside its frames, or an
// error naming the segments file, the line and the clip.
#[test]
fn a_window_outside_the_clip_is_an_error_when_resolved() {
    let dir = tempfile::tempdir().expect("tempdir");
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data-synthetic/p01/r01.bvh");
    let clip_path = dir.path().join("r01.bvh");
    std::fs::copy(&fixture, &clip_path).expect("copy");
    let (clip, _) = read_clip(&clip_path, &ImportOptions::default()).expect("clip");
    let n = clip.frame_count();
    let path = dir.path().join("segments.csv");
    std::fs::write(
        &path,
        format!(
            "{HEADER}r01.bvh,0,{n},right,reach,p\nr01.bvh,5,{},right,reach,p\n",
            n + 1
        ),
    )
    .expect("write");
    let m = SegmentsFile::read(&path).expect("read");
    assert_eq!(m.resolve(&m.rows()[0], &clip), Ok(0..n));
    let e = m.resolve(&m.rows()[1], &clip).expect_err("past the end");
    let msg = e.to_string();
    assert_eq!(e.line, Some(3));
    assert!(
        msg.starts_with(&format!("{} line 3: frames 5..{}", path.display(), n + 1))
            && msg.contains(&format!("which has {n} frames")),
        "{msg}"
    );
}

/// What the writer writes the reader reads — clips named with a line break,
/// a leading `#` or a leading space, persons with quotes and line breaks — and a file whose
/// lines end in CR alone (classic Mac) or CR LF reads the same rows with the right lines.
#[test]
fn awkward_names_and_line_ends_round_trip() {
    let dir = tempfile::tempdir().expect("tempdir");
    let names = ["a\nb.bvh", "#take.bvh", " lead.bvh", "q\"uote,d.bvh"];
    let rows: Vec<SegmentRow> = names
        .iter()
        .enumerate()
        .map(|(k, name)| {
            let clip = dir.path().join(name);
            std::fs::write(&clip, "").expect("clip");
            SegmentRow {
                person: format!("p\n{k} \"x\""),
                ..SegmentRow::new(clip, k..k + 5, Side::Right, Label::Reach)
            }
        })
        .collect();
    let path = dir.path().join("s.csv");
    SegmentsFile::new(&path, rows.clone())
        .write()
        .expect("write");
    let read = SegmentsFile::read(&path).expect("read back");
    assert_eq!(read.rows().len(), rows.len());
    for (r, w) in read.rows().iter().zip(&rows) {
        assert_eq!(
            std::fs::canonicalize(&r.clip).expect("clip"),
            std::fs::canonicalize(&w.clip).expect("clip")
        );
        assert_eq!((&r.frames, &r.person), (&w.frames, &w.person));
    }

    let (_dir, ann, _) = folder();
    let lf = "# comment\nclip,onset,end,arm\n  # indented comment\nr1.bvh,0,10,right\n\nr2.bvh,3,9,left\n";
    for text in [
        lf.to_string(),
        lf.replace('\n', "\r"),
        lf.replace('\n', "\r\n"),
    ] {
        let file = SegmentsFile::parse(&text, &ann.join("s.csv")).expect("parsed");
        let frames: Vec<_> = file.rows().iter().map(|r| r.frames.clone()).collect();
        assert_eq!(frames, vec![0..10, 3..9], "{text:?}");
        // Lines are counted the same way whatever ends them: the bad row is on line 4.
        let bad = text.replace("0,10", "10,0");
        let e = SegmentsFile::parse(&bad, &ann.join("s.csv")).expect_err("empty frames");
        assert_eq!(e.line, Some(4), "{text:?}: {e}");
    }
}
