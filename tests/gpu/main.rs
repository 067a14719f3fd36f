//! The GPU tests, one binary: the real shaders on the adapter there is
//! (lavapipe in CI) against the CPU references — the preview tracer and
//! the path tracer.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

#[path = "../common/mod.rs"]
mod common;

mod animation;
mod denoise;
mod ground;
mod path_trace;
mod trace_gpu;
mod turns;
