//! Area lights: every primitive with a non-zero emission (rect and sphere lights, OBJ/MTL
//! `Ke` meshes) is a light that can be sampled from a shading point. One emitter is chosen
//! in proportion to its power, then a point on it by the selected strategy; `pdf` returns
//! the same density for a direction found by BSDF sampling, for multiple importance sampling.

use std::f32::consts::PI;

use raylab_core::color::luminance;
use raylab_core::{sampling, Frame, Rgb, Vec2, Vec3};

use super::spherical_rect::{SphericalRect, MIN_SOLID_ANGLE};
use crate::shape::{Geometry, PrimRef};
use crate::texture::Texture;

/// How direct light from area lights is estimated (`[render] light_sampling`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSampling {
    /// Points uniformly distributed over the light's area (the report's area form).
    Uniform,
    /// Points distributed uniformly in the solid angle the light subtends: cones for
    /// spheres, spherical rectangles for rectangles (Ureña et al. 2013); triangles fall
    /// back to area sampling.
    SolidAngle,
    /// The third report's importance sampling of parallelogram lights: a `k × k` grid of
    /// cells, one chosen by a discrete CDF over the cells' unshadowed contributions
    /// (evaluated at their centres), then a uniform point inside it. Other emitters fall
    /// back to solid-angle sampling.
    Cells,
    /// Only BSDF sampling: light is found when a sampled direction hits an emitter.
    Bsdf,
    /// Light samples (solid angle) and BSDF samples combined by the power heuristic
    /// (Veach 1997).
    Mis,
}

raylab_core::named_enum!(LightSampling, "light sampling", {
    Uniform => "uniform",
    SolidAngle => "solid-angle",
    Cells => "cells",
    Bsdf => "bsdf",
    Mis => "mis",
});

impl LightSampling {
    /// Whether light sampling is used at all.
    pub fn samples_lights(self) -> bool {
        self != LightSampling::Bsdf
    }
}

/// A sampled point on an emitter, seen from a shading point.
#[derive(Clone, Copy, Debug)]
pub struct AreaSample {
    /// Unit direction from the shading point to the light point.
    pub wi: Vec3,
    pub dist: f32,
    /// Radiance arriving along `-wi` (zero when the back of the emitter faces the point).
    pub le: Rgb,
    /// Solid-angle density of `wi`, the choice of the emitter included.
    pub pdf: f32,
}

/// Cells per side of the `cells` strategy's grid: the default and the largest allowed.
pub const DEFAULT_CELLS: u32 = 8;
pub const MAX_CELLS: u32 = 16;

/// Share of the `cells` strategy's choice spread uniformly over all cells: a cell whose
/// centre sees no light may still light the point in part (defensive sampling, Hesterberg
/// 1995), so every cell keeps a non-zero probability and the estimate stays unbiased.
const CELLS_UNIFORM_SHARE: f32 = 0.1;

/// How much the receiving point turns light from world direction `wi` towards the viewer:
/// the luminance of `f(wo, wi) · |cos θi|`. The `cells` strategy weighs cells by it (the
/// report's importance `G · (f_diffuse + f_specular)`); the other strategies ignore it.
pub type Receiver<'a> = &'a dyn Fn(Vec3) -> f32;

/// An emitting mesh that is one parallelogram (two triangles `[0, 1, 2]`, `[0, 2, 3]`):
/// sampled as a whole by the `cells` strategy.
#[derive(Clone, Copy, Debug)]
struct Parallelogram {
    prims: [u32; 2],
    corner: Vec3,
    e1: Vec3,
    e2: Vec3,
    normal: Vec3,
    /// Right angles at the corners: solid-angle sampling as a spherical rectangle applies.
    rectangular: bool,
}

impl Parallelogram {
    /// The spherical rectangle it subtends from `p`, when it is a rectangle and not too
    /// small for the parametrisation.
    fn spherical(&self, p: Vec3) -> Option<SphericalRect> {
        let r = SphericalRect::new(p, self.corner, self.e1, self.e2);
        (self.rectangular && r.solid_angle > MIN_SOLID_ANGLE).then_some(r)
    }
}

/// The scene's emitting primitives with a power-proportional choice among them.
#[derive(Clone, Debug, Default)]
pub struct AreaLights {
    parallelograms: Vec<Parallelogram>,
    prims: Vec<u32>,
    /// Inclusive prefix sums of the emitters' powers, normalised to end at 1.
    cdf: Vec<f32>,
    /// Probability of choosing each emitter, indexed by primitive (0 for non-emitters).
    choice: Vec<f32>,
    /// Cells per side of the `cells` strategy's grid (1 to [`MAX_CELLS`]).
    cells: u32,
}

impl AreaLights {
    /// The emitters of `geometry`; `cells` per side for the `cells` strategy (clamped to
    /// 1..=[`MAX_CELLS`]).
    pub fn new(geometry: &Geometry, cells: u32) -> Self {
        use raylab_accel::Primitives;
        let n = geometry.len() as u32;
        let prims: Vec<u32> = (0..n).filter(|&p| geometry.emission(p) != Rgb::ZERO).collect();
        let power: Vec<f64> = prims.iter().map(|&p| (area(geometry, p) * luminance(geometry.emission(p)).max(1e-6)) as f64).collect();
        let total: f64 = power.iter().sum();
        let mut choice = vec![0.0; n as usize];
        let mut cdf = Vec::with_capacity(prims.len());
        let mut acc = 0.0;
        for (&p, &w) in prims.iter().zip(&power) {
            acc += w / total;
            cdf.push(acc as f32);
            choice[p as usize] = (w / total) as f32;
        }
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        Self { parallelograms: find_parallelograms(geometry), prims, cdf, choice, cells: cells.clamp(1, MAX_CELLS) }
    }

    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    pub fn len(&self) -> usize {
        self.prims.len()
    }

