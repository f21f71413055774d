//! The warps' densities against their definitions: the fraction of cosine-hemisphere samples
//! in a band of cos θ is ∫ cos θ / π dω = b² − a² (written out, not taken from
//! `cosine_hemisphere_pdf`), and the pdf itself is cos θ / π and integrates to one.

use raylab_core::sampling::{concentric_disk, cosine_hemisphere, cosine_hemisphere_pdf, uniform_sphere, uniform_triangle};
use raylab_core::{Pcg32, Vec2};

#[test]
fn cosine_hemisphere_pdf_known_values() {
    let pi = std::f32::consts::PI;
    assert_eq!(cosine_hemisphere_pdf(1.0), 1.0 / pi);
    assert!((cosine_hemisphere_pdf(0.5) - 0.5 / pi).abs() < 1e-7);
    assert_eq!(cosine_hemisphere_pdf(0.0), 0.0);
    assert_eq!(cosine_hemisphere_pdf(-0.3), 0.0, "nothing below the horizon");
    // ∫ pdf dω = 2π ∫₀¹ pdf(z) dz (dω = dz dφ), midpoint rule.
    let n = 10_000;
    let integral: f64 = (0..n).map(|i| cosine_hemisphere_pdf((i as f32 + 0.5) / n as f32) as f64).sum::<f64>() * 2.0 * std::f64::consts::PI / n as f64;
    assert!((integral - 1.0).abs() < 1e-5, "{integral}");
}

#[test]
fn cosine_hemisphere_samples_follow_cos_over_pi() {
    // 10 bands of cos θ × 8 sectors of φ; a band [a, b) holds (b² − a²)/8 of the samples per sector.
    let (nz, np, n) = (10usize, 8usize, 200_000usize);
    let mut observed = vec![0.0f64; nz * np];
    let mut rng = Pcg32::new(17, 3);
    for _ in 0..n {
        let w = cosine_hemisphere(rng.next_vec2());
        let iz = ((w.z * nz as f32) as usize).min(nz - 1);
        let ip = ((w.y.atan2(w.x).rem_euclid(std::f32::consts::TAU) / std::f32::consts::TAU * np as f32) as usize).min(np - 1);
        observed[iz * np + ip] += 1.0;
    }
    let expected: Vec<f64> = (0..nz * np)
        .map(|c| {
            let (a, b) = ((c / np) as f64 / nz as f64, (c / np + 1) as f64 / nz as f64);
            (b * b - a * a) / np as f64 * n as f64
        })
        .collect();
    let (chi2, dof) = chi_square(&expected, &observed);
    assert!(chi2 < limit(dof), "χ² = {chi2} with {dof} dof");
}

#[test]
fn concentric_disk_is_uniform_and_maps_the_square_edges_to_the_circle() {
    // Equal-area rings: a fraction r² of the samples lies within radius r.
    let mut rng = Pcg32::new(5, 8);
    let n = 100_000;
    let inside = (0..n).filter(|_| concentric_disk(rng.next_vec2()).length() < 0.5).count() as f64 / n as f64;
    assert!((inside - 0.25).abs() < 0.007, "{inside}");
    // The square's border goes to the unit circle, its centre to the origin.
    for u in [Vec2::new(1.0, 0.5), Vec2::new(0.0, 0.3), Vec2::new(0.7, 1.0), Vec2::new(1.0, 1.0)] {
        assert!((concentric_disk(u).length() - 1.0).abs() < 1e-6, "{u}");
    }
    assert_eq!(concentric_disk(Vec2::splat(0.5)), Vec2::ZERO);
    assert!((concentric_disk(Vec2::new(1.0, 0.5)) - Vec2::X).length() < 1e-6);
    // Shirley & Chiu: the square's point o = 2u − 1 maps to radius max(|oₓ|, |o_y|) and angle
    // π/4 · o_y/oₓ in the wedges around ±x, π/2 − π/4 · oₓ/o_y in those around ±y.
    let polar = |r: f32, a: f32| Vec2::new(r * a.cos(), r * a.sin());
    let pi = std::f32::consts::PI;
    for (u, expected) in [
        (Vec2::new(1.0, 0.75), polar(1.0, pi / 8.0)),
        (Vec2::new(0.75, 1.0), polar(1.0, 3.0 * pi / 8.0)),
        (Vec2::new(0.7, 0.6), polar(0.4, pi / 4.0 * 0.5)),
        (Vec2::new(0.6, 0.2), polar(-0.6, pi / 2.0 - pi / 4.0 * (0.2 / -0.6))),
        (Vec2::new(0.25, 0.25), polar(-0.5, pi / 4.0)),
    ] {
        assert!((concentric_disk(u) - expected).length() < 1e-6, "{u}: {} vs {expected}", concentric_disk(u));
    }
    // Uniform in angle too: 16 equal sectors hold a sixteenth each.
    let mut sectors = [0.0f64; 16];
    for _ in 0..n {
        let d = concentric_disk(rng.next_vec2());
        sectors[((d.y.atan2(d.x).rem_euclid(std::f32::consts::TAU) / std::f32::consts::TAU * 16.0) as usize).min(15)] += 1.0;
    }
    let (chi2, dof) = chi_square(&[n as f64 / 16.0; 16], &sectors);
    assert!(chi2 < limit(dof), "sectors: χ² = {chi2}");
}

