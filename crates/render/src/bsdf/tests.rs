//! BSDF tests: hand-computed values, normalisation, sample/pdf/eval consistency, a
//! chi-square test of sampling against the pdf, white furnace, reciprocity, and the
//! dielectric's Fresnel split, total internal reflection and Snell's law. Seeded, so
//! deterministic.

use std::f64::consts::PI as PI64;

use raylab_core::{Pcg32, Rgb, Vec2, Vec3};

use super::microfacet::schlick;
use super::*;
use super::fresnel_dielectric;

/// Unit vector with `cos θ = cos_theta` and azimuth `phi`.
fn dir(cos_theta: f32, phi: f32) -> Vec3 {
    let sin = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    Vec3::new(sin * phi.cos(), sin * phi.sin(), cos_theta)
}

fn close(a: f32, b: f32, rel: f32) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-12
}

fn close_rgb(a: Rgb, b: Rgb, rel: f32) -> bool {
    close(a.x, b.x, rel) && close(a.y, b.y, rel) && close(a.z, b.z, rel)
}

fn cook_torrance(distribution: Distribution, geometry: Geometry, alpha: f32) -> Bsdf {
    Bsdf::CookTorrance { diffuse: Rgb::new(0.2, 0.3, 0.1), specular: Rgb::new(0.6, 0.5, 0.7), alpha, distribution, geometry, fresnel: Fresnel::Schlick(Rgb::new(0.9, 0.5, 0.04)) }
}

const DISTRIBUTIONS: [Distribution; 2] = [Distribution::Beckmann, Distribution::Ggx];
const GEOMETRIES: [Geometry; 2] = [Geometry::Smith, Geometry::VCavity];

/// Every non-delta model, with a label for failure messages.
fn smooth_models() -> Vec<(String, Bsdf)> {
    let mut v = vec![
        ("lambert".to_string(), Bsdf::Lambert { albedo: Rgb::new(0.8, 0.5, 0.2) }),
        ("phong n=1".to_string(), Bsdf::Phong { kd: Rgb::new(0.3, 0.2, 0.1), ks: Rgb::new(0.5, 0.6, 0.7), exponent: 1.0 }),
        ("phong n=20".to_string(), Bsdf::Phong { kd: Rgb::new(0.3, 0.2, 0.1), ks: Rgb::new(0.5, 0.6, 0.7), exponent: 20.0 }),
        ("phong specular only".to_string(), Bsdf::Phong { kd: Rgb::ZERO, ks: Rgb::ONE, exponent: 50.0 }),
        ("kajiya-kay".to_string(), Bsdf::KajiyaKay { color: Rgb::new(0.6, 0.4, 0.2), kd: 0.7, ks: 0.3, exponent: 30.0 }),
    ];
    for d in DISTRIBUTIONS {
        for g in GEOMETRIES {
            for alpha in [0.05, 0.3, 1.0] {
                v.push((format!("cook-torrance {d} {g} α={alpha}"), cook_torrance(d, g, alpha)));
            }
        }
    }
    let gold = Fresnel::Conductor { eta: Rgb::new(0.143, 0.374, 1.442), k: Rgb::new(3.983, 2.385, 1.603) };
    v.push(("conductor gold ggx α=0.2".to_string(), Bsdf::CookTorrance { diffuse: Rgb::ZERO, specular: Rgb::ONE, alpha: 0.2, distribution: Distribution::Ggx, geometry: Geometry::Smith, fresnel: gold }));
    v
}

/// Outgoing directions from normal to grazing, at assorted azimuths.
fn wos() -> [Vec3; 4] {
    [Vec3::Z, dir(0.8, 0.3), dir(0.4, 2.0), dir(0.1, -1.0)]
}

#[test]
fn lambert_eval_is_albedo_over_pi() {
    let albedo = Rgb::new(0.8, 0.5, 0.2);
    let b = Bsdf::Lambert { albedo };
    for (wo, wi) in [(Vec3::Z, Vec3::Z), (dir(0.3, 1.0), dir(0.9, -2.0)), (dir(0.01, 0.0), dir(0.5, 3.0))] {
        assert_eq!(b.eval(wo, wi), albedo / std::f32::consts::PI);
        assert_eq!(b.eval(wo, -wi), Rgb::ZERO, "below the surface");
        assert_eq!(b.eval(-wo, wi), Rgb::ZERO, "seen from below");
    }
}

#[test]
fn ndf_peaks_at_one_over_pi_alpha_squared() {
    for d in DISTRIBUTIONS {
        for alpha in [0.05f32, 0.3, 1.0] {
            let expected = 1.0 / (std::f32::consts::PI * alpha * alpha);
            assert!(close(d.d(Vec3::Z, alpha), expected, 1e-6), "{d} α={alpha}: {} vs {expected}", d.d(Vec3::Z, alpha));
        }
    }
}

#[test]
fn schlick_is_f0_at_normal_incidence_and_one_at_grazing() {
    let f0 = Rgb::new(0.04, 0.5, 0.9);
    assert_eq!(schlick(f0, 1.0), f0);
    assert_eq!(schlick(f0, 0.0), Rgb::ONE);
    assert!(close_rgb(schlick(f0, 1e-3), Rgb::ONE, 1e-2));
    // Hand value: cos = 0.5 gives f0 + (1 − f0)/32.
    assert!(close_rgb(schlick(f0, 0.5), f0 + (Rgb::ONE - f0) / 32.0, 1e-6));
    assert_eq!(schlick(Rgb::ONE, 0.37), Rgb::ONE);
}

