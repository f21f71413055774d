//! The thin-lens camera against its geometry (pbrt-v4 §5.2.3): every ray through one film
//! point passes through the same point of the plane of focus, and the ray origins fill the
//! lens disc of diameter `aperture`, uniformly. Expected values come from the camera's
//! parameters, never from another call of the camera.

use raylab_core::{Pcg32, Vec2, Vec3};
use raylab_render::Camera;

/// Where `ray` crosses the plane at distance `d` in front of `from` along `forward`.
fn crossing(origin: Vec3, dir: Vec3, from: Vec3, forward: Vec3, d: f32) -> Vec3 {
    let t = (d - (origin - from).dot(forward)) / dir.dot(forward);
    origin + t * dir
}

#[test]
fn rays_through_one_film_point_meet_at_the_focus_distance() {
    let (from, at) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(-2.0, 1.0, -4.0));
    let forward = (at - from).normalize();
    let (aperture, focus) = (0.4f32, 5.0f32);
    let lens = Camera::new(from, at, Vec3::Y, 40.0, 1.5, aperture, Some(focus)).unwrap();
    let pinhole = Camera::new(from, at, Vec3::Y, 40.0, 1.5, 0.0, Some(focus)).unwrap();
    let mut rng = Pcg32::new(3, 5);
    for film in [Vec2::new(0.5, 0.5), Vec2::new(0.1, 0.8), Vec2::new(0.95, 0.05)] {
        let p = pinhole.ray(film, Vec2::ZERO);
        assert_eq!(p.origin, from);
        let sharp = crossing(p.origin, p.dir, from, forward, focus);
        // The pinhole ray's point on the plane of focus is where the film maps.
        assert!(((sharp - from).dot(forward) - focus).abs() < 1e-4);
        let mut spread_near = 0.0f32;
        for _ in 0..1000 {
            let r = lens.ray(film, rng.next_vec2());
            assert!((r.dir.length() - 1.0).abs() < 1e-5);
            let q = crossing(r.origin, r.dir, from, forward, focus);
            assert!((q - sharp).length() < 2e-5 * focus, "film {film}: meets the plane of focus at {q}, pinhole at {sharp}");
            // Anywhere else the rays spread: at half the focus distance by up to half the aperture's radius.
            let near = crossing(r.origin, r.dir, from, forward, 0.5 * focus);
            spread_near = spread_near.max((near - crossing(p.origin, p.dir, from, forward, 0.5 * focus)).length());
        }
        assert!(spread_near > 0.45 * 0.5 * aperture && spread_near <= 0.5 * 0.5 * aperture + 1e-4, "film {film}: spread {spread_near}");
    }
}

#[test]
fn ray_origins_fill_the_aperture_disc_uniformly() {
    let (from, at) = (Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, -3.0));
    let aperture = 0.8f32;
    let radius = 0.5 * aperture;
    let cam = Camera::new(from, at, Vec3::Y, 50.0, 1.0, aperture, None).unwrap();
    assert_eq!(cam.focus_distance, 3.0, "focus defaults to |at − from|");
    let mut rng = Pcg32::new(7, 11);
    let n = 20_000;
    let (mut max_r, mut inner, mut quadrants) = (0.0f32, 0usize, [0usize; 4]);
    for _ in 0..n {
        let o = cam.ray(Vec2::new(0.3, 0.6), rng.next_vec2()).origin - from;
        assert!(o.z.abs() < 1e-6, "the lens lies in the plane facing the view direction: {o}");
        let r = o.length();
        assert!(r <= radius * (1.0 + 1e-5), "origin {o} outside the lens of radius {radius}");
        max_r = max_r.max(r);
        inner += (r < radius / 2f32.sqrt()) as usize;
        quadrants[(o.x > 0.0) as usize * 2 + (o.y > 0.0) as usize] += 1;
    }
    assert!(max_r > 0.99 * radius, "the origins reach the rim: {max_r} of {radius}");
    // Uniform over the disc: half of them inside radius/√2 (binomial, 5σ ≈ 0.018).
    let frac = inner as f64 / n as f64;
    assert!((frac - 0.5).abs() < 0.018, "{frac} inside r/√2");
    for q in quadrants {
        assert!((q as f64 / n as f64 - 0.25).abs() < 0.016, "{quadrants:?}");
    }
}