#[test]
fn uniform_sphere_has_uniform_height() {
    // Archimedes: z is uniform on [−1, 1], so each of 10 bands holds a tenth.
    let mut rng = Pcg32::new(9, 1);
    let n = 100_000;
    let mut bands = [0.0f64; 10];
    for _ in 0..n {
        let z = uniform_sphere(rng.next_vec2()).z;
        bands[(((z + 1.0) * 5.0) as usize).min(9)] += 1.0;
    }
    let (chi2, dof) = chi_square(&[n as f64 / 10.0; 10], &bands);
    assert!(chi2 < limit(dof), "χ² = {chi2}");
    // z = 1 − 2u₁, φ = 2πu₂: u = (1/4, 1/4) is z = 1/2, φ = π/2.
    let w = uniform_sphere(Vec2::splat(0.25));
    assert!((w - raylab_core::Vec3::new(0.0, 0.75f32.sqrt(), 0.5)).length() < 1e-6, "{w}");
    let w = uniform_sphere(Vec2::new(0.5, 0.625));
    assert!((w - raylab_core::Vec3::new(-(0.5f32.sqrt()), -(0.5f32.sqrt()), 0.0)).length() < 1e-6, "{w}");
}

#[test]
fn uniform_triangle_hand_values_and_uniformity() {
    // Heitz 2019: u₁ < u₂ gives b₀ = u₁/2, b₁ = u₂ − b₀; otherwise b₁ = u₂/2, b₀ = u₁ − b₁.
    assert_eq!(uniform_triangle(Vec2::new(0.2, 0.6)), (0.1, 0.5));
    assert_eq!(uniform_triangle(Vec2::new(0.6, 0.2)), (0.5, 0.1));
    assert_eq!(uniform_triangle(Vec2::new(0.0, 1.0)), (0.0, 1.0));
    // Uniform over the triangle: the four midpoint sub-triangles hold a quarter each.
    let mut rng = Pcg32::new(23, 4);
    let n = 80_000;
    let mut parts = [0.0f64; 4];
    for _ in 0..n {
        let (b0, b1) = uniform_triangle(rng.next_vec2());
        let b2 = 1.0 - b0 - b1;
        let k = if b0 > 0.5 { 0 } else if b1 > 0.5 { 1 } else if b2 > 0.5 { 2 } else { 3 };
        parts[k] += 1.0;
    }
    let (chi2, dof) = chi_square(&[n as f64 / 4.0; 4], &parts);
    assert!(chi2 < limit(dof), "{parts:?}");
}

/// Pearson's χ² over cells that all expect at least 5 (true of the cells above), and its
/// degrees of freedom (raylab-testkit has the pooled version; core cannot depend on it).
fn chi_square(expected: &[f64], observed: &[f64]) -> (f64, usize) {
    assert!(expected.iter().all(|&e| e >= 5.0));
    (expected.iter().zip(observed).map(|(e, o)| (o - e) * (o - e) / e).sum(), expected.len() - 1)
}

/// Mean plus five standard deviations of χ² with `dof` degrees of freedom.
fn limit(dof: usize) -> f64 {
    dof as f64 + 5.0 * (2.0 * dof as f64).sqrt()
}
