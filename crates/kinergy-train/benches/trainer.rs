//! Trainer benchmarks (in progress).
fn main() {}
