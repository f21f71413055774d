//! Shapes and the scene's geometry: the list of primitives that acceleration structures
//! index into.

pub mod bezier_patch;
pub mod curve;
mod mesh;
mod patch_surface;
mod sphere;

use std::ops::Range;

pub use bezier_patch::BezierPatch;
pub use curve::Curve;
pub use mesh::TriangleMesh;
pub use patch_surface::{PatchSurfaces, DEFAULT_SEED_GRID};
pub use sphere::Sphere;

use raylab_accel::{PrimHit, Primitives};
use raylab_core::{Aabb, Ray, Rgb, Vec2, Vec3};

use crate::material::{MaterialId, TextureId};

/// Local surface data at a hit.
#[derive(Clone, Copy, Debug)]
pub struct SurfaceGeometry {
    pub p: Vec3,
    /// Conservative bound on the absolute error of each coordinate of `p`, for robust
    /// spawning of secondary rays ([`raylab_core::offset_ray_origin`]).
    pub p_error: Vec3,
    /// Unit geometric normal (outward for spheres; for meshes, agreeing with `ns`).
    pub ng: Vec3,
    /// Unit shading normal (interpolated vertex normals, or `ng`).
    pub ns: Vec3,
    pub uv: Vec2,
    /// ∂p/∂u, for tangent frames; not normalised.
    pub dpdu: Vec3,
    /// ∂p/∂v, for bump maps and the bitangent's sign; not normalised.
    pub dpdv: Vec3,
}

/// Which shape a primitive belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrimRef {
    Triangle { mesh: u32, tri: u32 },
    Sphere(u32),
    /// One Bézier segment of a strand.
    Curve { curve: u32, seg: u32 },
    /// One bicubic patch intersected directly (Newton), of patch set `set`.
    Patch { set: u32, patch: u32 },
}

/// All shapes of a scene, flattened into primitives. Each shape's primitives are
/// consecutive, so each shape is one object for per-object bounding boxes.
#[derive(Clone, Debug, Default)]
pub struct Geometry {
    pub meshes: Vec<TriangleMesh>,
    pub spheres: Vec<Sphere>,
    pub curves: Vec<Curve>,
    pub patch_sets: Vec<PatchSurfaces>,
    prims: Vec<PrimRef>,
    objects: Vec<Range<u32>>,
}

impl Geometry {
    /// Appends one object's primitives (consecutive, so the object is one range).
    fn push_object(&mut self, prims: impl IntoIterator<Item = PrimRef>) {
        let start = self.prims.len() as u32;
        self.prims.extend(prims);
        self.objects.push(start..self.prims.len() as u32);
    }

    pub fn add_mesh(&mut self, mesh: TriangleMesh) {
        let m = self.meshes.len() as u32;
        self.push_object((0..mesh.len() as u32).map(|tri| PrimRef::Triangle { mesh: m, tri }));
        self.meshes.push(mesh);
    }

    pub fn add_sphere(&mut self, sphere: Sphere) {
        self.push_object([PrimRef::Sphere(self.spheres.len() as u32)]);
        self.spheres.push(sphere);
    }

    pub fn add_curve(&mut self, curve: Curve) {
        let c = self.curves.len() as u32;
        self.push_object((0..curve.len() as u32).map(|seg| PrimRef::Curve { curve: c, seg }));
        self.curves.push(curve);
    }

    /// Bicubic patches intersected directly; the set is one object.
    pub fn add_patches(&mut self, set: PatchSurfaces) {
        let s = self.patch_sets.len() as u32;
        self.push_object((0..set.len() as u32).map(|patch| PrimRef::Patch { set: s, patch }));
        self.patch_sets.push(set);
    }

    pub fn prim(&self, i: u32) -> PrimRef {
        self.prims[i as usize]
    }