    /// Samples light arriving at `p` from one emitter (`receiver` weighs the `cells`).
    /// `u_choice` picks the emitter, `u` the point on it.
    #[allow(clippy::too_many_arguments)]
    pub fn sample(&self, geometry: &Geometry, textures: &[Texture], p: Vec3, receiver: Receiver, strategy: LightSampling, u_choice: f32, u: Vec2) -> Option<AreaSample> {
        let k = self.cdf.partition_point(|&c| c <= u_choice).min(self.prims.len().checked_sub(1)?);
        let prim = self.prims[k];
        let choice = self.choice[prim as usize];
        let le = geometry.emission(prim);
        // Emission at texture coordinates `uv` of this emitter.
        let tex = geometry.emission_texture(prim).map(|t| &textures[t.0 as usize]);
        let le_at = |uv: Vec2, q: Vec3| tex.map_or(le, |t| le * t.eval(uv, q));
        if strategy != LightSampling::Uniform {
            if let Some(quad) = self.parallelogram(prim) {
                // Either triangle's choice leads here: the quad's probability is their sum.
                let choice = quad.prims.iter().map(|&t| self.choice[t as usize]).sum::<f32>();
                if strategy == LightSampling::Cells {
                    return sample_cells(quad, self.cells, p, receiver, &le_at, choice, u_choice_rescaled(u_choice, &self.cdf, k), u);
                }
                if let Some(sr) = quad.spherical(p) {
                    let q = p + sr.sample(u);
                    let st = Vec2::new((q - quad.corner).dot(quad.e1) / quad.e1.length_squared(), (q - quad.corner).dot(quad.e2) / quad.e2.length_squared());
                    let dist = (q - p).length();
                    let wi = (q - p) / dist;
                    #[allow(clippy::neg_cmp_op_on_partial_ord)] // a NaN distance is no sample either
                    let behind = !(dist > 0.0) || quad.normal.dot(-wi) <= 0.0;
                    if behind {
                        return None; // the back of the one-sided light
                    }
                    return Some(AreaSample { wi, dist, le: le_at(st, q), pdf: choice / sr.solid_angle });
                }
            }
        }
        match geometry.prim(prim) {
            PrimRef::Sphere(s) if strategy != LightSampling::Uniform => {
                let sphere = &geometry.spheres[s as usize];
                let (c, r) = (sphere.to_world.point(sphere.center), sphere.radius);
                let d = c - p;
                let dc2 = d.length_squared();
                if dc2 <= r * r {
                    return self.sample_area(geometry, prim, p, &le_at, choice, u);
                }
                // Cone sampling (pbrt-v4 `Sphere::Sample`): uniform within the cap of
                // directions that hit the sphere, then the point the direction hits.
                let dc = dc2.sqrt();
                let sin2_max = r * r / dc2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                let mut one_minus_cos_max = 1.0 - cos_max;
                let mut cos_t = (cos_max - 1.0) * u.x + 1.0;
                let mut sin2_t = 1.0 - cos_t * cos_t;
                if sin2_max < 0.000_685_23 {
                    // Tiny caps: the Taylor expansion keeps precision.
                    sin2_t = sin2_max * u.x;
                    cos_t = (1.0 - sin2_t).sqrt();
                    one_minus_cos_max = sin2_max / 2.0;
                }
                let cos_alpha = sin2_t / sin2_max.sqrt() + cos_t * (1.0 - sin2_t / sin2_max).max(0.0).sqrt();
                let sin_alpha = (1.0 - cos_alpha * cos_alpha).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                let frame = Frame::from_z(d / dc);
                let n = frame.to_world(-Vec3::new(sin_alpha * phi.cos(), sin_alpha * phi.sin(), cos_alpha));
                let q = c + r * n;
                let to = q - p;
                let dist = to.length();
                if dist <= 0.0 {
                    return None;
                }
                Some(AreaSample { wi: to / dist, dist, le, pdf: choice / (2.0 * PI * one_minus_cos_max) })
            }
            _ => self.sample_area(geometry, prim, p, &le_at, choice, u),
        }
    }

    /// Uniform area sampling of emitter `prim`, converted to solid angle.
    fn sample_area(&self, geometry: &Geometry, prim: u32, p: Vec3, le_at: &dyn Fn(Vec2, Vec3) -> Rgb, choice: f32, u: Vec2) -> Option<AreaSample> {
        let (q, n, uv) = match geometry.prim(prim) {
            PrimRef::Triangle { mesh, tri } => {
                let m = &geometry.meshes[mesh as usize];
                let [a, b, c] = m.vertices(tri);
                let (b0, b1) = sampling::uniform_triangle(u);
                let b2 = 1.0 - b0 - b1;
                (b0 * a + b1 * b + b2 * c, m.winding_normal(tri), geometry.triangle_uv(prim, b1, b2))
            }
            PrimRef::Sphere(s) => {
                let sphere = &geometry.spheres[s as usize];
                let n = sampling::uniform_sphere(u);
                (sphere.to_world.point(sphere.center) + sphere.radius * n, n, Vec2::ZERO)
            }
            PrimRef::Curve { .. } | PrimRef::Patch { .. } => unreachable!("curves and patches do not emit light"),
        };
        towards(p, q, n, le_at(uv, q), choice / area(geometry, prim))
    }

    /// Solid-angle density with which `sample` would pick direction `wi` from `p` towards
    /// point `q` (normal `n`) on emitter `prim`.
    pub fn pdf(&self, geometry: &Geometry, strategy: LightSampling, prim: u32, p: Vec3, q: Vec3, n: Vec3) -> f32 {
        let choice = self.choice.get(prim as usize).copied().unwrap_or(0.0);
        if choice == 0.0 {
            return 0.0;
        }
        if let PrimRef::Sphere(s) = geometry.prim(prim) {
            let sphere = &geometry.spheres[s as usize];
            let (c, r) = (sphere.to_world.point(sphere.center), sphere.radius);
            let dc2 = (c - p).length_squared();
            if strategy != LightSampling::Uniform && dc2 > r * r {
                let sin2_max = r * r / dc2;
                let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
                let one_minus = if sin2_max < 0.000_685_23 { sin2_max / 2.0 } else { 1.0 - cos_max };
                return choice / (2.0 * PI * one_minus);
            }
        }
        if let Some(quad) = self.parallelogram(prim).filter(|_| strategy != LightSampling::Uniform) {
            if let Some(sr) = quad.spherical(p) {
                return quad.prims.iter().map(|&t| self.choice[t as usize]).sum::<f32>() / sr.solid_angle;
            }
        }
        let to = q - p;
        let cos_l = n.dot(-to.normalize_or_zero()).abs();
        if cos_l == 0.0 {
            return 0.0;
        }
        choice / area(geometry, prim) * to.length_squared() / cos_l
    }

    fn parallelogram(&self, prim: u32) -> Option<&Parallelogram> {
        self.parallelograms.iter().find(|q| q.prims.contains(&prim))
    }
}

/// `u_choice` stretched back to [0, 1) within the CDF bin `k` it fell in: a fresh uniform
/// number for a second discrete choice, without another sampler dimension.
fn u_choice_rescaled(u: f32, cdf: &[f32], k: usize) -> f32 {
    let lo = if k == 0 { 0.0 } else { cdf[k - 1] };
    let hi = cdf[k];
    if hi > lo { ((u - lo) / (hi - lo)).clamp(0.0, 1.0 - f32::EPSILON / 2.0) } else { 0.5 }
}

/// Emitting meshes made of exactly one parallelogram.
fn find_parallelograms(geometry: &Geometry) -> Vec<Parallelogram> {
    use raylab_accel::Primitives;
    let mut out = Vec::new();
    // A mesh's primitives are consecutive: its first triangle's index locates the rest.
    for prim in 0..geometry.len() as u32 {
        let PrimRef::Triangle { mesh, tri: 0 } = geometry.prim(prim) else { continue };
        let m = &geometry.meshes[mesh as usize];
        if m.emission != Rgb::ZERO && m.indices == [[0, 1, 2], [0, 2, 3]] && m.positions.len() == 4 {
            let [a, b, c, d] = [m.positions[0], m.positions[1], m.positions[2], m.positions[3]];
            let scale = (b - a).length().max((d - a).length());
            if ((a + c) - (b + d)).length() <= 1e-5 * scale {
                let (e1, e2) = (b - a, d - a);
                let rectangular = e1.dot(e2).abs() <= 1e-5 * e1.length() * e2.length();
                out.push(Parallelogram { prims: [prim, prim + 1], corner: a, e1, e2, normal: m.winding_normal(0), rectangular });
            }
        }
    }
    out
}

