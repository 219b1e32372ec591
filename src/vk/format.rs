//! The format table's Vulkan side: a [`Format`] as ash's `vk::Format` and back,
//! and its aspects as Vulkan flags. The facts are the table's
//! (`crate::format`, pure: the cost model reads them too); this file only
//! names them in ash's types.

use ash::vk;

use crate::format::{Aspect, Format};

/// The Vulkan format of `f` (the table names it by its registry value).
pub fn to_vk(f: Format) -> vk::Format {
    vk::Format::from_raw(f.info().vulkan_value)
}

/// The table's format for a Vulkan one (`None`: dermis does not use it).
pub fn from_vk(f: vk::Format) -> Option<Format> {
    Format::ALL.into_iter().find(|&x| to_vk(x) == f)
}

pub fn aspect_flag(a: Aspect) -> vk::ImageAspectFlags {
    match a {
        Aspect::Color => vk::ImageAspectFlags::COLOR,
        Aspect::Depth => vk::ImageAspectFlags::DEPTH,
        Aspect::Stencil => vk::ImageAspectFlags::STENCIL,
    }
}

/// Every aspect of `f`: what a view or barrier of the whole image names.
pub fn aspect_flags(f: Format) -> vk::ImageAspectFlags {
    f.info()
        .aspects
        .iter()
        .fold(vk::ImageAspectFlags::empty(), |m, &(a, _)| {
            m | aspect_flag(a)
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    // The table names each format by the registry's name and value: ash (its
    // generated `Debug`, from the same registry) must print that name.
    #[test]
    fn each_row_is_the_vulkan_format_it_names() {
        for f in Format::ALL {
            assert_eq!(format!("{:?}", to_vk(f)), f.info().vulkan, "{f:?}");
            assert_eq!(from_vk(to_vk(f)), Some(f));
        }
        assert_eq!(
            to_vk(Format::D32FloatS8Uint),
            vk::Format::D32_SFLOAT_S8_UINT
        );
        assert_eq!(from_vk(vk::Format::B8G8R8A8_UNORM), None);
        assert_eq!(from_vk(vk::Format::D16_UNORM), None);
    }

    #[test]
    fn aspects_as_vulkan_flags() {
        type F = vk::ImageAspectFlags;
        assert_eq!(aspect_flags(Format::Rgba16Float), F::COLOR);
        assert_eq!(aspect_flags(Format::D32Float), F::DEPTH);
        for f in [Format::D24UnormS8Uint, Format::D32FloatS8Uint] {
            assert_eq!(aspect_flags(f), F::DEPTH | F::STENCIL);
        }
    }
}