    pub fn triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.len()).sum()
    }

    pub fn material(&self, prim: u32) -> MaterialId {
        match self.prims[prim as usize] {
            PrimRef::Triangle { mesh, .. } => self.meshes[mesh as usize].material,
            PrimRef::Sphere(s) => self.spheres[s as usize].material,
            PrimRef::Curve { curve, .. } => self.curves[curve as usize].material,
            PrimRef::Patch { set, .. } => self.patch_sets[set as usize].material,
        }
    }

    /// Surface data for a hit reported by an acceleration structure.
    pub fn surface(&self, ray: &Ray, prim: u32, t: f32, u: f32, v: f32) -> SurfaceGeometry {
        match self.prims[prim as usize] {
            PrimRef::Triangle { mesh, tri } => self.meshes[mesh as usize].surface(tri, u, v),
            PrimRef::Sphere(s) => self.spheres[s as usize].surface(ray, t),
            PrimRef::Curve { curve, seg } => self.curves[curve as usize].surface(seg, ray, t, u, v),
            PrimRef::Patch { set, patch } => self.patch_sets[set as usize].surface(patch, u, v),
        }
    }

    /// The tangent (along +u) and bitangent sign that tangent-space normal maps are decoded
    /// with at hit `(b1, b2)` of `prim` (see [`crate::shading::TangentFrame`]): a mesh's
    /// interpolated per-vertex tangents, else ∂p/∂u with the side of ∂p/∂v.
    pub fn tangent(&self, prim: u32, b1: f32, b2: f32, geom: &SurfaceGeometry) -> (Vec3, f32) {
        if let PrimRef::Triangle { mesh, tri } = self.prims[prim as usize] {
            if let Some(t) = self.meshes[mesh as usize].interpolated_tangent(tri, b1, b2) {
                return t;
            }
        }
        (geom.dpdu, if geom.ns.cross(geom.dpdu).dot(geom.dpdv) < 0.0 { -1.0 } else { 1.0 })
    }

    /// A normal in the object space of `prim`'s shape, in world space (unit).
    pub fn object_normal_to_world(&self, prim: u32, n: Vec3) -> Vec3 {
        let to_world = match self.prims[prim as usize] {
            PrimRef::Triangle { mesh, .. } => &self.meshes[mesh as usize].object_to_world,
            PrimRef::Sphere(s) => &self.spheres[s as usize].to_world,
            // Curves and patches are stored in world space.
            PrimRef::Curve { .. } | PrimRef::Patch { .. } => return n.try_normalize().unwrap_or(n),
        };
        to_world.normal(n).try_normalize().unwrap_or(n)
    }

    /// Radiance the primitive emits (zero for most).
    pub fn emission(&self, prim: u32) -> Rgb {
        match self.prims[prim as usize] {
            PrimRef::Triangle { mesh, .. } => self.meshes[mesh as usize].emission,
            PrimRef::Sphere(s) => self.spheres[s as usize].emission,
            PrimRef::Curve { .. } | PrimRef::Patch { .. } => Rgb::ZERO,
        }
    }

    /// The texture scaling the primitive's emission, if any.
    pub fn emission_texture(&self, prim: u32) -> Option<TextureId> {
        match self.prims[prim as usize] {
            PrimRef::Triangle { mesh, .. } => self.meshes[mesh as usize].emission_texture,
            PrimRef::Sphere(_) | PrimRef::Curve { .. } | PrimRef::Patch { .. } => None,
        }
    }

    /// Texture coordinates at barycentrics `(b1, b2)` of triangle primitive `prim`
    /// (`(b1, b2)` itself without vertex UVs).
    pub fn triangle_uv(&self, prim: u32, b1: f32, b2: f32) -> Vec2 {
        match self.prims[prim as usize] {
            PrimRef::Triangle { mesh, tri } => {
                let m = &self.meshes[mesh as usize];
                if m.uvs.is_empty() {
                    return Vec2::new(b1, b2);
                }
                let [a, b, c] = m.indices[tri as usize].map(|i| m.uvs[i as usize]);
                (1.0 - b1 - b2) * a + b1 * b + b2 * c
            }
            PrimRef::Sphere(_) | PrimRef::Curve { .. } | PrimRef::Patch { .. } => Vec2::ZERO,
        }
    }

    /// Radiance leaving point `geom` of primitive `prim` in direction `w`, before any
    /// emission texture (see `Scene::emitted`): emitters are
    /// one-sided (triangles along their winding normal, spheres outwards).
    pub fn emitted(&self, prim: u32, geom: &SurfaceGeometry, w: Vec3) -> Rgb {
        let le = self.emission(prim);
        if le == Rgb::ZERO {
            return le;
        }
        let n = match self.prims[prim as usize] {
            PrimRef::Triangle { mesh, tri } => self.meshes[mesh as usize].winding_normal(tri),
            PrimRef::Sphere(_) | PrimRef::Curve { .. } | PrimRef::Patch { .. } => geom.ng,
        };
        if n.dot(w) > 0.0 { le } else { Rgb::ZERO }
    }

    pub fn total_bounds(&self) -> Aabb {
        raylab_accel::primitives::total_bounds(self)
    }
}