#[test]
fn geometry_terms_hand_values() {
    for d in DISTRIBUTIONS {
        for alpha in [0.05, 0.5, 1.0] {
            // At normal incidence nothing is masked.
            assert_eq!(Geometry::VCavity.g(d, alpha, Vec3::Z, Vec3::Z, Vec3::Z), 1.0);
            assert_eq!(Geometry::Smith.g(d, alpha, Vec3::Z, Vec3::Z, Vec3::Z), 1.0);
        }
    }
    // V-cavity with wo = wi = h at θ = 60°: min(1, 2 cos²θ) = 0.5.
    let w = dir(0.5, 0.7);
    assert!(close(Geometry::VCavity.g(Distribution::Ggx, 0.3, w, w, w), 0.5, 1e-5));
    // Smith GGX, θ = 60° both ways, α = 1: Λ = (√(1 + tan²θ) − 1)/2 = (2 − 1)/2, G2 = 1/2.
    assert!(close(Geometry::Smith.g(Distribution::Ggx, 1.0, w, w, w), 0.5, 1e-5));
    // Smith Beckmann: a = 1/(α tanθ) ≥ 1.6 means no masking.
    let steep = dir(0.9, 0.0);
    assert_eq!(Geometry::Smith.g(Distribution::Beckmann, 0.1, steep, steep, steep), 1.0);
}

#[test]
fn ndf_projected_area_is_one() {
    // ∫ D(h) cos θh dω = 2π ∫ D(θ) cos θ sin θ dθ, midpoint rule in θ.
    let n = 200_000;
    let dtheta = std::f64::consts::FRAC_PI_2 / n as f64;
    for d in DISTRIBUTIONS {
        for alpha in [0.05f32, 0.1, 0.3, 0.6, 1.0] {
            let sum: f64 = (0..n)
                .map(|i| {
                    let theta = (i as f64 + 0.5) * dtheta;
                    let h = dir(theta.cos() as f32, 0.4);
                    d.d(h, alpha) as f64 * theta.cos() * theta.sin()
                })
                .sum();
            let integral = 2.0 * PI64 * sum * dtheta;
            assert!((integral - 1.0).abs() < 5e-3, "{d} α={alpha}: ∫D cos = {integral}");
        }
    }
}

#[test]
fn samples_agree_with_eval_and_pdf() {
    let mut rng = Pcg32::new(1, 2);
    for (name, b) in smooth_models() {
        for wo in wos() {
            for _ in 0..2_000 {
                let Some(s) = b.sample(wo, rng.next_f32(), rng.next_vec2()) else { continue };
                assert!(!s.delta && s.wi.z > 0.0 && (s.wi.length() - 1.0).abs() < 1e-4, "{name}: {s:?}");
                assert_eq!((b.pdf(wo, -s.wi), b.eval(wo, -s.wi)), (0.0, Rgb::ZERO), "{name}: one-sided");
                assert!(close(s.pdf, b.pdf(wo, s.wi), 1e-4), "{name}: pdf {} vs {}", s.pdf, b.pdf(wo, s.wi));
                assert!(close_rgb(s.f, b.eval(wo, s.wi), 1e-4), "{name}: f {} vs {}", s.f, b.eval(wo, s.wi));
            }
        }
        assert!(b.sample(-Vec3::Z, 0.5, Vec2::splat(0.5)).is_none(), "{name} sampled from below");
    }
}

/// ∫ pdf over the upper hemisphere (one-sided models have none below, see
/// `samples_agree_with_eval_and_pdf`): midpoint rule in (θ, φ), dω = sin θ dθ dφ. Fine
/// steps in φ resolve the lobes of grazing `wo`, squeezed sideways near the horizon.
fn pdf_integral(b: &Bsdf, wo: Vec3) -> f64 {
    let (nt, np) = (512, 2048);
    let (dt, dp) = (0.5 * PI64 / nt as f64, 2.0 * PI64 / np as f64);
    let mut sum = 0.0;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) * dt;
        let ring: f64 = (0..np).map(|j| b.pdf(wo, dir(theta.cos() as f32, ((j as f64 + 0.5) * dp) as f32)) as f64).sum();
        sum += ring * theta.sin();
    }
    sum * dt * dp
}

#[test]
fn pdf_integrates_to_sample_acceptance() {
    // `sample` rejects directions below the horizon, so its density integrates to the
    // fraction of samples it returns: 1 for Lambert, ≤ 1 otherwise.
    let mut rng = Pcg32::new(5, 6);
    for (name, b) in smooth_models() {
        for wo in wos() {
            let integral = pdf_integral(&b, wo);
            let n = 100_000;
            let accepted = (0..n).filter(|_| b.sample(wo, rng.next_f32(), rng.next_vec2()).is_some()).count() as f64 / n as f64;
            assert!(integral <= 1.01, "{name} wo={wo}: ∫pdf = {integral}");
            assert!((integral - accepted).abs() < 0.01, "{name} wo={wo}: ∫pdf = {integral}, accepted {accepted}");
            if name == "lambert" || (name.starts_with("phong") && wo == Vec3::Z) {
                assert!((integral - 1.0).abs() < 0.01, "{name} wo={wo}: ∫pdf = {integral}");
            }
        }
    }
}

/// Chi-square statistic and degrees of freedom comparing where `sample` sends 500 000
/// directions, over 16 (cos θ) × 32 (φ) bins of the upper hemisphere plus a "rejected"
/// cell, with the counts the pdf predicts (bins integrated by a 16 × 16 midpoint rule in
/// (cos θ, φ), where dω = d cos θ dφ). Cells expecting fewer than 5 are pooled.
fn chi_square(b: &Bsdf, wo: Vec3, seed: u64) -> (f64, usize) {
    const NZ: usize = 16;
    const NP: usize = 32;
    const SUB: usize = 16;
    let n = 500_000;
    let two_pi = 2.0 * std::f32::consts::PI;
    let mut observed = vec![0.0f64; NZ * NP + 1];
    let mut rng = Pcg32::new(seed, 7);
    for _ in 0..n {
        let cell = match b.sample(wo, rng.next_f32(), rng.next_vec2()) {
            Some(s) => {
                assert!(s.wi.z > 0.0);
                let iz = ((s.wi.z * NZ as f32) as usize).min(NZ - 1);
                let ip = ((s.wi.y.atan2(s.wi.x).rem_euclid(two_pi) / two_pi * NP as f32) as usize).min(NP - 1);
                iz * NP + ip
            }
            None => NZ * NP,
        };
        observed[cell] += 1.0;
    }
    let (dz, dphi) = (1.0 / NZ as f64, 2.0 * PI64 / NP as f64);
    let mut expected: Vec<f64> = (0..NZ * NP)
        .map(|cell| {
            let (iz, ip) = (cell / NP, cell % NP);
            let mut sum = 0.0;
            for (a, c) in (0..SUB * SUB).map(|k| (k / SUB, k % SUB)) {
                let z = (iz as f64 + (a as f64 + 0.5) / SUB as f64) * dz;
                let phi = (ip as f64 + (c as f64 + 0.5) / SUB as f64) * dphi;
                sum += b.pdf(wo, dir(z as f32, phi as f32)) as f64;
            }
            sum / (SUB * SUB) as f64 * dz * dphi * n as f64
        })
        .collect();
    let total: f64 = expected.iter().sum();
    expected.push((n as f64 - total).max(0.0));
    raylab_testkit::chi_square(&expected, &observed)
}

