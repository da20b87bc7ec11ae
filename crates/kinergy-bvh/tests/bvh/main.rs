//! Integration tests of `kinergy-bvh`: hand-written quirk fixtures, real mocap files,
//! round trips, a differential test against `bvh_anim`, mutation robustness, and atomic
//! writes. One binary, so the crate links once.

mod common;
mod differential;
mod quirks;
mod real_files;
#[path = "../../../../tests/support/require_shared.rs"]
mod require_shared;
mod robustness;
mod round_trip;
mod write_file;
