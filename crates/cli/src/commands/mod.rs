pub mod bench;
pub mod compare;
pub mod converge;
pub mod gen;
pub mod inspect;
pub mod render;
pub mod scene_args;
pub mod trace;