#[test]
fn sample_histogram_matches_pdf() {
    let models = [
        ("lambert", Bsdf::Lambert { albedo: Rgb::splat(0.7) }),
        ("phong n=20", Bsdf::Phong { kd: Rgb::splat(0.3), ks: Rgb::splat(0.6), exponent: 20.0 }),
        ("cook-torrance ggx α=0.3", cook_torrance(Distribution::Ggx, Geometry::Smith, 0.3)),
        ("cook-torrance beckmann α=0.3", cook_torrance(Distribution::Beckmann, Geometry::Smith, 0.3)),
    ];
    for (i, (name, b)) in models.iter().enumerate() {
        for (j, wo) in [dir(0.77, 0.5), dir(0.3, 4.0)].into_iter().enumerate() {
            let (chi2, dof) = chi_square(b, wo, (10 * i + j) as u64);
            let limit = raylab_testkit::chi_square_limit(dof);
            assert!(chi2 < limit, "{name} wo={wo}: χ² = {chi2:.1} with {dof} dof (limit {limit:.1})");
        }
    }
}

/// E[f cos θi / pdf] over `sample`, with its standard error: the albedo for `wo`.
fn albedo(b: &Bsdf, wo: Vec3, seed: u64) -> (f64, f64) {
    let mut rng = Pcg32::new(seed, 9);
    let n = 200_000;
    let (mut sum, mut sum2) = (0.0f64, 0.0f64);
    for _ in 0..n {
        if let Some(s) = b.sample(wo, rng.next_f32(), rng.next_vec2()) {
            let w = (s.f.x * s.wi.z / s.pdf) as f64;
            sum += w;
            sum2 += w * w;
        }
    }
    let mean = sum / n as f64;
    (mean, ((sum2 / n as f64 - mean * mean).max(0.0) / n as f64).sqrt())
}

#[test]
fn white_furnace() {
    // Closed form: GGX, α = 1, Smith, normal incidence. D = 1/π, wi = 2θh off the normal,
    // G2 = 2 cos θi / (1 + cos θi): E = 2 ∫₀^{π/4} G2 cos θh sin θh dθh = 1 − ln 2.
    let ggx =
        Bsdf::CookTorrance { diffuse: Rgb::ZERO, specular: Rgb::ONE, alpha: 1.0, distribution: Distribution::Ggx, geometry: Geometry::Smith, fresnel: Fresnel::Schlick(Rgb::ONE) };
    let (e, se) = albedo(&ggx, Vec3::Z, 99);
    assert!((e - (1.0 - 2f64.ln())).abs() < 4.0 * se + 1e-3, "GGX α=1 at normal incidence: {e} ± {se}");
    let lambert = Bsdf::Lambert { albedo: Rgb::ONE };
    for (k, wo) in wos().into_iter().enumerate() {
        let (e, _) = albedo(&lambert, wo, k as u64);
        assert!((e - 1.0).abs() < 1e-3, "lambert wo={wo}: {e}");
        for exponent in [1.0, 20.0, 200.0] {
            let phong = Bsdf::Phong { kd: Rgb::splat(0.3), ks: Rgb::splat(0.7), exponent };
            let (e, se) = albedo(&phong, wo, k as u64);
            assert!(e <= 1.0 + 4.0 * se + 1e-3, "phong n={exponent} wo={wo}: {e} ± {se}");
            if wo == Vec3::Z {
                // At normal incidence the normalised lobe reflects exactly ks.
                assert!((e - 1.0).abs() < 4.0 * se + 1e-3, "phong n={exponent} at normal incidence: {e} ± {se}");
            }
        }
        for d in DISTRIBUTIONS {
            for g in GEOMETRIES {
                for alpha in [0.05, 0.1, 0.3, 0.6, 1.0] {
                    let b = Bsdf::CookTorrance { diffuse: Rgb::ZERO, specular: Rgb::ONE, alpha, distribution: d, geometry: g, fresnel: Fresnel::Schlick(Rgb::ONE) };
                    let (e, se) = albedo(&b, wo, k as u64);
                    assert!(e <= 1.0 + 4.0 * se + 5e-3, "{d} {g} α={alpha} wo={wo}: {e} ± {se}");
                    if g == Geometry::Smith && alpha <= 0.1 && wo.z >= 0.8 {
                        // Little masking: nearly all energy is reflected.
                        assert!(e >= 0.97, "{d} {g} α={alpha} wo={wo}: {e} ± {se}");
                    }
                }
            }
        }
    }
}

#[test]
fn reciprocity() {
    let mut rng = Pcg32::new(11, 12);
    // Kajiya–Kay's diffuse term depends on the light's direction only: not reciprocal.
    for (name, b) in smooth_models().into_iter().filter(|(name, _)| name != "kajiya-kay") {
        for _ in 0..2_000 {
            let wo = dir(rng.next_f32(), 6.3 * rng.next_f32());
            let wi = dir(rng.next_f32(), 6.3 * rng.next_f32());
            let (a, c) = (b.eval(wo, wi), b.eval(wi, wo));
            assert!(close_rgb(a, c, 1e-4), "{name}: f({wo}, {wi}) = {a} but f({wi}, {wo}) = {c}");
        }
    }
}

