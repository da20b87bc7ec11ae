//! The ranges of every rate, duration, size and count the subcommands take
//! ([`kinergy_train::limits`], shared with the Python package). Each subcommand checks its
//! options against these before any work (exit 2 naming the option and the range, see
//! [`check_range`]); the `--help` text of each option states its range.

use std::fmt::Display;

use super::failure::Failure;

pub use kinergy_train::limits::*;

/// Checks that `value` of option `name` is within `range` (both ends included; NaN never
/// is), else bad input: `--fps 0: expected 1 to 100`.
pub fn check_range<T: PartialOrd + Display + Copy>(
    name: &str,
    value: T,
    range: (T, T),
) -> Result<(), Failure> {
    let (lo, hi) = range;
    if lo <= value && value <= hi {
        Ok(())
    } else {
        Err(Failure::Input(format!(
            "{name} {}: expected {lo} to {hi}",
            kinergy_io::quote_number(value)
        )))
    }
}

/// [`check_range`] for an optional value.
pub fn check_optional<T: PartialOrd + Display + Copy>(
    name: &str,
    value: Option<T>,
    range: (T, T),
) -> Result<(), Failure> {
    value.map_or(Ok(()), |v| check_range(name, v, range))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_include_both_ends_and_refuse_nan() {
        assert!(check_range("--x", 1.0, (1.0, 2.0)).is_ok());
        assert!(check_range("--x", 2.0, (1.0, 2.0)).is_ok());
        let e = check_range("--x", 1e7, (1.0, 1000.0)).unwrap_err();
        assert_eq!(e.to_string(), "--x 10000000: expected 1 to 1000");
        assert!(check_range("--x", f64::NAN, (1.0, 2.0)).is_err());
        assert!(check_range("--x", f64::INFINITY, (1.0, 2.0)).is_err());
        assert!(check_optional("--n", None, (1, 2)).is_ok());
        assert!(check_optional("--n", Some(3), (1, 2)).is_err());
    }
}
