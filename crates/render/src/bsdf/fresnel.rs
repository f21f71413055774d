use raylab_core::{Rgb, Vec3};

/// The Fresnel term of a microfacet BRDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Fresnel {
    /// Schlick's approximation from the reflectance at normal incidence `f0` (`f0 = 1`: no
    /// falloff).
    Schlick(Rgb),
    /// A conductor's exact unpolarised Fresnel reflectance, complex index `eta + i·k` per
    /// channel (pbrt-v4's `FrComplex`).
    Conductor { eta: Rgb, k: Rgb },
}

impl Fresnel {
    /// Reflectance at incidence cosine `cos_i` (on the outside, ≥ 0).
    pub fn eval(&self, cos_i: f32) -> Rgb {
        match *self {
            Fresnel::Schlick(f0) => super::microfacet::schlick(f0, cos_i),
            Fresnel::Conductor { eta, k } => Rgb::new(
                fresnel_conductor(cos_i, Complex(eta.x, k.x)),
                fresnel_conductor(cos_i, Complex(eta.y, k.y)),
                fresnel_conductor(cos_i, Complex(eta.z, k.z)),
            ),
        }
    }
}

/// Just enough complex arithmetic for the conductor Fresnel equations.
#[derive(Clone, Copy, Debug)]
struct Complex(f32, f32);

impl Complex {
    fn add(self, o: Complex) -> Complex {
        Complex(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: Complex) -> Complex {
        Complex(self.0 - o.0, self.1 - o.1)
    }
    fn mul(self, o: Complex) -> Complex {
        Complex(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn scale(self, s: f32) -> Complex {
        Complex(self.0 * s, self.1 * s)
    }
    fn div(self, o: Complex) -> Complex {
        let d = o.0 * o.0 + o.1 * o.1;
        Complex((self.0 * o.0 + self.1 * o.1) / d, (self.1 * o.0 - self.0 * o.1) / d)
    }
    fn norm(self) -> f32 {
        self.0 * self.0 + self.1 * self.1
    }
    /// Principal square root (non-negative real part).
    fn sqrt(self) -> Complex {
        let n = self.norm().sqrt();
        let re = (0.5 * (n + self.0)).max(0.0).sqrt();
        let im = (0.5 * (n - self.0)).max(0.0).sqrt();
        Complex(re, if self.1 < 0.0 { -im } else { im })
    }
}

/// Unpolarised Fresnel reflectance of a conductor with complex relative index `eta`, light
/// arriving at `cos_i` from outside: the dielectric equations with a complex index.
fn fresnel_conductor(cos_i: f32, eta: Complex) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let one = Complex(1.0, 0.0);
    let sin2_t = Complex(1.0 - cos_i * cos_i, 0.0).div(eta.mul(eta));
    let cos_t = one.sub(sin2_t).sqrt();
    let r_parl = eta.scale(cos_i).sub(cos_t).div(eta.scale(cos_i).add(cos_t));
    let r_perp = Complex(cos_i, 0.0).sub(eta.mul(cos_t)).div(Complex(cos_i, 0.0).add(eta.mul(cos_t)));
    0.5 * (r_parl.norm() + r_perp.norm())
}

/// Mirror direction of `wo` (pointing away from the surface) about `n`.
#[inline]
pub fn reflect(wo: Vec3, n: Vec3) -> Vec3 {
    2.0 * wo.dot(n) * n - wo
}

/// Refracted direction of `wo` (pointing away from the surface, on the side of `n`) through
/// an interface with relative index `eta = n_transmitted / n_incident`, or `None` under total
/// internal reflection (Snell's law; pbrt-v4 §9.3.2).
pub fn refract(wo: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = wo.dot(n);
    let sin2_i = (1.0 - cos_i * cos_i).max(0.0);
    let sin2_t = sin2_i / (eta * eta);
    if sin2_t >= 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some(-wo / eta + (cos_i / eta - cos_t) * n)
}

/// Fresnel reflectance of a smooth dielectric interface for unpolarised light: the mean of
/// the s- and p-polarised Fresnel equations. `cos_i` is taken on the side of the normal the
/// light arrives from (negative = from inside); `eta = n_inside / n_outside`.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let (cos_i, eta) = if cos_i < 0.0 { (-cos_i, 1.0 / eta) } else { (cos_i, eta) };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).max(0.0).sqrt();
    let r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parl * r_parl + r_perp * r_perp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fresnel_known_values() {
        // Normal incidence: ((n-1)/(n+1))² = 0.04 for n = 1.5.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(-1.0, 1.5) - 0.04).abs() < 1e-6);
        // Grazing incidence reflects everything.
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-6);
        // Brewster's angle: p-polarised reflectance vanishes, so F = R_s / 2.
        let theta_b = 1.5f32.atan();
        let cos_i = theta_b.cos();
        let cos_t = (1.0 - (theta_b.sin() / 1.5).powi(2)).sqrt();
        let rs = ((cos_i - 1.5 * cos_t) / (cos_i + 1.5 * cos_t)).powi(2);
        assert!((fresnel_dielectric(cos_i, 1.5) - 0.5 * rs).abs() < 1e-6);
        // Beyond the critical angle from inside: total internal reflection.
        let critical = (1.0f32 / 1.5).asin();
        assert_eq!(fresnel_dielectric(-(critical + 0.01).cos(), 1.5), 1.0);
    }

