//! Geometric robustness, measured (issue 12): for every structure and primitive kind, at
//! scene scales from 1e-10 to 1e12,
//! - **leaks**: rays from inside a closed shape (an icosphere aimed exactly at its vertices
//!   and at points of its edges; a sphere; a capsule-shaped curve) that escape it;
//! - **self-intersections**: secondary rays spawned from a hit as the renderer spawns them
//!   (`offset_ray_origin` on the shape's own error bound) that find their origin surface
//!   again: any hit of a ray leaving a convex shape outwards, or, for one leaving it
//!   inwards, a hit on its origin primitive nearer than 1e-3 of the shape's size.
//!
//! Every shape is convex, so both counts are exact: the right answer is 0 in every cell.

use raylab_accel::{Accel, AccelKind, AnyAccel, BuildOptions, Counters};
use raylab_core::sampling::{cosine_hemisphere, uniform_sphere};
use raylab_core::{offset_ray_origin, Frame, Pcg32, Ray, Transform, Vec3, Vec4};
use raylab_render::shape::curve::{Bezier, Curve};
use raylab_render::shape::{BezierPatch, Geometry, PatchSurfaces, Sphere, TriangleMesh};
use raylab_render::MaterialId;
use rayon::prelude::*;
use serde::Serialize;

/// Scene scales of the table: the shapes have this size (radius, half-length). Every
/// decade near the unit, every second one out to the 1e-10 and 1e12.
pub const SCALES: [f32; 17] = [1e-10, 1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 1e-1, 1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e8, 1e10, 1e12];

/// The primitive kinds of the table.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PrimKind {
    Triangles,
    Spheres,
    Curves,
    Patches,
}

impl PrimKind {
    pub const ALL: [PrimKind; 4] = [PrimKind::Triangles, PrimKind::Spheres, PrimKind::Curves, PrimKind::Patches];

    pub fn name(self) -> &'static str {
        match self {
            PrimKind::Triangles => "triangles",
            PrimKind::Spheres => "spheres",
            PrimKind::Curves => "curves",
            PrimKind::Patches => "patches",
        }
    }

    /// The kind named `name` (as [`PrimKind::name`] spells it).
    pub fn from_name(name: &str) -> Option<PrimKind> {
        PrimKind::ALL.into_iter().find(|p| p.name() == name)
    }

    /// A single patch is not closed: it has no inside to leak from.
    pub fn has_leak_test(self) -> bool {
        self != PrimKind::Patches
    }
}

/// One cell of the table: a structure, a primitive kind and a scale.
#[derive(Clone, Debug, Serialize)]
pub struct Cell {
    pub accel: &'static str,
    pub prims: PrimKind,
    pub scale: f32,
    /// Rays shot from inside (0 for patches, which have no inside) and how many escaped.
    pub leak_rays: u64,
    pub leaks: u64,
    /// Secondary rays spawned and how many re-hit their origin surface.
    pub spawn_rays: u64,
    pub self_intersections: u64,
}

/// The whole measurement.
#[derive(Clone, Debug, Serialize)]
pub struct Robustness {
    /// Rays of each kind (leak, spawned) per cell.
    pub rays_per_cell: u64,
    pub cells: Vec<Cell>,
}

impl Robustness {
    pub fn total_leaks(&self) -> u64 {
        self.cells.iter().map(|c| c.leaks).sum()
    }

    pub fn total_self_intersections(&self) -> u64 {
        self.cells.iter().map(|c| c.self_intersections).sum()
    }
}

/// Measures every structure of `kinds` on every primitive kind of `prims` at every scale of
/// `scales`, with `rays` leak rays and `rays` spawned rays per cell (cells in parallel).
pub fn measure(kinds: &[AccelKind], prims: &[PrimKind], scales: &[f32], rays: u64) -> Robustness {
    let jobs: Vec<(AccelKind, PrimKind, f32)> = kinds.iter().flat_map(|&k| prims.iter().flat_map(move |&p| scales.iter().map(move |&s| (k, p, s)))).collect();
    let cells = jobs.into_par_iter().map(|(kind, prims, scale)| measure_cell(kind, prims, scale, rays)).collect();
    Robustness { rays_per_cell: rays, cells }
}

