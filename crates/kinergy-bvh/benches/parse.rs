//! Parse and write throughput on the real files, with `bvh_anim` 0.4 side by side.
//!
//! `cargo bench -p kinergy-bvh --bench parse`; the report shows MB/s per file.

use std::hint::black_box;
use std::path::{Path, PathBuf};
use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};

const COMMITTED_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data");
const SHARED_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/real-bvh");

/// The committed files, then the shared ones not already among them (if present).
fn files() -> Vec<(String, Vec<u8>)> {
    let mut paths: Vec<PathBuf> = ["cmu_12_01_walk.bvh", "006_14.bvh"]
        .iter()
        .map(|f| Path::new(COMMITTED_DIR).join(f))
        .collect();
    for f in [
        "dataset-1_guide_normal_001.bvh",
        "dataset-1_bye_normal_001.bvh",
    ] {
        let path = Path::new(SHARED_DIR).join(f);
        if path.is_file() {
            paths.push(path);
        }
    }
    paths
        .into_iter()
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            let bytes = std::fs::read(&p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
            (name, bytes)
        })
        .collect()
}

fn parse(c: &mut Criterion) {
    let mut group = c.benchmark_group("parse");
    group.measurement_time(Duration::from_secs(3));
    group.sample_size(40);
    for (name, bytes) in files() {
        group.throughput(Throughput::Bytes(bytes.len() as u64));
        let options = kinergy_bvh::ReadOptions::default();
        group.bench_with_input(
            BenchmarkId::new("kinergy-bvh", &name),
            &bytes,
            |b, bytes| b.iter(|| kinergy_bvh::parse_bytes(black_box(bytes), &options).unwrap()),
        );
        group.bench_with_input(BenchmarkId::new("bvh_anim", &name), &bytes, |b, bytes| {
            b.iter(|| bvh_anim::from_bytes(black_box(&bytes[..])).unwrap())
        });
    }
    group.finish();
}

fn write(c: &mut Criterion) {
    let mut group = c.benchmark_group("write");
    group.measurement_time(Duration::from_secs(3));
    group.sample_size(40);
    for (name, bytes) in files() {
        let bvh = kinergy_bvh::parse_bytes(&bytes, &kinergy_bvh::ReadOptions::default()).unwrap();
        let written = kinergy_bvh::to_string(&bvh).unwrap();
        group.throughput(Throughput::Bytes(written.len() as u64));
        group.bench_with_input(BenchmarkId::new("kinergy-bvh", &name), &bvh, |b, bvh| {
            b.iter(|| kinergy_bvh::to_string(black_box(bvh)).unwrap())
        });
        let theirs = bvh_anim::from_bytes(&bytes[..]).unwrap();
        group.bench_with_input(BenchmarkId::new("bvh_anim", &name), &theirs, |b, theirs| {
            b.iter(|| black_box(theirs).to_bstring())
        });
    }
    group.finish();
}

criterion_group!(benches, parse, write);
criterion_main!(benches);
