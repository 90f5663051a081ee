//! The host side of the theses: scenes (`scenes/*.toml`, OBJ via tobj,
//! procedural reconstructions), cameras and flights, the CPU-built
//! acceleration structures, images, and the native reference ray caster.

pub mod camera;
pub mod image;
pub mod kdtree;
pub mod path;
pub mod procedural;
pub mod raycast;
pub mod rt_kernels;
pub mod scene;
pub mod scene_file;
