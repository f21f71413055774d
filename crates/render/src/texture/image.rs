//! Bitmap textures: wrap modes, nearest and bilinear filtering.
//!
//! Texel `(x, y)` covers `[x, x+1] × [y, y+1]` in continuous image coordinates, so its centre is
//! at `x + 0.5` (Heckbert's convention, pbrt-v4 `Image::Bilerp`): bilinear filtering therefore
//! looks up `u·w - 0.5`, and a lookup exactly at a texel centre returns that texel unblended.

use raylab_core::{Rgb, Vec2};

/// What a lookup outside `[0, 1]` sees.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Wrap {
    /// Tiles the image (`u = 1.25` reads `u = 0.25`).
    #[default]
    Repeat,
    /// Extends the edge texels outwards.
    Clamp,
    /// Tiles the image, flipping every other copy, so tiles meet without a seam.
    Mirror,
}

raylab_core::named_enum!(Wrap, "wrap mode", {
    Repeat => "repeat",
    Clamp => "clamp",
    Mirror => "mirror",
});

impl Wrap {
    /// Maps an integer texel index onto `0..n` (`n > 0`).
    #[inline]
    fn index(self, i: i64, n: i64) -> usize {
        let i = match self {
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Mirror => {
                // Period 2n: 0..n forwards, then n..2n backwards (GL_MIRRORED_REPEAT).
                let m = i.rem_euclid(2 * n);
                if m < n { m } else { 2 * n - 1 - m }
            }
        };
        i as usize
    }
}

/// How a lookup between texel centres is reconstructed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Filter {
    /// The texel under `uv`: blocky, but exact for pixel art and for tests.
    Nearest,
    /// Linear blend of the four nearest texel centres.
    #[default]
    Bilinear,
}

raylab_core::named_enum!(Filter, "texture filter", {
    Nearest => "nearest",
    Bilinear => "bilinear",
});

/// A linear-RGB bitmap with a wrap mode and a filter.
#[derive(Clone, Debug)]
pub struct ImageTexture {
    width: u32,
    height: u32,
    /// Row-major, row 0 at the top; `len() == width * height`, every texel finite.
    texels: Vec<Rgb>,
    average: Rgb,
    /// Behaviour outside `[0, 1]²`.
    pub wrap: Wrap,
    /// Reconstruction between texel centres.
    pub filter: Filter,
    /// Tiling: `lookup(uv)` reads the image at `uv * scale`. `(1, 1)` after [`ImageTexture::new`].
    pub scale: Vec2,
}

/// Integer texel indices are kept within ±2^40 so that `i + 1` and `2n` never overflow, whatever
/// `uv` is; `as` already maps NaN to 0 and ±∞ to the extremes.
const MAX_INDEX: i64 = 1 << 40;

#[inline]
fn floor_index(x: f32) -> (i64, f32) {
    let f = x.floor();
    let i = (f as i64).clamp(-MAX_INDEX, MAX_INDEX);
    // The fraction is only meaningful for finite x; elsewhere any value in [0, 1] will do.
    let t = x - f;
    (i, if t.is_finite() { t.clamp(0.0, 1.0) } else { 0.0 })
}

impl ImageTexture {
    /// A texture from `texels`, row-major, row 0 at the TOP of the image, linear RGB.
    ///
    /// Never panics: returns `Err` if `texels.len() != width * height`, if `width` or `height`
    /// is 0, or if a texel is not finite.
    pub fn new(width: u32, height: u32, texels: Vec<Rgb>, wrap: Wrap, filter: Filter) -> Result<Self, String> {
        if width == 0 || height == 0 {
            return Err(format!("image texture: empty size {width}x{height}"));
        }
        let expected = width as u64 * height as u64;
        if texels.len() as u64 != expected {
            return Err(format!(
                "image texture: {} texels for a {width}x{height} image (expected {expected})",
                texels.len()
            ));
        }
        if let Some(i) = texels.iter().position(|t| !t.is_finite()) {
            let (x, y) = (i as u64 % width as u64, i as u64 / width as u64);
            return Err(format!("image texture: texel ({x}, {y}) is not finite: {}", texels[i]));
        }
        // f64: a 4k image sums 16M texels, enough to lose bits of an f32 accumulator.
        let sum = texels.iter().fold([0.0f64; 3], |s, t| [s[0] + t.x as f64, s[1] + t.y as f64, s[2] + t.z as f64]);
        let n = texels.len() as f64;
        let average = Rgb::new((sum[0] / n) as f32, (sum[1] / n) as f32, (sum[2] / n) as f32);
        Ok(Self { width, height, texels, average, wrap, filter, scale: Vec2::ONE })
    }

    /// Width in texels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// The texels, row-major, row 0 at the top.
    pub fn texels(&self) -> &[Rgb] {
        &self.texels
    }

