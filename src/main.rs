#[cfg(not(target_arch = "wasm32"))]
use std::process::ExitCode;

#[cfg(not(target_arch = "wasm32"))]
use clap::Parser;

mod app;
mod cli;
#[cfg(not(target_arch = "wasm32"))]
mod commands;

/// The browser's entry: the page (web/index.html) calls it once the
/// module is loaded.
#[cfg(target_arch = "wasm32")]
fn main() {
    app::start();
}

#[cfg(not(target_arch = "wasm32"))]
fn main() -> ExitCode {
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = cli::Cli::parse();
    if cli.command.is_some() {
        quiet_device_select();
    }
    match commands::run(cli) {
        Ok(code) => code,
        // A closed pipe (`octovox info x.vox | head -1`) is a normal end.
        Err(err) if is_broken_pipe(&err) => ExitCode::SUCCESS,
        Err(err) => {
            eprintln!("octovox: error: {}", error_chain(&err));
            ExitCode::FAILURE
        }
    }
}

#[cfg(not(target_arch = "wasm32"))]
/// Mesa's implicit Vulkan layer `VK_LAYER_MESA_device_select` connects to
/// Wayland to rank the GPUs, and where `XDG_RUNTIME_DIR` is not set (a
/// shell over SSH, a cron job) libwayland prints "error: XDG_RUNTIME_DIR is
/// invalid…" twice, though nothing failed. A command without a window
/// needs no ranking (wgpu picks the adapter), so it turns the layer off the
/// way the layer documents (`NODEVICE_SELECT=1`), unless the user set it.
fn quiet_device_select() {
    let runtime_dir = std::env::var_os("XDG_RUNTIME_DIR").filter(|d| std::path::Path::new(d).is_dir());
    // A user's own choice of GPU goes through the layer: leave it on then.
    let chosen =
        ["NODEVICE_SELECT", "MESA_VK_DEVICE_SELECT", "DRI_PRIME"].iter().any(|v| std::env::var_os(v).is_some());
    if runtime_dir.is_some() || chosen {
        return;
    }
    log::debug!("XDG_RUNTIME_DIR is not set: Mesa's device-select layer is turned off (NODEVICE_SELECT=1)");
    #[expect(unsafe_code, reason = "std::env::set_var is unsafe in Rust 2024; see SAFETY")]
    // SAFETY: called first thing in `main`, before any thread is spawned
    // (no other thread can read or write the environment meanwhile).
    unsafe {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
}

#[cfg(not(target_arch = "wasm32"))]
fn is_broken_pipe(err: &anyhow::Error) -> bool {
    err.chain()
        .any(|cause| cause.downcast_ref::<std::io::Error>().is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe))
}

#[cfg(not(target_arch = "wasm32"))]
/// The error and its causes, skipping a cause that the text already quotes
/// (our error types print their source in their own message).
fn error_chain(err: &anyhow::Error) -> String {
    let mut text = err.to_string();
    for cause in err.chain().skip(1) {
        let cause = cause.to_string();
        if !text.contains(&cause) {
            text = format!("{text}: {cause}");
        }
    }
    text
}