#[test]
fn delta_lobes_have_no_density() {
    for b in [Bsdf::Mirror { reflectance: Rgb::ONE }, Bsdf::Dielectric { ior: 1.5 }] {
        assert!(b.is_delta());
        let wo = dir(0.6, 1.0);
        let wi = Vec3::new(-wo.x, -wo.y, wo.z);
        assert_eq!((b.eval(wo, wi), b.pdf(wo, wi)), (Rgb::ZERO, 0.0));
    }
    assert!(smooth_models().iter().all(|(_, b)| !b.is_delta()));
}

#[test]
fn mirror_reflects_about_the_normal() {
    let reflectance = Rgb::new(0.9, 0.6, 0.3);
    let b = Bsdf::Mirror { reflectance };
    for wo in wos() {
        let s = b.sample(wo, 0.3, Vec2::splat(0.6)).expect("mirror sample");
        assert_eq!(s.wi, Vec3::new(-wo.x, -wo.y, wo.z));
        assert!(s.delta && s.pdf == 1.0);
        assert!(close_rgb(s.f * s.wi.z / s.pdf, reflectance, 1e-6));
    }
    assert!(b.sample(dir(-0.5, 0.0), 0.3, Vec2::ZERO).is_none());
}

#[test]
fn dielectric_reflects_with_fresnel_probability() {
    let mut rng = Pcg32::new(21, 22);
    let n = 100_000;
    for ior in [1.5f32, 1.33] {
        for cos in [1.0f32, 0.8, 0.5, 0.2, 0.05, -1.0, -0.9, -0.8, -0.5] {
            let wo = dir(cos, 0.8);
            let f = fresnel_dielectric(cos, ior);
            // η = n_transmitted / n_incident as seen from wo.
            let eta = if cos > 0.0 { ior } else { 1.0 / ior };
            let mut reflected = 0;
            for _ in 0..n {
                let s = Bsdf::Dielectric { ior }.sample(wo, rng.next_f32(), rng.next_vec2()).expect("dielectric sample");
                assert!(s.delta);
                let weight = s.f.x * s.wi.z.abs() / s.pdf;
                if s.wi.z * wo.z > 0.0 {
                    reflected += 1;
                    assert!(close(s.pdf, f, 1e-6) && close(weight, 1.0, 1e-5), "reflection {s:?}");
                } else {
                    assert!(close(s.pdf, 1.0 - f, 1e-6) && close(weight, 1.0 / (eta * eta), 1e-5), "refraction {s:?}");
                }
            }
            let frac = reflected as f32 / n as f32;
            let tol = 5.0 * (f * (1.0 - f) / n as f32).sqrt() + 1e-6;
            assert!((frac - f).abs() <= tol, "ior {ior} cos {cos}: reflected {frac}, Fresnel {f}");
        }
    }
}

#[test]
fn dielectric_total_internal_reflection() {
    let ior = 1.5f32;
    let sin_critical = 1.0 / ior;
    let mut rng = Pcg32::new(31, 32);
    for sin in [sin_critical + 1e-3, 0.8, 0.99] {
        let wo = dir(-(1.0 - sin * sin).sqrt(), 2.5);
        assert_eq!(fresnel_dielectric(wo.z, ior), 1.0);
        for _ in 0..1_000 {
            let s = Bsdf::Dielectric { ior }.sample(wo, rng.next_f32(), rng.next_vec2()).expect("TIR sample");
            assert_eq!(s.wi, Vec3::new(-wo.x, -wo.y, wo.z), "sinθ = {sin}: must reflect");
            assert!(s.pdf == 1.0 && close(s.f.x * s.wi.z.abs(), 1.0, 1e-6));
        }
    }
}

#[test]
fn dielectric_refraction_obeys_snell() {
    let ior = 1.5f32;
    let sin_of = |w: Vec3| (w.x * w.x + w.y * w.y).sqrt();
    // (cos θi, η = n_t/n_i): from outside into glass, and from inside out below the critical angle.
    for (cos, eta) in [(0.9f32, ior), (0.5, ior), (0.1, ior), (-0.95, 1.0 / ior), (-0.8, 1.0 / ior)] {
        let wo = dir(cos, 1.2);
        // u_lobe just below 1 always picks refraction unless F ≈ 1.
        let s = Bsdf::Dielectric { ior }.sample(wo, 0.99999, Vec2::ZERO).expect("refraction");
        assert!(s.wi.z * wo.z < 0.0, "crossed the interface");
        assert!((s.wi.length() - 1.0).abs() < 1e-5);
        assert!(close(sin_of(s.wi), sin_of(wo) / eta, 1e-4), "cos {cos}: sinθt {} vs {}", sin_of(s.wi), sin_of(wo) / eta);
        // The transmitted ray continues on the far side of the normal: opposite azimuth.
        assert!(s.wi.x * wo.x + s.wi.y * wo.y < 0.0 && (s.wi.x * wo.y - s.wi.y * wo.x).abs() < 1e-5);
    }
}

