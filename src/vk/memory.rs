//! Images and buffers, all memory through gpu-allocator. Objects are freed
//! explicitly with `destroy` once the GPU is done with them (after a fence or
//! wait-idle): a Drop impl could not know that. While they are being made, a
//! `Guard` holds them (`vk::guard`), so a failed step frees what exists.

use anyhow::{Context as _, Result};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::context::Context;
use super::error::Error;
use super::format::{aspect_flags, from_vk};
use super::guard::{Destroy, Guard};

/// `Default` is the null object: destroying it does nothing (set-up fills
/// fields one by one in a `Guard`, which destroys whatever exists when a step
/// fails).
#[derive(Default)]
pub struct Image {
    pub raw: vk::Image,
    /// View of mip level 0 (attachments, texel fetches).
    pub view: vk::ImageView,
    /// Mip levels (1 for most targets).
    pub levels: u32,
    /// One view per mip level (`level_views[0] == view`).
    pub level_views: Vec<vk::ImageView>,
    /// View of the whole mip chain (for `textureLod`); `view` when there is one level.
    pub chain_view: vk::ImageView,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub aspect: vk::ImageAspectFlags,
    /// A depth-only view of a depth/stencil image, for sampling.
    pub depth_view: Option<vk::ImageView>,
    /// A stencil-only view of a sampled depth/stencil image (the compute
    /// path reads the skin mask through it, as the fragment path tests it).
    pub stencil_view: Option<vk::ImageView>,
    /// An sRGB image's level 0 read as UNORM (its encoded values, no
    /// decode), made only when asked for (`with_unorm_view`).
    pub unorm_view: Option<vk::ImageView>,
    pub name: String,
    allocation: Option<Allocation>,
}

/// The Vulkan sample-count flag of `n` samples per pixel (1, 2, 4 or 8:
/// what `--msaa` takes).
pub fn sample_count(n: u32) -> Result<vk::SampleCountFlags> {
    Ok(match n {
        1 => vk::SampleCountFlags::TYPE_1,
        2 => vk::SampleCountFlags::TYPE_2,
        4 => vk::SampleCountFlags::TYPE_4,
        8 => vk::SampleCountFlags::TYPE_8,
        _ => anyhow::bail!("{n} samples per pixel: dermis multisamples at 1, 2, 4 or 8"),
    })
}

impl Image {
    pub fn new(
        ctx: &Context,
        name: &str,
        extent: vk::Extent2D,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self> {
        Self::with_levels(ctx, name, extent, format, usage, 1)
    }

    /// The UNORM format of the same texels as sRGB `format` (the one pair
    /// dermis views both ways).
    pub fn unorm_of(format: vk::Format) -> Option<vk::Format> {
        match format {
            vk::Format::R8G8B8A8_SRGB => Some(vk::Format::R8G8B8A8_UNORM),
            _ => None,
        }
    }

    /// An image with `levels` mip levels and, when `unorm_view`, created
    /// mutable-format with a second view of level 0 as UNORM (its format must
    /// be sRGB: [`Image::unorm_of`]).
    pub fn with_unorm_view(
        ctx: &Context,
        name: &str,
        extent: vk::Extent2D,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        levels: u32,
        unorm_view: bool,
    ) -> Result<Self> {
        if !unorm_view {
            return Self::with_levels(ctx, name, extent, format, usage, levels);
        }
        let unorm = Self::unorm_of(format).with_context(|| {
            format!("image '{name}': a UNORM view of {format:?} (not an sRGB format)")
        })?;
        let mut image = Guard::new(
            ctx,
            Self::create(ctx, name, extent, format, usage, levels, true, 1)?,
        );
        ctx.creation_step(&format!("the UNORM view of image '{name}'"))?;
        let view = unsafe {
            ctx.device.create_image_view(
                &vk::ImageViewCreateInfo::default()
                    .image(image.raw)
                    .view_type(vk::ImageViewType::TYPE_2D)
                    .format(unorm)
                    .subresource_range(
                        vk::ImageSubresourceRange::default()
                            .aspect_mask(vk::ImageAspectFlags::COLOR)
                            .level_count(1)
                            .layer_count(1),
                    ),
                None,
            )
        }
        .map_err(Error::from)
        .with_context(|| format!("creating the UNORM view of image '{name}'"))?;
        ctx.name(view, &format!("{name} unorm view"));
        image.unorm_view = Some(view);
        Ok(image.keep())
    }

    /// An image with `levels` mip levels (each half the size of the previous).
    pub fn with_levels(
        ctx: &Context,
        name: &str,
        extent: vk::Extent2D,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        levels: u32,
    ) -> Result<Self> {
        Self::create(ctx, name, extent, format, usage, levels, false, 1)
    }

    /// A single-level image of `samples` samples per pixel (the multisampled
    /// geometry pass's attachments, resolved at the end of the pass; never
    /// sampled nor copied: `vkCmdCopyImageToBuffer` takes one sample only).
    pub fn multisampled(
        ctx: &Context,
        name: &str,
        extent: vk::Extent2D,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        samples: u32,
    ) -> Result<Self> {
        Self::create(ctx, name, extent, format, usage, 1, false, samples)
    }

    // Every fact of a VkImageCreateInfo dermis varies, one argument each.
    #[allow(clippy::too_many_arguments)]
    fn create(
        ctx: &Context,
        name: &str,
        extent: vk::Extent2D,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
        levels: u32,
        mutable_format: bool,
        samples: u32,
    ) -> Result<Self> {
        let levels = levels.max(1);
        // Its aspects from the format table; a format the table lacks is a
        // programmer error, refused before anything is made.
        let aspect = from_vk(format).map(aspect_flags).with_context(|| {
            format!("image '{name}': {format:?} is not in the format table (src/format.rs)")
        })?;
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D {
                width: extent.width,
                height: extent.height,
                depth: 1,
            })
            .mip_levels(levels)
            .array_layers(1)
            .samples(sample_count(samples)?)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let info = if mutable_format {
            info.flags(vk::ImageCreateFlags::MUTABLE_FORMAT)
        } else {
            info
        };
        ctx.creation_step(&format!("image '{name}'"))?;
        let raw = unsafe { ctx.device.create_image(&info, None) }
            .map_err(Error::from)
            .with_context(|| {
                format!(
                    "creating image '{name}' {}x{} {format:?}",
                    extent.width, extent.height
                )
            })?;
        // Filled in step by step: on an error, the guard frees what exists.
        let mut image = Guard::new(
            ctx,
            Image {
                raw,
                levels,
                format,
                extent,
                aspect,
                name: name.to_string(),
                ..Default::default()
            },
        );
        image.bind_and_view(ctx, usage)?;
        Ok(image.keep())
    }

