//! Normal-map baking: the detail of a high-resolution mesh stored in the tangent space of a
//! low-resolution one (the third report's dragon). For each texel of the low mesh's atlas,
//! rays leave the texel's point on the low surface along ± its shading normal; the closest
//! hit on the high mesh within `max_distance` gives the normal to store, expressed in
//! [`TangentFrame`] at that point, the frame the renderer decodes with. Formulas and
//! conventions: docs/normal-maps.md.

mod atlas;
mod raster;

pub use atlas::with_atlas_uvs;

use rayon::prelude::*;

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters};
use raylab_core::{Ray, Rgb, Vec3};
use raylab_render::shading::{encode_normal, TangentFrame};
use raylab_render::{Geometry, TriangleMesh};

/// Texels whose centre lies within this many texels of a triangle are baked from its
/// closest point, so a bilinear lookup anywhere inside the triangle reads only its own
/// texels (the four nearest centres are at most √2 away).
pub const COVERAGE_RADIUS: f32 = 1.5;

/// A baked tangent-space normal map, encoded `(n + 1) / 2`, top row first.
#[derive(Clone, Debug)]
pub struct BakedMap {
    pub size: u32,
    pub texels: Vec<Rgb>,
    /// Texels covered by a triangle (the rest is gutter, filled by dilation).
    pub covered: usize,
    /// Covered texels whose rays found the high mesh.
    pub hits: usize,
}

/// Bakes `high`'s shading normals into the tangent space of `low`, which needs UVs inside
/// `[0, 1]²`, normals and tangents (see [`with_atlas_uvs`] and
/// [`TriangleMesh::compute_tangents`]). `high` should have normals (smooth shading).
pub fn bake_normal_map(low: &TriangleMesh, high: &TriangleMesh, size: u32, max_distance: f32) -> BakedMap {
    assert!(!low.uvs.is_empty() && !low.normals.is_empty() && !low.tangents.is_empty(), "the low mesh needs UVs, normals and tangents");
    let mut low_geometry = Geometry::default();
    low_geometry.add_mesh(low.clone());
    let mut high_geometry = Geometry::default();
    high_geometry.add_mesh(high.clone());
    let accel = AnyAccel::build(AccelKind::Bvh, &high_geometry, &BuildOptions::default());
    let samples = raster::texel_samples(low, size);
    // A flat map (0, 0, 1) wherever nothing is baked.
    let flat = encode_normal(Vec3::Z);
    let baked: Vec<Option<(Rgb, bool)>> = samples
        .par_iter()
        .map(|s| {
            let s = s.as_ref()?;
            let geom = low_geometry.surface(&Ray::new(Vec3::ZERO, Vec3::Z), s.prim, 0.0, s.b1, s.b2);
            let (t, sign) = low_geometry.tangent(s.prim, s.b1, s.b2, &geom);
            let frame = TangentFrame::new(geom.ns, t, sign);
            let found = closest_normal(&accel, &high_geometry, geom.p, geom.ns, max_distance);
            Some(found.map_or((flat, false), |n| (encode_normal(frame.to_local(n)), true)))
        })
        .collect();
    let covered: Vec<bool> = baked.iter().map(Option::is_some).collect();
    let hits = baked.iter().filter(|b| b.is_some_and(|(_, hit)| hit)).count();
    let mut texels: Vec<Rgb> = baked.iter().map(|b| b.map_or(flat, |(c, _)| c)).collect();
    raster::dilate(&mut texels, &covered, size, (2.0 * atlas::GUTTER) as usize + 1);
    BakedMap { size, texels, covered: covered.iter().filter(|&&c| c).count(), hits }
}

/// The shading normal of the high mesh at the hit closest to `p` along `±n` within
/// `max_distance`. Both rays start a little behind `p` so that a high surface through `p`
/// itself (baking a mesh onto itself) is found by both: far enough that the triangle test's
/// rejection of hits within rounding error of the origin does not discard it.
fn closest_normal(accel: &AnyAccel, high: &Geometry, p: Vec3, n: Vec3, max_distance: f32) -> Option<Vec3> {
    let eps = 0.01 * max_distance;
    let mut counters = Counters::default();
    [n, -n]
        .into_iter()
        .filter_map(|d| {
            let ray = Ray::segment(p - eps * d, d, 0.0, max_distance + eps);
            let h = accel.intersect(high, &ray, &mut counters)?;
            Some(((h.t - eps).abs(), high.surface(&ray, h.prim, h.t, h.u, h.v).ns))
        })
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, ns)| ns)
}

#[cfg(test)]
mod tests;
