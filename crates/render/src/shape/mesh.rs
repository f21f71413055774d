use glam::Vec4;
use raylab_core::{intersect, Aabb, Frame, Ray, Rgb, Transform, Vec2, Vec3};

use super::SurfaceGeometry;
use crate::material::{MaterialId, TextureId};

/// A triangle mesh in world space (transforms are applied when it is loaded), with
/// optional per-vertex normals and texture coordinates sharing the position indices.
#[derive(Clone, Debug, Default)]
pub struct TriangleMesh {
    pub name: String,
    pub positions: Vec<Vec3>,
    /// Empty, or one unit normal per position.
    pub normals: Vec<Vec3>,
    /// Empty, or one coordinate per position.
    pub uvs: Vec<Vec2>,
    /// Empty, or one per position for tangent-space normal maps: `xyz` the unit tangent along
    /// +u, `w = ±1` the bitangent sign, `b = w · (n × t)` (MikkTSpace's convention).
    pub tangents: Vec<Vec4>,
    /// The transform the mesh was loaded with (its positions are already in world space), for
    /// object-space normal maps.
    pub object_to_world: Transform,
    pub indices: Vec<[u32; 3]>,
    pub material: MaterialId,
    /// Radiance emitted on the side of the winding normal `(p1 - p0) × (p2 - p0)`, zero for
    /// surfaces that do not emit (pbrt's one-sided diffuse area light).
    pub emission: Rgb,
    /// A texture scaling `emission` by the surface's UVs (the third report's window light).
    pub emission_texture: Option<TextureId>,
}

impl TriangleMesh {
    pub fn len(&self) -> usize {
        self.indices.len()
    }

    pub fn is_empty(&self) -> bool {
        self.indices.is_empty()
    }

    #[inline]
    pub fn vertices(&self, tri: u32) -> [Vec3; 3] {
        let [a, b, c] = self.indices[tri as usize];
        [self.positions[a as usize], self.positions[b as usize], self.positions[c as usize]]
    }

    /// Unit normal of the triangle's winding order, `(p1 - p0) × (p2 - p0)`: the side an
    /// emitting triangle lights.
    pub fn winding_normal(&self, tri: u32) -> Vec3 {
        let [a, b, c] = self.vertices(tri);
        raylab_core::edges::unit_cross(b - a, c - a).unwrap_or(Vec3::Y)
    }

    pub fn area(&self, tri: u32) -> f32 {
        let [a, b, c] = self.vertices(tri);
        0.5 * raylab_core::edges::cross_length(b - a, c - a)
    }

