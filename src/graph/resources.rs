//! Declared images and tracked buffers, their last access, and the barriers
//! between accesses.

use anyhow::{Context as _, Result};
use ash::vk;

use super::work::{Format, ImageUse, ImageUseKind};
use crate::vk::barrier::{image_barrier, AccessKind, ResourceState};
use crate::vk::context::Context;
use crate::vk::format::from_vk;
use crate::vk::memory::Image;

/// A tracked image subresource: one mip level of a declared image (level 0 for
/// single-level images). Levels are tracked apart because passes read one level
/// and write the next.
/// (`Default` is a placeholder for a field that set-up fills in.)
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct ImageId(pub usize);
/// A tracked buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct BufferId(pub usize);

/// What an image is, before it exists. Its usage is not part of it: it follows
/// from the accesses the passes declare.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageDesc {
    pub name: String,
    pub extent: vk::Extent2D,
    pub format: vk::Format,
    pub levels: u32,
    /// Also a view of level 0 as UNORM (an sRGB image read without its
    /// decode: the post chain's edge tests work on the encoded values).
    pub unorm_view: bool,
    /// Samples per pixel (1 but for the multisampled geometry pass's
    /// attachments, `--msaa`; such an image has one level and is resolved,
    /// never sampled or copied).
    pub samples: u32,
}

impl ImageDesc {
    pub fn new(name: &str, extent: vk::Extent2D, format: vk::Format) -> Self {
        ImageDesc {
            name: name.into(),
            extent,
            format,
            levels: 1,
            unorm_view: false,
            samples: 1,
        }
    }

    /// `samples` samples per pixel (see [`ImageDesc::samples`]).
    pub fn with_samples(mut self, samples: u32) -> Self {
        self.samples = samples.max(1);
        self
    }

    pub fn with_levels(mut self, levels: u32) -> Self {
        self.levels = levels.max(1);
        self
    }
}

struct Slot {
    desc: ImageDesc,
    /// The format in the work vocabulary (every declared image has one).
    texel: Format,
    usage: vk::ImageUsageFlags,
    image: Option<Image>,
}

struct ImageEntry {
    name: String,
    slot: usize,
    level: u32,
    state: ResourceState,
}

struct BufferEntry {
    name: String,
    raw: vk::Buffer,
    state: ResourceState,
}

/// Every declared image (the graph owns them), every tracked buffer (their
/// owners keep them), and their last access. Lives as long as the renderer, so
/// the state carries over from frame to frame.
#[derive(Default)]
pub struct Resources {
    slots: Vec<Slot>,
    images: Vec<ImageEntry>,
    buffers: Vec<BufferEntry>,
    /// Put before the name of every image declared from now on (a frame of
    /// several groups builds each group's method under its own prefix, so two
    /// groups of one method declare images that dumps and errors tell apart).
    prefix: String,
}

impl Resources {
    /// Sets the prefix of the names of images declared from now on (empty: none).
    pub fn set_name_prefix(&mut self, prefix: &str) {
        self.prefix = prefix.to_string();
    }

    /// Declares an image; returns the id of level 0 (level `l` is
    /// [`Resources::level`]). It is created by [`Resources::create`].
    ///
    /// Panics when the format has no name in the work vocabulary: formats are
    /// chosen by dermis's code, so one missing from [`Format`] is a programmer
    /// error caught where it is made, and [`Resources::texel_format`] is total.
    pub fn declare(&mut self, mut desc: ImageDesc) -> ImageId {
        if !self.prefix.is_empty() {
            desc.name = format!("{}{}", self.prefix, desc.name);
        }
        let texel = from_vk(desc.format).unwrap_or_else(|| {
            panic!(
                "image '{}' is declared with {:?}, which the work vocabulary cannot name",
                desc.name, desc.format
            )
        });
        let slot = self.slots.len();
        let first = ImageId(self.images.len());
        for level in 0..desc.levels.max(1) {
            let name = if level == 0 {
                desc.name.clone()
            } else {
                format!("{} mip {level}", desc.name)
            };
            self.images.push(ImageEntry {
                name,
                slot,
                level,
                state: ResourceState::default(),
            });
        }
        self.slots.push(Slot {
            desc,
            texel,
            usage: vk::ImageUsageFlags::empty(),
            image: None,
        });
        first
    }

