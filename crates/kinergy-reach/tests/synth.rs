//! The synthetic set: made in memory and written in one place, the same files either way.

use kinergy_reach::drive::Driver;
use kinergy_reach::synth::{MANIFEST, SynthSet, SynthSettings, write_set};

/// Every file under `dir`, by its path relative to `dir`, with its bytes.
fn files(dir: &std::path::Path) -> Vec<(std::path::PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for entry in std::fs::read_dir(&d).expect("read_dir") {
            let path = entry.expect("entry").path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let bytes = std::fs::read(&path).expect("read");
                out.push((path.strip_prefix(dir).expect("inside").to_path_buf(), bytes));
            }
        }
    }
    out.sort();
    out
}

#[test]
fn the_set_in_memory_writes_what_write_set_writes() {
    let settings = SynthSettings {
        persons: 2,
        reaches: 2,
        ..SynthSettings::default()
    };
    let set = SynthSet::make(&settings, Driver::Profile).expect("set");
    assert_eq!(set.clips.len(), 4);
    for c in &set.clips {
        let [reach] = &c.reaches[..] else {
            panic!("one reach a take without both hands")
        };
        assert_eq!(c.clip.frame_count(), reach.row.frames);
        assert!(reach.driven.end <= reach.row.frames && !reach.driven.is_empty());
    }
    let (a, b) = (
        tempfile::tempdir().expect("dir"),
        tempfile::tempdir().expect("dir"),
    );
    set.write(a.path()).expect("write");
    let made = write_set(b.path(), &settings, Driver::Profile).expect("write_set");
    let rows: Vec<_> = made.iter().map(|r| &r.row).collect();
    assert_eq!(rows, set.rows().collect::<Vec<_>>());
    let (ours, theirs) = (files(a.path()), files(b.path()));
    assert_eq!(ours.len(), 5, "four clips and the manifest");
    assert!(
        ours.iter()
            .any(|(p, _)| p == std::path::Path::new(MANIFEST))
    );
    assert!(ours == theirs, "the same files, byte for byte");
}

#[test]
fn every_person_reaches_their_floor_targets_as_drawn() {
    // Person 43 of the default seed (1.83 m tall, the least flexible legs, 0.62) reached none
    // of 20 `floor_far` targets drawn around 0.15 m above the floor before the posture search
    // (issue 43): the set pulled the draw up toward `front_near` (to 0.128 m). Now the body
    // steps, stoops and squats until the hand reaches: every floor target is as drawn, and
    // reached within a centimetre.
    let settings = SynthSettings {
        persons: 43,
        reaches: 4,
        ..SynthSettings::default()
    };
    let set = SynthSet::make(&settings, Driver::Profile).expect("a set of any size is made");
    assert_eq!(set.clips.len(), 43 * 4);
    let row = set
        .rows()
        .find(|row| row.clip == "p43/r04.bvh")
        .expect("p43/r04");
    assert_eq!(row.kind, "floor_far");
    let mut floor = 0;
    for row in set.rows().filter(|row| row.kind == "floor_far") {
        let drawn_at_most = (0.08 * row.height_m + 0.04).max(0.03);
        assert!(
            row.target_y <= drawn_at_most + 1e-12,
            "{}: pulled up from the floor to {} m",
            row.clip,
            row.target_y
        );
        assert!(
            row.final_error_m < 0.01,
            "{}: {} m short",
            row.clip,
            row.final_error_m
        );
        floor += 1;
    }
    assert!(floor >= 20, "{floor} floor reaches");
}
