//! A simple automatic UV atlas for meshes without UVs: triangles in pairs, each pair in its
//! own square cell of a grid over the texture, each triangle mapped to a right isosceles
//! triangle of the cell. Texel density ignores triangle area: plain, but it needs no
//! parameterisation and every triangle gets the same number of texels.

use raylab_core::Vec2;
use raylab_render::TriangleMesh;

/// Texels kept free between a cell's border and its triangles.
pub const GUTTER: f32 = 2.0;
/// Extra inset of the two hypotenuses of a cell, so the triangles of a pair lie
/// `DIAGONAL_GAP · √2` texels apart (more than twice [`super::COVERAGE_RADIUS`]).
const DIAGONAL_GAP: f32 = 3.0;

/// `mesh` with one vertex per triangle corner (the layout an OBJ with per-corner `vt`
/// loads as), atlas UVs for a `size`² texture, and its normals carried over (compute them
/// first: the atlas needs smooth shading normals to bake against).
pub fn with_atlas_uvs(mesh: &TriangleMesh, size: u32) -> Result<TriangleMesh, String> {
    let cells = mesh.len().div_ceil(2).max(1);
    let per_row = (cells as f64).sqrt().ceil() as usize;
    let cell = (size as usize / per_row) as f32;
    let legs = cell - 2.0 * GUTTER - DIAGONAL_GAP;
    if legs < 2.0 {
        return Err(format!("a {size}² texture is too small for {} triangles: cells of {cell} texels", mesh.len()));
    }
    let mut out = TriangleMesh { name: mesh.name.clone(), material: mesh.material, ..Default::default() };
    for (k, tri) in mesh.indices.iter().enumerate() {
        let c = k / 2;
        let origin = Vec2::new((c % per_row) as f32, (c / per_row) as f32) * cell;
        let corners = if k % 2 == 0 {
            let a = origin + Vec2::splat(GUTTER);
            [a, a + Vec2::new(legs, 0.0), a + Vec2::new(0.0, legs)]
        } else {
            let a = origin + Vec2::splat(cell - GUTTER);
            [a, a - Vec2::new(legs, 0.0), a - Vec2::new(0.0, legs)]
        };
        let base = out.positions.len() as u32;
        for (corner, &i) in corners.iter().zip(tri) {
            out.positions.push(mesh.positions[i as usize]);
            if !mesh.normals.is_empty() {
                out.normals.push(mesh.normals[i as usize]);
            }
            out.uvs.push(*corner / size as f32);
        }
        out.indices.push([base, base + 1, base + 2]);
    }
    Ok(out)
}
