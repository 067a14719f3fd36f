//! The engine's integration tests, one binary (each test binary links
//! wgpu, naga and egui: one link instead of one per file): loading and
//! saving, editing and replay scripts, the CPU tracers, meshes, hostile
//! input, exports, .ovx files, the fuzz corpus and the bench's smoke run,
//! each in the module named for it.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

#[path = "../common/mod.rs"]
mod common;

mod animation;
mod bench_cli;
mod budgets;
mod cluster;
mod export;
mod export_scene;
mod fuzz_corpus;
mod ground;
mod hostile_input;
mod instanced;
mod mesh_import;
mod octree_props;
mod ovx;
mod palette_files;
mod replay_cli;
mod trace_cpu;
mod trace_exact;
mod turns;
mod turns_traced;
mod vox_info;
mod vox_robust;
mod vox_roundtrip;
mod vox_scene;