    pub fn triangle_bounds(&self, tri: u32) -> Aabb {
        Aabb::from_points(self.vertices(tri))
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.indices.iter().flatten().map(|&i| self.positions[i as usize]))
    }

    #[inline]
    pub fn intersect(&self, tri: u32, ray: &Ray) -> Option<(f32, f32, f32)> {
        let [a, b, c] = self.vertices(tri);
        intersect::triangle(ray, a, b, c)
    }

    /// Surface data at barycentrics `(b1, b2)`. The point comes from the barycentrics, not
    /// from `o + t·d`, which keeps it on the plane. Without vertex UVs, `uv = (b1, b2)`.
    pub fn surface(&self, tri: u32, b1: f32, b2: f32) -> SurfaceGeometry {
        let idx = self.indices[tri as usize].map(|i| i as usize);
        let [p0, p1, p2] = idx.map(|i| self.positions[i]);
        let b0 = 1.0 - b1 - b2;
        let p = b0 * p0 + b1 * p1 + b2 * p2;
        // Error of the barycentric interpolation (pbrt-v4 §6.8.6).
        let p_error = raylab_core::gamma(7) * ((b0 * p0).abs() + (b1 * p1).abs() + (b2 * p2).abs());
        let e1 = p1 - p0;
        let e2 = p2 - p0;
        let mut ng = raylab_core::edges::unit_cross(e1, e2).unwrap_or(Vec3::Y);
        let (uv, (dpdu, dpdv)) = if self.uvs.is_empty() {
            (Vec2::new(b1, b2), (e1, e2))
        } else {
            let [t0, t1, t2] = idx.map(|i| self.uvs[i]);
            (b0 * t0 + b1 * t1 + b2 * t2, uv_derivatives(e1, e2, t1 - t0, t2 - t0).unwrap_or((e1, e2)))
        };
        let ns = if self.normals.is_empty() {
            ng
        } else {
            let [n0, n1, n2] = idx.map(|i| self.normals[i]);
            let n = (b0 * n0 + b1 * n1 + b2 * n2).try_normalize().unwrap_or(ng);
            // Orient the geometric normal like the interpolated one (pbrt does the same), so
            // that "outside" agrees between the two whatever the winding order.
            if n.dot(ng) < 0.0 {
                ng = -ng;
            }
            n
        };
        SurfaceGeometry { p, p_error, ng, ns, uv, dpdu, dpdv }
    }

    /// Angle-weighted vertex normals (Thürmer & Wüthrich 1998) for `smooth = true` on meshes
    /// without normals. Vertices at the same position are welded first, so meshes split
    /// along UV seams (the teapot's patches) shade without a visible crease.
    ///
    /// Each face corner averages only the faces around its vertex whose normals are within
    /// `crease_degrees` of its own face's (three.js's `toCreasedNormals`, Blender's auto
    /// smooth), so edges sharper than that stay sharp; 180 averages every face. A vertex
    /// whose corners end up with different normals is split, one copy per normal.
    pub fn compute_smooth_normals(&mut self, crease_degrees: f32) {
        let mut group_of = std::collections::HashMap::new();
        let groups: Vec<usize> = self.positions.iter().map(|p| {
            let next = group_of.len();
            *group_of.entry(p.to_array().map(|c| (c + 0.0).to_bits())).or_insert(next)
        }).collect();
        // Unit face normals (none for zero-area faces), and per welded vertex the faces
        // around it with their normals weighted by the corner's angle.
        let mut faces = Vec::with_capacity(self.indices.len());
        let mut around = vec![Vec::new(); group_of.len()];
        for (f, &tri) in self.indices.iter().enumerate() {
            let p = tri.map(|i| self.positions[i as usize]);
            let face = raylab_core::edges::unit_cross(p[1] - p[0], p[2] - p[0]);
            faces.push(face);
            let Some(face) = face else { continue };
            for k in 0..3 {
                let angle = raylab_core::edges::angle_between(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
                if angle.is_finite() {
                    around[groups[tri[k] as usize]].push((f, angle * face));
                }
            }
        }
        // A little slack, so that coplanar faces join even at 0° and all do at 180°.
        let min_cos = crease_degrees.to_radians().cos() - 1e-6;
        let normal_of = |group: usize, own: Option<Vec3>| -> Vec3 {
            let joined = around[group].iter().filter(|(f, _)| own.is_none_or(|n| faces[*f].is_some_and(|m| m.dot(n) >= min_cos)));
            joined.map(|(_, weighted)| *weighted).sum::<Vec3>().try_normalize().unwrap_or(Vec3::Y)
        };
        let mut normals: Vec<Option<Vec3>> = vec![None; self.positions.len()];
        let mut copies = std::collections::HashMap::new();
        #[allow(clippy::needless_range_loop)] // the loop rewrites `self.indices[f]` and grows `self.positions`
        for f in 0..self.indices.len() {
            for k in 0..3 {
                let v = self.indices[f][k] as usize;
                let n = normal_of(groups[v], faces[f]);
                match normals[v] {
                    None => normals[v] = Some(n),
                    Some(m) if m == n => {}
                    Some(_) => {
                        self.indices[f][k] = *copies.entry((v, n.to_array().map(f32::to_bits))).or_insert_with(|| {
                            self.positions.push(self.positions[v]);
                            if !self.uvs.is_empty() {
                                self.uvs.push(self.uvs[v]);
                            }
                            normals.push(Some(n));
                            normals.len() as u32 - 1
                        });
                    }
                }
            }
        }
        // Vertices no face uses take the average of everything at their position.
        self.normals = normals.iter().enumerate().map(|(v, n)| n.unwrap_or_else(|| normal_of(groups[v], None))).collect();
    }

    /// Per-vertex tangents for tangent-space normal maps (needs `uvs`). Each triangle's unit
    /// ∂p/∂u and ∂p/∂v are summed at its corners weighted by the corner angle, as MikkTSpace
    /// does; the tangent is then made orthogonal to the vertex normal (Gram–Schmidt) and
    /// `w` records whether ∂p/∂v lies along `n × t` (+1) or against it (-1, mirrored UVs).
    /// Unlike MikkTSpace, a vertex shared by faces of opposite UV orientation is not split:
    /// the angle-weighted majority decides its sign.
    pub fn compute_tangents(&mut self) {
        assert_eq!(self.uvs.len(), self.positions.len(), "tangents need one UV per vertex");
        let n = self.positions.len();
        let (mut su, mut sv, mut sn) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]);
        for &tri in &self.indices {
            let p = tri.map(|i| self.positions[i as usize]);
            let t = tri.map(|i| self.uvs[i as usize]);
            let Some((dpdu, dpdv)) = uv_derivatives(p[1] - p[0], p[2] - p[0], t[1] - t[0], t[2] - t[0]) else { continue };
            let (Some(tu), Some(tv), Some(face)) = (dpdu.try_normalize(), dpdv.try_normalize(), raylab_core::edges::unit_cross(p[1] - p[0], p[2] - p[0])) else { continue };
            for k in 0..3 {
                let angle = raylab_core::edges::angle_between(p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
                if angle.is_finite() {
                    let i = tri[k] as usize;
                    su[i] += angle * tu;
                    sv[i] += angle * tv;
                    sn[i] += angle * face;
                }
            }
        }
        self.tangents = (0..n)
            .map(|i| {
                let normal = self.normals.get(i).copied().or_else(|| sn[i].try_normalize()).unwrap_or(Vec3::Z);
                let t = (su[i] - normal * normal.dot(su[i])).try_normalize().unwrap_or_else(|| Frame::from_z(normal).x);
                let w = if normal.cross(t).dot(sv[i]) < 0.0 { -1.0 } else { 1.0 };
                t.extend(w)
            })
            .collect();
    }

    /// The tangent and bitangent sign at barycentrics `(b1, b2)`, interpolated from the
    /// per-vertex tangents; `None` when the mesh has none.
    pub fn interpolated_tangent(&self, tri: u32, b1: f32, b2: f32) -> Option<(Vec3, f32)> {
        if self.tangents.is_empty() {
            return None;
        }
        let [t0, t1, t2] = self.indices[tri as usize].map(|i| self.tangents[i as usize]);
        let t = (1.0 - b1 - b2) * t0 + b1 * t1 + b2 * t2;
        Some((t.truncate(), if t.w < 0.0 { -1.0 } else { 1.0 }))
    }
}

