//! With the `oidn` feature, the binaries find Open Image Denoise's shared
//! library where they were linked against it (OIDN_DIR/lib), without
//! LD_LIBRARY_PATH. The default build does nothing here.

fn main() {
    println!("cargo:rerun-if-env-changed=OIDN_DIR");
    if std::env::var_os("CARGO_FEATURE_OIDN").is_none() {
        return;
    }
    if let Some(dir) = std::env::var_os("OIDN_DIR") {
        let lib = std::path::Path::new(&dir).join("lib");
        println!("cargo:rustc-link-arg=-Wl,-rpath,{}", lib.display());
    }
}
