//! Bézier segments of degree 1–3 with a radius per control point, and the conversion of
//! uniform B-spline and Catmull–Rom control polygons to them.
//!
//! A control point is a `Vec4`: `xyz` the position, `w` the radius. The radius is a
//! polynomial in the same Bernstein basis, so de Casteljau's algorithm evaluates and
//! splits position and radius together.

use raylab_core::{Aabb, Transform, Vec3};
use glam::Vec4;

/// One Bézier segment: `degree + 1` control points, `degree` in 1..=3.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bezier {
    cp: [Vec4; 4],
    degree: usize,
}

impl Bezier {
    /// From `degree + 1` control points (`xyz` position, `w` radius); `None` for other counts.
    pub fn new(cp: &[Vec4]) -> Option<Self> {
        if !(2..=4).contains(&cp.len()) {
            return None;
        }
        let mut all = [Vec4::ZERO; 4];
        all[..cp.len()].copy_from_slice(cp);
        Some(Self { cp: all, degree: cp.len() - 1 })
    }

    pub fn degree(&self) -> usize {
        self.degree
    }

    pub fn control_points(&self) -> &[Vec4] {
        &self.cp[..=self.degree]
    }

    /// Position and radius at `u` in `[0, 1]` (de Casteljau).
    pub fn eval(&self, u: f32) -> Vec4 {
        let mut p = self.cp;
        for level in (1..=self.degree).rev() {
            for i in 0..level {
                p[i] = p[i].lerp(p[i + 1], u);
            }
        }
        p[0]
    }

    pub fn point(&self, u: f32) -> Vec3 {
        self.eval(u).truncate()
    }

    pub fn radius(&self, u: f32) -> f32 {
        self.eval(u).w
    }

    /// `d/du` of position (`xyz`) and radius (`w`): `degree` times the hodograph, a Bézier
    /// curve over the control points' differences.
    pub fn derivative(&self, u: f32) -> Vec4 {
        let n = self.degree;
        let mut d = [Vec4::ZERO; 4];
        for (i, di) in d.iter_mut().enumerate().take(n) {
            *di = n as f32 * (self.cp[i + 1] - self.cp[i]);
        }
        if n == 1 {
            return d[0];
        }
        Bezier { cp: d, degree: n - 1 }.eval(u)
    }

    /// The two halves at `u`: control points of `[0, u]` and `[u, 1]` reparametrised to
    /// `[0, 1]`, from the sides of de Casteljau's triangle.
    pub fn split(&self, u: f32) -> (Bezier, Bezier) {
        let n = self.degree;
        let (mut left, mut right) = ([Vec4::ZERO; 4], [Vec4::ZERO; 4]);
        let mut p = self.cp;
        for level in 0..=n {
            left[level] = p[0];
            right[n - level] = p[n - level];
            for i in 0..n - level {
                p[i] = p[i].lerp(p[i + 1], u);
            }
        }
        (Bezier { cp: left, degree: n }, Bezier { cp: right, degree: n })
    }

    /// The same curve as a cubic (exact degree elevation), which the intersector works on.
    pub fn to_cubic(&self) -> [Vec4; 4] {
        let c = &self.cp;
        match self.degree {
            1 => [c[0], c[0].lerp(c[1], 1.0 / 3.0), c[0].lerp(c[1], 2.0 / 3.0), c[1]],
            2 => [c[0], c[0].lerp(c[1], 2.0 / 3.0), c[2].lerp(c[1], 2.0 / 3.0), c[2]],
            _ => *c,
        }
    }

    /// The largest radius of a control point: a bound on the radius along the segment
    /// (Bernstein weights are a partition of unity).
    pub fn max_radius(&self) -> f32 {
        self.control_points().iter().fold(0.0f32, |m, p| m.max(p.w))
    }

    /// Bounds of the tube: the control-point hull grown by the largest radius.
    pub fn bounds(&self) -> Aabb {
        let hull = Aabb::from_points(self.control_points().iter().map(|p| p.truncate()));
        let r = Vec3::splat(self.max_radius());
        Aabb { min: hull.min - r, max: hull.max + r }
    }

