//! Area lights: every primitive with a non-zero emission (rect and sphere lights, OBJ/MTL
//! `Ke` meshes) is a light that can be sampled from a shading point. One emitter is chosen
//! in proportion to its power, then a point on it by the selected strategy; `pdf` returns
//! the same density for a direction found by BSDF sampling, for multiple importance sampling.

use std::f32::consts::PI;
use std::fmt;
use std::str::FromStr;

use raylab_core::color::luminance;
use raylab_core::{sampling, Frame, Rgb, Vec2, Vec3};

use crate::shape::{Geometry, PrimRef};

/// How direct light from area lights is estimated (`[render] light_sampling`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LightSampling {
    /// Points uniformly distributed over the light's area (the report's area form).
    Uniform,
    /// Points distributed uniformly in the solid angle the light subtends: cones for
    /// spheres; triangles fall back to area sampling.
    SolidAngle,
    /// Only BSDF sampling: light is found when a sampled direction hits an emitter.
    Bsdf,
    /// Light samples (solid angle) and BSDF samples combined by the power heuristic
    /// (Veach 1997).
    Mis,
}

impl LightSampling {
    pub const ALL: &'static [LightSampling] = &[LightSampling::Uniform, LightSampling::SolidAngle, LightSampling::Bsdf, LightSampling::Mis];

    pub fn name(self) -> &'static str {
        match self {
            LightSampling::Uniform => "uniform",
            LightSampling::SolidAngle => "solid-angle",
            LightSampling::Bsdf => "bsdf",
            LightSampling::Mis => "mis",
        }
    }

    pub fn names() -> String {
        Self::ALL.iter().map(|k| k.name()).collect::<Vec<_>>().join(", ")
    }

    /// Whether light sampling is used at all.
    pub fn samples_lights(self) -> bool {
        self != LightSampling::Bsdf
    }
}

impl fmt::Display for LightSampling {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for LightSampling {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.iter().copied().find(|k| k.name() == s).ok_or_else(|| format!("unknown light sampling `{s}` (valid: {})", Self::names()))
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

/// The scene's emitting primitives with a power-proportional choice among them.
#[derive(Clone, Debug, Default)]
pub struct AreaLights {
    prims: Vec<u32>,
    /// Inclusive prefix sums of the emitters' powers, normalised to end at 1.
    cdf: Vec<f32>,
    /// Probability of choosing each emitter, indexed by primitive (0 for non-emitters).
    choice: Vec<f32>,
}

impl AreaLights {
    pub fn new(geometry: &Geometry) -> Self {
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
        Self { prims, cdf, choice }
    }

    pub fn is_empty(&self) -> bool {
        self.prims.is_empty()
    }

    pub fn len(&self) -> usize {
        self.prims.len()
    }

    /// Samples light arriving at `p` from one emitter. `u_choice` picks the emitter, `u` the
    /// point on it.
    pub fn sample(&self, geometry: &Geometry, p: Vec3, strategy: LightSampling, u_choice: f32, u: Vec2) -> Option<AreaSample> {
        let k = self.cdf.partition_point(|&c| c <= u_choice).min(self.prims.len().checked_sub(1)?);
        let prim = self.prims[k];
        let choice = self.choice[prim as usize];
        let le = geometry.emission(prim);
        match geometry.prim(prim) {
            PrimRef::Sphere(s) if strategy != LightSampling::Uniform => {
                let sphere = &geometry.spheres[s as usize];
                let (c, r) = (sphere.to_world.point(sphere.center), sphere.radius);
                let d = c - p;
                let dc2 = d.length_squared();
                if dc2 <= r * r {
                    return self.sample_area(geometry, prim, p, le, choice, u);
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
            _ => self.sample_area(geometry, prim, p, le, choice, u),
        }
    }

    /// Uniform area sampling of emitter `prim`, converted to solid angle.
    fn sample_area(&self, geometry: &Geometry, prim: u32, p: Vec3, le: Rgb, choice: f32, u: Vec2) -> Option<AreaSample> {
        let (q, n) = match geometry.prim(prim) {
            PrimRef::Triangle { mesh, tri } => {
                let m = &geometry.meshes[mesh as usize];
                let [a, b, c] = m.vertices(tri);
                let (b0, b1) = sampling::uniform_triangle(u);
                (b0 * a + b1 * b + (1.0 - b0 - b1) * c, m.winding_normal(tri))
            }
            PrimRef::Sphere(s) => {
                let sphere = &geometry.spheres[s as usize];
                let n = sampling::uniform_sphere(u);
                (sphere.to_world.point(sphere.center) + sphere.radius * n, n)
            }
        };
        let to = q - p;
        let d2 = to.length_squared();
        let dist = d2.sqrt();
        if dist <= 0.0 {
            return None;
        }
        let wi = to / dist;
        let cos_l = n.dot(-wi);
        if cos_l <= 0.0 {
            return None; // the back of a one-sided emitter
        }
        Some(AreaSample { wi, dist, le, pdf: choice / area(geometry, prim) * d2 / cos_l })
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
        let to = q - p;
        let cos_l = n.dot(-to.normalize_or_zero()).abs();
        if cos_l == 0.0 {
            return 0.0;
        }
        choice / area(geometry, prim) * to.length_squared() / cos_l
    }
}

/// Surface area of a primitive (spheres untransformed: lights are not scaled).
fn area(geometry: &Geometry, prim: u32) -> f32 {
    match geometry.prim(prim) {
        PrimRef::Triangle { mesh, tri } => geometry.meshes[mesh as usize].area(tri),
        PrimRef::Sphere(s) => {
            let r = geometry.spheres[s as usize].radius;
            4.0 * PI * r * r
        }
    }
}