    /// The id of mip level `level` of the image whose level 0 is `id`.
    pub fn level(&self, id: ImageId, level: u32) -> ImageId {
        let e = &self.images[id.0];
        assert!(
            e.level == 0 && level < self.slots[e.slot].desc.levels,
            "image '{}' has no mip level {level}",
            e.name
        );
        ImageId(id.0 + level as usize)
    }

    /// Every level of the image whose level 0 is `id`, in order.
    pub fn levels(&self, id: ImageId) -> Vec<ImageId> {
        let n = self.slots[self.images[id.0].slot].desc.levels;
        (0..n).map(|l| self.level(id, l)).collect()
    }

    /// Adds the usages that `accesses` need to their images. Any image a pass
    /// writes may also be copied to the host (captures, `--dump`): that copy is
    /// declared here, once, rather than by every pass that writes an image.
    pub fn allow(&mut self, accesses: &[(ImageId, AccessKind)]) {
        for &(id, access) in accesses {
            let slot = self.images[id.0].slot;
            let mut usage = access.image_usage();
            if access.is_write() {
                usage |= vk::ImageUsageFlags::TRANSFER_SRC;
            }
            let s = &mut self.slots[slot];
            assert!(
                s.image.is_none() || s.usage.contains(usage),
                "image '{}' is used as {access:?} after it was created without that usage",
                s.desc.name
            );
            s.usage |= usage;
        }
    }

    /// Creates every declared image that does not exist yet, with the usage its
    /// declared accesses need.
    pub fn create(&mut self, ctx: &Context) -> Result<()> {
        for s in &mut self.slots {
            if s.image.is_some() {
                continue;
            }
            anyhow::ensure!(
                !s.usage.is_empty(),
                "image '{}' is declared but no pass uses it",
                s.desc.name
            );
            let d = &s.desc;
            let image = if d.samples > 1 {
                Image::multisampled(ctx, &d.name, d.extent, d.format, s.usage, d.samples)
            } else {
                Image::with_unorm_view(
                    ctx,
                    &d.name,
                    d.extent,
                    d.format,
                    s.usage,
                    d.levels,
                    d.unorm_view,
                )
            };
            s.image =
                Some(image.with_context(|| format!("creating the frame image '{}'", d.name))?);
        }
        Ok(())
    }

    /// Bytes the declared images take once created, as the format table's
    /// memory estimate counts a texel (mip chains included).
    pub fn declared_bytes(&self) -> u64 {
        self.slots
            .iter()
            .map(|s| {
                let d = &s.desc;
                let texel = u64::from(s.texel.info().memory_bytes);
                let level0 =
                    d.extent.width as u64 * d.extent.height as u64 * texel * d.samples as u64;
                // A full chain adds a third.
                if d.levels > 1 {
                    level0 + level0 / 3
                } else {
                    level0
                }
            })
            .sum()
    }

    /// Destroys every image the graph created (after the GPU is done with them).
    pub fn destroy(&mut self, ctx: &Context) {
        for s in &mut self.slots {
            if let Some(mut i) = s.image.take() {
                i.destroy(ctx);
            }
        }
    }

    fn slot(&self, id: ImageId) -> &Slot {
        &self.slots[self.images[id.0].slot]
    }

    /// The image behind `id` (any level). Panics before [`Resources::create`]:
    /// a pass that records before set-up finished is a programmer error.
    /// The graph's alone, as its views are: a frame image's handles reach
    /// descriptors and commands only through a pass's declared references
    /// (`refs.rs`).
    pub(super) fn image(&self, id: ImageId) -> &Image {
        let s = self.slot(id);
        s.image
            .as_ref()
            .unwrap_or_else(|| panic!("image '{}' used before it was created", s.desc.name))
    }

