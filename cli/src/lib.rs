//! The user's commands around the voxsplat renderer: the `voxsplat` binary's scene flags, file
//! opening, `render`, `view`, `bench` and the rest. The studies that measure the renderer are the
//! `voxsplat-lab` binary (the `lab/` package), which builds on this library; the renderer itself is
//! the `voxsplat` library, which needs neither.
pub mod devices;
pub mod measure;
pub use devices::{describe_device, device_toml};
pub mod open;
pub mod parse;
pub mod progress;
pub mod pyramid;
pub mod render;
pub mod scene_args;
pub mod series;
pub mod session;
pub mod stdout;
pub mod suite;
pub mod uneven;
pub mod view;
pub mod volumes;
