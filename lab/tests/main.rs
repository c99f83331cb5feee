//! The lab's integration tests, one binary: each file is a module. They share the core's helpers
//! (`tests/common`).
#[path = "../../tests/common/mod.rs"]
mod common;
use voxsplat as vs;
mod soak;
mod stability;