#[test]
fn extreme_inputs_stay_finite() {
    let cosines = [1.0f32, 0.5, 1e-4, 1e-7, 1e-20, 1e-30, 1e-40, 0.0, -0.0, -1e-30, -1e-7, -0.5, -1.0];
    let us = [0.0f32, 1e-7, 0.5, 1.0 - f32::EPSILON / 2.0];
    let mut models = smooth_models();
    for alpha in [0.0f32, -1.0, 1e-9, 1e-3, 2.0, 10.0] {
        for d in DISTRIBUTIONS {
            for g in GEOMETRIES {
                models.push((format!("{d} {g} α={alpha}"), cook_torrance(d, g, alpha)));
            }
        }
    }
    for exponent in [0.0, 1e4] {
        models.push((format!("phong n={exponent}"), Bsdf::Phong { kd: Rgb::splat(0.5), ks: Rgb::splat(0.5), exponent }));
    }
    models.push(("black".into(), Bsdf::Phong { kd: Rgb::ZERO, ks: Rgb::ZERO, exponent: 5.0 }));
    models.push(("mirror".into(), Bsdf::Mirror { reflectance: Rgb::ONE }));
    for ior in [1.0, 1.5, 0.7, 2.4] {
        models.push((format!("dielectric {ior}"), Bsdf::Dielectric { ior }));
    }
    for (name, b) in &models {
        for &co in &cosines {
            let wo = dir(co, 0.9);
            for &ci in &cosines {
                for wi in [dir(ci, 0.9 + std::f32::consts::PI), dir(ci, -0.3), dir(ci, 0.9)] {
                    let (f, p) = (b.eval(wo, wi), b.pdf(wo, wi));
                    assert!(f.is_finite() && f.min_element() >= 0.0, "{name}: f({wo}, {wi}) = {f}");
                    assert!(p.is_finite() && p >= 0.0, "{name}: pdf({wo}, {wi}) = {p}");
                }
            }
            for &ul in &us {
                for &ux in &us {
                    for &uy in &us {
                        if let Some(s) = b.sample(wo, ul, Vec2::new(ux, uy)) {
                            let ok = s.wi.is_finite() && (s.wi.length() - 1.0).abs() < 1e-3 && s.f.is_finite() && s.pdf.is_finite() && s.pdf > 0.0;
                            assert!(ok, "{name}: wo = {wo}: {s:?}");
                        }
                    }
                }
            }
        }
    }
}

#[test]
fn names_parse_and_errors_list_valid_names() {
    for d in DISTRIBUTIONS {
        assert_eq!(d.name().parse::<Distribution>(), Ok(d));
    }
    for g in GEOMETRIES {
        assert_eq!(g.name().parse::<Geometry>(), Ok(g));
    }
    assert_eq!("ggx".parse(), Ok(Distribution::Ggx));
    assert_eq!("v-cavity".parse(), Ok(Geometry::VCavity));
    assert_eq!("GGX".parse::<Distribution>(), Err("unknown microfacet distribution `GGX` (valid: beckmann, ggx)".to_string()));
    assert_eq!("torrance".parse::<Geometry>(), Err("unknown geometry term `torrance` (valid: smith, v-cavity)".to_string()));
}

// ---------------------------------------------------------------------------------------
// Independent references: every expected value below is computed here, in f64, from the
// published formula written out in the test, never by calling the code under test.

fn dir64(w: Vec3) -> [f64; 3] {
    [w.x as f64, w.y as f64, w.z as f64]
}

fn tan2_of(w: [f64; 3]) -> f64 {
    (w[0] * w[0] + w[1] * w[1]) / (w[2] * w[2])
}

/// Walter et al. 2007, eq. 27, in its published G1 form (the code stores Λ = 1/G1 − 1):
/// `G1 = (3.535a + 2.181a²) / (1 + 2.276a + 2.577a²)` for `a = 1/(α tanθ) < 1.6`, else 1.
fn walter_beckmann_g1(alpha: f64, w: [f64; 3]) -> f64 {
    let a = 1.0 / (alpha * tan2_of(w).sqrt());
    if a >= 1.6 { 1.0 } else { (3.535 * a + 2.181 * a * a) / (1.0 + 2.276 * a + 2.577 * a * a) }
}

/// erf by its Maclaurin series (converges fast for |x| < 3; enough for these tests).
fn erf(x: f64) -> f64 {
    let (mut term, mut sum) = (x, x);
    for n in 1..80 {
        term *= -x * x / n as f64;
        sum += term / (2 * n + 1) as f64;
    }
    2.0 / PI64.sqrt() * sum
}

/// Beckmann's exact Smith Λ (Walter et al. 2007, eq. 26 / Heitz 2014, eq. 78):
/// `Λ(a) = (erf(a) − 1)/2 + exp(−a²)/(2a√π)`.
fn exact_beckmann_lambda(alpha: f64, w: [f64; 3]) -> f64 {
    let a = 1.0 / (alpha * tan2_of(w).sqrt());
    (erf(a) - 1.0) / 2.0 + (-a * a).exp() / (2.0 * a * PI64.sqrt())
}

#[test]
fn erf_matches_published_table() {
    // Abramowitz & Stegun, table 7.1.
    for (x, e) in [(0.5, 0.520_499_877_8), (1.0, 0.842_700_792_9), (1.5, 0.966_105_146_5), (2.0, 0.995_322_265_0)] {
        assert!((erf(x) - e).abs() < 1e-9, "erf({x}) = {}", erf(x));
    }
}

#[test]
fn beckmann_smith_g1_matches_walter_and_the_exact_lambda() {
    // With wi along the normal Λ(wi) = 0, so G2(wo, n) = G1(wo) = 1/(1 + Λ(wo)).
    let mut checked = 0;
    for alpha in [0.2f32, 0.5, 1.0, 1.6] {
        for cos in [0.9f32, 0.7, 0.5, 0.3, 0.15] {
            let wo = dir(cos, 0.7);
            let g1 = Geometry::Smith.g(Distribution::Beckmann, alpha, wo, Vec3::Z, (wo + Vec3::Z).normalize()) as f64;
            let walter = walter_beckmann_g1(alpha as f64, dir64(wo));
            assert!((g1 - walter).abs() < 2e-6, "α={alpha} cosθ={cos}: G1 {g1}, Walter {walter}");
            // The rational fit is within 0.5 % of the exact G1 (Walter et al. 2007, §5.1); the
            // erf series is only used where it converges (a < 3).
            let a = 1.0 / (alpha as f64 * tan2_of(dir64(wo)).sqrt());
            let exact = 1.0 / (1.0 + exact_beckmann_lambda(alpha as f64, dir64(wo)));
            assert!(a >= 3.0 || (g1 - exact).abs() < 5e-3 * exact, "α={alpha} cosθ={cos}: G1 {g1}, exact {exact}");
            checked += (walter < 0.999) as usize;
        }
    }
    // Most cases lie away from Λ = 0, where a typo in the fit shows.
    assert!(checked >= 12, "{checked}");
    // A hand value: α = 1, θ = 60°: a = 1/√3, G1 = (3.535a + 2.181a²)/(1 + 2.276a + 2.577a²) = 0.872 31.
    let w = dir(0.5, 0.0);
    assert!(close(Geometry::Smith.g(Distribution::Beckmann, 1.0, w, Vec3::Z, w), 0.872_31, 2e-5));
    // Height-correlated G2 with both directions masked: 1/(1 + Λo + Λi).
    let (wo, wi) = (dir(0.4, 0.3), dir(0.6, 2.0));
    let lo = 1.0 / walter_beckmann_g1(0.7, dir64(wo)) - 1.0;
    let li = 1.0 / walter_beckmann_g1(0.7, dir64(wi)) - 1.0;
    let g2 = Geometry::Smith.g(Distribution::Beckmann, 0.7, wo, wi, (wo + wi).normalize()) as f64;
    assert!((g2 - 1.0 / (1.0 + lo + li)).abs() < 2e-6, "{g2}");
}