/// The `cells` strategy on one parallelogram: cell weights are the unshadowed light the
/// point reflects from each cell's centre, `receiver(ω) · max(0, n_l·-ω) / d² · lum(Le)`,
/// mixed with a uniform share.
#[allow(clippy::too_many_arguments)]
fn sample_cells(quad: &Parallelogram, k: u32, p: Vec3, receiver: Receiver, le_at: &dyn Fn(Vec2, Vec3) -> Rgb, choice: f32, u_cell: f32, u: Vec2) -> Option<AreaSample> {
    let k = k as usize;
    let mut storage = [0.0f32; (MAX_CELLS * MAX_CELLS) as usize];
    let weights = &mut storage[..k * k];
    let mut total = 0.0;
    for (idx, w) in weights.iter_mut().enumerate() {
        let st = Vec2::new(((idx % k) as f32 + 0.5) / k as f32, ((idx / k) as f32 + 0.5) / k as f32);
        let centre = quad.corner + st.x * quad.e1 + st.y * quad.e2;
        let d = centre - p;
        let d2 = d.length_squared();
        let wi = d / d2.sqrt();
        let facing = quad.normal.dot(-wi).max(0.0);
        *w = if facing > 0.0 { receiver(wi).max(0.0) * facing / d2 * luminance(le_at(st, centre)).max(0.0) } else { 0.0 };
        total += *w;
    }
    let cells = weights.len() as f32;
    let prob = |w: f32| if total > 0.0 { (1.0 - CELLS_UNIFORM_SHARE) * w / total + CELLS_UNIFORM_SHARE / cells } else { 1.0 / cells };
    // Invert the discrete CDF.
    let mut acc = 0.0;
    let mut chosen = weights.len() - 1;
    for (idx, &w) in weights.iter().enumerate() {
        acc += prob(w);
        if u_cell < acc {
            chosen = idx;
            break;
        }
    }
    let cell = Vec2::new((chosen % k) as f32, (chosen / k) as f32);
    let st = (cell + u) / k as f32;
    let q = quad.corner + st.x * quad.e1 + st.y * quad.e2;
    let area = raylab_core::edges::cross_length(quad.e1, quad.e2);
    // The rect's UVs run (0,0), (1,0), (1,1), (0,1) around its corners: `st` itself.
    towards(p, q, quad.normal, le_at(st, q), choice * prob(weights[chosen]) * cells / area)
}

/// The sample of light point `q` (normal `n`) from `p`, its area density `pdf_area`
/// converted to solid angle; `None` from the back of a one-sided emitter.
fn towards(p: Vec3, q: Vec3, n: Vec3, le: Rgb, pdf_area: f32) -> Option<AreaSample> {
    let to = q - p;
    let d2 = to.length_squared();
    let dist = d2.sqrt();
    if dist <= 0.0 {
        return None;
    }
    let wi = to / dist;
    let cos_l = n.dot(-wi);
    if cos_l <= 0.0 {
        return None;
    }
    Some(AreaSample { wi, dist, le, pdf: pdf_area * d2 / cos_l })
}

/// Surface area of a primitive (spheres untransformed: lights are not scaled).
fn area(geometry: &Geometry, prim: u32) -> f32 {
    match geometry.prim(prim) {
        PrimRef::Triangle { mesh, tri } => geometry.meshes[mesh as usize].area(tri),
        PrimRef::Sphere(s) => {
            let r = geometry.spheres[s as usize].radius;
            4.0 * PI * r * r
        }
        PrimRef::Curve { .. } | PrimRef::Patch { .. } => unreachable!("curves and patches do not emit light"),
    }
}

#[cfg(test)]
mod tests {
    //! Hand-worked values for the area lights' choice, samples and densities, seen from the
    //! origin: a 2 × 2 square light A at height 1 facing down (radiance 3, power 4·3 = 12)
    //! and a 1 × 1 square light B at depth 2 facing up (radiance 2, power 2), after a
    //! non-emitting triangle (prim 0): A is prims 1 and 2, B prims 3 and 4.
    use super::*;
    use crate::shape::{Sphere, TriangleMesh};
    use raylab_core::Transform;

    fn quad(corners: [Vec3; 4], le: f32) -> TriangleMesh {
        TriangleMesh { name: "quad".into(), positions: corners.to_vec(), indices: vec![[0, 1, 2], [0, 2, 3]], emission: Rgb::splat(le), ..Default::default() }
    }

    /// Light A's corners: (b − a) × (c − a) = (2, 0, 0) × (2, 0, 2) = (0, −4, 0), facing down;
    /// edges e1 = b − a along x, e2 = d − a along z.
    const A: [Vec3; 4] = [Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(-1.0, 1.0, 1.0)];

    fn scene() -> Geometry {
        let mut g = Geometry::default();
        g.add_mesh(TriangleMesh { name: "dark".into(), positions: vec![Vec3::new(5.0, 0.0, 0.0), Vec3::new(6.0, 0.0, 0.0), Vec3::new(5.0, 1.0, 0.0)], indices: vec![[0, 1, 2]], ..Default::default() });
        g.add_mesh(quad(A, 3.0));
        // (0, 0, 1) × (1, 0, 1) = (0, 1, 0): facing up, towards the origin.
        g.add_mesh(quad([Vec3::new(2.0, -2.0, -0.5), Vec3::new(2.0, -2.0, 0.5), Vec3::new(3.0, -2.0, 0.5), Vec3::new(3.0, -2.0, -0.5)], 2.0));
        g
    }

    fn close(a: f32, b: f64, rel: f64) -> bool {
        (a as f64 - b).abs() <= rel * b.abs()
    }

    #[test]
    fn emitters_are_chosen_by_power_and_densities_follow_by_hand() {
        let g = scene();
        let lights = AreaLights::new(&g, 4);
        assert!(!lights.is_empty());
        assert_eq!(lights.len(), 4);
        let down = Vec3::new(0.0, -1.0, 0.0);
        // Uniform: A's triangle 0 (half of A's 12/14, area 2) at q = (0.5, 1, −0.5):
        // d² = 1.5, cos = 1/√1.5, so p = (6/14)/2 · d²/cos = (3/14)·1.5^1.5.
        let q = Vec3::new(0.5, 1.0, -0.5);
        let uniform = lights.pdf(&g, LightSampling::Uniform, 1, Vec3::ZERO, q, down);
        assert!(close(uniform, 3.0 / 14.0 * 1.5f64.powf(1.5), 1e-5), "{uniform}");
        // B's triangle at its nearest corner (2, −2, −0.5) with B's 2/14 over area 1:
        // (1/14)/0.5 · d²/cos, d² = 8.25, cos = 2/√8.25.
        let qb = Vec3::new(2.0, -2.0, -0.5);
        let b = lights.pdf(&g, LightSampling::Uniform, 3, Vec3::ZERO, qb, Vec3::Y);
        assert!(close(b, 1.0 / 7.0 * 8.25 * 8.25f64.sqrt() / 2.0, 1e-5), "{b}");
        // Solid angle: A is a square of half side 1 at distance 1, Ω = 4·asin(1/2) = 2π/3, so
        // p = (12/14)/(2π/3) = 9/(7π) for a direction towards either triangle.
        for (strategy, prim) in [(LightSampling::SolidAngle, 1), (LightSampling::SolidAngle, 2), (LightSampling::Mis, 2), (LightSampling::Bsdf, 1)] {
            let p = lights.pdf(&g, strategy, prim, Vec3::ZERO, q, down);
            assert!(close(p, 9.0 / (7.0 * std::f64::consts::PI), 1e-5), "{strategy:?} {prim}: {p}");
        }
        // B by solid angle: x in [2, 3], z in [−0.5, 0.5] at distance 2, by inclusion and
        // exclusion of atan(xz / (d·√(x² + z² + d²))) over the corners.
        let f = |x: f64, z: f64| (x * z / (2.0 * (x * x + z * z + 4.0).sqrt())).atan();
        let omega = f(3.0, 0.5) - f(2.0, 0.5) - f(3.0, -0.5) + f(2.0, -0.5);
        let p = lights.pdf(&g, LightSampling::SolidAngle, 4, Vec3::ZERO, qb, Vec3::Y);
        assert!(close(p, 2.0 / 14.0 / omega, 1e-4), "{p} against {}", 2.0 / 14.0 / omega);
        // Not an emitter, out of range, or seen edge-on (n ⊥ q): no density.
        assert_eq!(lights.pdf(&g, LightSampling::Uniform, 0, Vec3::ZERO, Vec3::new(5.0, 0.5, 0.0), Vec3::Z), 0.0);
        assert_eq!(lights.pdf(&g, LightSampling::Uniform, 9, Vec3::ZERO, q, down), 0.0);
        assert_eq!(lights.pdf(&g, LightSampling::Uniform, 1, Vec3::ZERO, q, Vec3::new(1.0, 0.0, 1.0)), 0.0);
    }