    /// Whether the image behind `id` exists yet.
    pub fn is_created(&self, id: ImageId) -> bool {
        self.slot(id).image.is_some()
    }

    /// The view of exactly the level `id` names.
    pub(super) fn view(&self, id: ImageId) -> vk::ImageView {
        self.image(id).level_views[self.images[id.0].level as usize]
    }

    /// Asks for a UNORM view of an sRGB image declared earlier (before the
    /// images are created: it is created mutable-format).
    pub fn request_unorm_view(&mut self, id: ImageId) {
        let slot = self.images[id.0].slot;
        let s = &mut self.slots[slot];
        assert!(
            s.image.is_none(),
            "image '{}': a UNORM view asked for after its creation",
            s.desc.name
        );
        s.desc.unorm_view = true;
    }

    /// The UNORM view of an sRGB image ([`Resources::request_unorm_view`]);
    /// a pass that binds one it did not ask for is a programmer error.
    pub(super) fn unorm_view(&self, id: ImageId) -> vk::ImageView {
        self.image(id).unorm_view.unwrap_or_else(|| {
            panic!(
                "image '{}' has no UNORM view (request_unorm_view)",
                self.name(id)
            )
        })
    }

    /// The stencil-only view of a sampled depth/stencil image; binding one
    /// of an image without a stencil (or never sampled) is a programmer error.
    pub(super) fn stencil_view(&self, id: ImageId) -> vk::ImageView {
        self.image(id).stencil_view.unwrap_or_else(|| {
            panic!(
                "image '{}' has no stencil view (not a sampled depth/stencil image)",
                self.name(id)
            )
        })
    }

    /// The mip level `id` names.
    pub fn level_of(&self, id: ImageId) -> u32 {
        self.images[id.0].level
    }

    pub fn name(&self, id: ImageId) -> &str {
        &self.images[id.0].name
    }

    pub fn format(&self, id: ImageId) -> vk::Format {
        self.slot(id).desc.format
    }

    /// Samples per pixel of `id`'s image.
    pub fn samples(&self, id: ImageId) -> u32 {
        self.slot(id).desc.samples
    }

    /// The format of `id` as pass declarations and reports name it.
    pub fn texel_format(&self, id: ImageId) -> Format {
        self.slot(id).texel
    }

    /// The size of the level `id` names.
    pub fn extent(&self, id: ImageId) -> vk::Extent2D {
        let d = &self.slot(id).desc;
        let l = self.images[id.0].level;
        vk::Extent2D {
            width: (d.extent.width >> l).max(1),
            height: (d.extent.height >> l).max(1),
        }
    }

    /// The usage `id`'s image is (or will be) created with.
    pub fn usage(&self, id: ImageId) -> vk::ImageUsageFlags {
        self.slot(id).usage
    }

    /// Every tracked image subresource.
    pub fn image_ids(&self) -> impl Iterator<Item = ImageId> {
        (0..self.images.len()).map(ImageId)
    }

    /// Marks `id` as filled by a finished upload that left it in `access`.
    pub fn set_uploaded(&mut self, id: ImageId, access: AccessKind) {
        self.images[id.0].state = ResourceState::uploaded(access);
    }

    pub fn add_buffer(&mut self, name: &str, raw: vk::Buffer) -> BufferId {
        self.buffers.push(BufferEntry {
            name: name.into(),
            raw,
            state: ResourceState::default(),
        });
        BufferId(self.buffers.len() - 1)
    }

    /// Marks buffer `id` as filled by a finished upload that left it in `access`.
    pub fn set_buffer_uploaded(&mut self, id: BufferId, access: AccessKind) {
        self.buffers[id.0].state = ResourceState::uploaded(access);
    }

    /// The buffer behind `id` (for the graph's sets and commands).
    pub(super) fn buffer(&self, id: BufferId) -> vk::Buffer {
        self.buffers[id.0].raw
    }

