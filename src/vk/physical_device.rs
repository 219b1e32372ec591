//! Choosing the physical device (`--device`) and the facts about it that the
//! renderer and the report need. Queries only: nothing here is created, so
//! nothing needs destroying.

use std::fmt;

use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;

/// How to choose the physical device.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum DeviceChoice {
    /// First discrete GPU, else the first device.
    #[default]
    Auto,
    /// Index in enumeration order.
    Index(usize),
    /// Case-insensitive substring of the device name.
    Name(String),
}

/// Why a text names no device choice (see [`DeviceChoice`]'s `FromStr`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeviceChoiceError(String);

impl fmt::Display for DeviceChoiceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for DeviceChoiceError {}

impl std::str::FromStr for DeviceChoice {
    type Err = DeviceChoiceError;

    /// `auto` (any case) is [`DeviceChoice::Auto`]; digits are an index; any
    /// other text is a part of the device's name. Spaces around it are
    /// dropped. Empty text is an error (as a name part it would match every
    /// device), and so is an index too large to be one.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        let lists = "`dermis devices` lists them";
        if t.is_empty() {
            return Err(DeviceChoiceError(format!(
                "no device named: give a device's index or a part of its name ({lists})"
            )));
        }
        if t.eq_ignore_ascii_case("auto") {
            return Ok(DeviceChoice::Auto);
        }
        if t.bytes().all(|b| b.is_ascii_digit()) {
            return t.parse().map(DeviceChoice::Index).map_err(|_| {
                DeviceChoiceError(format!("device index {t} is out of range ({lists})"))
            });
        }
        Ok(DeviceChoice::Name(t.to_string()))
    }
}

/// The text [`DeviceChoice`]'s `FromStr` reads back as the same choice.
impl fmt::Display for DeviceChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DeviceChoice::Auto => f.write_str("auto"),
            DeviceChoice::Index(i) => write!(f, "{i}"),
            DeviceChoice::Name(n) => f.write_str(n),
        }
    }
}

/// Facts about the chosen device that the renderer and the report need.
#[derive(Clone, Debug)]
pub struct DeviceFacts {
    pub name: String,
    pub driver: String,
    pub api_version: String,
    pub device_type: String,
    pub timestamp_period_ns: f64,
    pub timestamp_valid_bits: u32,
    pub pipeline_statistics: bool,
    pub occlusion_query_precise: bool,
    pub independent_blend: bool,
    pub max_image_dimension_2d: u32,
    pub max_storage_buffer_range: u32,
    pub min_storage_buffer_offset_alignment: u64,
    pub sub_texel_precision_bits: u32,
    /// Size of the largest device-local memory heap, bytes.
    pub device_local_bytes: u64,
    /// Whether fragment shaders may write storage buffers (enabled when present:
    /// the fetch-counting build of the shaders needs it).
    pub fragment_stores_and_atomics: bool,
    /// Whether shaders may write clip distances (enabled when present:
    /// texture-space diffusion clips its unwrapped meshes with them).
    pub shader_clip_distance: bool,
    /// Samples per pixel a render target may have (`--msaa`): the counts in
    /// the colour, depth and stencil framebuffer sample-count limits alike,
    /// ascending (1 always).
    pub framebuffer_sample_counts: Vec<u32>,
    /// The depth and stencil resolve modes of VK_KHR_depth_stencil_resolve
    /// (core in 1.2; SAMPLE_ZERO is required of both).
    pub depth_resolve_modes: vk::ResolveModeFlags,
    pub stencil_resolve_modes: vk::ResolveModeFlags,
}

/// The chosen physical device: what creating the logical device needs, and
/// its facts.
pub struct PhysicalDevice {
    pub raw: vk::PhysicalDevice,
    /// The first queue family with graphics and compute (dermis uses one queue).
    pub queue_family: u32,
    /// Its features (the logical device enables those dermis uses, when present).
    pub features: vk::PhysicalDeviceFeatures,
    pub facts: DeviceFacts,
}