/// One cell: the shape of kind `prims` at size `scale`, a structure `kind` over it.
pub fn measure_cell(kind: AccelKind, prims: PrimKind, scale: f32, rays: u64) -> Cell {
    let shape = Shape::new(prims, scale);
    let accel = AnyAccel::build(kind, &shape.geometry, &BuildOptions::default());
    let mut c = Counters::default();
    // Seeded per cell, so a cell's counts do not depend on which others run.
    let mut rng = Pcg32::new(scale.to_bits() as u64, prims as u64 * 64 + kind as u64);
    let (mut leak_rays, mut leaks) = (0, 0);
    if prims.has_leak_test() {
        for k in 0..rays {
            let ray = shape.ray_from_inside(&mut rng, k);
            leak_rays += 1;
            leaks += u64::from(accel.intersect(&shape.geometry, &ray, &mut c).is_none());
        }
    }
    let (mut spawn_rays, mut self_intersections) = (0, 0);
    for k in 0..rays {
        // A primary ray onto the shape, from outside, then one ray leaving the hit outwards
        // and one inwards (halves of `rays` each).
        let primary = shape.ray_onto(&mut rng);
        let Some(hit) = accel.intersect(&shape.geometry, &primary, &mut c) else { continue };
        let s = shape.geometry.surface(&primary, hit.prim, hit.t, hit.u, hit.v);
        let outward = if s.ng.dot(primary.dir) < 0.0 { s.ng } else { -s.ng };
        let side = if k % 2 == 0 { outward } else { -outward };
        let dir = Frame::from_z(side).to_world(cosine_hemisphere(rng.next_vec2()));
        let origin = offset_ray_origin(s.p, s.p_error, s.ng, dir);
        let spawned = Ray::new(origin, dir);
        spawn_rays += 1;
        let again = accel.intersect(&shape.geometry, &spawned, &mut c);
        // The side is the direction's own: a sample on the hemisphere's rim can round to the
        // other side of the tangent plane (cos θ = -6e-8), and then the ray is spawned, and
        // travels, inwards on a grazing chord.
        let leaving = dir.dot(outward) > 0.0;
        let bad = match again {
            None => false,
            // Leaving a convex shape outwards, nothing is there to hit.
            Some(_) if leaving => true,
            // Inwards, the far side (or, next to an edge, the neighbouring face at a grazing
            // angle) is a genuine hit; the origin primitive found again close by is not.
            Some(h) => h.prim == hit.prim && (h.t * dir).length() < 1e-3 * scale,
        };
        self_intersections += u64::from(bad);
    }
    Cell { accel: kind.name(), prims, scale, leak_rays, leaks, spawn_rays, self_intersections }
}

/// A closed convex shape (or a dome patch) of size `scale` centred at the origin.
struct Shape {
    geometry: Geometry,
    kind: PrimKind,
    scale: f32,
    /// Mesh vertices and edges, for rays aimed exactly at them.
    vertices: Vec<Vec3>,
    edges: Vec<[Vec3; 2]>,
}

impl Shape {
    fn new(kind: PrimKind, scale: f32) -> Self {
        let mut geometry = Geometry::default();
        let (mut vertices, mut edges) = (Vec::new(), Vec::new());
        match kind {
            PrimKind::Triangles => {
                let (positions, indices) = icosphere(2);
                let positions: Vec<Vec3> = positions.iter().map(|&p| p * scale).collect();
                for t in &indices {
                    edges.extend([0, 1, 2].map(|k| [positions[t[k] as usize], positions[t[(k + 1) % 3] as usize]]));
                }
                vertices = positions.clone();
                geometry.add_mesh(TriangleMesh { name: "icosphere".into(), positions, indices, ..TriangleMesh::default() });
            }
            PrimKind::Spheres => {
                geometry.add_sphere(Sphere { center: Vec3::ZERO, radius: scale, to_world: Transform::IDENTITY, material: MaterialId(0), emission: Vec3::ZERO });
            }
            PrimKind::Curves => {
                // A straight strand of two cubic segments along x, radius a fifth of its
                // half-length: a capsule (round tube with round ends).
                let r = 0.2 * scale;
                let seg = |x0: f32| {
                    let cp: Vec<Vec4> = (0..4).map(|k| Vec4::new((x0 + k as f32 / 3.0) * scale, 0.0, 0.0, r)).collect();
                    Bezier::new(&cp).expect("four control points")
                };
                geometry.add_curve(Curve::new(vec![seg(-1.0), seg(0.0)], MaterialId(0)));
            }
            PrimKind::Patches => {
                geometry.add_patches(PatchSurfaces::new(vec![dome(DOME, scale)], 4, MaterialId(0)));
            }
        }
        Self { geometry, kind, scale, vertices, edges }
    }

    /// A point strictly inside the shape, well away from its surface.
    fn inside(&self, rng: &mut Pcg32) -> Vec3 {
        let u = uniform_sphere(rng.next_vec2()) * rng.next_f32();
        match self.kind {
            // Within half the radius: the icosphere's inscribed radius is above 0.9.
            PrimKind::Triangles | PrimKind::Spheres => 0.5 * self.scale * u,
            // On the strand's core, within half its radius.
            _ => Vec3::new(0.8 * (2.0 * rng.next_f32() - 1.0), 0.0, 0.0) * self.scale + 0.1 * self.scale * u,
        }
    }

