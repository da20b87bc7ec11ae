//! Length units of BVH files (the format has none) and the automatic guess.

use std::fmt;
use std::str::FromStr;

/// A length unit a BVH file may be written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LengthUnit {
    /// Meters.
    Meter,
    /// Centimeters (most exporters: Bandai Namco, Character Creator, Mixamo).
    Centimeter,
    /// Millimeters.
    Millimeter,
    /// Inches.
    Inch,
    /// The CMU database's own unit (the cgspeed conversions): 1/0.45 inch ≈ 0.05644 m,
    /// from the CMU FAQ's `(1.0/0.45) * 2.54 / 100`.
    Cmu,
}

impl LengthUnit {
    /// Every unit, in the order the automatic guess considers them.
    pub const ALL: [LengthUnit; 5] = [
        LengthUnit::Meter,
        LengthUnit::Centimeter,
        LengthUnit::Millimeter,
        LengthUnit::Inch,
        LengthUnit::Cmu,
    ];

    /// How many meters one unit is.
    pub fn meters(self) -> f64 {
        match self {
            LengthUnit::Meter => 1.0,
            LengthUnit::Centimeter => 0.01,
            LengthUnit::Millimeter => 0.001,
            LengthUnit::Inch => 0.0254,
            LengthUnit::Cmu => (1.0 / 0.45) * 2.54 / 100.0,
        }
    }

    /// The short name used on the command line: `m`, `cm`, `mm`, `in`, `cmu`.
    pub fn name(self) -> &'static str {
        match self {
            LengthUnit::Meter => "m",
            LengthUnit::Centimeter => "cm",
            LengthUnit::Millimeter => "mm",
            LengthUnit::Inch => "in",
            LengthUnit::Cmu => "cmu",
        }
    }

    /// The unit in which a standing adult whose extent is `extent` file units comes closest
    /// to [`TYPICAL_HUMAN_HEIGHT`] meters, comparing ratios (so 1.2 m and 2.4 m are equally
    /// far from 1.7 m). Units differ by at least a factor 2.2, so the guess is robust to
    /// children, seated captures and raised arms. `None` for a non-positive or non-finite extent.
    pub fn guess_from_extent(extent: f64) -> Option<LengthUnit> {
        if !(extent.is_finite() && extent > 0.0) {
            return None;
        }
        LengthUnit::ALL.into_iter().min_by(|a, b| {
            let da = (extent * a.meters() / TYPICAL_HUMAN_HEIGHT).ln().abs();
            let db = (extent * b.meters() / TYPICAL_HUMAN_HEIGHT).ln().abs();
            da.total_cmp(&db)
        })
    }
}

/// The height, in meters, that the unit guess expects of a captured person.
pub const TYPICAL_HUMAN_HEIGHT: f64 = 1.7;

impl fmt::Display for LengthUnit {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The unit named on the command line was not one we know.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown unit `{0}`: expected m, cm, mm, in, cmu or auto")]
pub struct UnknownUnit(pub String);

impl FromStr for LengthUnit {
    type Err = UnknownUnit;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        LengthUnit::ALL
            .into_iter()
            .find(|u| u.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| UnknownUnit(s.to_string()))
    }
}

/// Which unit to read a file in: a given one, or guessed from the skeleton's size.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UnitChoice {
    /// Guess from the extent of the skeleton in its first frame
    /// ([`LengthUnit::guess_from_extent`]).
    #[default]
    Auto,
    /// Use this unit.
    Fixed(LengthUnit),
}

impl UnitChoice {
    /// As `--from-unit` spells it: `auto`, `m`, `cm`, `mm`, `in` or `cmu`.
    pub fn name(self) -> &'static str {
        match self {
            UnitChoice::Auto => "auto",
            UnitChoice::Fixed(unit) => unit.name(),
        }
    }
}

impl FromStr for UnitChoice {
    type Err = UnknownUnit;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.eq_ignore_ascii_case("auto") {
            Ok(UnitChoice::Auto)
        } else {
            s.parse().map(UnitChoice::Fixed)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guesses_the_real_files_units() {
        // Extents measured on the real captures (file units, first frame).
        assert_eq!(
            LengthUnit::guess_from_extent(170.0),
            Some(LengthUnit::Centimeter)
        );
        assert_eq!(LengthUnit::guess_from_extent(1.8), Some(LengthUnit::Meter));
        assert_eq!(LengthUnit::guess_from_extent(31.0), Some(LengthUnit::Cmu));
        assert_eq!(LengthUnit::guess_from_extent(68.0), Some(LengthUnit::Inch));
        assert_eq!(
            LengthUnit::guess_from_extent(1750.0),
            Some(LengthUnit::Millimeter)
        );
        // A seated capture (1.25 m) and a child (1.1 m) in cm are still cm.
        assert_eq!(
            LengthUnit::guess_from_extent(110.0),
            Some(LengthUnit::Centimeter)
        );
        assert_eq!(LengthUnit::guess_from_extent(f64::NAN), None);
        assert_eq!(LengthUnit::guess_from_extent(0.0), None);
    }

    #[test]
    fn parses_names() {
        assert_eq!("CM".parse::<LengthUnit>(), Ok(LengthUnit::Centimeter));
        assert_eq!("auto".parse::<UnitChoice>(), Ok(UnitChoice::Auto));
        assert!("furlong".parse::<UnitChoice>().is_err());
    }
}