impl PhysicalDevice {
    /// The device `choice` names, if it has Vulkan 1.3 and a graphics+compute
    /// queue.
    pub fn choose(instance: &ash::Instance, choice: &DeviceChoice) -> Result<Self> {
        let raw = pick(instance, choice)?;
        let props = unsafe { instance.get_physical_device_properties(raw) };
        let name = device_name(&props);
        if props.api_version < vk::API_VERSION_1_3 {
            bail!(
                "device '{name}' supports Vulkan {}.{} but dermis needs 1.3 (synchronization2 and dynamic rendering)",
                vk::api_version_major(props.api_version),
                vk::api_version_minor(props.api_version)
            );
        }
        let mut driver_props = vk::PhysicalDeviceDriverProperties::default();
        let mut resolve_props = vk::PhysicalDeviceDepthStencilResolveProperties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default()
            .push_next(&mut driver_props)
            .push_next(&mut resolve_props);
        unsafe { instance.get_physical_device_properties2(raw, &mut props2) };
        let driver = format!(
            "{} {}",
            driver_props
                .driver_name_as_c_str()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            driver_props
                .driver_info_as_c_str()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default()
        );

        let families = unsafe { instance.get_physical_device_queue_family_properties(raw) };
        let Some((queue_family, family)) = families.iter().enumerate().find(|(_, f)| {
            f.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
        }) else {
            bail!("device '{name}' has no graphics+compute queue");
        };
        let features = unsafe { instance.get_physical_device_features(raw) };
        let limits = &props.limits;
        let facts = DeviceFacts {
            name,
            driver: driver.trim().to_string(),
            api_version: format!(
                "{}.{}.{}",
                vk::api_version_major(props.api_version),
                vk::api_version_minor(props.api_version),
                vk::api_version_patch(props.api_version)
            ),
            device_type: format!("{:?}", props.device_type),
            timestamp_period_ns: limits.timestamp_period as f64,
            timestamp_valid_bits: family.timestamp_valid_bits,
            pipeline_statistics: features.pipeline_statistics_query == vk::TRUE,
            occlusion_query_precise: features.occlusion_query_precise == vk::TRUE,
            independent_blend: features.independent_blend == vk::TRUE,
            max_image_dimension_2d: limits.max_image_dimension2_d,
            max_storage_buffer_range: limits.max_storage_buffer_range,
            min_storage_buffer_offset_alignment: limits.min_storage_buffer_offset_alignment,
            sub_texel_precision_bits: limits.sub_texel_precision_bits,
            device_local_bytes: {
                let m = unsafe { instance.get_physical_device_memory_properties(raw) };
                m.memory_heaps_as_slice()
                    .iter()
                    .filter(|h| h.flags.contains(vk::MemoryHeapFlags::DEVICE_LOCAL))
                    .map(|h| h.size)
                    .max()
                    .unwrap_or(0)
            },
            fragment_stores_and_atomics: features.fragment_stores_and_atomics == vk::TRUE,
            shader_clip_distance: features.shader_clip_distance == vk::TRUE,
            framebuffer_sample_counts: {
                let both = limits.framebuffer_color_sample_counts
                    & limits.framebuffer_depth_sample_counts
                    & limits.framebuffer_stencil_sample_counts;
                [1u32, 2, 4, 8, 16, 32, 64]
                    .into_iter()
                    .filter(|&n| both.as_raw() & n != 0)
                    .collect()
            },
            depth_resolve_modes: resolve_props.supported_depth_resolve_modes,
            stencil_resolve_modes: resolve_props.supported_stencil_resolve_modes,
        };
        Ok(PhysicalDevice {
            raw,
            queue_family: queue_family as u32,
            features,
            facts,
        })
    }
}

