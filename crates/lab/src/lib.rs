//! The laboratory: ray sets generated once per scene and shared by every structure,
//! measured tracing checked against an oracle, the binary ray-file format, and reports.

pub mod bench;
pub mod compare;
pub mod bake;
pub mod converge;
pub mod heatmap;
pub mod merge;
pub mod rayfile;
pub mod report;
pub mod robustness;
pub mod rays;
pub mod sweep;
pub mod trace;

pub use rays::{RayKind, RaySet};
pub use trace::{trace, TraceResult};