#[test]
fn pinhole_has_a_single_origin() {
    let cam = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 60.0, 1.0, 0.0, Some(2.0)).unwrap();
    for lens in [Vec2::ZERO, Vec2::new(0.9, 0.1), Vec2::ONE] {
        assert_eq!(cam.ray(Vec2::splat(0.25), lens).origin, Vec3::ZERO);
    }
}

#[test]
fn the_film_spans_the_field_of_view_on_the_plane_of_focus() {
    // The film's unit square maps onto the rectangle of the plane of focus that the field of
    // view cuts out: half height `focus·tan(vfov/2)`, half width `aspect` times that, `(0,0)`
    // at the top left. The camera's axes are built here from the viewing direction and `up`
    // (right = forward × up, image up = right × forward). A focus distance other than
    // |at − from| and half sizes other than 1 keep `*` and `/` apart.
    let (from, at) = (Vec3::new(1.0, 2.0, 3.0), Vec3::new(-2.0, 1.0, -4.0));
    let forward = (at - from).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let image_up = right.cross(forward);
    let (vfov, aspect, focus) = (60.0f32, 1.5f32, 4.0f32);
    let half_h = focus * (vfov.to_radians() / 2.0).tan();
    let half_w = aspect * half_h;
    let pinhole = Camera::new(from, at, Vec3::Y, vfov, aspect, 0.0, Some(focus)).unwrap();
    let lens = Camera::new(from, at, Vec3::Y, vfov, aspect, 0.3, Some(focus)).unwrap();
    let mut rng = Pcg32::new(13, 17);
    for film in [Vec2::new(0.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.25, 0.75), Vec2::new(0.5, 0.5), Vec2::new(0.8, 0.3)] {
        let expected = from + focus * forward + (2.0 * film.x - 1.0) * half_w * right + (1.0 - 2.0 * film.y) * half_h * image_up;
        let r = pinhole.ray(film, Vec2::ZERO);
        assert!((r.dir - (expected - from).normalize()).length() < 1e-5, "film {film}: direction {} against {}", r.dir, (expected - from).normalize());
        for _ in 0..20 {
            let r = lens.ray(film, rng.next_vec2());
            let q = crossing(r.origin, r.dir, from, forward, focus);
            assert!((q - expected).length() < 2e-5 * focus, "film {film}: crosses the plane of focus at {q}, not {expected}");
        }
    }
    // Without a focus distance the plane of focus goes through `at`, which the film's centre sees.
    let cam = Camera::new(from, at, Vec3::Y, vfov, aspect, 0.3, None).unwrap();
    let r = cam.ray(Vec2::splat(0.5), Vec2::new(0.9, 0.2));
    let q = crossing(r.origin, r.dir, from, forward, (at - from).length());
    assert!((q - at).length() < 1e-4, "{q} against {at}");
}

#[test]
fn lens_samples_map_to_the_lens_as_in_pbrt() {
    // pbrt-v4's thin lens puts `lensRadius · SampleUniformDiskConcentric(u)` at (x, y) of
    // camera space, x to the image's right and y up. The concentric map sends the middle of
    // the unit square's right edge, u = (1, ½), to the disc's point (1, 0) and the middle of
    // its top edge, (½, 1), to (0, 1). The uniform disc alone does not fix this (a mirrored
    // lens is as uniform), but images rendered from the same sample streams do.
    let cam = Camera::new(Vec3::ZERO, -Vec3::Z, Vec3::Y, 50.0, 1.0, 0.8, Some(3.0)).unwrap();
    for (lens, expected) in [(Vec2::new(1.0, 0.5), Vec3::new(0.4, 0.0, 0.0)), (Vec2::new(0.0, 0.5), Vec3::new(-0.4, 0.0, 0.0)), (Vec2::new(0.5, 1.0), Vec3::new(0.0, 0.4, 0.0)), (Vec2::new(0.5, 0.0), Vec3::new(0.0, -0.4, 0.0))] {
        let o = cam.ray(Vec2::splat(0.5), lens).origin;
        assert!((o - expected).length() < 1e-6, "lens {lens}: origin {o}, not {expected}");
    }
}