fn device_name(props: &vk::PhysicalDeviceProperties) -> String {
    props
        .device_name_as_c_str()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Every Vulkan device the instance sees: index, name, type.
pub fn list(instance: &ash::Instance) -> Result<Vec<(usize, String, String)>> {
    let devices = unsafe { instance.enumerate_physical_devices() }?;
    Ok(devices
        .iter()
        .enumerate()
        .map(|(i, d)| {
            let p = unsafe { instance.get_physical_device_properties(*d) };
            (i, device_name(&p), format!("{:?}", p.device_type))
        })
        .collect())
}

/// Whether optimal-tiling images of `format` support `features`.
pub fn format_supports(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    format: vk::Format,
    features: vk::FormatFeatureFlags,
) -> bool {
    let p = unsafe { instance.get_physical_device_format_properties(physical, format) };
    p.optimal_tiling_features.contains(features)
}

/// Whether an optimal-tiling 2D image of `format` with `usage` may have
/// `samples` samples per pixel (the format's own limit, below the
/// framebuffer's).
pub fn format_supports_samples(
    instance: &ash::Instance,
    physical: vk::PhysicalDevice,
    format: vk::Format,
    usage: vk::ImageUsageFlags,
    samples: u32,
) -> bool {
    let p = unsafe {
        instance.get_physical_device_image_format_properties(
            physical,
            format,
            vk::ImageType::TYPE_2D,
            vk::ImageTiling::OPTIMAL,
            usage,
            vk::ImageCreateFlags::empty(),
        )
    };
    p.is_ok_and(|p| p.sample_counts.as_raw() & samples != 0)
}

fn pick(instance: &ash::Instance, choice: &DeviceChoice) -> Result<vk::PhysicalDevice> {
    let devices =
        unsafe { instance.enumerate_physical_devices() }.context("enumerating Vulkan devices")?;
    if devices.is_empty() {
        bail!("no Vulkan device found; install a driver (mesa-vulkan-drivers gives lavapipe)");
    }
    let names: Vec<(vk::PhysicalDevice, String, vk::PhysicalDeviceType)> = devices
        .iter()
        .map(|&d| {
            let p = unsafe { instance.get_physical_device_properties(d) };
            (d, device_name(&p), p.device_type)
        })
        .collect();
    let list = || {
        names
            .iter()
            .enumerate()
            .map(|(i, (_, n, _))| format!("{i}: {n}"))
            .collect::<Vec<_>>()
            .join(", ")
    };
    match choice {
        DeviceChoice::Auto => Ok(names
            .iter()
            .find(|(_, _, t)| *t == vk::PhysicalDeviceType::DISCRETE_GPU)
            .unwrap_or(&names[0])
            .0),
        DeviceChoice::Index(i) => names
            .get(*i)
            .map(|d| d.0)
            .ok_or_else(|| anyhow!("no Vulkan device with index {i} (devices: {})", list())),
        DeviceChoice::Name(s) => {
            let s = s.to_lowercase();
            names
                .iter()
                .find(|(_, n, _)| n.to_lowercase().contains(&s))
                .map(|d| d.0)
                .ok_or_else(|| {
                    anyhow!(
                        "no Vulkan device whose name contains '{s}' (devices: {})",
                        list()
                    )
                })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_device_choice_reads_back_as_itself() {
        for c in [
            DeviceChoice::Auto,
            DeviceChoice::Index(0),
            DeviceChoice::Index(12),
            DeviceChoice::Name("llvmpipe".into()),
            DeviceChoice::Name("NVIDIA H100".into()),
            DeviceChoice::Name("-1".into()),
        ] {
            assert_eq!(c.to_string().parse::<DeviceChoice>(), Ok(c.clone()), "{c}");
        }
        let parse = |s: &str| s.parse::<DeviceChoice>();
        assert_eq!(parse(" 1 "), Ok(DeviceChoice::Index(1)));
        assert_eq!(parse("AUTO"), Ok(DeviceChoice::Auto));
        assert_eq!(
            parse("lavapipe 2"),
            Ok(DeviceChoice::Name("lavapipe 2".into()))
        );
    }

    // Text that names no device is an error at once, in one line, not a
    // choice that silently matches (an empty name part matches every device).
    #[test]
    fn a_device_choice_that_names_nothing_is_refused() {
        for s in ["", "   ", "99999999999999999999999"] {
            let e = s.parse::<DeviceChoice>().unwrap_err().to_string();
            assert!(
                e.contains("`dermis devices` lists them") && !e.contains('\n'),
                "{e}"
            );
        }
    }
}
