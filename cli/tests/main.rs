//! The CLI's integration tests, one binary: each file is a module (`cargo test --test commands
//! family::` runs one). They share the core's helpers (`tests/common`) and `cmd`.
mod cli;
mod cmd;
#[path = "../../tests/common/mod.rs"]
mod common;
use voxsplat as vs;
mod coverage;
mod dicom;
mod distributed;
mod family;
mod foreign;
mod fuzz_corpus;
mod hostile;
mod layers;
mod orientation;
mod peer;
mod phantom;
mod properties;
mod readme;
mod sample_types;
mod series;
mod view;
mod viewer;
mod zarr;
