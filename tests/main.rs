//! The engine's tests, compiled into the library's test build (`mod tests` in src/lib.rs), so they
//! reach the internals from inside the crate: `cargo test --release --lib -- tests::lod::` runs one
//! file, `cargo test --release --lib the_pyramid` one test. `fuzz_corpus.rs` is a binary of its own:
//! the fuzz bodies set the process's host budget (`set_host_budget`), which the other tests must
//! not share.
// The tests set options one field at a time, as a program outside the crate must (the option
// structs are non_exhaustive): clippy, inside the crate, would have struct literals.
#![allow(clippy::field_reassign_with_default)]
use crate as vs;
mod aa;
mod bands;
mod bisect;
mod bricked;
mod bricks;
mod clip;
mod common;
mod depth;
mod device;
mod distributed;
mod gpu;
mod hostile;
mod iso;
mod labels;
mod large;
mod layout;
mod loaders;
mod lod;
mod modes;
mod motion;
mod order;
mod orient;
mod pick;
mod plan;
mod present;
mod probes;
mod raster;
mod reliability;
mod resample;
mod series;
mod spirv;
mod stacks;
mod truth;
mod units;
