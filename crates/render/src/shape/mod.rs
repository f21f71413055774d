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

    fn objects(&self) -> Vec<Range<u32>> {
        self.objects.clone()
    }
}