    /// The buffer behind `id`, for a copy recorded outside the graph's
    /// passes (a read-back, whose barriers `transition` derives).
    pub fn raw_buffer(&self, id: BufferId) -> vk::Buffer {
        self.buffers[id.0].raw
    }

    pub fn buffer_name(&self, id: BufferId) -> &str {
        &self.buffers[id.0].name
    }

    /// Number of tracked buffers (temporary ones are dropped with `truncate_buffers`).
    pub fn buffer_count(&self) -> usize {
        self.buffers.len()
    }

    pub fn truncate_buffers(&mut self, n: usize) {
        self.buffers.truncate(n);
    }

    /// How a pass uses each image it declares, for reports and the budget model.
    pub fn image_uses(&self, accesses: &[(ImageId, AccessKind)]) -> Vec<ImageUse> {
        accesses
            .iter()
            .filter_map(|&(id, a)| {
                let kind = match a {
                    AccessKind::ColorAttachmentWrite => ImageUseKind::ColorTarget,
                    AccessKind::ColorAttachmentLoadWrite => ImageUseKind::ColorTargetLoad,
                    AccessKind::DepthStencilWrite => ImageUseKind::DepthTarget,
                    AccessKind::DepthStencilReadOnly => ImageUseKind::DepthTest,
                    AccessKind::ColorResolveWrite | AccessKind::DepthStencilResolveWrite => {
                        ImageUseKind::ResolveTarget
                    }
                    AccessKind::FragmentSampledRead
                    | AccessKind::ComputeSampledRead
                    | AccessKind::AnyShaderSampledRead => ImageUseKind::Sampled,
                    AccessKind::ComputeStorageWrite
                    | AccessKind::ComputeStorageRead
                    | AccessKind::ComputeStorageReadWrite
                    | AccessKind::FragmentStorageRead
                    | AccessKind::FragmentStorageReadWrite => ImageUseKind::Storage,
                    AccessKind::TransferRead => ImageUseKind::CopySource,
                    AccessKind::TransferWrite
                    | AccessKind::TransferWritePartial
                    | AccessKind::ClearWrite => ImageUseKind::CopyDestination,
                    AccessKind::HostRead | AccessKind::HostWrite => ImageUseKind::Host,
                    // Buffer-only accesses: no image is used so.
                    AccessKind::Nothing
                    | AccessKind::UniformRead
                    | AccessKind::VertexInputRead
                    | AccessKind::IndirectCommandRead => return None,
                };
                let e = self.extent(id);
                Some(ImageUse {
                    image: self.name(id).to_string(),
                    format: self.texel_format(id),
                    width: e.width,
                    height: e.height,
                    kind,
                })
            })
            .collect()
    }

    /// The barriers that take every listed resource from its last access to
    /// the given one, and the state update.
    pub fn plan(
        &mut self,
        images: &[(ImageId, AccessKind)],
        buffers: &[(BufferId, AccessKind)],
    ) -> (
        Vec<vk::ImageMemoryBarrier2<'static>>,
        Vec<vk::BufferMemoryBarrier2<'static>>,
    ) {
        let mut ib = Vec::new();
        for &(id, next) in images {
            let (slot, level) = (self.images[id.0].slot, self.images[id.0].level);
            let (raw, range) = {
                let img = self.slots[slot].image.as_ref().unwrap_or_else(|| {
                    panic!(
                        "image '{}' used before it was created",
                        self.images[id.0].name
                    )
                });
                (img.raw, img.level_range(level))
            };
            if let Some(p) = self.images[id.0].state.plan(next, true) {
                ib.push(image_barrier(&p, raw, range));
            }
        }
        let mut bb = Vec::new();
        for &(id, next) in buffers {
            let e = &mut self.buffers[id.0];
            if let Some(p) = e.state.plan(next, false) {
                bb.push(
                    vk::BufferMemoryBarrier2::default()
                        .src_stage_mask(p.src_stage)
                        .src_access_mask(p.src_access)
                        .dst_stage_mask(p.dst_stage)
                        .dst_access_mask(p.dst_access)
                        .buffer(e.raw)
                        .offset(0)
                        .size(vk::WHOLE_SIZE),
                );
            }
        }
        (ib, bb)
    }

