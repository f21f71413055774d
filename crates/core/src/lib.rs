//! Math and infrastructure shared by every raylab crate, built on `glam`.
//!
//! Nothing here knows about shapes, materials or files.

pub mod bounds;
pub mod clip;
pub mod color;
pub mod distribution;
pub mod edges;
pub mod frame;
pub mod intersect;
#[macro_use]
pub mod named;
pub mod offset;
pub mod ray;
pub mod rng;
pub mod sampling;
pub mod transform;

// For `named_enum!`'s `ValueEnum` impls, so that crates using it need no clap dependency.
#[doc(hidden)]
pub use clap as __clap;

pub use bounds::{Aabb, BoundingSphere};
pub use distribution::{Distribution1D, Distribution2D};
pub use frame::Frame;
pub use glam::{Vec2, Vec3, Vec4};
pub use offset::{gamma, offset_ray_origin};
pub use ray::Ray;
pub use rng::Pcg32;
pub use transform::Transform;

/// Linear RGB radiance or reflectance, one `f32` per channel.
pub type Rgb = Vec3;
