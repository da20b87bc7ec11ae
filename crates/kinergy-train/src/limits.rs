//! The ranges of every rate, duration, size and count the toolkit's front ends take — the
//! `kinergy` command's options and the Python package's keyword arguments — in one place, so
//! the two accept the same values. Each front end checks its settings against these before
//! any work. They keep the memory and time a call needs bounded by its inputs and settings.
//! (The option names below are the CLI's; the Python arguments are named alike.)

/// `--max-input-mb`: the largest BVH file read, MiB (default 256).
pub const MAX_INPUT_MB: (u64, u64) = (1, 4096);
/// `--max-input-mb`'s default, MiB.
pub const DEFAULT_INPUT_MB: u64 = 256;

/// `synth --persons`.
pub const SYNTH_PERSONS: (usize, usize) = (1, 100);
/// `synth --reaches` (per person).
pub const SYNTH_REACHES: (usize, usize) = (1, 100);
/// `synth --frame-rate`, Hz.
pub const SYNTH_FRAME_RATE: (f64, f64) = (1.0, 1000.0);
/// `synth --both-hands`: the share of each person's takes that reach with both hands.
pub const SYNTH_BOTH_HANDS: (f64, f64) = (0.0, 1.0);

/// `synthesize --max-seconds`.
pub const SYNTHESIZE_SECONDS: (f64, f64) = (0.01, 60.0);
/// `synthesize --tolerance`, meters.
pub const TOLERANCE_M: (f64, f64) = (1e-5, 1.0);

/// `reach --timeout` (seconds), `--height` (meters) and `--flexibility`: the full-body
/// reach's own ranges ([`kinergy_reach::drive`]).
pub use kinergy_reach::drive::{
    FLEXIBILITY as REACH_FLEXIBILITY, HEIGHT_M as REACH_HEIGHT, TIMEOUT_S as REACH_TIMEOUT,
};

// `plan`'s ranges are the planner's own: `kinergy_plan::request::{DISTANCE_M, BUDGET_MS}`.

/// `animate --fps`.
pub const ANIMATE_FPS: (u32, u32) = (1, 100);
/// `animate --strip-frames`.
pub const ANIMATE_STRIP_FRAMES: (usize, usize) = (1, 24);
/// Each side of a picture (`animate --size`, `plot speed --size`), pixels.
pub const PICTURE_SIDE: (u32, u32) = (64, 3840);
/// `animate`: GIF width × height × frames (frames = duration × fps + 1), at most: about
/// 52 s of clip at the default 640x480 and 25 fps.
pub const MAX_GIF_PIXELS: u64 = 400_000_000;
/// `animate`: the film strip's width × height, at most (its bitmap, 3 bytes a pixel, is
/// held in memory).
pub const MAX_STRIP_PIXELS: u64 = 100_000_000;

/// `plot speed --smoothing`, seconds.
pub const PLOT_SMOOTHING: (f64, f64) = (0.0, 10.0);

/// `segment --min-peak-speed`, m/s.
pub const MIN_PEAK_SPEED: (f64, f64) = (0.001, 50.0);

/// `--threads` (fit, compare).
pub const THREADS: (usize, usize) = (1, 1024);
/// `--budget` (fit, compare): evaluations per model fit.
pub const BUDGET: (usize, usize) = (1, 10_000_000);
/// `--population` (fit, compare).
pub const POPULATION: (usize, usize) = (1, 1000);
/// `--temperature` (fit, compare).
pub const TEMPERATURE: (f64, f64) = (0.0, 1e6);
/// `--stable-change` (fit, compare): relative change of the mean score.
pub const STABLE_CHANGE: (f64, f64) = (0.0, 1.0);
/// `--stable-window` (fit, compare): iterations.
pub const STABLE_WINDOW: (usize, usize) = (1, 100_000);
/// `--speed-weight`, seconds of distance per m/s of hand-speed error.
pub const SPEED_WEIGHT: (f64, f64) = (0.0, 10.0);
/// `fit --checkpoint-every`, iterations.
pub const CHECKPOINT_EVERY: (usize, usize) = (1, 1_000_000);
/// `compare --holdout`, takes per person.
pub const HOLDOUT: (usize, usize) = (1, 1000);
