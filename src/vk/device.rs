//! The logical device on the chosen physical device: one graphics+compute
//! queue, Vulkan 1.3's synchronization2 and dynamic rendering, and the
//! optional features dermis uses where the device has them (what each is for
//! is said beside it).

use anyhow::{Context as _, Result};
use ash::vk;

use super::error::Error;
use super::physical_device::PhysicalDevice;

/// The logical device with one queue of `physical`'s queue family (the
/// caller destroys it).
pub fn create(instance: &ash::Instance, physical: &PhysicalDevice) -> Result<ash::Device> {
    let has = |f: vk::Bool32| f == vk::TRUE;
    let features = &physical.features;
    let priorities = [1.0f32];
    let queue_info = [vk::DeviceQueueCreateInfo::default()
        .queue_family_index(physical.queue_family)
        .queue_priorities(&priorities)];
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
        .synchronization2(true)
        .dynamic_rendering(true);
    let base_features = vk::PhysicalDeviceFeatures::default()
        .pipeline_statistics_query(has(features.pipeline_statistics_query))
        .occlusion_query_precise(has(features.occlusion_query_precise))
        // Sum-of-Gaussians SSS writes RT1 unblended and blends RTF in one MRT pass.
        .independent_blend(has(features.independent_blend))
        // The fetch-counting build of the shaders counts with atomics.
        .fragment_stores_and_atomics(has(features.fragment_stores_and_atomics))
        // Texture-space diffusion clips its unwrapped meshes by the view
        // frustum with clip distances (thesis eq. 3.4).
        .shader_clip_distance(has(features.shader_clip_distance))
        .sampler_anisotropy(false);
    let mut features2 = vk::PhysicalDeviceFeatures2::default().features(base_features);
    let device_info = vk::DeviceCreateInfo::default()
        .queue_create_infos(&queue_info)
        .push_next(&mut features2)
        .push_next(&mut f13);
    unsafe { instance.create_device(physical.raw, &device_info, None) }
        .map_err(Error::from)
        .with_context(|| format!("creating the logical device on '{}'", physical.facts.name))
}