impl Primitives for Geometry {
    fn len(&self) -> usize {
        self.prims.len()
    }

    fn bounds(&self, i: u32) -> Aabb {
        match self.prims[i as usize] {
            PrimRef::Triangle { mesh, tri } => self.meshes[mesh as usize].triangle_bounds(tri),
            PrimRef::Sphere(s) => self.spheres[s as usize].bounds(),
            PrimRef::Curve { curve, seg } => self.curves[curve as usize].segment_bounds(seg),
            PrimRef::Patch { set, patch } => self.patch_sets[set as usize].bounds(patch),
        }
    }

    #[inline]
    fn intersect(&self, i: u32, ray: &Ray) -> Option<PrimHit> {
        match self.prims[i as usize] {
            PrimRef::Triangle { mesh, tri } => self.meshes[mesh as usize].intersect(tri, ray).map(|(t, u, v)| PrimHit { t, u, v }),
            PrimRef::Sphere(s) => self.spheres[s as usize].intersect(ray).map(|t| PrimHit { t, u: 0.0, v: 0.0 }),
            PrimRef::Curve { curve, seg } => self.curves[curve as usize].intersect(seg, ray).map(|h| PrimHit { t: h.t, u: h.u, v: h.v }),
            PrimRef::Patch { set, patch } => self.patch_sets[set as usize].intersect(patch, ray),
        }
    }

    /// Triangles clipped exactly (spatial splits); other shapes keep `bounds ∩ clip`.
    fn clipped_bounds(&self, i: u32, clip: &Aabb) -> Aabb {
        match self.prims[i as usize] {
            PrimRef::Triangle { mesh, tri } => raylab_core::clip::triangle_bounds(self.meshes[mesh as usize].vertices(tri), clip),
            PrimRef::Sphere(_) | PrimRef::Curve { .. } | PrimRef::Patch { .. } => self.bounds(i).intersection(*clip),
        }
    }

    /// Mesh triangles, whose `intersect` is `intersect::triangle` on these vertices.
    fn triangle(&self, i: u32) -> Option<[Vec3; 3]> {
        match self.prims[i as usize] {
            PrimRef::Triangle { mesh, tri } => Some(self.meshes[mesh as usize].vertices(tri)),
            PrimRef::Sphere(_) | PrimRef::Curve { .. } | PrimRef::Patch { .. } => None,
        }
    }

    fn is_triangle(&self, i: u32) -> bool {
        matches!(self.prims[i as usize], PrimRef::Triangle { .. })
    }

