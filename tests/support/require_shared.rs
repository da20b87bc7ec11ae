//! What a test does when `../shared/data` (the captures never committed) is absent: it skips,
//! saying so — or, with `KINERGY_REQUIRE_SHARED` set (CI sets it in `.ci/run`), it fails, so
//! that CI cannot take a skipped check for a passed one.
//!
//! One file, included by every test crate that reads the shared data
//! (`#[path = "…/tests/support/require_shared.rs"] mod require_shared;`).

/// The environment variable that turns a skip into a failure.
pub const REQUIRE_SHARED: &str = "KINERGY_REQUIRE_SHARED";

/// True when [`REQUIRE_SHARED`] is set to anything but an empty string or `0`.
pub fn shared_required() -> bool {
    std::env::var_os(REQUIRE_SHARED).is_some_and(|v| !v.is_empty() && v != "0")
}

/// The decision, apart from the environment: `Ok(message)` to print and skip, or
/// `Err(message)` to fail with when the data are required.
pub fn absent_outcome(message: &str, required: bool) -> Result<String, String> {
    if required {
        Err(format!(
            "{message}\n{REQUIRE_SHARED} is set: a test that needs ../shared/data fails where \
             it is absent (unset it to skip)"
        ))
    } else {
        Ok(message.to_string())
    }
}

/// The shared data a test needs are absent: prints `message` (why the test skips), or
/// panics with it when [`shared_required`].
#[track_caller]
pub fn shared_absent(message: &str) {
    match absent_outcome(message, shared_required()) {
        Ok(note) => eprintln!("{note}"),
        Err(failure) => panic!("{failure}"),
    }
}