#[test]
fn ggx_smith_g1_matches_the_closed_form() {
    // GGX: G1 = 2 / (1 + √(1 + α² tan²θ)) (Walter et al. 2007, eq. 34).
    for alpha in [0.1f32, 0.4, 1.0] {
        for cos in [0.9f32, 0.5, 0.2] {
            let wo = dir(cos, -1.1);
            let expected = 2.0 / (1.0 + (1.0 + (alpha as f64).powi(2) * tan2_of(dir64(wo))).sqrt());
            let g1 = Geometry::Smith.g(Distribution::Ggx, alpha, wo, Vec3::Z, wo) as f64;
            assert!((g1 - expected).abs() < 2e-6, "α={alpha} cosθ={cos}: {g1} vs {expected}");
        }
    }
}

/// pbrt-v3's `FrConductor` (real arithmetic, after Born & Wolf), an independent derivation
/// of the conductor reflectance the code computes with complex numbers.
fn fr_conductor_pbrt_v3(cos: f64, eta: f64, k: f64) -> f64 {
    let (cos2, sin2) = (cos * cos, 1.0 - cos * cos);
    let (eta2, k2) = (eta * eta, k * k);
    let t0 = eta2 - k2 - sin2;
    let a2plusb2 = (t0 * t0 + 4.0 * eta2 * k2).sqrt();
    let t1 = a2plusb2 + cos2;
    let a = (0.5 * (a2plusb2 + t0)).max(0.0).sqrt();
    let t2 = 2.0 * cos * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2 * a2plusb2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rp + rs)
}

/// Gold at 650, 550 and 450 nm (Johnson & Christy 1972, as pbrt ships it).
fn gold() -> Fresnel {
    Fresnel::Conductor { eta: Rgb::new(0.143, 0.374, 1.442), k: Rgb::new(3.983, 2.385, 1.603) }
}

#[test]
fn gold_reflectance_at_normal_incidence_and_at_angles() {
    let (eta, k) = ([0.143, 0.374, 1.442], [3.983, 2.385, 1.603]);
    // Normal incidence, written out: ((η−1)² + k²)/((η+1)² + k²) = 0.966 7, 0.802 5, 0.324 0.
    let f0 = gold().eval(1.0);
    for (c, expected) in [(f0.x, 0.966_7), (f0.y, 0.802_5), (f0.z, 0.324_0)] {
        assert!((c - expected).abs() < 2e-4, "gold F0 {f0} vs {expected}");
    }
    // Gold is yellow: red reflects more than blue at every angle.
    for cos in [1.0f32, 0.866, 0.5, 0.25, 0.05] {
        let f = gold().eval(cos);
        for ch in 0..3 {
            let expected = fr_conductor_pbrt_v3(cos as f64, eta[ch], k[ch]);
            assert!((f[ch] as f64 - expected).abs() < 2e-5, "cos {cos} channel {ch}: {} vs {expected}", f[ch]);
        }
        assert!(f.x > f.z, "cos {cos}: {f}");
    }
    // Metals dip near a principal angle before rising to 1 at grazing: gold's red channel
    // reflects 0.959 4 at 70°, less than its 0.966 7 at normal incidence.
    let dip = gold().eval((70f32).to_radians().cos()).x;
    assert!((dip - 0.959_4).abs() < 2e-4 && dip < f0.x, "{dip}");
}

#[test]
fn dielectric_fresnel_published_value_at_45_degrees() {
    // Glass n = 1.5 at 45°: R_s = 0.092 0, R_p = 0.008 5 (Hecht, Optics, fig. 4.46), F = 0.050 3.
    let (ci, st) = (0.5f64.sqrt(), 0.5f64.sqrt() / 1.5);
    let ct = (1.0 - st * st).sqrt();
    let rs = ((ci - 1.5 * ct) / (ci + 1.5 * ct)).powi(2);
    let rp = ((1.5 * ci - ct) / (1.5 * ci + ct)).powi(2);
    assert!((rs - 0.0920).abs() < 1e-4 && (rp - 0.0085).abs() < 1e-4, "{rs} {rp}");
    assert!((fresnel_dielectric(0.5f32.sqrt(), 1.5) as f64 - 0.5 * (rs + rp)).abs() < 1e-6);
}

/// Cook–Torrance written out in f64: `diffuse/π + specular · F(wo·h) · D(h) · G2 / (4 cos θo cos θi)`.
fn cook_torrance_reference(distribution: Distribution, alpha: f64, fresnel: impl Fn(f64) -> [f64; 3], diffuse: [f64; 3], specular: [f64; 3], wo: Vec3, wi: Vec3) -> [f64; 3] {
    let (o, i) = (dir64(wo), dir64(wi));
    let s = [o[0] + i[0], o[1] + i[1], o[2] + i[2]];
    let len = (s[0] * s[0] + s[1] * s[1] + s[2] * s[2]).sqrt();
    let h = [s[0] / len, s[1] / len, s[2] / len];
    let cos_oh = o[0] * h[0] + o[1] * h[1] + o[2] * h[2];
    let (a2, cos2h, tan2h) = (alpha * alpha, h[2] * h[2], tan2_of(h));
    type Lambda = Box<dyn Fn([f64; 3]) -> f64>;
    let (d, lambda): (f64, Lambda) = match distribution {
        // Walter et al. 2007, eqs. 25 and 33.
        Distribution::Beckmann => ((-tan2h / a2).exp() / (PI64 * a2 * cos2h * cos2h), Box::new(move |w| 1.0 / walter_beckmann_g1(alpha, w) - 1.0)),
        Distribution::Ggx => (a2 / (PI64 * cos2h * cos2h * (a2 + tan2h).powi(2)), Box::new(move |w| 0.5 * ((1.0 + a2 * tan2_of(w)).sqrt() - 1.0))),
    };
    let g = 1.0 / (1.0 + lambda(o) + lambda(i));
    let f = fresnel(cos_oh);
    std::array::from_fn(|c| diffuse[c] / PI64 + specular[c] * f[c] * d * g / (4.0 * o[2] * i[2]))
}