    /// Memory and views of a fresh image (`with_levels`).
    fn bind_and_view(&mut self, ctx: &Context, usage: vk::ImageUsageFlags) -> Result<()> {
        let (raw, name, format, aspect) = (self.raw, self.name.clone(), self.format, self.aspect);
        let req = unsafe { ctx.device.get_image_memory_requirements(raw) };
        ctx.creation_step(&format!("memory of image '{name}'"))?;
        let allocation = ctx
            .allocator()
            .allocate(&AllocationCreateDesc {
                name: &name,
                requirements: req,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::DedicatedImage(raw),
            })
            .map_err(Error::from)
            .with_context(|| format!("allocating memory for image '{name}'"))?;
        let (memory, offset) = (unsafe { allocation.memory() }, allocation.offset());
        self.allocation = Some(allocation);
        unsafe { ctx.device.bind_image_memory(raw, memory, offset) }
            .map_err(Error::from)
            .with_context(|| format!("binding the memory of image '{name}'"))?;
        let make_view = |aspect: vk::ImageAspectFlags, base: u32, count: u32| {
            ctx.creation_step(&format!("a view of image '{name}'"))?;
            unsafe {
                ctx.device.create_image_view(
                    &vk::ImageViewCreateInfo::default()
                        .image(raw)
                        .view_type(vk::ImageViewType::TYPE_2D)
                        .format(format)
                        .subresource_range(
                            vk::ImageSubresourceRange::default()
                                .aspect_mask(aspect)
                                .base_mip_level(base)
                                .level_count(count)
                                .layer_count(1),
                        ),
                    None,
                )
            }
            .map_err(Error::from)
            .with_context(|| format!("creating a view of image '{name}'"))
        };
        for l in 0..self.levels {
            let v = make_view(aspect, l, 1)?;
            self.level_views.push(v);
        }
        self.view = self.level_views[0];
        self.chain_view = self.view;
        if self.levels > 1 {
            self.chain_view = make_view(aspect, 0, self.levels)?;
        }
        if aspect.contains(vk::ImageAspectFlags::STENCIL)
            && usage.contains(vk::ImageUsageFlags::SAMPLED)
        {
            self.depth_view = Some(make_view(vk::ImageAspectFlags::DEPTH, 0, 1)?);
            self.stencil_view = Some(make_view(vk::ImageAspectFlags::STENCIL, 0, 1)?);
        }
        ctx.name(raw, &name);
        ctx.name(self.view, &format!("{name} view"));
        Ok(())
    }

    /// The view to sample: the depth aspect for depth/stencil images.
    pub fn sampled_view(&self) -> vk::ImageView {
        self.depth_view.unwrap_or(self.view)
    }

    /// Mip level 0 (the whole image when it has one level).
    pub fn subresource_range(&self) -> vk::ImageSubresourceRange {
        self.level_range(0)
    }

