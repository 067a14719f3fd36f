//! The window tests, one binary: the real window under Xvfb, driven with
//! xdotool (each test starts its own X server on its own display number,
//! so they run side by side). Needs `Xvfb` and `xdotool`.
#![allow(clippy::unwrap_used)] // in tests a panic is the failure report

#[path = "../common/mod.rs"]
mod common;

mod dialogs;
mod e2e;
mod extrude;
mod ground;
mod objects;
mod panel;
mod record;
mod recovery;
mod select;
mod stray;
mod timeline;