#[test]
fn cook_torrance_hand_values_include_the_fresnel_factor() {
    let configs = [(dir(0.8, 0.3), dir(0.6, 2.9)), (dir(0.5, 1.0), dir(0.45, -2.0)), (dir(0.95, 0.0), dir(0.9, 3.0)), (dir(0.3, -0.4), dir(0.7, 2.2))];
    let (diffuse, specular) = ([0.2, 0.3, 0.1], [0.6, 0.5, 0.7]);
    let f0 = [0.9, 0.5, 0.04];
    // Schlick 1994: F = f0 + (1 − f0)(1 − cos)⁵.
    let schlick_ref = |cos: f64| std::array::from_fn(|c| f0[c] + (1.0 - f0[c]) * (1.0 - cos).powi(5));
    let (eta, k) = ([0.143, 0.374, 1.442], [3.983, 2.385, 1.603]);
    let gold_ref = |cos: f64| std::array::from_fn(|c| fr_conductor_pbrt_v3(cos, eta[c], k[c]));
    for d in DISTRIBUTIONS {
        for alpha in [0.15f32, 0.4, 0.9] {
            let schlick_model = Bsdf::CookTorrance { diffuse: Rgb::new(0.2, 0.3, 0.1), specular: Rgb::new(0.6, 0.5, 0.7), alpha, distribution: d, geometry: Geometry::Smith, fresnel: Fresnel::Schlick(Rgb::new(0.9, 0.5, 0.04)) };
            let gold_model = Bsdf::CookTorrance { diffuse: Rgb::new(0.2, 0.3, 0.1), specular: Rgb::new(0.6, 0.5, 0.7), alpha, distribution: d, geometry: Geometry::Smith, fresnel: gold() };
            for (wo, wi) in configs {
                let expected = cook_torrance_reference(d, alpha as f64, schlick_ref, diffuse, specular, wo, wi);
                let got = schlick_model.eval(wo, wi);
                for c in 0..3 {
                    assert!((got[c] as f64 - expected[c]).abs() <= 2e-5 * expected[c].abs() + 1e-7, "{d} α={alpha} Schlick: {got} vs {expected:?}");
                }
                let expected = cook_torrance_reference(d, alpha as f64, gold_ref, diffuse, specular, wo, wi);
                let got = gold_model.eval(wo, wi);
                for c in 0..3 {
                    assert!((got[c] as f64 - expected[c]).abs() <= 2e-5 * expected[c].abs() + 1e-7, "{d} α={alpha} gold: {got} vs {expected:?}");
                }
            }
        }
    }
}

/// ∫ g(wi) dωi over the upper hemisphere, midpoint rule in (θ, φ) (as `pdf_integral`, on a
/// coarser grid: the integrand f·cos θi is smoother than the pdf near the horizon).
fn hemisphere_integral(g: impl Fn(Vec3) -> f64) -> f64 {
    let (nt, np) = (256, 1024);
    let (dt, dp) = (0.5 * PI64 / nt as f64, 2.0 * PI64 / np as f64);
    let mut sum = 0.0;
    for i in 0..nt {
        let theta = (i as f64 + 0.5) * dt;
        let ring: f64 = (0..np).map(|j| g(dir(theta.cos() as f32, ((j as f64 + 0.5) * dp) as f32))).sum();
        sum += ring * theta.sin();
    }
    sum * dt * dp
}

#[test]
fn sampled_weights_estimate_the_quadrature_albedo() {
    // `samples_agree_with_eval_and_pdf` cannot fail by construction (`sample` takes its f and
    // pdf from `eval` and `pdf`). This one can: E[f cos θi / pdf] over `sample` equals
    // ∫ f cos θi dωi, computed here by quadrature of `eval` alone, only if the returned pdf
    // is the density the directions are actually drawn with (wherever f ≠ 0).
    for (m, (name, b)) in smooth_models().into_iter().enumerate() {
        for (k, wo) in wos().into_iter().enumerate() {
            let reference = hemisphere_integral(|wi| b.eval(wo, wi).x as f64 * wi.z as f64);
            let (estimate, se) = albedo(&b, wo, (100 * m + k) as u64);
            assert!((estimate - reference).abs() < 5.0 * se + 3e-3 * reference.max(0.1), "{name} wo={wo}: sampled {estimate} ± {se}, quadrature {reference}");
        }
    }
}

#[test]
fn sample_histogram_matches_pdf_for_every_model() {
    // The χ² test above covers four models; the others (V-cavity, conductor, Kajiya–Kay,
    // narrow lobes) are checked here against their pdf too, at a moderate and a grazing wo.
    for (i, (name, b)) in smooth_models().into_iter().enumerate() {
        for (j, wo) in [dir(0.6, 1.3), dir(0.2, -2.0)].into_iter().enumerate() {
            let (chi2, dof) = chi_square(&b, wo, (1000 + 10 * i + j) as u64);
            let limit = raylab_testkit::chi_square_limit(dof);
            assert!(chi2 < limit, "{name} wo={wo}: χ² = {chi2:.1} with {dof} dof (limit {limit:.1})");
        }
    }
}

