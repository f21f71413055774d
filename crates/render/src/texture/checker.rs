//! Checkerboard: two colours alternating on a grid, in `uv` (2D) or in space (3D, a "solid"
//! checker that needs no parameterisation, as in *Ray Tracing: The Next Week*).
//!
//! The board is unfiltered, like the book's and pbrt-v4's `NoAA` mode: it aliases under
//! minification, which pixel supersampling averages away.

use raylab_core::{Rgb, Vec2, Vec3};

/// Where a [`Checker`] lays its grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CheckerSpace {
    /// Squares on the surface parameters `uv`.
    #[default]
    Uv,
    /// Cubes in object space, on the point `p`.
    Solid,
}

raylab_core::named_enum!(CheckerSpace, "checker space", {
    Uv => "uv",
    Solid => "solid",
});

/// Two colours on a grid of `1 / scale`-sized cells.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Checker {
    /// Colour of the cells whose integer coordinates sum to an even number (the cell at the origin).
    pub even: Rgb,
    /// Colour of the other cells.
    pub odd: Rgb,
    /// Checks per unit of `uv` or of object space.
    pub scale: f32,
    /// 2D on `uv` or 3D on `p`.
    pub space: CheckerSpace,
}

/// 0 or 1: the parity of the cell index `floor(x)`. Computed in `f32`, where `rem_euclid(2)` is
/// exact for any finite value, so far-away points neither overflow an integer nor lose parity;
/// NaN and ±∞ land on 0 (`as` saturates, and `rem_euclid` returns NaN for them).
#[inline]
fn parity(x: f32) -> u32 {
    x.floor().rem_euclid(2.0) as u32
}

impl Checker {
    /// Colour at `uv` (for [`CheckerSpace::Uv`]) or `p` (for [`CheckerSpace::Solid`]).
    #[inline]
    pub fn eval(&self, uv: Vec2, p: Vec3) -> Rgb {
        let s = self.scale;
        let sum = match self.space {
            CheckerSpace::Uv => parity(uv.x * s) + parity(uv.y * s),
            CheckerSpace::Solid => parity(p.x * s) + parity(p.y * s) + parity(p.z * s),
        };
        if sum % 2 == 0 { self.even } else { self.odd }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const E: Rgb = Rgb::ONE;
    const O: Rgb = Rgb::ZERO;

    fn board(scale: f32, space: CheckerSpace) -> Checker {
        Checker { even: E, odd: O, scale, space }
    }

    #[test]
    fn uv_parity() {
        let c = board(4.0, CheckerSpace::Uv);
        let at = |u, v| c.eval(Vec2::new(u, v), Vec3::splat(0.1));
        assert_eq!(at(0.1, 0.1), E); // cell (0, 0)
        assert_eq!(at(0.3, 0.1), O); // cell (1, 0)
        assert_eq!(at(0.3, 0.3), E); // cell (1, 1)
        assert_eq!(at(0.1, 0.6), E); // cell (0, 2)
        assert_eq!(at(0.9, 0.6), O); // cell (3, 2)
        assert_eq!(at(-0.1, 0.1), O); // cell (-1, 0): floor, not truncation
        assert_eq!(at(-0.1, -0.1), E); // cell (-1, -1)
        assert_eq!(at(0.25, 0.0), O); // a cell's lower edge belongs to it: cell (1, 0)
    }

    #[test]
    fn solid_parity_ignores_uv() {
        let c = board(1.0, CheckerSpace::Solid);
        let at = |x, y, z| c.eval(Vec2::splat(0.7), Vec3::new(x, y, z));
        assert_eq!(at(0.5, 0.5, 0.5), E);
        assert_eq!(at(1.5, 0.5, 0.5), O);
        assert_eq!(at(1.5, 1.5, 0.5), E);
        assert_eq!(at(1.5, 1.5, 1.5), O);
        assert_eq!(at(-0.5, 0.5, 0.5), O);
        assert_eq!(at(-0.5, -0.5, -0.5), O);
        assert_eq!(at(-2.5, 0.5, 0.5), O); // cell -3
        assert_eq!(at(3.0e7 + 0.0, 0.5, 0.5), E); // far away: parity still exact
        assert_eq!(at(3.0e7 + 2.0, 0.5, 0.5), E);
        assert_eq!(at(f32::NAN, f32::INFINITY, 0.5), E); // no panic on garbage
    }

    #[test]
    fn solid_cells_are_one_over_scale_wide_on_every_axis() {
        // Scale 2: cells 0.5 wide. 0.3 is in cell 0 and 0.6 in cell 1 along each axis; with
        // `p * s` read as `p / s` (0.15, 0.3) or `p + s` (2.3, 2.6) both would be in one cell.
        let c = board(2.0, CheckerSpace::Solid);
        let at = |x, y, z| c.eval(Vec2::splat(0.7), Vec3::new(x, y, z));
        assert_eq!(at(0.3, 0.3, 0.3), E); // cell (0, 0, 0)
        assert_eq!(at(0.6, 0.3, 0.3), O); // cell (1, 0, 0)
        assert_eq!(at(0.3, 0.6, 0.3), O); // cell (0, 1, 0)
        assert_eq!(at(0.3, 0.3, 0.6), O); // cell (0, 0, 1)
        assert_eq!(at(0.6, 0.6, 0.3), E); // cell (1, 1, 0): 2 is even
        assert_eq!(at(0.6, 0.3, 0.6), E); // cell (1, 0, 1)
        assert_eq!(at(0.3, 0.6, 0.6), E); // cell (0, 1, 1)
        assert_eq!(at(0.6, 0.6, 0.6), O); // cell (1, 1, 1): 3 is odd
        assert_eq!(at(1.1, 0.3, 0.3), E); // cell (2, 0, 0)
        assert_eq!(at(-0.3, 0.3, 0.3), O); // cell (-1, 0, 0)
        // Scale 0.5: cells 2 wide, so 1.5 is still cell 0 and 2.5 cell 1.
        let c = board(0.5, CheckerSpace::Solid);
        let at = |x, y, z| c.eval(Vec2::splat(0.7), Vec3::new(x, y, z));
        assert_eq!(at(1.5, 1.5, 1.5), E);
        assert_eq!(at(2.5, 1.5, 1.5), O);
        assert_eq!(at(1.5, 1.5, 2.5), O);
        // A uv board ignores p: the same uv gives the same colour anywhere in space.
        let c = board(2.0, CheckerSpace::Uv);
        assert_eq!(c.eval(Vec2::new(0.6, 0.3), Vec3::splat(0.3)), O);
        assert_eq!(c.eval(Vec2::new(0.6, 0.3), Vec3::new(0.6, 5.3, -2.4)), O);
        assert_eq!(c.eval(Vec2::new(0.6, 0.6), Vec3::splat(0.3)), E);
        assert_eq!(c.eval(Vec2::new(0.3, 0.6), Vec3::splat(0.3)), O); // cell (0, 1)
    }

    #[test]
    fn names_parse() {
        assert_eq!("solid".parse(), Ok(CheckerSpace::Solid));
        assert_eq!("uv".parse(), Ok(CheckerSpace::Uv));
        assert_eq!("xyz".parse::<CheckerSpace>().unwrap_err(), "unknown checker space `xyz` (valid: uv, solid)");
    }
}
