//! Sets `cfg(shared_data)` when `../../shared/data` (the real scans, meshes
//! and volumes beside the clone) is there when the package is built: the
//! tests that read it are then compiled as tests, and otherwise as ignored
//! tests with the reason, instead of passing without testing anything.
//! The check is made once per build of the package (after adding or
//! removing the folder, `cargo clean -p data-gen`).

fn main() {
    println!("cargo::rustc-check-cfg=cfg(shared_data)");
    println!("cargo::rerun-if-changed=build.rs");
    if std::path::Path::new("../../shared/data").is_dir() {
        println!("cargo::rustc-cfg=shared_data");
    }
}