    /// One mip level, for barriers that track levels separately.
    pub fn level_range(&self, level: u32) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange::default()
            .aspect_mask(self.aspect)
            .base_mip_level(level)
            .level_count(1)
            .layer_count(1)
    }

    /// Size of mip level `level`.
    pub fn level_extent(&self, level: u32) -> vk::Extent2D {
        vk::Extent2D {
            width: (self.extent.width >> level).max(1),
            height: (self.extent.height >> level).max(1),
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe {
            if let Some(v) = self.depth_view.take() {
                ctx.device.destroy_image_view(v, None);
            }
            if let Some(v) = self.stencil_view.take() {
                ctx.device.destroy_image_view(v, None);
            }
            if let Some(v) = self.unorm_view.take() {
                ctx.device.destroy_image_view(v, None);
            }
            if self.chain_view != self.view {
                ctx.device.destroy_image_view(self.chain_view, None);
            }
            for v in self.level_views.drain(..) {
                ctx.device.destroy_image_view(v, None);
            }
            ctx.device.destroy_image(self.raw, None);
        }
        self.raw = vk::Image::null();
        self.view = vk::ImageView::null();
        self.chain_view = vk::ImageView::null();
        if let Some(a) = self.allocation.take() {
            let _ = ctx.allocator().free(a);
        }
    }
}

/// `Default` is the null object: destroying it does nothing (set-up fills
/// fields one by one in a `Guard`, which destroys whatever exists when a step
/// fails).
#[derive(Default)]
pub struct Buffer {
    pub raw: vk::Buffer,
    pub size: u64,
    allocation: Option<Allocation>,
}

impl Buffer {
    pub fn new(
        ctx: &Context,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self> {
        ctx.creation_step(&format!("buffer '{name}'"))?;
        let raw = unsafe {
            ctx.device.create_buffer(
                &vk::BufferCreateInfo::default()
                    .size(size.max(4))
                    .usage(usage)
                    .sharing_mode(vk::SharingMode::EXCLUSIVE),
                None,
            )
        }
        .map_err(Error::from)
        .with_context(|| format!("creating buffer '{name}' ({size} bytes)"))?;
        // On an error below, the guard frees the buffer (and memory, once bound).
        let mut buffer = Guard::new(
            ctx,
            Buffer {
                raw,
                size,
                allocation: None,
            },
        );
        let req = unsafe { ctx.device.get_buffer_memory_requirements(raw) };
        ctx.creation_step(&format!("memory of buffer '{name}'"))?;
        let a = ctx
            .allocator()
            .allocate(&AllocationCreateDesc {
                name,
                requirements: req,
                location,
                linear: true,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(Error::from)
            .with_context(|| format!("allocating memory for buffer '{name}' ({size} bytes)"))?;
        let (memory, offset) = (unsafe { a.memory() }, a.offset());
        buffer.allocation = Some(a);
        unsafe { ctx.device.bind_buffer_memory(raw, memory, offset) }
            .map_err(Error::from)
            .with_context(|| format!("binding the memory of buffer '{name}'"))?;
        ctx.name(raw, name);
        Ok(buffer.keep())
    }

    /// A host-visible buffer filled with `data`.
    pub fn with_data(
        ctx: &Context,
        name: &str,
        data: &[u8],
        usage: vk::BufferUsageFlags,
    ) -> Result<Self> {
        let mut b = Guard::new(
            ctx,
            Buffer::new(
                ctx,
                name,
                data.len() as u64,
                usage,
                MemoryLocation::CpuToGpu,
            )?,
        );
        b.write(data)?;
        Ok(b.keep())
    }

    pub fn write(&mut self, data: &[u8]) -> Result<()> {
        let slice = self
            .allocation
            .as_mut()
            .and_then(|a| a.mapped_slice_mut())
            .context("buffer is not host visible")?;
        slice[..data.len()].copy_from_slice(data);
        Ok(())
    }

    pub fn read(&self) -> Result<&[u8]> {
        let a = self.allocation.as_ref().context("buffer freed")?;
        let s = a.mapped_slice().context("buffer is not host visible")?;
        Ok(&s[..self.size as usize])
    }

    pub fn destroy(&mut self, ctx: &Context) {
        unsafe { ctx.device.destroy_buffer(self.raw, None) };
        self.raw = vk::Buffer::null();
        if let Some(a) = self.allocation.take() {
            let _ = ctx.allocator().free(a);
        }
    }
}

impl Destroy for Buffer {
    fn destroy(&mut self, ctx: &Context) {
        Buffer::destroy(self, ctx)
    }
}

impl Destroy for Image {
    fn destroy(&mut self, ctx: &Context) {
        Image::destroy(self, ctx)
    }
}
