//! The renderer: shapes, textures, materials, lights, camera, integrators and the render
//! loop. It reads no files (that is `raylab-loader`'s job) and knows acceleration
//! structures only through `raylab-accel`'s trait.

pub mod bsdf;
pub mod camera;
pub mod filter;
pub mod film;
pub mod integrator;
pub mod light;
pub mod material;
pub mod memory_guard;
pub mod render;
pub mod sampler;
pub mod scene;
pub mod settings;
pub mod shading;
pub mod shape;
pub mod texture;

pub use camera::Camera;
pub use integrator::IntegratorKind;
pub use light::Light;
pub use material::{Material, MaterialId, TexColor, TextureId};
pub use film::{Crop, Film, FilmError, FilmHeader};
pub use render::{render, render_tile, render_until, Control, RenderOutput, Stop};
pub use sampler::{PixelSampler, SamplerKind};
pub use scene::{Background, Scene, SurfaceHit};
pub use settings::{Overrides, RenderSettings};
pub use shape::{Geometry, Sphere, TriangleMesh};
pub use texture::Texture;
