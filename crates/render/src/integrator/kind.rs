//! The integrators by name: `[render] integrator` and `--integrator`.

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// Recursive ray tracing (Whitted 1980): Phong with point lights, shadows, mirror
    /// reflection and Fresnel-weighted refraction.
    Whitted,
    /// Direct lighting: one bounce of light, MIS between light and BSDF samples
    /// (specular chains are followed to the first non-specular surface).
    Direct,
    /// Path tracing: next-event estimation, MIS, Russian roulette.
    Path,
    /// World-space shading normals facing the camera, as colours (`0.5 · (n + 1)`; grey
    /// where nothing is hit), for checking geometry.
    Normals,
    /// The first hit's diffuse colour (an AOV for denoisers and checks).
    Albedo,
    /// Distance to the first hit along the camera ray (0 where nothing is hit).
    Depth,
    /// Acceleration-structure nodes visited by each camera ray, in false colour.
    Heatmap,
    /// Ray–primitive tests made by each camera ray, in false colour.
    HeatmapTests,
}

raylab_core::named_enum!(IntegratorKind, "integrator", {
    Whitted => "whitted",
    Direct => "direct",
    Path => "path",
    Normals => "normals",
    Albedo => "albedo",
    Depth => "depth",
    Heatmap => "heatmap",
    HeatmapTests => "heatmap-tests",
});

impl IntegratorKind {
    /// Whether the output holds raw costs to be colourised by [`super::heatmap::colorize`].
    pub fn is_heatmap(self) -> bool {
        matches!(self, IntegratorKind::Heatmap | IntegratorKind::HeatmapTests)
    }

}