    #[test]
    fn conductor_fresnel_known_values() {
        // Normal incidence: ((η − 1)² + k²) / ((η + 1)² + k²); gold's red channel.
        let (eta, k) = (0.143f32, 3.983f32);
        let f0 = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        let gold = Fresnel::Conductor { eta: Rgb::splat(eta), k: Rgb::splat(k) };
        assert!((gold.eval(1.0).x - f0).abs() < 1e-5, "{} vs {f0}", gold.eval(1.0).x);
        // Grazing incidence reflects everything.
        assert!((gold.eval(0.0).x - 1.0).abs() < 1e-5);
        // Without absorption it is the dielectric's reflectance, at every angle.
        let glass = Fresnel::Conductor { eta: Rgb::splat(1.5), k: Rgb::ZERO };
        for c in [1.0f32, 0.8, 0.5, 0.2, 0.05] {
            assert!((glass.eval(c).x - fresnel_dielectric(c, 1.5)).abs() < 1e-5, "cos {c}");
        }
    }

    #[test]
    fn complex_sqrt_is_the_principal_root() {
        // Squares worked by hand: (1 ∓ i)² = ∓2i, (2 + i)² = 3 + 4i, (1 − 2i)² = −3 − 4i, and
        // on the negative real axis (imaginary part +0) the root on the positive imaginary
        // axis, as C99's `csqrt(−4 + 0i) = 2i`. The conductor equations only take roots of
        // numbers in the upper half plane, so the lower half plane is checked here directly.
        for (z, root) in [((0.0, -2.0), (1.0, -1.0)), ((0.0, 2.0), (1.0, 1.0)), ((3.0, 4.0), (2.0, 1.0)), ((-3.0, -4.0), (1.0, -2.0)), ((-4.0, 0.0), (0.0, 2.0)), ((9.0, 0.0), (3.0, 0.0))] {
            let r = Complex(z.0, z.1).sqrt();
            assert!((r.0 - root.0).abs() < 1e-6 && (r.1 - root.1).abs() < 1e-6, "√{z:?} = {r:?}, not {root:?}");
        }
    }

    #[test]
    fn snell_law_holds() {
        let n = Vec3::Z;
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let wt = refract(wo, n, 1.5).unwrap();
        assert!((wt.length() - 1.0).abs() < 1e-5);
        let sin_i = 0.6f32;
        let sin_t = (wt.x * wt.x + wt.y * wt.y).sqrt();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-5);
        assert!(wt.z < 0.0 && wt.x < 0.0);
        // From the dense side at a grazing angle: total internal reflection.
        assert!(refract(Vec3::new(0.9, 0.0, 0.43589).normalize(), n, 1.0 / 1.5).is_none());
        assert_eq!(reflect(wo, n), Vec3::new(-0.6, 0.0, 0.8));
    }
}