#[test]
fn cook_torrance_horizon_cut_is_at_one_millionth() {
    // `cook_torrance.rs` gives light to directions at least 1e-6 above the horizon (its
    // `MIN_COS`, "at least": see `half_vector`) and none below: at exactly 1e-6 `f`, `pdf`
    // and `sample` are alive, 1 % lower they are zero. Either direction may be the grazing one.
    let at = Vec3::new((1.0f32 - 1e-12).sqrt(), 0.0, 1e-6);
    let below = Vec3::new(1.0, 0.0, 0.99e-6);
    let other = dir(0.6, 2.0);
    for d in DISTRIBUTIONS {
        for g in GEOMETRIES {
            let b = cook_torrance(d, g, 0.3);
            for (wo, wi) in [(at, other), (other, at)] {
                assert!(b.eval(wo, wi).min_element() > 0.0 && b.pdf(wo, wi) > 0.0, "{d} {g}: {wo} {wi}");
            }
            for (wo, wi) in [(below, other), (other, below)] {
                assert_eq!((b.eval(wo, wi), b.pdf(wo, wi)), (Rgb::ZERO, 0.0), "{d} {g}: {wo} {wi}");
            }
            // From a grazing wo the diffuse lobe (u_lobe = 0.99 ≥ its specular share) still samples.
            assert!(b.sample(at, 0.99, Vec2::new(0.3, 0.6)).is_some(), "{d} {g}");
            assert!(b.sample(below, 0.99, Vec2::new(0.3, 0.6)).is_none(), "{d} {g}");
        }
    }
}

#[test]
fn one_sided_models_reflect_nothing_exactly_at_the_horizon() {
    // One-sided means `wo.z > 0` and `wi.z > 0` (module doc): a direction in the tangent
    // plane, z = 0, gets neither `f` nor density, from either end.
    let flat = Vec3::new(0.6, 0.8, 0.0);
    let up = dir(0.7, 1.0);
    for b in [Bsdf::Lambert { albedo: Rgb::new(0.8, 0.5, 0.2) }, Bsdf::Phong { kd: Rgb::new(0.3, 0.2, 0.1), ks: Rgb::new(0.5, 0.6, 0.7), exponent: 3.0 }] {
        for (wo, wi) in [(flat, up), (up, flat), (flat, flat)] {
            assert_eq!(b.eval(wo, wi), Rgb::ZERO, "{b:?}: f({wo}, {wi})");
        }
        assert_eq!(b.pdf(flat, up), 0.0, "{b:?}: pdf from the horizon");
        assert!(b.sample(flat, 0.5, Vec2::new(0.3, 0.6)).is_none(), "{b:?}: sampled from the horizon");
    }
}

#[test]
fn index_matched_dielectric_is_invisible() {
    // n = 1 on both sides: the Fresnel equations give r_s = r_p = 0 below grazing, so all
    // the light goes straight through, for every u_lobe down to 0, with weight 1 (η = 1).
    // At these cosines cos θt = √(1 − (1 − cos²θ)) is exact in f32, so F is exactly 0
    // (elsewhere rounding leaves F ~ 1e-15, and u_lobe = 0 may reflect, rightly).
    for cos in [1.0f32, 0.75, 0.5, 0.25, -0.5, -0.75] {
        let wo = dir(cos, 0.8);
        assert_eq!(fresnel_dielectric(cos, 1.0), 0.0, "cos {cos}");
        for u_lobe in [0.0f32, 0.5, 1.0 - f32::EPSILON / 2.0] {
            let s = Bsdf::Dielectric { ior: 1.0 }.sample(wo, u_lobe, Vec2::ZERO).expect("transmission");
            assert!((s.wi + wo).length() < 1e-6 && s.pdf == 1.0, "cos {cos} u_lobe {u_lobe}: {s:?}");
            assert!(close(s.f.x * s.wi.z.abs() / s.pdf, 1.0, 1e-6), "cos {cos}: {s:?}");
        }
    }
}

#[test]
fn phong_chooses_its_lobes_in_proportion_to_their_luminance() {
    // `lobe_probability`: the specular lobe is chosen with probability
    // p = Y(ks) / (Y(kd) + Y(ks)), Y the Rec. 709 luminance 0.2126 R + 0.7152 G + 0.0722 B,
    // and Phong's density mixes the two lobes by it: at the mirror direction (cos α = 1),
    // pdf = (1 − p)·cos θi/π + p·(n + 1)/(2π).
    let y = |c: [f64; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let wo = dir(0.8, 0.4);
    let wi = Vec3::new(-wo.x, -wo.y, wo.z);
    let n = 3.0;
    for (kd, ks) in [([0.3, 0.2, 0.1], [0.5, 0.4, 0.6]), ([0.0; 3], [0.5, 0.4, 0.6]), ([0.3, 0.2, 0.1], [0.0; 3])] {
        let p = y(ks) / (y(kd) + y(ks));
        let want = (1.0 - p) * 0.8 / PI64 + p * (n + 1.0) / (2.0 * PI64);
        let phong = Bsdf::Phong { kd: Rgb::from_array(kd.map(|v| v as f32)), ks: Rgb::from_array(ks.map(|v| v as f32)), exponent: n as f32 };
        let got = phong.pdf(wo, wi) as f64;
        assert!((got - want).abs() < 1e-5 * want, "kd {kd:?} ks {ks:?}: pdf {got}, expected {want} (p = {p})");
        // The diffuse lobe is taken for u_lobe ≥ p: its cosine sample of u = (0.5, 0.5) is the normal.
        let s = phong.sample(wo, ((p + 1.0) / 2.0) as f32, Vec2::splat(0.5));
        assert!(p == 1.0 || s.is_some_and(|s| (s.wi - Vec3::Z).length() < 1e-6), "kd {kd:?}: {s:?}");
    }
    // Both lobes black: no density and no sample.
    let black = Bsdf::Phong { kd: Rgb::ZERO, ks: Rgb::ZERO, exponent: n as f32 };
    assert_eq!(black.pdf(wo, wi), 0.0);
    assert!(black.sample(wo, 0.5, Vec2::splat(0.5)).is_none());
}
