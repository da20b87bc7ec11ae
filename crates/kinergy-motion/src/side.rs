//! Left or right: the one type every crate names a side of the body with.

use std::fmt;
use std::str::FromStr;

/// Left or right: an arm, a foot, or the side of the body a target is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// The right side.
    Right,
    /// The left side.
    Left,
}

impl Side {
    /// The other side.
    pub fn opposite(self) -> Side {
        match self {
            Side::Left => Side::Right,
            Side::Right => Side::Left,
        }
    }
}

impl fmt::Display for Side {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Side::Right => "right",
            Side::Left => "left",
        })
    }
}

impl FromStr for Side {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "right" | "r" => Ok(Side::Right),
            "left" | "l" => Ok(Side::Left),
            _ => Err(format!("unknown side `{s}`: expected right or left")),
        }
    }
}
