//! The core's integration tests, one binary: each file is a module (`cargo test --test engine
//! lod::` runs one, `cargo test --test engine the_pyramid` one test). As thirty-one binaries, each
//! linked the whole engine. `fuzz_corpus.rs` stays a binary of its own: the fuzz bodies set the
//! process's host budget (`set_host_budget`), which the other tests must not share.
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
mod raster;
mod resample;
mod series;
mod spirv;
mod stacks;
mod truth;
mod units;