    /// Control points through `to_world`; radii scale by the cube root of the determinant
    /// (the mean scale), since a non-uniform scale cannot keep a tube round.
    pub fn transformed(&self, to_world: &Transform) -> Bezier {
        let scale = to_world.m.matrix3.determinant().abs().cbrt();
        let mut cp = self.cp;
        for p in &mut cp[..=self.degree] {
            *p = to_world.point(p.truncate()).extend(p.w * scale);
        }
        Bezier { cp, degree: self.degree }
    }
}

/// How control points describe a curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Basis {
    /// Bézier segments of the given degree sharing their end points: `degree·k + 1` points.
    Bezier,
    /// Uniform B-spline of the given degree (1–3): each window of `degree + 1` consecutive
    /// points is a segment, which approximates the points.
    BSpline,
    /// Uniform Catmull–Rom spline (cubic only): interpolates the points; each window of 4
    /// points gives the segment between its middle two.
    CatmullRom,
}

impl std::str::FromStr for Basis {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "bezier" => Ok(Basis::Bezier),
            "bspline" => Ok(Basis::BSpline),
            "catmull-rom" => Ok(Basis::CatmullRom),
            _ => Err(format!("unknown basis `{s}` (valid: bezier, bspline, catmull-rom)")),
        }
    }
}

/// The Bézier segments of a control polygon (positions in `xyz`, radii in `w`).
pub fn to_bezier_segments(basis: Basis, degree: usize, points: &[Vec4]) -> Result<Vec<Bezier>, String> {
    if !(1..=3).contains(&degree) {
        return Err(format!("degree must be 1, 2 or 3, found {degree}"));
    }
    let n = points.len();
    let seg = |cp: &[Vec4]| Bezier::new(cp).expect("2 to 4 control points");
    match basis {
        Basis::Bezier => {
            if n < degree + 1 || !(n - 1).is_multiple_of(degree) {
                return Err(format!("a Bézier curve of degree {degree} needs {degree}·k + 1 points, found {n}"));
            }
            Ok((0..(n - 1) / degree).map(|k| seg(&points[k * degree..=k * degree + degree])).collect())
        }
        Basis::BSpline => {
            if n < degree + 1 {
                return Err(format!("a B-spline of degree {degree} needs at least {} points, found {n}", degree + 1));
            }
            Ok(points.windows(degree + 1).map(|w| seg(&bspline_window(w))).collect())
        }
        Basis::CatmullRom => {
            if degree != 3 {
                return Err(format!("Catmull–Rom splines are cubic: degree must be 3, found {degree}"));
            }
            if n < 4 {
                return Err(format!("a Catmull–Rom spline needs at least 4 points, found {n}"));
            }
            Ok(points.windows(4).map(|w| seg(&[w[1], w[1] + (w[2] - w[0]) / 6.0, w[2] - (w[3] - w[1]) / 6.0, w[2]])).collect())
        }
    }
}

