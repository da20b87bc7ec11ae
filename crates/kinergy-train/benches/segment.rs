//! What segmentation costs: `find_segments` (forward kinematics of four arm joints, despike,
//! speed, motions, sub-movements, labels) on one Bandai Namco raise-hand take (read from
//! `../shared`, skipped when absent: CC BY-NC, never committed) and one clip of the committed
//! synthetic set. The clip is read once, outside the timing.
//!
//! `cargo bench -p kinergy-train --bench segment`

use std::hint::black_box;
use std::path::{Path, PathBuf};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use kinergy_motion::segment::{SegmentSettings, find_segments};
use kinergy_motion::{ArmJoints, ImportOptions, Side, read_clip};

fn clips() -> Vec<(String, PathBuf, Side)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut out = Vec::new();
    let bandai = root.join("../shared/data/bandai-raise-left/elderly_001.bvh");
    if bandai.exists() {
        out.push(("bandai_elderly_001_left".to_string(), bandai, Side::Left));
    } else {
        #[allow(clippy::print_stderr)]
        {
            eprintln!(
                "skipping the Bandai take: {} is absent (never committed)",
                bandai.display()
            );
        }
    }
    out.push((
        "synthetic_p01_r01_right".to_string(),
        root.join("data-synthetic/p01/r01.bvh"),
        Side::Right,
    ));
    out
}

fn segmentation(c: &mut Criterion) {
    let settings = SegmentSettings::default();
    let mut group = c.benchmark_group("find_segments");
    for (name, path, side) in clips() {
        let (clip, _) = read_clip(&path, &ImportOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let arm = ArmJoints::find(clip.skeleton(), side).expect("arm");
        group.throughput(Throughput::Elements(clip.frame_count() as u64));
        group.bench_function(&name, |b| {
            b.iter(|| find_segments(black_box(&clip), &arm, &settings).expect("segments"))
        });
    }
    group.finish();
}

criterion_group!(benches, segmentation);
criterion_main!(benches);