    #[test]
    fn a_scene_without_emitters_has_no_area_lights() {
        // Only the dark triangle: nothing to choose, no sample, no density.
        let mut g = Geometry::default();
        g.add_mesh(TriangleMesh { name: "dark".into(), positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y], indices: vec![[0, 1, 2]], ..Default::default() });
        let lights = AreaLights::new(&g, 4);
        assert!(lights.is_empty());
        assert_eq!(lights.len(), 0);
        assert!(lights.sample(&g, &[], Vec3::new(0.2, 0.2, 1.0), &|_| 1.0, LightSampling::Uniform, 0.5, Vec2::splat(0.5)).is_none());
        assert_eq!(lights.pdf(&g, LightSampling::Uniform, 0, Vec3::new(0.2, 0.2, 1.0), Vec3::new(0.2, 0.2, 0.0), Vec3::Z), 0.0);
    }

    #[test]
    fn samples_pick_emitters_by_the_cdf_and_report_their_density() {
        let g = scene();
        let lights = AreaLights::new(&g, 4);
        // The choice CDF over prims 1..=4 is 6/14, 12/14, 13/14, 1: u_choice 0.1 picks A's
        // first triangle, 0.5 its second, 0.9 B's first, 0.99 B's second.
        let u = Vec2::new(0.3, 0.6);
        for (u_choice, light) in [(0.1f32, 'A'), (0.5, 'A'), (0.9, 'B'), (0.99, 'B')] {
            let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 1.0, LightSampling::Uniform, u_choice, u).unwrap();
            let q = s.wi * s.dist;
            let (height, le, n) = if light == 'A' { (1.0, 3.0, -Vec3::Y) } else { (-2.0, 2.0, Vec3::Y) };
            assert!((q.y - height).abs() < 1e-5, "{u_choice}: {q}");
            assert_eq!(s.le, Rgb::splat(le));
            // Area density (half the light's power share over half its area) to solid angle.
            let share = if light == 'A' { 6.0 / 14.0 / 2.0 } else { 1.0 / 14.0 / 0.5 };
            let expected = share * (s.dist as f64).powi(2) / n.dot(-s.wi) as f64;
            assert!(close(s.pdf, expected, 1e-5), "{u_choice}: {} against {expected}", s.pdf);
            // The same by solid angle: A's 12/14 over 2π/3.
            let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 1.0, LightSampling::SolidAngle, u_choice, u).unwrap();
            assert!((s.wi.length() - 1.0).abs() < 1e-5 && ((s.wi * s.dist).y - height).abs() < 1e-4, "{u_choice}: {} {}", s.wi, s.dist);
            if light == 'A' {
                assert!(close(s.pdf, 9.0 / (7.0 * std::f64::consts::PI), 1e-5), "{}", s.pdf);
            }
        }
        // From above A (its back) nothing is lit, by any strategy.
        for strategy in [LightSampling::Uniform, LightSampling::SolidAngle, LightSampling::Cells] {
            assert!(lights.sample(&g, &[], Vec3::new(0.0, 2.0, 0.0), &|_| 1.0, strategy, 0.1, u).is_none(), "{strategy:?}");
        }
        assert!(LightSampling::Mis.samples_lights() && LightSampling::Uniform.samples_lights() && !LightSampling::Bsdf.samples_lights());
    }

    #[test]
    fn cells_are_chosen_by_their_centres_light_with_a_uniform_share() {
        // A alone, k = 2: cells in order (0, 0), (1, 0), (0, 1), (1, 1) along (e1, e2), centres
        // (∓0.5, 1, ∓0.5). A receiver that takes light only from +x weighs cells 1 and 3
        // equally (mirror images in z) and 0 and 2 not at all: probabilities 0.9·½ + 0.1/4 =
        // 0.475 and 0.1/4 = 0.025, CDF 0.025, 0.5, 0.525, 1. The cell's point has area density
        // prob·4 cells / area 4, in solid angle prob·d²/cos = prob·1.5^1.5 at a cell's centre.
        let mut g = Geometry::default();
        g.add_mesh(quad(A, 3.0));
        let lights = AreaLights::new(&g, 2);
        let receiver = |w: Vec3| w.x.max(0.0);
        let centre = Vec2::splat(0.5);
        // u_choice in A's first triangle (CDF 0.5) is stretched to 2·u_choice, in the second
        // to 2·(u_choice − 0.5).
        for (u_choice, cell, prob) in [(0.005f32, Vec3::new(-0.5, 1.0, -0.5), 0.025), (0.2, Vec3::new(0.5, 1.0, -0.5), 0.475), (0.6, Vec3::new(0.5, 1.0, -0.5), 0.475), (0.26, Vec3::new(-0.5, 1.0, 0.5), 0.025), (0.9, Vec3::new(0.5, 1.0, 0.5), 0.475)] {
            let s = lights.sample(&g, &[], Vec3::ZERO, &receiver, LightSampling::Cells, u_choice, centre).unwrap();
            assert!((s.wi * s.dist - cell).length() < 1e-5, "{u_choice}: {} against {cell}", s.wi * s.dist);
            assert!(close(s.pdf, prob * 1.5f64.powf(1.5), 1e-5), "{u_choice}: {} against {}", s.pdf, prob * 1.5f64.powf(1.5));
            assert_eq!(s.le, Rgb::splat(3.0));
        }
        // A point inside a cell: cell (1, 1) at offset (0.25, 0.75) is st = (0.625, 0.875),
        // (−1 + 1.25, 1, −1 + 1.75).
        let s = lights.sample(&g, &[], Vec3::ZERO, &receiver, LightSampling::Cells, 0.9, Vec2::new(0.25, 0.75)).unwrap();
        assert!((s.wi * s.dist - Vec3::new(0.25, 1.0, 0.75)).length() < 1e-5, "{}", s.wi * s.dist);
        // A receiver that takes no light: every cell 1/4, the density of uniform area sampling.
        let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 0.0, LightSampling::Cells, 0.2, centre).unwrap();
        assert!(close(s.pdf, 0.25 * 1.5f64.powf(1.5), 1e-5), "{}", s.pdf);
    }

    #[test]
    fn cell_weights_follow_the_documented_importance_from_off_centre() {
        // From p = (0.3, 0, −0.6) the four cells' centres c lie at different distances: the
        // weight is receiver(ω)·(n·−ω)/d²·lum(Le) (n = −y, so n·−ω = ω.y), with a receiver
        // 0.1 + max(0, ω.x) + 2·max(0, ω.z) (an offset, so that scaling ω would show), and the
        // probability 0.9·w/Σw + 0.1/4. Each cell's centre (u = ½) must come out with density
        // prob·(4 cells / area 4)·d²/(n·−ω).
        let mut g = Geometry::default();
        g.add_mesh(quad(A, 3.0));
        let lights = AreaLights::new(&g, 2);
        let p = Vec3::new(0.3, 0.0, -0.6);
        let receiver = |w: Vec3| 0.1 + w.x.max(0.0) + 2.0 * w.z.max(0.0);
        let centres = [(-0.5f64, -0.5f64), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5)];
        let geo = |(x, z): (f64, f64)| {
            let d = (x - 0.3, 1.0, z + 0.6);
            let d2 = d.0 * d.0 + d.1 * d.1 + d.2 * d.2;
            let w = (d.0 / d2.sqrt(), d.1 / d2.sqrt(), d.2 / d2.sqrt());
            (d2, w.1, (0.1 + w.0.max(0.0) + 2.0 * w.2.max(0.0)) * w.1 / d2 * 3.0)
        };
        let total: f64 = centres.iter().map(|&c| geo(c).2).sum();
        let mut lo = 0.0;
        for &(x, z) in &centres {
            let (d2, cos, w) = geo((x, z));
            let prob = 0.9 * w / total + 0.025;
            // The middle of the cell's CDF interval, as u_choice in A's first triangle (×2).
            let u_choice = ((lo + prob / 2.0) / 2.0) as f32;
            lo += prob;
            let s = lights.sample(&g, &[], p, &receiver, LightSampling::Cells, u_choice, Vec2::splat(0.5)).unwrap();
            assert!((p + s.wi * s.dist - Vec3::new(x as f32, 1.0, z as f32)).length() < 1e-5, "cell ({x}, {z}): {}", p + s.wi * s.dist);
            assert!(close(s.pdf, prob * d2 / cos, 1e-5), "cell ({x}, {z}): {} against {}", s.pdf, prob * d2 / cos);
        }
    }

    #[test]
    fn cell_counts_are_clamped_and_the_last_cell_catches_rounding() {
        // From the origin with a receiver taking nothing, every cell has probability 1/k²
        // and the density of uniform area sampling, ¼·d²/cos.
        let mut g = Geometry::default();
        g.add_mesh(quad(A, 3.0));
        let pick = |cells: u32, u_choice: f32| {
            let lights = AreaLights::new(&g, cells);
            let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 0.0, LightSampling::Cells, u_choice, Vec2::splat(0.5)).unwrap();
            let q = s.wi * s.dist;
            assert!(close(s.pdf, 0.25 * q.length_squared() as f64 / s.wi.y as f64, 1e-5), "{cells} cells: {}", s.pdf);
            q
        };
        // 0 cells means 1: the whole light, its centre.
        assert!((pick(0, 0.2) - Vec3::Y).length() < 1e-5, "{}", pick(0, 0.2));
        // 99 means 16: u_cell = 2·0.2 = 0.4 falls in cell ⌊0.4·256⌋ = 102 = (6, 6), centre
        // st = 6.5/16 = 0.40625 on both edges: (−0.1875, 1, −0.1875).
        assert!((pick(99, 0.2) - Vec3::new(-0.1875, 1.0, -0.1875)).length() < 1e-5, "{}", pick(99, 0.2));
        // 7 × 7: the f32 sum of 49 sevenths-squared ends at 0.9999997, below the largest
        // u_cell (1 − 2⁻²⁴, from u_choice just under ½): the last cell, (6, 6), centre
        // st = 6.5/7, takes it.
        let last = -1.0 + 2.0 * 6.5 / 7.0;
        assert!((pick(7, 0.5 - f32::EPSILON / 4.0) - Vec3::new(last, 1.0, last)).length() < 1e-5, "{}", pick(7, 0.5 - f32::EPSILON / 4.0));
    }

    #[test]
    fn only_rectangles_are_sampled_by_solid_angle() {
        // A sheared parallelogram (a + c = b + d, e1·e2 = 1): no spherical rectangle, so its
        // solid-angle density is the area one, per triangle: (½)/2 · d²/cos = ¼·1.5^1.5 at
        // (0.5, 1, −0.5) (area 4, each triangle 2, half the choice each).
        let mut g = Geometry::default();
        g.add_mesh(quad([Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(1.5, 1.0, 1.0), Vec3::new(-0.5, 1.0, 1.0)], 1.0));
        let lights = AreaLights::new(&g, 2);
        let p = lights.pdf(&g, LightSampling::SolidAngle, 0, Vec3::ZERO, Vec3::new(0.5, 1.0, -0.5), -Vec3::Y);
        assert!(close(p, 0.25 * 1.5f64.powf(1.5), 1e-5), "{p}");
        // Its cells still work: four equal cells from a receiver taking nothing, 1/4 each, at
        // cell (1, 0)'s centre st = (0.75, 0.25): a + 0.75·e1 + 0.25·e2 = (0.625, 1, −0.5).
        let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 0.0, LightSampling::Cells, 0.2, Vec2::splat(0.5)).unwrap();
        let q = Vec3::new(0.625, 1.0, -0.5);
        assert!((s.wi * s.dist - q).length() < 1e-5, "{}", s.wi * s.dist);
        assert!(close(s.pdf, 0.25 * q.length_squared() as f64 / (1.0 / q.length() as f64), 1e-5), "{}", s.pdf);
        // A quadrilateral that is no parallelogram (d moved): each triangle on its own, even
        // with the cells strategy: triangle 0 (a, b, c) has area 2, half the power of 2 + 2.5.
        let mut g = Geometry::default();
        g.add_mesh(quad([Vec3::new(-1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, -1.0), Vec3::new(1.0, 1.0, 1.0), Vec3::new(-1.5, 1.0, 1.0)], 1.0));
        let lights = AreaLights::new(&g, 2);
        for strategy in [LightSampling::SolidAngle, LightSampling::Cells] {
            let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 1.0, strategy, 0.1, Vec2::new(0.3, 0.6)).unwrap();
            let expected = (2.0 / 4.5) / 2.0 * (s.dist as f64).powi(2) / s.wi.y as f64;
            assert!(close(s.pdf, expected, 1e-5), "{strategy:?}: {} against {expected}", s.pdf);
        }
    }

    #[test]
    fn textured_emission_is_read_where_the_sample_lands() {
        // A with UVs (0, 0), (1, 0), (1, 1), (0, 1) at a, b, c, d (so uv = ((x + 1)/2, (z + 1)/2)
        // on it) and a 2 × 2 nearest-texel emission texture: row 0 (v > ½) red, green; row 1
        // blue, white. Seen from off the axis, every strategy's sample must carry the texel
        // under its own point (2 × the texel), and lie on A at the distance it reports.
        let mut g = Geometry::default();
        g.add_mesh(TriangleMesh { uvs: vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y], emission_texture: Some(crate::material::TextureId(0)), ..quad(A, 2.0) });
        let texels = vec![Rgb::X, Rgb::Y, Rgb::Z, Rgb::ONE];
        let textures = [Texture::Image(crate::texture::ImageTexture::new(2, 2, texels.clone(), crate::texture::Wrap::Clamp, crate::texture::Filter::Nearest).unwrap())];
        let lights = AreaLights::new(&g, 2);
        let p = Vec3::new(0.3, -0.5, 0.2);
        let mut rng = raylab_core::Pcg32::new(7, 2);
        let mut seen = [0; 4];
        for _ in 0..200 {
            let (u_choice, u) = (rng.next_f32(), rng.next_vec2());
            for strategy in [LightSampling::Uniform, LightSampling::SolidAngle, LightSampling::Cells] {
                let s = lights.sample(&g, &textures, p, &|_| 1.0, strategy, u_choice, u).unwrap();
                let q = p + s.wi * s.dist;
                assert!((s.wi.length() - 1.0).abs() < 1e-5, "{strategy:?}: wi {} not unit", s.wi);
                assert!((q.y - 1.0).abs() < 1e-5 && q.x.abs() <= 1.0 + 1e-5 && q.z.abs() <= 1.0 + 1e-5, "{strategy:?}: {q} off A");
                let uv = Vec2::new((q.x + 1.0) / 2.0, (q.z + 1.0) / 2.0);
                if (uv.x - 0.5).abs() < 1e-3 || (uv.y - 0.5).abs() < 1e-3 {
                    continue;
                }
                if strategy == LightSampling::Uniform {
                    // Half the choice over half the area 4, turned to solid angle from p; the
                    // same from `pdf` for either triangle.
                    let expected = 0.25 * (s.dist as f64).powi(2) / s.wi.y as f64;
                    assert!(close(s.pdf, expected, 1e-4), "{} against {expected}", s.pdf);
                    assert!(close(lights.pdf(&g, strategy, 0, p, q, -Vec3::Y), expected, 1e-4), "pdf at {q}");
                }
                let texel = (uv.x >= 0.5) as usize + 2 * (uv.y < 0.5) as usize;
                seen[texel] += 1;
                assert_eq!(s.le, texels[texel] * 2.0, "{strategy:?}: at uv {uv}");
            }
        }
        assert!(seen.iter().all(|&n| n > 50), "{seen:?}");
    }

    #[test]
    fn a_cell_owns_the_start_of_its_cdf_interval() {
        // Cells invert their CDF half-open, as the emitter choice does (the first CDF value
        // above u): with a receiver taking nothing, k = 2 cells of ¼ each (sums 0.25, 0.5, 0.75,
        // exact in f32), u_cell = 2·u_choice exactly 0.25 or 0.5 is the start of cell (1, 0),
        // centre (0.5, 1, −0.5), or of cell (0, 1), centre (−0.5, 1, 0.5).
        let mut g = Geometry::default();
        g.add_mesh(quad(A, 3.0));
        let lights = AreaLights::new(&g, 2);
        for (u_choice, centre) in [(0.125f32, Vec3::new(0.5, 1.0, -0.5)), (0.25, Vec3::new(-0.5, 1.0, 0.5))] {
            let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 0.0, LightSampling::Cells, u_choice, Vec2::splat(0.5)).unwrap();
            assert!((s.wi * s.dist - centre).length() < 1e-5, "{u_choice}: {} against {centre}", s.wi * s.dist);
        }
    }

    #[test]
    fn cells_are_weighed_by_the_emission_texture() {
        // A (radiance 1) with the grey 2 × 2 texture [1, 2 | 3, 4] (row 0 at v > ½), k = 2
        // cells on its texels, from the origin with a receiver taking everything: the four
        // centres (±½, 1, ±½) have the same d² and cosine, so the weights are the texels'
        // luminances, cells (0, 0), (1, 0), (0, 1), (1, 1) reading 3, 4, 1, 2 (sum 10), and
        // the probabilities 0.9·lum/10 + 0.1/4: 0.295, 0.385, 0.115, 0.205 (CDF 0.295, 0.68,
        // 0.795, 1). Each centre comes with density prob·(4 cells/area 4)·d²/cos = prob·1.5^1.5
        // and its texel's radiance.
        let mut g = Geometry::default();
        g.add_mesh(TriangleMesh { uvs: vec![Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y], emission_texture: Some(crate::material::TextureId(0)), ..quad(A, 1.0) });
        let texels = vec![Rgb::splat(1.0), Rgb::splat(2.0), Rgb::splat(3.0), Rgb::splat(4.0)];
        let textures = [Texture::Image(crate::texture::ImageTexture::new(2, 2, texels, crate::texture::Wrap::Clamp, crate::texture::Filter::Nearest).unwrap())];
        let lights = AreaLights::new(&g, 2);
        // u_cell = 2·u_choice in A's first triangle: the middle of each cell's interval.
        for (u_cell, centre, lum, prob) in [(0.1475f32, Vec3::new(-0.5, 1.0, -0.5), 3.0, 0.295), (0.4875, Vec3::new(0.5, 1.0, -0.5), 4.0, 0.385), (0.7375, Vec3::new(-0.5, 1.0, 0.5), 1.0, 0.115), (0.8975, Vec3::new(0.5, 1.0, 0.5), 2.0, 0.205)] {
            let s = lights.sample(&g, &textures, Vec3::ZERO, &|_| 1.0, LightSampling::Cells, u_cell / 2.0, Vec2::splat(0.5)).unwrap();
            assert!((s.wi * s.dist - centre).length() < 1e-5, "{u_cell}: {} against {centre}", s.wi * s.dist);
            assert!(close(s.pdf, prob * 1.5f64.powf(1.5), 1e-5), "{u_cell}: {} against {}", s.pdf, prob * 1.5f64.powf(1.5));
            assert!((s.le.x - lum).abs() < 1e-6 && (s.le.y - lum).abs() < 1e-6, "{u_cell}: {:?}", s.le);
        }
    }

    #[test]
    fn a_mesh_is_a_parallelogram_only_with_both_triangles() {
        // A's four corners but only the triangle (a, b, c) (d unused), and B after it: no
        // parallelogram, so the triangle's solid-angle density is its area one, the whole
        // choice over area 2: ½·d²/cos at (0.5, 1, −0.5), ½·1.5^1.5 (not 1/Ω of the square).
        let mut g = Geometry::default();
        g.add_mesh(TriangleMesh { indices: vec![[0, 1, 2]], ..quad(A, 3.0) });
        g.add_mesh(quad([Vec3::new(2.0, -2.0, -0.5), Vec3::new(2.0, -2.0, 0.5), Vec3::new(3.0, -2.0, 0.5), Vec3::new(3.0, -2.0, -0.5)], 0.0));
        let lights = AreaLights::new(&g, 2);
        let p = lights.pdf(&g, LightSampling::SolidAngle, 0, Vec3::ZERO, Vec3::new(0.5, 1.0, -0.5), -Vec3::Y);
        assert!(close(p, 0.5 * 1.5f64.powf(1.5), 1e-5), "{p}");
    }

    #[test]
    fn quads_within_the_tolerances_are_sampled_as_rectangles() {
        // A 4 × 2 light (e1 = b − a the longer edge) at height 1 facing down, centred above
        // the origin: half sides 2 and 1 at distance 1 subtend Ω = 4·asin(2·1/√((4 + 1)(1 + 1)))
        // = 4·asin(2/√10), solid-angle density 1/Ω against the area one, (½)/4 at the foot,
        // if it were not taken for a rectangle.
        // (i) c off by 3·10⁻⁵: a + c − (b + d) is within 10⁻⁵ of the longer edge (4·10⁻⁵);
        // (ii) c and d shifted by 10⁻⁵ along x: a parallelogram with e1·e2 = 4·10⁻⁵, within
        // 10⁻⁵·|e1|·|e2| = 8·10⁻⁵ of a right angle.
        let omega = 4.0 * (2.0 / 10f64.sqrt()).asin();
        let (a, b) = (Vec3::new(-2.0, 1.0, -1.0), Vec3::new(2.0, 1.0, -1.0));
        for (c, d) in [(Vec3::new(2.0 + 3e-5, 1.0, 1.0), Vec3::new(-2.0, 1.0, 1.0)), (Vec3::new(2.0 + 1e-5, 1.0, 1.0), Vec3::new(-2.0 + 1e-5, 1.0, 1.0))] {
            let mut g = Geometry::default();
            g.add_mesh(quad([a, b, c, d], 1.0));
            let lights = AreaLights::new(&g, 2);
            let p = lights.pdf(&g, LightSampling::SolidAngle, 0, Vec3::ZERO, Vec3::new(0.0, 1.0, 0.0), -Vec3::Y);
            assert!(close(p, 1.0 / omega, 1e-4), "c {c}, d {d}: {p} against {}", 1.0 / omega);
        }
        // (iii) The same light turned a quarter, e2 = d − a now the longer edge (4), c off by
        // 3·10⁻⁵: the scale is the longer of the two edges, whichever it is.
        let mut g = Geometry::default();
        g.add_mesh(quad([Vec3::new(-1.0, 1.0, -2.0), Vec3::new(1.0, 1.0, -2.0), Vec3::new(1.0 + 3e-5, 1.0, 2.0), Vec3::new(-1.0, 1.0, 2.0)], 1.0));
        let p = AreaLights::new(&g, 2).pdf(&g, LightSampling::SolidAngle, 0, Vec3::ZERO, Vec3::new(0.0, 1.0, 0.0), -Vec3::Y);
        assert!(close(p, 1.0 / omega, 1e-4), "e2 the longer edge: {p} against {}", 1.0 / omega);
    }

    #[test]
    fn quads_past_the_tolerances_are_two_triangles() {
        // The 4 × 2 light of the test above moved 20 along x (so that a sum of corners, as
        // |d + a| ≈ 36, would give a much looser tolerance than the longer edge, 4), seen from
        // p = (20, 0, 0) below its centre: (i) c off by 10⁻⁴ along x, 2.5 × the tolerance
        // 10⁻⁵·4, is no parallelogram; (ii) c and d both shifted by 10⁻⁴ along x is a
        // parallelogram with e1·e2 = 4·10⁻⁴, 5 × the right-angle tolerance 10⁻⁵·4·2, so no
        // rectangle. Either way its solid-angle density is the area one of triangle 0 (area
        // 4 to within 10⁻⁴, half the choice): ½/4·d²/cos = ⅛ at the foot, not 1/Ω = 0.365.
        let t = Vec3::new(20.0, 0.0, 0.0);
        let (a, b) = (t + Vec3::new(-2.0, 1.0, -1.0), t + Vec3::new(2.0, 1.0, -1.0));
        for (c, d) in [(t + Vec3::new(2.0 + 1e-4, 1.0, 1.0), t + Vec3::new(-2.0, 1.0, 1.0)), (t + Vec3::new(2.0 + 1e-4, 1.0, 1.0), t + Vec3::new(-2.0 + 1e-4, 1.0, 1.0))] {
            let mut g = Geometry::default();
            g.add_mesh(quad([a, b, c, d], 1.0));
            let lights = AreaLights::new(&g, 2);
            let p = lights.pdf(&g, LightSampling::SolidAngle, 0, t, t + Vec3::Y, -Vec3::Y);
            assert!(close(p, 0.125, 1e-4), "c {c}, d {d}: {p}");
        }
    }

    #[test]
    fn sphere_lights_are_sampled_uniformly_in_their_cone() {
        // Radius 1 at distance 2: sin²θmax = 1/4, cos θmax = √3/2, the cap's solid angle
        // 2π(1 − √3/2). u.x = 0 is the axis (the nearest point, at distance 1), u.x → 1 the
        // silhouette (tangent, at distance √(4 − 1)), and cos θ = 1 − u.x(1 − cos θmax) between,
        // hitting the sphere at 2cos θ − √(1 − 4 sin²θ).
        let mut g = Geometry::default();
        let c = Vec3::new(0.0, 0.0, 2.0);
        g.add_sphere(Sphere { center: c, radius: 1.0, to_world: Transform::IDENTITY, material: Default::default(), emission: Rgb::splat(5.0) });
        let lights = AreaLights::new(&g, 2);
        let cos_max = 3f64.sqrt() / 2.0;
        let cap = 1.0 / (2.0 * std::f64::consts::PI * (1.0 - cos_max));
        for (ux, uy) in [(0.0f32, 0.3f32), (0.5, 0.3), (0.5, 0.8), (0.9, 0.1), (1.0 - f32::EPSILON / 2.0, 0.6)] {
            let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 1.0, LightSampling::SolidAngle, 0.5, Vec2::new(ux, uy)).unwrap();
            let cos = 1.0 - ux as f64 * (1.0 - cos_max);
            let sin2 = 1.0 - cos * cos;
            assert!(close(s.wi.z, cos, 1e-5), "{ux}: wi {}", s.wi);
            assert!(close(s.dist, 2.0 * cos - (1.0 - 4.0 * sin2).max(0.0).sqrt(), 2e-3), "{ux}: dist {}", s.dist);
            assert!(((s.wi * s.dist - c).length() - 1.0).abs() < 1e-4, "{ux}: off the sphere");
            assert!(close(s.pdf, cap, 1e-5), "{ux}: {}", s.pdf);
            assert_eq!(s.le, Rgb::splat(5.0));
        }
        // u.y turns the direction about the axis: half a turn apart, mirror images.
        let at = |uy: f32| lights.sample(&g, &[], Vec3::ZERO, &|_| 1.0, LightSampling::SolidAngle, 0.5, Vec2::new(0.5, uy)).unwrap().wi;
        let (w0, w1) = (at(0.1), at(0.6));
        assert!((w0.x + w1.x).abs() < 1e-5 && (w0.y + w1.y).abs() < 1e-5 && (w0.z - w1.z).abs() < 1e-6, "{w0} {w1}");
        assert!((at(0.35).x - w0.y).abs() < 1e-5 || (at(0.35).x + w0.y).abs() < 1e-5, "a quarter turn: {} {w0}", at(0.35));
        // The density for a direction found otherwise is the cap's too; uniform sampling of
        // the whole sphere (area 4π) gives the nearest point 1/(4π)·d²/cos = 1/(4π).
        let near = Vec3::new(0.0, 0.0, 1.0);
        assert!(close(lights.pdf(&g, LightSampling::SolidAngle, 0, Vec3::ZERO, near, -Vec3::Z), cap, 1e-5));
        let p = lights.pdf(&g, LightSampling::Uniform, 0, Vec3::ZERO, near, -Vec3::Z);
        assert!(close(p, 1.0 / (4.0 * std::f64::consts::PI), 1e-5), "{p}");
        // Uniform sampling takes points all over the sphere (the far side refused, facing
        // away), at the area density 1/(4π)·d²/cos turned to solid angle, not the cap's.
        let mut rng = raylab_core::Pcg32::new(3, 4);
        let mut lit = 0;
        for _ in 0..256 {
            if let Some(s) = lights.sample(&g, &[], Vec3::ZERO, &|_| 1.0, LightSampling::Uniform, 0.5, rng.next_vec2()) {
                let n = (s.wi * s.dist - c).normalize();
                let expected = (s.dist as f64).powi(2) / (4.0 * std::f64::consts::PI * n.dot(-s.wi) as f64);
                assert!(close(s.pdf, expected, 1e-4), "{} against {expected}", s.pdf);
                lit += 1;
            }
        }
        // The near side, (1 − r/d)/2 = ¼ of the sphere, takes about 64 of 256.
        assert!((32..128).contains(&lit), "{lit} of 256 on the near side");
        // Outside but within √2 of the centre (r² = 1 < d² = 1.44 < 2r): still the cone, with
        // sin²θmax = 1/1.44.
        let p = c - Vec3::new(0.0, 0.0, 1.2);
        let s = lights.sample(&g, &[], p, &|_| 1.0, LightSampling::SolidAngle, 0.5, Vec2::new(0.3, 0.3)).unwrap();
        let cap = 1.0 / (2.0 * std::f64::consts::PI * (1.0 - (1.0 - 1.0 / 1.44f64).sqrt()));
        assert!(close(s.pdf, cap, 1e-4), "{} against {cap}", s.pdf);
        let q = p + s.wi * s.dist;
        assert!(close(lights.pdf(&g, LightSampling::SolidAngle, 0, p, q, (q - c).normalize()), cap, 1e-4));
        // A sphere of radius ½ has area π: uniformly, its nearest point (0, 0, 1.5) has
        // density d²/(area·cos) = 2.25/π.
        let mut g_half = Geometry::default();
        g_half.add_sphere(Sphere { center: c, radius: 0.5, to_world: Transform::IDENTITY, material: Default::default(), emission: Rgb::ONE });
        let p = AreaLights::new(&g_half, 2).pdf(&g_half, LightSampling::Uniform, 0, Vec3::ZERO, Vec3::new(0.0, 0.0, 1.5), -Vec3::Z);
        assert!(close(p, 2.25 / std::f64::consts::PI, 1e-5), "{p}");
        // From inside, the emitter's outside faces away: no sample.
        assert!(lights.sample(&g, &[], c + Vec3::new(0.1, 0.2, 0.0), &|_| 1.0, LightSampling::SolidAngle, 0.5, Vec2::new(0.4, 0.7)).is_none());
    }

    #[test]
    fn cone_samples_from_off_the_origin_land_on_the_sphere() {
        // The radius-1 sphere at distance 2 of the test above, the whole scene moved by t: each
        // sample's direction makes the same angle with the axis, cos θ = 1 − u.x(1 − √3/2), and
        // its point p + wi·dist (distance 2cos θ − √(1 − 4 sin²θ)) lies on the sphere.
        let t = Vec3::new(0.7, -0.4, 0.3);
        let c = t + Vec3::new(0.0, 0.0, 2.0);
        let mut g = Geometry::default();
        g.add_sphere(Sphere { center: c, radius: 1.0, to_world: Transform::IDENTITY, material: Default::default(), emission: Rgb::ONE });
        let lights = AreaLights::new(&g, 2);
        let cos_max = 3f64.sqrt() / 2.0;
        for (ux, uy) in [(0.1f32, 0.2f32), (0.5, 0.7), (0.8, 0.45)] {
            let s = lights.sample(&g, &[], t, &|_| 1.0, LightSampling::SolidAngle, 0.5, Vec2::new(ux, uy)).unwrap();
            let cos = 1.0 - ux as f64 * (1.0 - cos_max);
            assert!(close(s.wi.z, cos, 1e-5), "{ux}: wi {}", s.wi);
            assert!(close(s.dist, 2.0 * cos - (1.0 - 4.0 * (1.0 - cos * cos)).max(0.0).sqrt(), 1e-4), "{ux}: dist {}", s.dist);
            assert!(((t + s.wi * s.dist - c).length() - 1.0).abs() < 1e-5, "{ux}: {} off the sphere", t + s.wi * s.dist);
        }
    }

    #[test]
    fn from_the_spheres_surface_densities_are_the_area_ones() {
        // p = (0, 0, 1) on the radius-1 sphere at (0, 0, 2): d² = r² exactly, where `sample`
        // falls back to area sampling, so `pdf` must too: towards the far point (0, 0, 3),
        // 1/(4π)·d²/cos = 4/(4π) = 1/π, not the cone's 1/(2π(1 − cos θmax)) = 1/(2π) (θmax = 90°).
        let mut g = Geometry::default();
        g.add_sphere(Sphere { center: Vec3::new(0.0, 0.0, 2.0), radius: 1.0, to_world: Transform::IDENTITY, material: Default::default(), emission: Rgb::ONE });
        let lights = AreaLights::new(&g, 2);
        for strategy in [LightSampling::SolidAngle, LightSampling::Mis, LightSampling::Uniform] {
            let p = lights.pdf(&g, strategy, 0, Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.0, 0.0, 3.0), Vec3::Z);
            assert!(close(p, 1.0 / std::f64::consts::PI, 1e-6), "{strategy:?}: {p}");
        }
    }

    #[test]
    fn tiny_caps_hit_the_sampled_angle_precisely() {
        // Radius 0.01 at distance 1 (sin²θmax = 10⁻⁴): the direction's sin²θ must be 10⁻⁴·u.x
        // to f32 precision (10⁻⁵ relative here), not just to the 2·10⁻³ of the test below: a
        // cos θ of √(1 + sin²θ) in place of √(1 − sin²θ) moves the point by ~5·10⁻⁷, 10⁻⁴ of
        // sin²θ.
        let mut g = Geometry::default();
        g.add_sphere(Sphere { center: Vec3::new(0.0, 1.0, 0.0), radius: 0.01, to_world: Transform::IDENTITY, material: Default::default(), emission: Rgb::ONE });
        let lights = AreaLights::new(&g, 2);
        for ux in [0.25f32, 0.5, 0.9] {
            let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 1.0, LightSampling::SolidAngle, 0.5, Vec2::new(ux, 0.2)).unwrap();
            let sin2 = s.wi.cross(Vec3::Y).length_squared();
            assert!(close(sin2, 1e-4 * ux as f64, 1e-5), "{ux}: sin² {sin2} against {}", 1e-4 * ux as f64);
        }
    }

    #[test]
    fn tiny_sphere_caps_use_the_small_angle_expansion() {
        // Radius 0.01 at distance 1: sin²θmax = 10⁻⁴, 1 − cos θmax = sin²θmax/2 + O(sin⁴) =
        // 5·10⁻⁵ (to 2.5·10⁻⁵ relative; computed as 1 − cos in f32 it would lose ~10⁻³), so the
        // density is 1/(2π·5·10⁻⁵), and sin²θ = 10⁻⁴·u.x.
        let mut g = Geometry::default();
        g.add_sphere(Sphere { center: Vec3::new(0.0, 1.0, 0.0), radius: 0.01, to_world: Transform::IDENTITY, material: Default::default(), emission: Rgb::ONE });
        let lights = AreaLights::new(&g, 2);
        let expected = 1.0 / (2.0 * std::f64::consts::PI * 5e-5);
        for ux in [0.25f32, 0.5, 0.9] {
            let s = lights.sample(&g, &[], Vec3::ZERO, &|_| 1.0, LightSampling::SolidAngle, 0.5, Vec2::new(ux, 0.2)).unwrap();
            assert!(close(s.pdf, expected, 1e-4), "{}", s.pdf);
            let sin2 = s.wi.cross(Vec3::Y).length_squared();
            assert!(close(sin2, 1e-4 * ux as f64, 2e-3), "{ux}: sin² {sin2}");
        }
        let p = lights.pdf(&g, LightSampling::Mis, 0, Vec3::ZERO, Vec3::new(0.0, 0.99, 0.0), -Vec3::Y);
        assert!(close(p, expected, 1e-4), "{p}");
    }
}
