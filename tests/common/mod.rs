//! Shared set-up of the GPU tests: lavapipe, validation with synchronization
//! validation always on (any message fails the test), and the shared test asset.
#![allow(dead_code)]

use std::path::PathBuf;

use dermis::vk::context::{Context, ContextDesc, DeviceChoice};

/// The test device: lavapipe unless DERMIS_TEST_DEVICE names another.
pub fn ctx() -> Context {
    let name = std::env::var("DERMIS_TEST_DEVICE").unwrap_or_else(|_| "llvmpipe".into());
    Context::new(&ContextDesc { device: DeviceChoice::Name(name), validate: true, count_fetches: false })
        .expect("creating a validated Vulkan context on lavapipe (install mesa-vulkan-drivers and vulkan-validationlayers)")
}

/// The Lee Perry-Smith head beside the project (`../shared/assets`). Under CI it
/// must exist; elsewhere a missing asset skips the test that needs it.
pub fn lps_path() -> Option<PathBuf> {
    let candidates = [
        std::env::var("DERMIS_ASSETS").ok().map(PathBuf::from),
        Some(PathBuf::from(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../shared/assets/lee-perry-smith/LeePerrySmith.glb"
        ))),
    ];
    for c in candidates.into_iter().flatten() {
        let p = if c.is_dir() {
            c.join("LeePerrySmith.glb")
        } else {
            c
        };
        if p.exists() {
            return Some(p);
        }
    }
    if std::env::var_os("CI").is_some() {
        panic!("the Lee Perry-Smith head is missing: CI needs ../shared/assets/lee-perry-smith beside the project");
    }
    None
}

/// A registered method by CLI name.
pub fn m(name: &str) -> &'static dermis::method::MethodEntry {
    dermis::method::lookup(name).expect("a registered method")
}

/// The test device with every pipeline built from the fetch-counting build of
/// its shaders (see `dermis::render::counting`).
pub fn counting_ctx() -> Context {
    let name = std::env::var("DERMIS_TEST_DEVICE").unwrap_or_else(|_| "llvmpipe".into());
    Context::new(&ContextDesc {
        device: DeviceChoice::Name(name),
        validate: true,
        count_fetches: true,
    })
    .expect("creating a validated, fetch-counting Vulkan context on lavapipe")
}