    /// Emits the barriers for one set of accesses as a single call.
    pub fn transition(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        images: &[(ImageId, AccessKind)],
        buffers: &[(BufferId, AccessKind)],
    ) {
        let (ib, bb) = self.plan(images, buffers);
        if ib.is_empty() && bb.is_empty() {
            return;
        }
        let dep = vk::DependencyInfo::default()
            .image_memory_barriers(&ib)
            .buffer_memory_barriers(&bb);
        unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn desc(name: &str, format: vk::Format, levels: u32) -> ImageDesc {
        ImageDesc::new(
            name,
            vk::Extent2D {
                width: 64,
                height: 32,
            },
            format,
        )
        .with_levels(levels)
    }

    #[test]
    fn levels_are_tracked_apart_and_sized() {
        let mut r = Resources::default();
        let a = r.declare(desc("diffuse", vk::Format::R16G16B16A16_SFLOAT, 3));
        let b = r.declare(desc("depth", vk::Format::R32_SFLOAT, 1));
        assert_eq!(r.levels(a).len(), 3);
        assert_eq!(r.level(a, 2), ImageId(a.0 + 2));
        assert_eq!(r.name(r.level(a, 1)), "diffuse mip 1");
        assert_eq!(r.extent(r.level(a, 2)).width, 16);
        assert_eq!(r.extent(r.level(a, 2)).height, 8);
        assert_eq!(r.levels(b), vec![b]);
        assert!(!r.is_created(a));
    }

    // Usages come from the declared accesses; a written image may be read back.
    #[test]
    fn usage_is_derived_from_the_declared_accesses() {
        let mut r = Resources::default();
        let rt = r.declare(desc("rt", vk::Format::R16G16B16A16_SFLOAT, 2));
        let ds = r.declare(desc("ds", vk::Format::D24_UNORM_S8_UINT, 1));
        let mip1 = r.level(rt, 1);
        r.allow(&[
            (rt, AccessKind::ColorAttachmentWrite),
            (mip1, AccessKind::FragmentSampledRead),
            (ds, AccessKind::DepthStencilReadOnly),
        ]);
        type U = vk::ImageUsageFlags;
        assert_eq!(
            r.usage(rt),
            U::COLOR_ATTACHMENT | U::SAMPLED | U::TRANSFER_SRC
        );
        assert_eq!(r.usage(ds), U::DEPTH_STENCIL_ATTACHMENT);
        r.allow(&[(ds, AccessKind::TransferWrite)]);
        assert_eq!(
            r.usage(ds),
            U::DEPTH_STENCIL_ATTACHMENT | U::TRANSFER_DST | U::TRANSFER_SRC
        );
    }

    // Every declared image has a work format: the map is checked where an
    // image is declared, so nothing downstream handles a missing one.
    #[test]
    #[should_panic(expected = "the work vocabulary cannot name")]
    fn images_of_unnamed_formats_are_refused_when_declared() {
        let mut r = Resources::default();
        r.declare(desc("odd", vk::Format::B8G8R8A8_UNORM, 1));
    }

    #[test]
    fn image_uses_name_format_size_and_kind() {
        let mut r = Resources::default();
        let rt = r.declare(desc("rt", vk::Format::R16G16B16A16_SFLOAT, 2));
        let uses = r.image_uses(&[
            (r.level(rt, 1), AccessKind::ColorAttachmentLoadWrite),
            (rt, AccessKind::FragmentSampledRead),
        ]);
        assert_eq!(uses[0].image, "rt mip 1");
        assert_eq!(uses[0].kind, ImageUseKind::ColorTargetLoad);
        assert_eq!((uses[0].width, uses[0].height), (32, 16));
        assert_eq!(uses[1].kind, ImageUseKind::Sampled);
        assert_eq!(uses[1].format, Format::Rgba16Float);
        assert_eq!(r.texel_format(rt), Format::Rgba16Float);
    }
}
