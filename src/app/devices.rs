//! `dermis devices`: the Vulkan devices, by index, name and kind.

use anyhow::Result;

use super::cli::DevicesArgs;
use crate::vk::context::{Context, ContextDesc, DeviceChoice};

pub fn run(a: &DevicesArgs) -> Result<()> {
    let ctx = Context::new(&ContextDesc {
        device: DeviceChoice::Auto,
        validate: a.validate,
        ..Default::default()
    })?;
    let devices = ctx.devices();
    for (i, name, kind) in ctx.finish_with(devices)? {
        println!("{i}: {name} ({kind})");
    }
    Ok(())
}