    /// Ray `k` from inside: for the mesh, alternately aimed exactly at a vertex and at a
    /// point of an edge (the two places where a non-watertight kernel lets rays through);
    /// for the others, in a random direction.
    fn ray_from_inside(&self, rng: &mut Pcg32, k: u64) -> Ray {
        let origin = self.inside(rng);
        let target = match self.kind {
            PrimKind::Triangles if k.is_multiple_of(2) => self.vertices[rng.below(self.vertices.len() as u32) as usize],
            PrimKind::Triangles => {
                let [a, b] = self.edges[rng.below(self.edges.len() as u32) as usize];
                a + (b - a) * rng.next_f32()
            }
            // A direction, not a target a unit away: at scale 1e8 a unit is below the
            // origin's ulp and `target - origin` rounds to zero.
            _ => return Ray::new(origin, uniform_sphere(rng.next_vec2())),
        };
        Ray::new(origin, (target - origin).normalize())
    }

    /// A ray from outside aimed at the shape (from above, for the dome).
    fn ray_onto(&self, rng: &mut Pcg32) -> Ray {
        let (origin, target) = match self.kind {
            PrimKind::Patches => {
                let origin = Vec3::new(0.0, 0.0, 3.0 * self.scale) + self.scale * uniform_sphere(rng.next_vec2());
                (origin, Vec3::new(1.2 * rng.next_f32() - 0.6, 1.2 * rng.next_f32() - 0.6, 0.0) * self.scale)
            }
            _ => (3.0 * self.scale * uniform_sphere(rng.next_vec2()), self.inside(rng)),
        };
        Ray::new(origin, (target - origin).normalize())
    }
}

/// The dome's weights `(c, k)`: see [`dome`].
const DOME: (f32, f32) = (0.4, 0.8);

/// A dome over `[-scale, scale]²`: the bicubic patch whose control points have height
/// `(c·[i inner]·[j inner] + k·([i inner] + [j inner]))·scale` (inner: the middle two of a
/// row or column), so with `a(u) = B₁(u) + B₂(u) = 3u(1 - u)` its height is
/// `c·a(u)·a(v) + k·(a(u) + a(v))` while `x = 2u - 1` and `y = 2v - 1` are affine.
/// Its Hessian in `(u, v)` has diagonal `-6(c·a + k)` and off-diagonal
/// `c·(3 - 6u)(3 - 6v)`, so its determinant is at least `36k² - 81c²` (at the corners,
/// where `a = 0` and `|3 - 6u| = 3`): with `k > 1.5c` the height is strictly concave and
/// the whole patch lies below each of its tangent planes, which is what makes a ray
/// leaving it outwards a certain miss. (The table's first dome, `c = 1`, `k = 0.3`, was a
/// saddle near its corners: a ray leaving at 0.8° above the tangent plane at
/// `(u, v) = (0.22, 0.77)` truly met the patch again near the corner `(0, 1)`, the one
/// "self-intersection" of the 10⁶-ray table.)
fn dome((c, k): (f32, f32), scale: f32) -> BezierPatch {
    let mut points = [Vec3::ZERO; 16];
    for j in 0..4 {
        for i in 0..4 {
            let (x, y) = (i as f32 / 1.5 - 1.0, j as f32 / 1.5 - 1.0);
            let inner = |m: usize| if m == 1 || m == 2 { 1.0 } else { 0.0 };
            points[j * 4 + i] = Vec3::new(x, y, c * inner(i) * inner(j) + k * (inner(i) + inner(j))) * scale;
        }
    }
    BezierPatch { points }
}

