//! Ray sets: primary camera rays, diffuse bounces from their hits, shadow rays towards the
//! lights. Generated once per scene (with a reference structure) and traced by every
//! structure, so that all of them answer exactly the same queries.

use rayon::prelude::*;
use raylab_accel::Counters;
use raylab_core::{sampling, Frame, Pcg32, Ray, Vec2};
use raylab_render::light::LightSampling;
use raylab_render::{Light, Scene};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum RayKind {
    /// One camera ray through each pixel centre: coherent.
    Primary,
    /// A cosine-distributed bounce from each primary hit: incoherent.
    Diffuse,
    /// From each primary hit towards a light, stopping at it: any-hit queries.
    Shadow,
}

raylab_core::named_enum!(RayKind, "ray kind", {
    Primary => "primary",
    Diffuse => "diffuse",
    Shadow => "shadow",
});

impl RayKind {
    /// Shadow rays ask "is anything there?", the others "what is hit first?".
    pub fn any_hit(self) -> bool {
        self == RayKind::Shadow
    }
}

/// A named list of rays.
#[derive(Clone, Debug)]
pub struct RaySet {
    pub kind: RayKind,
    pub rays: Vec<Ray>,
}

/// One camera ray through the centre of each pixel of a `width × height` grid, row by row
/// from the top.
pub fn primary(scene: &Scene, width: u32, height: u32) -> Vec<Ray> {
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .map(|(x, y)| scene.camera.ray(Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32), Vec2::splat(0.5)))
        .collect()
}

/// Side of the pixel tiles primary rays are ordered in: 16 consecutive rays of a ray file
/// are one 4×4 tile, a packet for `raylab trace --packet 16`.
pub const TILE: u32 = 4;

/// Pixels of a `width × height` image in 4×4 tiles: tiles row by row, pixels row by row
/// within a tile; tiles on the right and bottom edges are cut to the image.
pub fn tile_order(width: u32, height: u32) -> impl Iterator<Item = (u32, u32)> {
    (0..height.div_ceil(TILE)).flat_map(move |ty| {
        (0..width.div_ceil(TILE)).flat_map(move |tx| (ty * TILE..((ty + 1) * TILE).min(height)).flat_map(move |y| (tx * TILE..((tx + 1) * TILE).min(width)).map(move |x| (x, y))))
    })
}

/// Generates the requested ray sets for `scene` at `width × height` camera rays, using the
/// scene's own structure to find the primary hits. Deterministic for a given `seed`.
/// Primary rays come in [`tile_order`]; each pixel's random stream is its scanline index,
/// so the diffuse and shadow sets do not depend on that order but for their own order.
pub fn generate(scene: &Scene, width: u32, height: u32, kinds: &[RayKind], seed: u64) -> Vec<RaySet> {
    let pixels: Vec<(u32, u32)> = tile_order(width, height).collect();
    let primary: Vec<Ray> = pixels.iter().map(|&(x, y)| scene.camera.ray(Vec2::new((x as f32 + 0.5) / width as f32, (y as f32 + 0.5) / height as f32), Vec2::splat(0.5))).collect();
    let lights: Vec<&Light> = scene.lights.iter().filter(|l| !matches!(l, Light::Ambient { .. })).collect();
    let secondary: Vec<(Option<Ray>, Option<Ray>)> = primary
        .par_iter()
        .enumerate()
        .map(|(i, ray)| {
            let mut c = Counters::default();
            let Some(hit) = scene.intersect(ray, &mut c) else { return (None, None) };
            let (x, y) = pixels[i];
            let mut rng = Pcg32::new(seed, y as u64 * width as u64 + x as u64);
            let wo = -ray.dir;
            let n = if hit.geom.ng.dot(wo) < 0.0 { -hit.geom.ng } else { hit.geom.ng };
            let d = Frame::from_z(n).to_world(sampling::cosine_hemisphere(rng.next_vec2()));
            let diffuse = hit.spawn(d);
            // One light, chosen uniformly among the delta lights and (as one) the area lights.
            let area = usize::from(!scene.area_lights.is_empty());
            let shadow = match rng.below((lights.len() + area).max(1) as u32) as usize {
                _ if lights.len() + area == 0 => None,
                k if k < lights.len() => {
                    let light = lights[k];
                    let (cell, u) = if light.is_jittered() { (rng.below(light.sample_count()), rng.next_vec2()) } else { (0, Vec2::ZERO) };
                    light.sample(hit.geom.p, cell, u).map(|s| hit.spawn_to(s.wi, s.dist.min(1e30)))
                }
                _ => scene
                    .area_lights
                    .sample(&scene.geometry, &scene.textures, hit.geom.p, &|_| 1.0, LightSampling::Uniform, rng.next_f32(), rng.next_vec2())
                    .map(|s| hit.spawn_to(s.wi, s.dist)),
            };
            (Some(diffuse), shadow)
        })
        .collect();
    kinds
        .iter()
        .map(|&kind| RaySet {
            kind,
            rays: match kind {
                RayKind::Primary => primary.clone(),
                RayKind::Diffuse => secondary.iter().filter_map(|s| s.0).collect(),
                RayKind::Shadow => secondary.iter().filter_map(|s| s.1).collect(),
            },
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tile_order_covers_the_image_once_in_4x4_tiles() {
        let order: Vec<(u32, u32)> = tile_order(8, 4).collect();
        // The first 16 pixels are the 4×4 tile at the origin, row by row, then the next tile.
        let first: Vec<(u32, u32)> = (0..4).flat_map(|y| (0..4).map(move |x| (x, y))).collect();
        assert_eq!(order[..16], first[..]);
        assert_eq!(order[16], (4, 0));
        assert_eq!(order[31], (7, 3));
        // Sizes that are not multiples of 4: edge tiles are cut, every pixel appears once.
        let (w, h) = (10, 7);
        let mut all: Vec<(u32, u32)> = tile_order(w, h).collect();
        assert_eq!(all[..6], [(0, 0), (1, 0), (2, 0), (3, 0), (0, 1), (1, 1)]);
        assert_eq!(all[16..18], [(4, 0), (5, 0)]);
        // The right-edge tile of the first tile row is 2 × 4 pixels.
        assert_eq!(all[32..40], [(8, 0), (9, 0), (8, 1), (9, 1), (8, 2), (9, 2), (8, 3), (9, 3)]);
        all.sort_by_key(|&(x, y)| (y, x));
        assert_eq!(all, (0..h).flat_map(|y| (0..w).map(move |x| (x, y))).collect::<Vec<_>>());
    }
}
