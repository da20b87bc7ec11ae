//! Where the camera looks from and how meters become pixels: the view's projection, the
//! figures' common box on screen and its fit into a panel.

use nalgebra::Point3;
use serde::Serialize;

/// The margin around the figures' common bounding box, as a part of its larger side.
const MARGIN: f64 = 0.06;

/// Where the camera looks from. The character faces +Z, Y up, its left at +X.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum View {
    /// From in front, the camera on +Z looking back ([`View::description`]).
    Front,
    /// From the character's right, the camera on −X ([`View::description`]).
    Side,
    /// From above ([`View::description`]).
    Top,
}

impl View {
    /// Every view, in the order front ends list them.
    pub const ALL: [View; 3] = [View::Front, View::Side, View::Top];

    /// Screen coordinates (right, up) of a world point, meters.
    pub fn project(self, p: &Point3<f64>) -> (f64, f64) {
        match self {
            View::Front => (p.x, p.y),
            View::Side => (p.z, p.y),
            View::Top => (p.x, -p.z),
        }
    }

    /// Its name: `front`, `side` or `top`.
    pub fn name(self) -> &'static str {
        match self {
            View::Front => "front",
            View::Side => "side",
            View::Top => "top",
        }
    }

    /// Where the screen's axes are in the world, for people (a command's help).
    pub fn description(self) -> &'static str {
        match self {
            View::Front => {
                "From in front, the camera on +Z looking back: screen right = world +X (the \
                 character's left), so its right arm is on the screen's left, as when you face \
                 someone; screen up = +Y"
            }
            View::Side => {
                "From the character's right, the camera on −X: screen right = +Z (the \
                 character faces right), screen up = +Y"
            }
            View::Top => {
                "From above: screen right = +X as in the front view, screen down = +Z (the \
                 character faces the bottom of the picture)"
            }
        }
    }
}

impl std::fmt::Display for View {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A view's name that is none of [`View::ALL`]'s.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown view `{0}`: expected front, side or top")]
pub struct UnknownView(pub String);

impl std::str::FromStr for View {
    type Err = UnknownView;

    /// A view by its [`name`](View::name).
    fn from_str(s: &str) -> Result<View, UnknownView> {
        View::ALL
            .into_iter()
            .find(|v| v.name() == s)
            .ok_or_else(|| UnknownView(s.to_string()))
    }
}

/// A screen-space box in meters: (left, right, bottom, top).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Bounds {
    pub(crate) u0: f64,
    pub(crate) u1: f64,
    pub(crate) v0: f64,
    pub(crate) v1: f64,
}

impl Bounds {
    /// The box around every finite point, grown by [`MARGIN`] of its larger side all round.
    pub(crate) fn around(points: impl Iterator<Item = (f64, f64)>) -> Bounds {
        let (mut u0, mut u1, mut v0, mut v1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (u, v) in points.filter(|(u, v)| u.is_finite() && v.is_finite()) {
            u0 = u0.min(u);
            u1 = u1.max(u);
            v0 = v0.min(v);
            v1 = v1.max(v);
        }
        if !u0.is_finite() {
            return Bounds {
                u0: -1.0,
                u1: 1.0,
                v0: -1.0,
                v1: 1.0,
            };
        }
        let pad = MARGIN * (u1 - u0).max(v1 - v0).max(0.05);
        Bounds {
            u0: u0 - pad,
            u1: u1 + pad,
            v0: v0 - pad,
            v1: v1 + pad,
        }
    }
}

/// Meters → pixels with one scale for both axes, the box centred in a pixel rectangle.
pub(crate) struct Mapping {
    scale: f64,
    centre: (f64, f64),
    pixel_centre: (f64, f64),
}

impl Mapping {
    /// Fits `b` into the rectangle `(x0, y0)–(x1, y1)`, pixels, keeping the aspect ratio.
    pub(crate) fn fit(b: &Bounds, (x0, y0, x1, y1): (i32, i32, i32, i32)) -> Mapping {
        let (w, h) = (f64::from(x1 - x0).max(1.0), f64::from(y1 - y0).max(1.0));
        Mapping {
            scale: (w / (b.u1 - b.u0)).min(h / (b.v1 - b.v0)),
            centre: ((b.u0 + b.u1) / 2.0, (b.v0 + b.v1) / 2.0),
            pixel_centre: (f64::from(x0 + x1) / 2.0, f64::from(y0 + y1) / 2.0),
        }
    }

    /// The pixel of a screen point (y grows downward), or `None` if it is not finite.
    pub(crate) fn pixel(&self, (u, v): (f64, f64)) -> Option<(i32, i32)> {
        let (x, y) = self.pixel_f((u, v));
        (x.is_finite() && y.is_finite()).then(|| (x.round() as i32, y.round() as i32))
    }

    /// The pixel of a screen point, unrounded (y grows downward).
    pub(crate) fn pixel_f(&self, (u, v): (f64, f64)) -> (f64, f64) {
        (
            self.pixel_centre.0 + (u - self.centre.0) * self.scale,
            self.pixel_centre.1 - (v - self.centre.1) * self.scale,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_put_the_characters_left_and_front_where_the_help_says() {
        let left = Point3::new(1.0, 0.0, 0.0);
        let front = Point3::new(0.0, 0.0, 1.0);
        let up = Point3::new(0.0, 1.0, 0.0);
        assert_eq!(View::Front.project(&left), (1.0, 0.0));
        assert_eq!(View::Front.project(&up), (0.0, 1.0));
        assert_eq!(View::Side.project(&front), (1.0, 0.0));
        assert_eq!(View::Side.project(&up), (0.0, 1.0));
        assert_eq!(View::Top.project(&left), (1.0, 0.0));
        assert_eq!(View::Top.project(&front), (0.0, -1.0));
    }

    #[test]
    fn views_are_read_by_their_names() {
        for v in View::ALL {
            assert_eq!(v.name().parse::<View>(), Ok(v));
            assert_eq!(v.to_string(), v.name());
        }
        assert!("Front".parse::<View>().is_err());
    }

    #[test]
    fn mapping_keeps_the_aspect_ratio() {
        let b = Bounds {
            u0: 0.0,
            u1: 1.0,
            v0: 0.0,
            v1: 2.0,
        };
        let m = Mapping::fit(&b, (0, 0, 400, 200));
        assert_eq!(m.pixel((0.5, 1.0)), Some((200, 100)));
        assert_eq!(m.pixel((1.0, 2.0)), Some((250, 0)));
        assert_eq!(m.pixel((0.0, 0.0)), Some((150, 200)));
        assert_eq!(m.pixel((f64::NAN, 0.0)), None);
    }
}