    fn objects(&self) -> Vec<Range<u32>> {
        self.objects.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use raylab_core::Transform;

    /// One of each shape. A mesh of two triangles in z = 0 wound towards +z (winding normal
    /// +z), the second's UVs mirrored in u: (0,0,0) (1,0,0) (0,1,0) with UVs (0,0) (1,0)
    /// (0,1), so ∂p/∂u = x̂, ∂p/∂v = ŷ; (2,0,0) (3,0,0) (2,1,0) with UVs (1,0) (0,0) (1,1),
    /// so ∂p/∂u = -x̂ (pbrt-v4 §6.5.3: det = -1, ∂p/∂u = (d2.y·e1 - d1.y·e2)/det), ∂p/∂v = ŷ.
    /// A unit sphere at (10, 0, 2.5) stretched by 2 in z (the ellipsoid around (10, 0, 5)
    /// with semi-axes 1, 1, 2). A strand of two straight segments of radius 0.1 along x at
    /// z = -5. A flat bicubic patch over the unit square at z = -10.
    fn scene() -> Geometry {
        let mut g = Geometry::default();
        g.add_mesh(TriangleMesh {
            positions: vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0)],
            uvs: vec![Vec2::ZERO, Vec2::X, Vec2::Y, Vec2::X, Vec2::ZERO, Vec2::ONE],
            indices: vec![[0, 1, 2], [3, 4, 5]],
            material: MaterialId(3),
            emission: Rgb::new(1.0, 2.0, 3.0),
            emission_texture: Some(TextureId(7)),
            object_to_world: Transform::scale(Vec3::new(1.0, 2.0, 1.0)).unwrap(),
            ..Default::default()
        });
        g.add_sphere(Sphere { center: Vec3::new(10.0, 0.0, 2.5), radius: 1.0, to_world: Transform::scale(Vec3::new(1.0, 1.0, 2.0)).unwrap(), material: MaterialId(4), emission: Rgb::new(0.5, 0.25, 0.125) });
        let cp = |x: f32| glam::Vec4::new(x, 0.0, -5.0, 0.1);
        g.add_curve(Curve::new(vec![curve::Bezier::new(&[cp(0.0), cp(1.0)]).unwrap(), curve::Bezier::new(&[cp(1.0), cp(2.0)]).unwrap()], MaterialId(5)));
        let points = std::array::from_fn(|k| Vec3::new((k % 4) as f32 / 3.0, (k / 4) as f32 / 3.0, -10.0));
        g.add_patches(PatchSurfaces::new(vec![BezierPatch { points }], 2, MaterialId(6)));
        g
    }

    #[test]
    fn each_shape_is_one_object_of_consecutive_primitives() {
        let g = scene();
        assert_eq!(Primitives::len(&g), 6);
        assert_eq!(g.triangle_count(), 2);
        let prims: Vec<PrimRef> = (0..6).map(|i| g.prim(i)).collect();
        assert_eq!(prims, [PrimRef::Triangle { mesh: 0, tri: 0 }, PrimRef::Triangle { mesh: 0, tri: 1 }, PrimRef::Sphere(0), PrimRef::Curve { curve: 0, seg: 0 }, PrimRef::Curve { curve: 0, seg: 1 }, PrimRef::Patch { set: 0, patch: 0 }]);
        assert_eq!(g.objects(), [0..2, 2..3, 3..5, 5..6]);
        assert_eq!((0..6).map(|i| g.material(i).0).collect::<Vec<_>>(), [3, 3, 4, 5, 5, 6]);
        assert_eq!((0..6).map(|i| g.emission(i)).collect::<Vec<_>>(), [Rgb::new(1.0, 2.0, 3.0), Rgb::new(1.0, 2.0, 3.0), Rgb::new(0.5, 0.25, 0.125), Rgb::ZERO, Rgb::ZERO, Rgb::ZERO]);
        assert_eq!((0..6).map(|i| g.emission_texture(i)).collect::<Vec<_>>(), [Some(TextureId(7)), Some(TextureId(7)), None, None, None, None]);
        assert_eq!(g.triangle(1), Some([Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0), Vec3::new(2.0, 1.0, 0.0)]));
        assert_eq!((g.triangle(2), g.triangle(3), g.triangle(5)), (None, None, None));
    }

    #[test]
    fn bounds_per_primitive_clipped_and_in_total() {
        let g = scene();
        let b = |a: Aabb| (a.min, a.max);
        assert_eq!(b(g.bounds(1)), (Vec3::new(2.0, 0.0, 0.0), Vec3::new(3.0, 1.0, 0.0)));
        assert_eq!(b(g.bounds(2)), (Vec3::new(9.0, -1.0, 3.0), Vec3::new(11.0, 1.0, 7.0)));
        // The curve's boxes: the tube, padded by a little more than 10⁻³ of the radius.
        for (i, x0) in [(3, 0.0), (4, 1.0)] {
            let (lo, hi) = b(g.bounds(i));
            let (tube_lo, tube_hi) = (Vec3::new(x0 - 0.1, -0.1, -5.1), Vec3::new(x0 + 1.1, 0.1, -4.9));
            assert!(lo.cmple(tube_lo).all() && hi.cmpge(tube_hi).all() && (lo - tube_lo).max_element().abs() < 1e-3 && (hi - tube_hi).max_element() < 1e-3, "{lo} {hi}");
        }
        let (lo, hi) = b(g.total_bounds());
        assert!((lo - Vec3::new(-0.1, -1.0, -10.0)).abs().max_element() < 1e-3 && (hi - Vec3::new(11.0, 1.0, 7.0)).abs().max_element() < 1e-3, "{lo} {hi}");
        // Triangle 0 cut by x, y ≤ ½ keeps the square's corner (½, ½) inside... the clipped
        // polygon (0,0) (½,0) (½,½) (0,½); the sphere keeps its box ∩ the clip box.
        let clip = Aabb::new(Vec3::splat(-1.0), Vec3::new(0.5, 0.5, 4.0));
        assert_eq!(b(g.clipped_bounds(0, &clip)), (Vec3::ZERO, Vec3::new(0.5, 0.5, 0.0)));
        let clip = Aabb::new(Vec3::new(9.5, -5.0, -5.0), Vec3::new(20.0, 0.5, 4.0));
        assert_eq!(b(g.clipped_bounds(2, &clip)), (Vec3::new(9.5, -1.0, 3.0), Vec3::new(11.0, 0.5, 4.0)));
    }

    #[test]
    fn hits_and_surfaces_dispatch_to_the_shape() {
        let g = scene();
        // Down onto triangle 0 at (¼, ½): barycentrics (¼, ½), uv the same (its UVs are its xy).
        let ray = Ray::new(Vec3::new(0.25, 0.5, 1.0), -Vec3::Z);
        let h = g.intersect(0, &ray).unwrap();
        assert_eq!((h.t, h.u, h.v), (1.0, 0.25, 0.5));
        assert!(g.intersect(1, &ray).is_none());
        let s = g.surface(&ray, 0, h.t, h.u, h.v);
        assert_eq!((s.p, s.ng, s.uv, s.dpdu, s.dpdv), (Vec3::new(0.25, 0.5, 0.0), Vec3::Z, Vec2::new(0.25, 0.5), Vec3::X, Vec3::Y));
        assert_eq!(g.tangent(0, h.u, h.v, &s), (Vec3::X, 1.0));
        // Triangle 1, UVs mirrored: at barycentrics (¼, ½) the point is (2,0,0)·¼ + (3,0,0)·¼ +
        // (2,1,0)·½ = (2.25, 0.5, 0) and uv = (1,0)·¼ + (0,0)·¼ + (1,1)·½ = (0.75, 0.5).
        let ray = Ray::new(Vec3::new(2.25, 0.5, 1.0), -Vec3::Z);
        let h = g.intersect(1, &ray).unwrap();
        assert_eq!((h.t, h.u, h.v), (1.0, 0.25, 0.5));
        let s = g.surface(&ray, 1, h.t, h.u, h.v);
        assert_eq!((s.p, s.uv, s.dpdu, s.dpdv), (Vec3::new(2.25, 0.5, 0.0), Vec2::new(0.75, 0.5), -Vec3::X, Vec3::Y));
        assert_eq!(g.tangent(1, h.u, h.v, &s), (-Vec3::X, -1.0));
        assert_eq!(g.triangle_uv(0, 0.25, 0.5), Vec2::new(0.25, 0.5));
        assert_eq!(g.triangle_uv(1, 0.25, 0.5), Vec2::new(0.75, 0.5));
        assert_eq!(g.triangle_uv(2, 0.25, 0.5), Vec2::ZERO);
        // The sphere from above its top (10, 0, 7): t = 3, the normal +z.
        let ray = Ray::new(Vec3::new(10.0, 0.0, 10.0), -Vec3::Z);
        let h = g.intersect(2, &ray).unwrap();
        assert!((h.t - 3.0).abs() < 1e-6, "{}", h.t);
        let s = g.surface(&ray, 2, h.t, h.u, h.v);
        assert!((s.p - Vec3::new(10.0, 0.0, 7.0)).length() < 1e-5 && (s.ng - Vec3::Z).length() < 1e-6, "{} {}", s.p, s.ng);
        // At its north pole (10, 1, 5) ∂p/∂u vanishes: n × ∂p/∂u · ∂p/∂v = 0, a sign of +1.
        let ray = Ray::new(Vec3::new(10.0, 3.0, 5.0), -Vec3::Y);
        let h = g.intersect(2, &ray).unwrap();
        let s = g.surface(&ray, 2, h.t, h.u, h.v);
        assert_eq!(s.dpdu.length(), 0.0);
        assert_eq!(g.tangent(2, h.u, h.v, &s).1, 1.0);
        // The strand's second segment from above, through (1.5, 0): its top at z = -4.9.
        let ray = Ray::new(Vec3::new(1.5, 0.0, 0.0), -Vec3::Z);
        assert!(g.intersect(3, &ray).is_none());
        let h = g.intersect(4, &ray).unwrap();
        assert!((h.t - 4.9).abs() < 1e-3, "{}", h.t);
        let s = g.surface(&ray, 4, h.t, h.u, h.v);
        assert!((s.p - Vec3::new(1.5, 0.0, -4.9)).length() < 1e-3 && (s.ng - Vec3::Z).length() < 1e-2, "{} {}", s.p, s.ng);
        // The patch from (0.25, 0.5, 0) down: t = 10.
        let ray = Ray::new(Vec3::new(0.25, 0.5, 0.0), -Vec3::Z);
        let h = g.intersect(5, &ray).unwrap();
        assert!((h.t - 10.0).abs() < 1e-5, "{}", h.t);
        let s = g.surface(&ray, 5, h.t, h.u, h.v);
        assert!((s.p - Vec3::new(0.25, 0.5, -10.0)).length() < 1e-5 && s.ng.z.abs() > 0.999, "{} {}", s.p, s.ng);
    }

    #[test]
    fn object_normals_and_one_sided_emission() {
        let g = scene();
        // The inverse transpose of diag(1, 2, 1) takes (1, 1, 0) to (1, ½, 0); of diag(1, 1, 2),
        // (1, 0, 1) to (1, 0, ½). Curves are in world space: only normalised.
        assert!((g.object_normal_to_world(0, Vec3::new(1.0, 1.0, 0.0)) - Vec3::new(2.0, 1.0, 0.0) / 5f32.sqrt()).length() < 1e-6);
        assert!((g.object_normal_to_world(2, Vec3::new(1.0, 0.0, 1.0)) - Vec3::new(2.0, 0.0, 1.0) / 5f32.sqrt()).length() < 1e-6);
        assert!((g.object_normal_to_world(3, Vec3::new(3.0, 4.0, 0.0)) - Vec3::new(0.6, 0.8, 0.0)).length() < 1e-6);
        // Triangles emit along their winding normal +z only (not sideways), the sphere along
        // the normal it is given, the strand nothing.
        let geom = |ng: Vec3| SurfaceGeometry { p: Vec3::ZERO, p_error: Vec3::ZERO, ng, ns: ng, uv: Vec2::ZERO, dpdu: Vec3::X, dpdv: Vec3::Y };
        let le = Rgb::new(1.0, 2.0, 3.0);
        // (the geometry's normal is ignored for triangles: -z given, +z used)
        assert_eq!(g.emitted(0, &geom(-Vec3::Z), Vec3::new(0.0, 0.6, 0.8)), le);
        assert_eq!(g.emitted(0, &geom(-Vec3::Z), Vec3::new(0.0, 0.6, -0.8)), Rgb::ZERO);
        assert_eq!(g.emitted(0, &geom(-Vec3::Z), Vec3::X), Rgb::ZERO);
        assert_eq!(g.emitted(2, &geom(Vec3::X), Vec3::new(0.8, 0.6, 0.0)), Rgb::new(0.5, 0.25, 0.125));
        assert_eq!(g.emitted(2, &geom(Vec3::X), Vec3::new(-0.8, 0.6, 0.0)), Rgb::ZERO);
        assert_eq!(g.emitted(3, &geom(Vec3::Z), Vec3::Z), Rgb::ZERO);
    }
}