/// ∂p/∂u and ∂p/∂v of a triangle with edges `e1 = p1 - p0`, `e2 = p2 - p0` and UV edges
/// `d1`, `d2` (pbrt-v4 §6.5.3); `None` when the UVs are degenerate.
fn uv_derivatives(e1: Vec3, e2: Vec3, d1: Vec2, d2: Vec2) -> Option<(Vec3, Vec3)> {
    let det = d1.x * d2.y - d1.y * d2.x;
    if det.abs() <= 1e-12 {
        return None;
    }
    Some(((d2.y * e1 - d1.y * e2) / det, (d1.x * e2 - d2.x * e1) / det))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One triangle p0 = (-1, 1, 0), p1 = p0 + e1, p2 = p0 + e2 with e1 = (4, 0, 0) and
    /// e2 = (0, 2, -2): e1 × e2 = (0, 8, 8), so the winding normal is (0, 1, 1)/√2 and the
    /// area ½·√128 = 4√2.
    fn tri(uvs: Vec<Vec2>, normals: Vec<Vec3>) -> TriangleMesh {
        TriangleMesh { positions: vec![Vec3::new(-1.0, 1.0, 0.0), Vec3::new(3.0, 1.0, 0.0), Vec3::new(-1.0, 3.0, -2.0)], uvs, normals, indices: vec![[0, 1, 2]], ..Default::default() }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-6
    }

    #[test]
    fn one_triangle_by_hand() {
        let m = tri(vec![], vec![]);
        assert_eq!((m.len(), m.is_empty()), (1, false));
        assert!(TriangleMesh::default().is_empty());
        assert!(close(m.winding_normal(0), Vec3::new(0.0, 1.0, 1.0) / 2f32.sqrt()));
        assert!((m.area(0) - 4.0 * 2f32.sqrt()).abs() < 1e-6, "{}", m.area(0));
        let b = m.triangle_bounds(0);
        assert_eq!((b.min, b.max), (Vec3::new(-1.0, 1.0, -2.0), Vec3::new(3.0, 3.0, 0.0)));
        // A position no triangle uses is not in the mesh's bounds.
        let mut with_unused = tri(vec![], vec![]);
        with_unused.positions.push(Vec3::splat(100.0));
        let b = with_unused.bounds();
        assert_eq!((b.min, b.max), (Vec3::new(-1.0, 1.0, -2.0), Vec3::new(3.0, 3.0, 0.0)));
        // A ray down y onto (0, 2, -1) = p0 + ¼e1 + ½e2: barycentrics (¼, ½) at t = 1.
        assert_eq!(m.intersect(0, &Ray::new(Vec3::new(0.0, 3.0, -1.0), -Vec3::Y)), Some((1.0, 0.25, 0.5)));
        // A degenerate triangle (three points on a line) has no normal: +y stands in.
        let line = TriangleMesh { positions: vec![Vec3::ZERO, Vec3::X, 2.0 * Vec3::X], indices: vec![[0, 1, 2]], ..Default::default() };
        assert_eq!((line.winding_normal(0), line.area(0)), (Vec3::Y, 0.0));
    }

    #[test]
    fn surface_without_uvs_or_normals() {
        let m = tri(vec![], vec![]);
        let g = m.surface(0, 0.25, 0.5);
        // ¼p0 + ¼p1 + ½p2 = (-0.25 + 0.75 - 0.5, 0.25 + 0.25 + 1.5, -1)
        assert_eq!(g.p, Vec3::new(0.0, 2.0, -1.0));
        // pbrt-v4's bound γ₇(|b0·p0| + |b1·p1| + |b2·p2|), not γ₇|p|: x sums 0.25 + 0.75 + 0.5.
        let g7 = 7.0 * f64::from(f32::EPSILON) * 0.5;
        let expected = [g7 * 1.5, g7 * 2.0, g7 * 1.0];
        for (k, e) in expected.into_iter().enumerate() {
            assert!((f64::from(g.p_error[k]) - e).abs() <= 1e-3 * e, "{k}: {}", g.p_error);
        }
        let n = Vec3::new(0.0, 1.0, 1.0) / 2f32.sqrt();
        assert!(close(g.ng, n) && g.ns == g.ng, "{} {}", g.ng, g.ns);
        assert_eq!((g.uv, g.dpdu, g.dpdv), (Vec2::new(0.25, 0.5), Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 2.0, -2.0)));
    }

    /// UVs t0 = (½, ¼), t1 = (1, ½), t2 = (¼, 1): the UV edges d1 = (½, ¼), d2 = (-¼, ¾). The
    /// point is linear in uv, so ∂p/∂u·d.x + ∂p/∂v·d.y must give back each edge e (e1 for d1,
    /// e2 for d2): that pins both derivatives, whatever formula computes them.
    #[test]
    fn surface_with_uvs_has_the_derivatives_that_map_uv_edges_to_edges() {
        let m = tri(vec![Vec2::new(0.5, 0.25), Vec2::new(1.0, 0.5), Vec2::new(0.25, 1.0)], vec![]);
        let g = m.surface(0, 0.25, 0.5);
        // ¼t0 + ¼t1 + ½t2
        assert!((g.uv - Vec2::new(0.5, 0.6875)).length() < 1e-7, "{}", g.uv);
        let (e1, e2) = (Vec3::new(4.0, 0.0, 0.0), Vec3::new(0.0, 2.0, -2.0));
        assert!(close(0.5 * g.dpdu + 0.25 * g.dpdv, e1), "{} {}", g.dpdu, g.dpdv);
        assert!(close(-0.25 * g.dpdu + 0.75 * g.dpdv, e2), "{} {}", g.dpdu, g.dpdv);
        // All three UVs equal: no derivatives from them, the edges stand in.
        let flat = tri(vec![Vec2::ONE; 3], vec![]);
        let g = flat.surface(0, 0.25, 0.5);
        assert_eq!((g.uv, g.dpdu, g.dpdv), (Vec2::ONE, e1, e2));
    }

    /// Vertex normals interpolated by the barycentrics (¼, ¼, ½ for b = (¼, ½)), and the
    /// geometric normal (0, 1, 1)/√2 turned to their side.
    #[test]
    fn surface_interpolates_vertex_normals_and_turns_ng_to_their_side() {
        let ng = Vec3::new(0.0, 1.0, 1.0) / 2f32.sqrt();
        // ¼ŷ + ¼(-ẑ) + ½x̂ = (½, ¼, -¼): along ng, 0; ng stays.
        let g = tri(vec![], vec![Vec3::Y, -Vec3::Z, Vec3::X]).surface(0, 0.25, 0.5);
        assert!(close(g.ns, Vec3::new(0.5, 0.25, -0.25) / 0.375f32.sqrt()) && close(g.ng, ng), "{} {}", g.ns, g.ng);
        // ¼(-ŷ) + ¼(-ẑ) + ½x̂ = (½, -¼, -¼): against ng, which turns.
        let g = tri(vec![], vec![-Vec3::Y, -Vec3::Z, Vec3::X]).surface(0, 0.25, 0.5);
        assert!(close(g.ns, Vec3::new(0.5, -0.25, -0.25) / 0.375f32.sqrt()) && close(g.ng, -ng), "{} {}", g.ns, g.ng);
        // ŷ + ½(-ŷ) + ... : (0, ¼, 0) + (0, -¼, 0)... normals summing to zero fall back to ng.
        let g = tri(vec![], vec![Vec3::Y, -Vec3::Y, Vec3::X]).surface(0, 0.5, 0.0);
        assert!(close(g.ns, ng) && close(g.ng, ng), "{} {}", g.ns, g.ng);
    }

    #[test]
    fn interpolated_tangents_and_their_sign() {
        let mut m = tri(vec![], vec![]);
        assert_eq!(m.interpolated_tangent(0, 0.25, 0.5), None);
        m.tangents = vec![Vec4::new(1.0, 0.0, 0.0, 1.0), Vec4::new(0.0, 1.0, 0.0, 1.0), Vec4::new(0.0, 0.0, 1.0, -1.0)];
        // ¼t0 + ¼t1 + ½t2: w = ¼ + ¼ - ½ = 0 counts as +1; at (¼, 0.6), w = -0.2 < 0.
        assert_eq!(m.interpolated_tangent(0, 0.25, 0.5), Some((Vec3::new(0.25, 0.25, 0.5), 1.0)));
        let (t, w) = m.interpolated_tangent(0, 0.25, 0.625).unwrap();
        assert!(close(t, Vec3::new(0.125, 0.25, 0.625)) && w == -1.0, "{t} {w}");
    }

    /// Two faces in z = 0 around the vertex O = (0, 0, 0), their UVs chosen so that ∂p/∂u is
    /// x̂ on A = O (1,0,0) (0,1,0) (uv = (x, y): ∂p/∂v = ŷ), and ŷ on B = O (0,-1,0) (1,-1,0)
    /// (uv = (y, -x): ∂p/∂v = -x̂). A's corner at O is 90°, B's 45°, so O's tangent is
    /// (π/2·x̂ + π/4·ŷ) normalised, (2, 1, 0)/√5; its sign +1 (ẑ × t along π/2·ŷ - π/4·x̂).
    /// A's other corners take A's frame alone (x̂, +1); B's (ŷ, +1). The whole is then moved
    /// by (0.5, -2, 3) (no vertex at the origin), which changes none of that.
    #[test]
    fn tangents_are_angle_weighted_and_orthogonal_to_the_normal() {
        let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, -Vec3::Y, Vec3::new(1.0, -1.0, 0.0)];
        // (UVs moved by (½, ¼), which changes no derivative: no UV at 0 either)
        let uvs = positions.iter().map(|p| Vec2::new(0.5, 0.25) + if p.y < 0.0 { Vec2::new(p.y, -p.x) } else { Vec2::new(p.x, p.y) }).collect();
        let positions = positions.iter().map(|p| *p + Vec3::new(0.5, -2.0, 3.0)).collect();
        let mut m = TriangleMesh { positions, uvs, indices: vec![[0, 1, 2], [0, 3, 4]], ..Default::default() };
        m.compute_tangents();
        let t = |m: &TriangleMesh, i: usize| (m.tangents[i].truncate(), m.tangents[i].w);
        assert!(close(t(&m, 0).0, Vec3::new(2.0, 1.0, 0.0) / 5f32.sqrt()) && t(&m, 0).1 == 1.0, "{:?}", t(&m, 0));
        for (i, expected) in [(1, Vec3::X), (2, Vec3::X), (3, Vec3::Y), (4, Vec3::Y)] {
            assert!(close(t(&m, i).0, expected) && t(&m, i).1 == 1.0, "{i}: {:?}", t(&m, i));
        }
        // With vertex normals leaning to (0.6, 0, 0.8), Gram–Schmidt: x̂ - 0.6·n = (0.64, 0,
        // -0.48), normalised (0.8, 0, -0.6) at A's corner (1, 0, 0).
        m.normals = vec![Vec3::new(0.6, 0.0, 0.8); 5];
        m.compute_tangents();
        assert!(close(t(&m, 1).0, Vec3::new(0.8, 0.0, -0.6)) && t(&m, 1).1 == 1.0, "{:?}", t(&m, 1));
        // UVs mirrored in u, in the plane y = 1: (1,1,1) (2,1,1) (1,1,2) with UVs (1,1) (0,1)
        // (1,2), so ∂p/∂u = -x̂ and ∂p/∂v = ẑ; the face's normal x̂ × ẑ = -ŷ, and -ŷ × -x̂ = -ẑ
        // is against ∂p/∂v: sign -1.
        let mut a = TriangleMesh { positions: vec![Vec3::ONE, Vec3::new(2.0, 1.0, 1.0), Vec3::new(1.0, 1.0, 2.0)], uvs: vec![Vec2::ONE, Vec2::Y, Vec2::new(1.0, 2.0)], indices: vec![[0, 1, 2]], ..Default::default() };
        a.compute_tangents();
        for v in &a.tangents {
            assert!(close(v.truncate(), -Vec3::X) && v.w == -1.0, "{v}");
        }
        // UVs all equal give no derivatives: a unit tangent across the face's normal, sign +1.
        a.uvs = vec![Vec2::ONE; 3];
        a.compute_tangents();
        for v in &a.tangents {
            assert!((v.truncate().length() - 1.0).abs() < 1e-6 && v.y.abs() < 1e-6 && v.w == 1.0, "{v}");
        }
    }

    #[test]
    fn smooth_normals_weld_split_vertices_and_weight_by_angle() {
        // A roof: two faces meeting at the ridge x = 0, the ridge vertices duplicated.
        let mut mesh = TriangleMesh {
            positions: vec![
                Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1.0), Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 1.0),
            ],
            indices: vec![[0, 2, 1], [3, 5, 4]],
            ..Default::default()
        };
        mesh.compute_smooth_normals(180.0);
        // Both copies of each ridge vertex get the average of the two faces: straight up.
        for i in [0, 1, 3, 5] {
            assert!((mesh.normals[i] - Vec3::Y).length() < 1e-6, "{i}: {}", mesh.normals[i]);
        }
        // The eaves belong to one face each.
        let left = Vec3::new(-1.0, 1.0, 0.0).normalize();
        assert!((mesh.normals[2] - left).length() < 1e-6, "{}", mesh.normals[2]);
    }

    /// -0 and +0 are one position: the roof's ridge copies at x = -0 and x = +0 weld, and
    /// get the two faces' average, straight up.
    #[test]
    fn smooth_normals_weld_minus_zero_with_zero() {
        let mut mesh = TriangleMesh {
            positions: vec![
                Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1.0), Vec3::new(-1.0, 0.0, 0.0),
                Vec3::new(-0.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(-0.0, 1.0, 1.0),
            ],
            indices: vec![[0, 2, 1], [3, 5, 4]],
            ..Default::default()
        };
        mesh.compute_smooth_normals(180.0);
        for i in [0, 1, 3, 5] {
            assert!((mesh.normals[i] - Vec3::Y).length() < 1e-6, "{i}: {}", mesh.normals[i]);
        }
    }

    /// Coplanar faces join even under a crease angle of 0 (the slack of 10⁻⁶ in the cosine),
    /// whatever the rounding of their normals: a fan of four triangles around (0.3, 0.7, 0)
    /// in z = 0 keeps one normal, +z, per vertex, and no vertex is split; a copy of a vertex
    /// that no triangle uses takes the normal at its position.
    #[test]
    fn coplanar_faces_join_at_a_crease_angle_of_zero() {
        let mut mesh = TriangleMesh {
            positions: vec![Vec3::new(0.3, 0.7, 0.0), Vec3::ZERO, Vec3::new(1.1, 0.0, 0.0), Vec3::new(1.1, 1.3, 0.0), Vec3::new(0.0, 1.3, 0.0), Vec3::new(1.1, 1.3, 0.0)],
            indices: vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 1]],
            uvs: vec![Vec2::ZERO; 6],
            ..Default::default()
        };
        mesh.compute_smooth_normals(0.0);
        assert_eq!((mesh.positions.len(), mesh.uvs.len()), (6, 6));
        for (i, n) in mesh.normals.iter().enumerate() {
            assert!((*n - Vec3::Z).length() < 1e-6, "{i}: {n}");
        }
    }

    #[test]
    fn roof_ridge_is_creased_only_beyond_the_crease_angle() {
        // The roof's faces are 90° apart.
        let roof = || TriangleMesh {
            positions: vec![Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 1.0), Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)],
            indices: vec![[0, 2, 1], [0, 1, 3]],
            ..Default::default()
        };
        let mut smooth = roof();
        smooth.compute_smooth_normals(91.0);
        assert_eq!(smooth.positions.len(), 4);
        assert!((smooth.normals[0] - Vec3::Y).length() < 1e-6);
        let mut creased = roof();
        creased.compute_smooth_normals(89.0);
        // Each ridge vertex is split in two, one copy per face.
        assert_eq!(creased.positions.len(), 6);
        for tri in 0..2 {
            let face = creased.winding_normal(tri);
            for k in creased.indices[tri as usize] {
                assert!((creased.normals[k as usize] - face).length() < 1e-6, "{tri}: {}", creased.normals[k as usize]);
            }
        }
    }

    /// A closed cube over 8 shared vertices, its triangles wound outwards.
    fn cube() -> TriangleMesh {
        let positions = (0..8).map(|i| Vec3::new((i & 1) as f32, (i >> 1 & 1) as f32, (i >> 2 & 1) as f32) * 2.0 - Vec3::ONE).collect();
        let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let indices = quads.iter().flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]).collect();
        TriangleMesh { positions, indices, ..Default::default() }
    }

    #[test]
    fn cube_keeps_flat_faces_under_a_crease_angle_and_averages_corners_without() {
        let mut flat = cube();
        for tri in 0..flat.len() as u32 {
            let [a, b, c] = flat.vertices(tri);
            assert!(flat.winding_normal(tri).dot(a + b + c) > 0.0, "triangle {tri} winds inwards");
        }
        flat.compute_smooth_normals(30.0);
        assert_eq!(flat.positions.len(), 24, "each corner split into one vertex per face");
        for tri in 0..flat.len() as u32 {
            let face = flat.winding_normal(tri);
            for k in flat.indices[tri as usize] {
                assert!((flat.normals[k as usize] - face).length() < 1e-6, "{tri}: {}", flat.normals[k as usize]);
            }
        }
        let mut round = cube();
        round.compute_smooth_normals(180.0);
        assert_eq!(round.positions.len(), 8);
        for (p, n) in round.positions.iter().zip(&round.normals) {
            // Each face meets the corner at 90° in all: the diagonal.
            assert!((*n - p.normalize()).length() < 1e-6, "{p}: {n}");
        }
    }
}