    /// Mean colour of all texels (ignores `scale` and `wrap`, which do not change it).
    pub fn average(&self) -> Rgb {
        self.average
    }

    /// The texel at integer coordinates, wrapped; `y` counts rows from the top.
    #[inline]
    fn texel(&self, x: i64, y: i64) -> Rgb {
        let x = self.wrap.index(x, self.width as i64);
        let y = self.wrap.index(y, self.height as i64);
        self.texels[y * self.width as usize + x]
    }

    /// Colour at `uv * scale`, with `(0, 0)` at the bottom-left of the image and `v` up (OBJ
    /// convention). Any `uv`, even NaN or infinite, returns a texel value or a blend of them.
    #[inline]
    pub fn lookup(&self, uv: Vec2) -> Rgb {
        let uv = uv * self.scale;
        // Continuous image coordinates: x right, y down from the top row.
        let x = uv.x * self.width as f32;
        let y = (1.0 - uv.y) * self.height as f32;
        match self.filter {
            Filter::Nearest => {
                let (ix, _) = floor_index(x);
                let (iy, _) = floor_index(y);
                self.texel(ix, iy)
            }
            Filter::Bilinear => {
                let (x0, tx) = floor_index(x - 0.5);
                let (y0, ty) = floor_index(y - 0.5);
                let top = self.texel(x0, y0).lerp(self.texel(x0 + 1, y0), tx);
                let bottom = self.texel(x0, y0 + 1).lerp(self.texel(x0 + 1, y0 + 1), tx);
                top.lerp(bottom, ty)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    // Row 0 (top): A B; row 1 (bottom): C D.
    const A: Rgb = Rgb::new(1.0, 0.0, 0.0);
    const B: Rgb = Rgb::new(0.0, 1.0, 0.0);
    const C: Rgb = Rgb::new(0.0, 0.0, 1.0);
    const D: Rgb = Rgb::new(1.0, 1.0, 1.0);

    fn tex(wrap: Wrap, filter: Filter) -> ImageTexture {
        ImageTexture::new(2, 2, vec![A, B, C, D], wrap, filter).unwrap()
    }

    fn assert_close(got: Rgb, want: Rgb) {
        assert!((got - want).abs().max_element() < 1e-6, "got {got}, want {want}");
    }

    #[test]
    fn v_points_up_and_row_zero_is_the_top() {
        let t = tex(Wrap::Clamp, Filter::Nearest);
        assert_eq!(t.lookup(Vec2::new(0.0, 0.0)), C, "uv (0,0) is the bottom-left texel = last row");
        assert_eq!(t.lookup(Vec2::new(0.99, 0.01)), D);
        assert_eq!(t.lookup(Vec2::new(0.01, 0.99)), A);
        assert_eq!(t.lookup(Vec2::new(0.99, 0.99)), B);
    }

    #[test]
    fn bilinear_at_centres_and_midpoints() {
        let t = tex(Wrap::Clamp, Filter::Bilinear);
        // Texel centres return the texel itself.
        assert_close(t.lookup(Vec2::new(0.25, 0.75)), A);
        assert_close(t.lookup(Vec2::new(0.75, 0.75)), B);
        assert_close(t.lookup(Vec2::new(0.25, 0.25)), C);
        assert_close(t.lookup(Vec2::new(0.75, 0.25)), D);
        // Midpoints between two centres, and the middle of all four.
        assert_close(t.lookup(Vec2::new(0.5, 0.75)), (A + B) / 2.0);
        assert_close(t.lookup(Vec2::new(0.25, 0.5)), (A + C) / 2.0);
        assert_close(t.lookup(Vec2::new(0.5, 0.5)), (A + B + C + D) / 4.0);
        // A quarter of the way from A's centre to B's: x = 0.375 * 2 - 0.5 = 0.25.
        assert_close(t.lookup(Vec2::new(0.375, 0.75)), A * 0.75 + B * 0.25);
        // Clamp: beyond the outer centres, nothing from the other side leaks in.
        assert_close(t.lookup(Vec2::new(0.0, 1.0)), A);
    }

    #[test]
    fn wrap_modes_outside_the_unit_square() {
        // v = 0.25 is the centre of the bottom row (C D) for both filters.
        for &filter in Filter::ALL {
            let at = |wrap, u| tex(wrap, filter).lookup(Vec2::new(u, 0.25));
            // u = -0.25: x = -0.5 (nearest) or -1.0 (bilinear), one texel left of the image.
            assert_close(at(Wrap::Repeat, -0.25), D);
            assert_close(at(Wrap::Clamp, -0.25), C);
            assert_close(at(Wrap::Mirror, -0.25), C);
            // u = 1.25: one texel right of the image.
            assert_close(at(Wrap::Repeat, 1.25), C);
            assert_close(at(Wrap::Clamp, 1.25), D);
            assert_close(at(Wrap::Mirror, 1.25), D);
        }
        // Bilinear between wrapped texels: u = -0.1 gives x = -0.7 -> texels -1 and 0, t = 0.3.
        let at = |wrap| tex(wrap, Filter::Bilinear).lookup(Vec2::new(-0.1, 0.25));
        assert_close(at(Wrap::Repeat), D * 0.7 + C * 0.3);
        assert_close(at(Wrap::Clamp), C);
        assert_close(at(Wrap::Mirror), C);
        // Mirror has period 2: u = 1.75 reads like u = 0.25, u = 2.25 like u = 0.25 too.
        let m = tex(Wrap::Mirror, Filter::Nearest);
        assert_eq!(m.lookup(Vec2::new(1.75, 0.25)), C);
        assert_eq!(m.lookup(Vec2::new(2.25, 0.25)), C);
        assert_eq!(m.lookup(Vec2::new(2.75, 0.25)), D);
        // v wraps too: v = 1.25 repeats to the bottom row.
        assert_eq!(tex(Wrap::Repeat, Filter::Nearest).lookup(Vec2::new(0.25, 1.25)), C);
    }

    #[test]
    fn scale_tiles() {
        let mut t = tex(Wrap::Repeat, Filter::Nearest);
        t.scale = Vec2::new(2.0, 2.0);
        assert_eq!(t.lookup(Vec2::new(0.5 + 0.125, 0.125)), C);
        assert_eq!(t.lookup(Vec2::new(0.5 + 0.375, 0.125)), D);
    }

    #[test]
    fn hostile_uv_never_panics() {
        for &filter in Filter::ALL {
            for &wrap in Wrap::ALL {
                let t = tex(wrap, filter);
                for u in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, f32::MAX, f32::MIN, -1e30, 1e30] {
                    let c = t.lookup(Vec2::new(u, u));
                    assert!(c.is_finite() && c.min_element() >= 0.0 && c.max_element() <= 1.0);
                }
            }
        }
    }

    #[test]
    fn constructor_rejects_bad_input() {
        let e = ImageTexture::new(2, 2, vec![A; 3], Wrap::Repeat, Filter::Nearest).unwrap_err();
        assert_eq!(e, "image texture: 3 texels for a 2x2 image (expected 4)");
        let e = ImageTexture::new(0, 2, vec![], Wrap::Repeat, Filter::Nearest).unwrap_err();
        assert_eq!(e, "image texture: empty size 0x2");
        let e = ImageTexture::new(2, 1, vec![A, Rgb::new(0.0, f32::NAN, 0.0)], Wrap::Repeat, Filter::Nearest)
            .unwrap_err();
        assert_eq!(e, "image texture: texel (1, 0) is not finite: [0, NaN, 0]");
    }

    #[test]
    fn size_and_average() {
        let t = ImageTexture::new(2, 1, vec![A, B], Wrap::Repeat, Filter::Nearest).unwrap();
        assert_eq!((t.width(), t.height()), (2, 1));
        assert_close(t.average(), Rgb::new(0.5, 0.5, 0.0));
    }

    /// A 3 × 2 image of greys: row 0 (top) 0, 1, 2; row 1 (bottom) 10, 20, 40.
    fn grey_3x2(wrap: Wrap, filter: Filter) -> ImageTexture {
        let texels = [0.0, 1.0, 2.0, 10.0, 20.0, 40.0].map(Rgb::splat).to_vec();
        ImageTexture::new(3, 2, texels, wrap, filter).unwrap()
    }

    fn assert_grey(got: Rgb, want: f32) {
        assert!((got - Rgb::splat(want)).abs().max_element() < 1e-4, "got {got}, want {want}");
    }

    #[test]
    fn wrap_modes_on_three_texels_by_hand() {
        // Texel column i of a 3-wide image is read at u = (i + ½) / 3. Repeat has period 3,
        // clamp holds the ends, mirror has period 6: 0 1 2 2 1 0.
        let texels = [5.0, 6.0, 7.0].map(Rgb::splat).to_vec();
        let row = |wrap| ImageTexture::new(3, 1, texels.clone(), wrap, Filter::Nearest).unwrap();
        let column = |wrap| ImageTexture::new(1, 3, texels.clone(), wrap, Filter::Nearest).unwrap();
        let cases: [(i32, [usize; 3]); 12] = [
            // (texel index, [repeat, clamp, mirror])
            (-6, [0, 0, 0]),
            (-5, [1, 0, 1]),
            (-4, [2, 0, 2]),
            (-3, [0, 0, 2]),
            (-2, [1, 0, 1]),
            (-1, [2, 0, 0]),
            (0, [0, 0, 0]),
            (2, [2, 2, 2]),
            (3, [0, 2, 2]),
            (4, [1, 2, 1]),
            (5, [2, 2, 0]),
            (7, [1, 2, 1]),
        ];
        for (i, want) in cases {
            let c = (i as f32 + 0.5) / 3.0;
            for (wrap, w) in [Wrap::Repeat, Wrap::Clamp, Wrap::Mirror].into_iter().zip(want) {
                assert_eq!(row(wrap).lookup(Vec2::new(c, 0.5)), Rgb::splat(5.0 + w as f32), "{wrap} column {i}");
                // Rows count down from the top: row i is at v = 1 − (i + ½) / 3.
                assert_eq!(column(wrap).lookup(Vec2::new(0.5, 1.0 - c)), Rgb::splat(5.0 + w as f32), "{wrap} row {i}");
            }
        }
    }

    #[test]
    fn nearest_on_a_wider_than_tall_image() {
        let t = grey_3x2(Wrap::Clamp, Filter::Nearest);
        assert_eq!((t.width(), t.height()), (3, 2));
        assert_eq!(t.texels(), &[0.0, 1.0, 2.0, 10.0, 20.0, 40.0].map(Rgb::splat)[..]);
        // u = 0.5 is column 1 (x = 1.5), v = 0.3 the bottom row (y = 1.4), v = 0.7 the top (y = 0.6).
        assert_grey(t.lookup(Vec2::new(0.5, 0.3)), 20.0);
        assert_grey(t.lookup(Vec2::new(0.5, 0.7)), 1.0);
        assert_grey(t.lookup(Vec2::new(0.9, 0.7)), 2.0);
        assert_grey(t.lookup(Vec2::new(0.1, 0.3)), 10.0);
    }

    #[test]
    fn bilinear_on_a_wider_than_tall_image_by_hand() {
        // u = 0.6: x = 1.8, x − ½ = 1.3, columns 1 and 2 at 0.3. v = 0.55: y = 0.9, y − ½ = 0.4,
        // rows 0 and 1 at 0.4. Top 1 + 0.3·(2 − 1) = 1.3, bottom 20 + 0.3·(40 − 20) = 26,
        // 1.3 + 0.4·(26 − 1.3) = 11.18 in every wrap mode (all four texels inside).
        for &wrap in Wrap::ALL {
            assert_grey(grey_3x2(wrap, Filter::Bilinear).lookup(Vec2::new(0.6, 0.55)), 11.18);
        }
        // u = 0.1: x − ½ = −0.2, columns −1 and 0 at 0.8. Repeat reads column −1 as 2:
        // top 2 + 0.8·(0 − 2) = 0.4, bottom 40 + 0.8·(10 − 40) = 16, 0.4 + 0.4·15.6 = 6.64.
        // Clamp and mirror read it as 0: top 0, bottom 10, 0.4·10 = 4.
        let at = |wrap, u, v| grey_3x2(wrap, Filter::Bilinear).lookup(Vec2::new(u, v));
        assert_grey(at(Wrap::Repeat, 0.1, 0.55), 6.64);
        assert_grey(at(Wrap::Clamp, 0.1, 0.55), 4.0);
        assert_grey(at(Wrap::Mirror, 0.1, 0.55), 4.0);
        // v = 0.1: y − ½ = 1.3, rows 1 and 2 at 0.3. Repeat reads row 2 as row 0:
        // 26 + 0.3·(1.3 − 26) = 18.59; clamp and mirror read it as row 1: 26.
        assert_grey(at(Wrap::Repeat, 0.6, 0.1), 18.59);
        assert_grey(at(Wrap::Clamp, 0.6, 0.1), 26.0);
        assert_grey(at(Wrap::Mirror, 0.6, 0.1), 26.0);
        // Tiled by (2, 3): uv (0.3, 0.85) reads (0.6, 2.55), which repeats (0.6, 0.55).
        let mut t = grey_3x2(Wrap::Repeat, Filter::Bilinear);
        t.scale = Vec2::new(2.0, 3.0);
        assert_grey(t.lookup(Vec2::new(0.3, 0.85)), 11.18);
        // Average (0 + 1 + 2 + 10 + 20 + 40) / 6 = 73/6.
        assert_grey(t.average(), 73.0 / 6.0);
    }

    #[test]
    fn names_parse_and_errors_list_them() {
        for &w in Wrap::ALL {
            assert_eq!(w.name().parse::<Wrap>(), Ok(w));
        }
        for &f in Filter::ALL {
            assert_eq!(f.name().parse::<Filter>(), Ok(f));
        }
        assert_eq!("tile".parse::<Wrap>().unwrap_err(), "unknown wrap mode `tile` (valid: repeat, clamp, mirror)");
        assert_eq!(
            "cubic".parse::<Filter>().unwrap_err(),
            "unknown texture filter `cubic` (valid: nearest, bilinear)"
        );
    }
}