/// A unit icosphere: the icosahedron subdivided `levels` times, vertices on the unit sphere,
/// edges shared exactly between neighbouring triangles (so the mesh is closed).
fn icosphere(levels: u32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let g = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<Vec3> = [
        (-1.0, g, 0.0), (1.0, g, 0.0), (-1.0, -g, 0.0), (1.0, -g, 0.0),
        (0.0, -1.0, g), (0.0, 1.0, g), (0.0, -1.0, -g), (0.0, 1.0, -g),
        (g, 0.0, -1.0), (g, 0.0, 1.0), (-g, 0.0, -1.0), (-g, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
        [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut midpoints = std::collections::HashMap::new();
        let mut mid = |a: u32, b: u32, positions: &mut Vec<Vec3>| {
            *midpoints.entry((a.min(b), a.max(b))).or_insert_with(|| {
                positions.push((positions[a as usize] + positions[b as usize]).normalize());
                positions.len() as u32 - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b, &mut positions), mid(b, c, &mut positions), mid(c, a, &mut positions));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    (positions, faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_is_closed() {
        let (positions, faces) = icosphere(2);
        // Euler: V - E + F = 2, with every edge shared by exactly two faces.
        assert_eq!((positions.len(), faces.len()), (162, 320));
        let mut edges = std::collections::HashMap::new();
        for f in &faces {
            for k in 0..3 {
                *edges.entry((f[k].min(f[(k + 1) % 3]), f[k].max(f[(k + 1) % 3]))).or_insert(0) += 1;
            }
        }
        assert_eq!(edges.len(), 480);
        assert!(edges.values().all(|&n| n == 2));
    }

    /// Every point of the dome lies on or below the tangent plane at every other (sampled
    /// on a grid that includes the corners): a ray leaving it outwards cannot meet it
    /// again, so any such hit the table counts is a defect. The first dome failed this, by up
    /// to 0.21 of its size.
    #[test]
    fn dome_lies_below_its_tangent_planes() {
        let patch = dome(DOME, 1.0);
        let grid: Vec<(f32, f32)> = (0..=20).flat_map(|i| (0..=20).map(move |j| (i as f32 / 20.0, j as f32 / 20.0))).collect();
        for &(u, v) in &grid {
            let (p, n) = (patch.point(u, v), patch.normal(u, v));
            assert!(n.z > 0.0, "({u}, {v}): normal {n} points down");
            for &(s, t) in &grid {
                let above = (patch.point(s, t) - p).dot(n);
                assert!(above <= 1e-6, "({s}, {t}) is {above} above the tangent plane at ({u}, {v})");
            }
        }
    }

    /// The one self-intersection of the 10⁶-ray table (`sbvh`, patches, 1e12, ray 417,512 of
    /// its cell, printed bit for bit) was the first dome's saddle, not rounding: every
    /// structure, the oracle included, finds the same hit near the corner `(0, 1)`, 0.83 of
    /// the dome's size away, and that point lies 0.0116 of the size above the tangent plane
    /// at the ray's origin.
    #[test]
    fn the_sbvh_self_intersection_was_a_true_hit_on_a_saddle() {
        let scale = 1e12;
        let old = dome((1.0, 0.3), scale);
        let mut geometry = Geometry::default();
        geometry.add_patches(PatchSurfaces::new(vec![old], 4, MaterialId(0)));
        let bits = |b: [u32; 3]| Vec3::from_array(b.map(f32::from_bits));
        let ray = Ray::new(bits([3540253281, 1392089289, 1393049007]), bits([3204478060, 1057493185, 3207509064]));
        // Spawned from (u, v) = (0.2166, 0.7680), 0.8° above the tangent plane there.
        let (u0, v0) = (2.1658032e-1f32, 7.680016e-1f32);
        let n = old.normal(u0, v0);
        assert!((0.0138..0.0140).contains(&ray.dir.dot(n)), "{}", ray.dir.dot(n));
        for &kind in AccelKind::ALL {
            let accel = AnyAccel::build(kind, &geometry, &BuildOptions::default());
            let h = accel.intersect(&geometry, &ray, &mut Counters::default()).unwrap_or_else(|| panic!("{kind:?}: no hit"));
            assert!((h.t / scale - 0.831518).abs() < 1e-5 && (h.u - 0.00796).abs() < 1e-4 && (h.v - 0.98898).abs() < 1e-4, "{kind:?}: {h:?}");
        }
        // The hit, relative to the tangent plane at the origin, in double precision.
        let (p0, q) = (old.point(u0, v0).as_dvec3() / 1e12, old.point(0.0079613, 0.9889807).as_dvec3() / 1e12);
        let above = (q - p0).dot(n.as_dvec3());
        assert!((0.0115..0.0117).contains(&above), "{above}");
    }

    /// The table's target, on a few cells of every kind: no leaks, no self-intersections.
    /// (Curves re-hit the interior halves of their joint and end spheres from inside, about
    /// 1 % of inward rays, until the intersector kept only the union's boundary; triangles
    /// at 1e12 had single-precision normals that overflowed to +y, 29 % of spawned rays.)
    #[test]
    fn no_leaks_and_no_self_intersections() {
        let r = measure(&[AccelKind::None, AccelKind::Bvh, AccelKind::Grid, AccelKind::Bvh8], &PrimKind::ALL, &[1e-10, 1e-4, 1.0, 1e5, 1e12], 400);
        for c in &r.cells {
            assert!(c.spawn_rays > 300, "{c:?}: too few primary rays hit the shape");
            assert_eq!(c.leak_rays, if c.prims.has_leak_test() { 400 } else { 0 }, "{c:?}");
            assert_eq!(c.leaks, 0, "{c:?}");
            assert_eq!(c.self_intersections, 0, "{c:?}");
        }
    }
}
