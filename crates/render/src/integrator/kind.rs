//! The integrators by name: `[render] integrator` and `--integrator`.

use std::fmt;
use std::str::FromStr;

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
    /// Shading normals as colours (`0.5 · (n + 1)`), for checking geometry.
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

impl IntegratorKind {
    pub const ALL: &'static [IntegratorKind] = &[
        IntegratorKind::Whitted,
        IntegratorKind::Direct,
        IntegratorKind::Path,
        IntegratorKind::Normals,
        IntegratorKind::Albedo,
        IntegratorKind::Depth,
        IntegratorKind::Heatmap,
        IntegratorKind::HeatmapTests,
    ];

    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Whitted => "whitted",
            IntegratorKind::Direct => "direct",
            IntegratorKind::Path => "path",
            IntegratorKind::Normals => "normals",
            IntegratorKind::Albedo => "albedo",
            IntegratorKind::Depth => "depth",
            IntegratorKind::Heatmap => "heatmap",
            IntegratorKind::HeatmapTests => "heatmap-tests",
        }
    }

    /// Whether the output holds raw costs to be colourised by [`super::heatmap::colorize`].
    pub fn is_heatmap(self) -> bool {
        matches!(self, IntegratorKind::Heatmap | IntegratorKind::HeatmapTests)
    }

    pub fn names() -> String {
        Self::ALL.iter().map(|k| k.name()).collect::<Vec<_>>().join(", ")
    }
}

impl fmt::Display for IntegratorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for IntegratorKind {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.iter().copied().find(|k| k.name() == s).ok_or_else(|| format!("unknown integrator `{s}` (valid: {})", Self::names()))
    }
}