/// Bézier control points of one uniform B-spline segment (the change of basis of
/// Foley et al. §11.2.3; Sederberg, *Computer Aided Geometric Design*, ch. 6).
fn bspline_window(w: &[Vec4]) -> Vec<Vec4> {
    match w.len() {
        2 => w.to_vec(),
        3 => vec![(w[0] + w[1]) / 2.0, w[1], (w[1] + w[2]) / 2.0],
        _ => vec![
            (w[0] + 4.0 * w[1] + w[2]) / 6.0,
            (2.0 * w[1] + w[2]) / 3.0,
            (w[1] + 2.0 * w[2]) / 3.0,
            (w[1] + 4.0 * w[2] + w[3]) / 6.0,
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: Vec4, b: Vec4) -> bool {
        (a - b).abs().max_element() < 1e-5
    }

    fn cubic() -> Bezier {
        Bezier::new(&[Vec4::new(0.0, 0.0, 0.0, 1.0), Vec4::new(1.0, 2.0, 0.0, 1.0), Vec4::new(3.0, 2.0, 0.0, 0.5), Vec4::new(4.0, 0.0, 1.0, 0.0)]).unwrap()
    }

    #[test]
    fn cubic_point_and_tangent_hand_computed() {
        let c = cubic();
        // u = 1/2: weights 1/8, 3/8, 3/8, 1/8.
        assert!(close(c.eval(0.5), Vec4::new(2.0, 1.5, 0.125, 0.6875)), "{}", c.eval(0.5));
        // Derivative at 1/2: 3·(¼(p1-p0) + ½(p2-p1) + ¼(p3-p2)) = 3·(1.5, 0, 0.25, -0.375).
        assert!(close(c.derivative(0.5), Vec4::new(4.5, 0.0, 0.75, -1.125)), "{}", c.derivative(0.5));
        // End tangents are 3·(p1 - p0) and 3·(p3 - p2).
        assert!(close(c.derivative(0.0), Vec4::new(3.0, 6.0, 0.0, 0.0)));
        assert!(close(c.derivative(1.0), Vec4::new(3.0, -6.0, 3.0, -1.5)));
        // u = 1/4: weights 27/64, 27/64, 9/64, 1/64.
        let want = (27.0 * Vec4::new(0.0, 0.0, 0.0, 1.0) + 27.0 * Vec4::new(1.0, 2.0, 0.0, 1.0) + 9.0 * Vec4::new(3.0, 2.0, 0.0, 0.5) + Vec4::new(4.0, 0.0, 1.0, 0.0)) / 64.0;
        assert!(close(c.eval(0.25), want));
    }

    #[test]
    fn quadratic_point_and_tangent_hand_computed() {
        let q = Bezier::new(&[Vec4::new(0.0, 0.0, 0.0, 0.2), Vec4::new(1.0, 2.0, 0.0, 0.2), Vec4::new(2.0, 0.0, 0.0, 0.1)]).unwrap();
        assert_eq!(q.degree(), 2);
        // u = 1/2: ¼ p0 + ½ p1 + ¼ p2.
        assert!(close(q.eval(0.5), Vec4::new(1.0, 1.0, 0.0, 0.175)));
        // Derivative 2·((1-u)(p1-p0) + u(p2-p1)): at 1/4 it is 2·(0.75·(1,2) + 0.25·(1,-2)).
        assert!(close(q.derivative(0.25), Vec4::new(2.0, 2.0, 0.0, -0.05)));
        // Elevated to a cubic it is the same curve.
        let c = Bezier::new(&q.to_cubic()).unwrap();
        for u in [0.0, 0.3, 0.5, 0.9] {
            assert!(close(c.eval(u), q.eval(u)) && close(c.derivative(u), q.derivative(u)), "u = {u}");
        }
        // A line: constant derivative p1 - p0.
        let l = Bezier::new(&[Vec4::ZERO, Vec4::new(2.0, 0.0, 0.0, 1.0)]).unwrap();
        assert!(close(l.derivative(0.7), Vec4::new(2.0, 0.0, 0.0, 1.0)) && close(l.eval(0.25), Vec4::new(0.5, 0.0, 0.0, 0.25)));
    }

    #[test]
    fn split_halves_trace_the_same_curve() {
        let c = cubic();
        let (a, b) = c.split(0.3);
        for s in [0.0, 0.25, 0.5, 1.0] {
            assert!(close(a.eval(s), c.eval(0.3 * s)));
            assert!(close(b.eval(s), c.eval(0.3 + 0.7 * s)));
        }
        // The hull bound contains sampled points of the tube.
        let bounds = c.bounds();
        for k in 0..=20 {
            let p = c.eval(k as f32 / 20.0);
            assert!(bounds.contains(p.truncate() + Vec3::splat(p.w)) && bounds.contains(p.truncate() - Vec3::splat(p.w)));
        }
    }

    #[test]
    fn bspline_and_catmull_rom_hand_computed() {
        let p = [Vec4::new(0.0, 0.0, 0.0, 1.0), Vec4::new(6.0, 0.0, 0.0, 1.0), Vec4::new(6.0, 6.0, 0.0, 1.0), Vec4::new(0.0, 6.0, 0.0, 1.0), Vec4::new(0.0, 12.0, 0.0, 1.0)];
        let b = to_bezier_segments(Basis::BSpline, 3, &p).unwrap();
        assert_eq!(b.len(), 2);
        // (p0 + 4p1 + p2)/6 = (5, 1); (2p1 + p2)/3 = (6, 2); (p1 + 2p2)/3 = (6, 4);
        // (p1 + 4p2 + p3)/6 = (5, 5).
        let want = [Vec4::new(5.0, 1.0, 0.0, 1.0), Vec4::new(6.0, 2.0, 0.0, 1.0), Vec4::new(6.0, 4.0, 0.0, 1.0), Vec4::new(5.0, 5.0, 0.0, 1.0)];
        assert!(b[0].control_points().iter().zip(&want).all(|(a, w)| close(*a, *w)), "{:?}", b[0]);
        // C² joint: the second segment starts where the first ends.
        assert!(close(b[1].eval(0.0), b[0].eval(1.0)) && close(b[1].derivative(0.0), b[0].derivative(1.0)));
        let q = to_bezier_segments(Basis::BSpline, 2, &p[..3]).unwrap();
        assert!(close(q[0].eval(0.0), Vec4::new(3.0, 0.0, 0.0, 1.0)) && close(q[0].eval(1.0), Vec4::new(6.0, 3.0, 0.0, 1.0)));

        let c = to_bezier_segments(Basis::CatmullRom, 3, &p).unwrap();
        assert_eq!(c.len(), 2);
        // p1 + (p2 - p0)/6 = (7, 1); p2 - (p3 - p1)/6 = (7, 5); it interpolates p1 and p2.
        let want = [p[1], Vec4::new(7.0, 1.0, 0.0, 1.0), Vec4::new(7.0, 5.0, 0.0, 1.0), p[2]];
        assert!(c[0].control_points().iter().zip(&want).all(|(a, w)| close(*a, *w)), "{:?}", c[0]);
        // Tangent at a point is (p[i+1] - p[i-1])/2, the same from both sides.
        assert!(close(c[0].derivative(1.0), (p[3] - p[1]) / 2.0) && close(c[1].derivative(0.0), (p[3] - p[1]) / 2.0));
    }

    #[test]
    fn radius_bounds_and_transform_by_hand() {
        let q = Bezier::new(&[Vec4::new(1.0, 1.0, 1.0, 0.3), Vec4::new(2.0, -1.0, 0.0, 0.7), Vec4::new(0.0, 0.0, 3.0, 0.2)]).unwrap();
        assert_eq!(q.max_radius(), 0.7);
        // At u = ½: ¼·0.3 + ½·0.7 + ¼·0.2.
        assert!((q.radius(0.5) - 0.475).abs() < 1e-6, "{}", q.radius(0.5));
        // The hull (0, -1, 0)–(2, 1, 3) grown by 0.7.
        let b = q.bounds();
        assert!(close(b.min.extend(0.0), Vec4::new(-0.7, -1.7, -0.7, 0.0)) && close(b.max.extend(0.0), Vec4::new(2.7, 1.7, 3.7, 0.0)), "{b:?}");
        // Scaled by (2, 4, 1) (determinant 8: radii × ∛8 = 2), then moved by (1, 0, 0).
        let to_world = Transform::scale(Vec3::new(2.0, 4.0, 1.0)).unwrap().then(Transform::translate(Vec3::X));
        let t = q.transformed(&to_world);
        let want = [Vec4::new(3.0, 4.0, 1.0, 0.6), Vec4::new(5.0, -4.0, 0.0, 1.4), Vec4::new(1.0, 0.0, 3.0, 0.4)];
        assert_eq!(t.degree(), 2);
        assert!(t.control_points().iter().zip(&want).all(|(a, w)| close(*a, *w)), "{t:?}");
        // A mirror (determinant -1) keeps the radii.
        let m = q.transformed(&Transform::scale(Vec3::new(-1.0, 1.0, 1.0)).unwrap());
        assert!(close(m.control_points()[1], Vec4::new(-2.0, -1.0, 0.0, 0.7)), "{m:?}");
        assert_eq!(Bezier::new(&[Vec4::ZERO]), None);
        assert_eq!(Bezier::new(&[Vec4::ZERO; 5]), None);
    }

    #[test]
    fn bezier_and_linear_bases_split_the_points_by_hand() {
        let p: Vec<Vec4> = (0..7).map(|i| Vec4::new(i as f32, (i * i) as f32, 0.0, 0.1 * i as f32)).collect();
        // Cubic Bézier segments share their ends: points 0–3 and 3–6.
        let c = to_bezier_segments(Basis::Bezier, 3, &p).unwrap();
        assert_eq!(c.iter().map(|b| b.control_points().to_vec()).collect::<Vec<_>>(), [p[0..4].to_vec(), p[3..7].to_vec()]);
        // Quadratic: 0–2, 2–4, 4–6.
        let q = to_bezier_segments(Basis::Bezier, 2, &p).unwrap();
        assert_eq!(q.iter().map(|b| b.control_points().to_vec()).collect::<Vec<_>>(), [p[0..3].to_vec(), p[2..5].to_vec(), p[4..7].to_vec()]);
        // A linear B-spline is the polygon itself.
        let l = to_bezier_segments(Basis::BSpline, 1, &p[..3]).unwrap();
        assert_eq!(l.iter().map(|b| b.control_points().to_vec()).collect::<Vec<_>>(), [p[0..2].to_vec(), p[1..3].to_vec()]);
        // The fewest points each basis takes: 4 for one cubic Bézier, B-spline or Catmull–Rom
        // segment, 2 for a line; one point is no line.
        assert_eq!(to_bezier_segments(Basis::Bezier, 3, &p[..4]).unwrap()[0].control_points(), &p[..4]);
        assert_eq!(to_bezier_segments(Basis::BSpline, 1, &p[..2]).unwrap()[0].control_points(), &p[..2]);
        assert_eq!(to_bezier_segments(Basis::CatmullRom, 3, &p[..4]).unwrap().len(), 1);
        assert_eq!(to_bezier_segments(Basis::Bezier, 1, &p[..1]).unwrap_err(), "a Bézier curve of degree 1 needs 1·k + 1 points, found 1");
        assert_eq!(to_bezier_segments(Basis::Bezier, 0, &p).unwrap_err(), "degree must be 1, 2 or 3, found 0");
        assert_eq!(to_bezier_segments(Basis::Bezier, 3, &p[..1]).unwrap_err(), "a Bézier curve of degree 3 needs 3·k + 1 points, found 1");
        assert_eq!(to_bezier_segments(Basis::CatmullRom, 3, &p[..3]).unwrap_err(), "a Catmull–Rom spline needs at least 4 points, found 3");
        assert_eq!(["bezier", "bspline", "catmull-rom"].map(|s| s.parse::<Basis>().unwrap()), [Basis::Bezier, Basis::BSpline, Basis::CatmullRom]);
        assert_eq!("nurbs".parse::<Basis>().unwrap_err(), "unknown basis `nurbs` (valid: bezier, bspline, catmull-rom)");
    }

    #[test]
    fn control_point_counts_are_checked() {
        let p = vec![Vec4::ZERO; 6];
        assert_eq!(to_bezier_segments(Basis::Bezier, 3, &p).unwrap_err(), "a Bézier curve of degree 3 needs 3·k + 1 points, found 6");
        assert_eq!(to_bezier_segments(Basis::Bezier, 1, &p).unwrap().len(), 5);
        assert_eq!(to_bezier_segments(Basis::CatmullRom, 2, &p).unwrap_err(), "Catmull–Rom splines are cubic: degree must be 3, found 2");
        assert_eq!(to_bezier_segments(Basis::BSpline, 3, &p[..3]).unwrap_err(), "a B-spline of degree 3 needs at least 4 points, found 3");
        assert_eq!(to_bezier_segments(Basis::Bezier, 4, &p).unwrap_err(), "degree must be 1, 2 or 3, found 4");
    }
}
