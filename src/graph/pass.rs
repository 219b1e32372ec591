//! A pass: a name (a label, nothing else keys on it), its role, what it
//! declares (its attachments with their load ops, the images and buffers it
//! reads and writes, through the typed references the declaration hands
//! back, its draws or its dispatch), and a record closure (what it records
//! with: `context.rs`; the executor that records a list of passes:
//! `record.rs`).
//!
//! A pass states each fact once (Granite's `add_color_output`, kajiya's typed
//! pass builder): a colour target with its load op, a depth/stencil use, an
//! optional render area. From that one declaration the pass derives its access
//! kinds (so its barriers and layouts), the executor begins and ends dynamic
//! rendering around the record closure (or dispatches after it), and
//! [`Pass::declared_work`] fills the declared work's colour writes, clears,
//! depth/stencil use, extent and invocations. No record closure chooses a load
//! op or begins rendering, and no pass types a clear twice.

use ash::vk;

use super::attach::{ColorTarget, DepthStencil, Load};
use super::context::PassContext;
use super::refs::{BufferRef, ClearDst, ImageRef, SetRef, TransferDst, TransferSrc};
use super::resources::{BufferId, ImageId, Resources};
use super::set::GraphSet;
use super::work::{ColorWrite, DepthStencilUse, PassRole, ShaderWork, Work};
use crate::vk::barrier::AccessKind;

/// What a raster pass declares: its attachments, render area and draws.
#[derive(Clone, Debug, Default)]
pub(super) struct Raster {
    pub(super) colors: Vec<ColorTarget>,
    pub(super) depth: Option<DepthStencil>,
    /// The render area from the origin; `None`: the whole first attachment.
    area: Option<vk::Extent2D>,
    /// Each colour target is rendered alone, one after the other, the record
    /// closure once for each ([`PassContext::target`] says which).
    pub(super) each_target_alone: bool,
    /// The fragment shader's work per fragment (`None`: depth-only) and the
    /// triangles the pass submits; `None` until declared.
    draws: Option<(Option<ShaderWork>, u64)>,
}

/// What a pass costs, as declared.
pub(super) enum Cost {
    Raster(Raster),
    /// `groups` workgroups of `group_size` invocations, dispatched by the
    /// executor after the record closure (which binds and pushes).
    Dispatch {
        shader: ShaderWork,
        groups: [u32; 3],
        group_size: u32,
    },
    /// Workgroups counted on the GPU: the executor dispatches from `args`
    /// (three u32 at `offset`, written by an earlier pass) after the record
    /// closure; the declared work is priced at `most` workgroups, the count's
    /// bound (as a shader's branches are priced at their bounds).
    DispatchIndirect {
        shader: ShaderWork,
        args: BufferId,
        offset: u64,
        most: [u32; 3],
        group_size: u32,
    },
    /// Copies and clears: their work as written.
    Other(Work),
}

type Record<'a> = Box<dyn Fn(&PassContext) + 'a>;

/// One pass: name, role, declaration, and the commands.
pub struct Pass<'a> {
    pub name: String,
    pub role: PassRole,
    /// Every image the pass touches with its access, in declaration order
    /// (the order dumps number a pass's writes in). Attachments' accesses come
    /// from their declarations.
    pub images: Vec<(ImageId, AccessKind)>,
    pub buffers: Vec<(BufferId, AccessKind)>,
    /// The descriptor sets it declared (what its closure may bind).
    pub(super) sets: Vec<vk::DescriptorSet>,
    /// `None` only for passes that record nothing (e.g. the host-visibility
    /// step of a readback).
    pub(super) cost: Option<Cost>,
    pub record: Record<'a>,
    /// The method group the pass belongs to (`mix::Group::index`), `None` for
    /// the frame's own passes (shadow, geometry, composite, tone map).
    pub group: Option<usize>,
    /// A merge: the copy of a group's result into the frame's diffuse target
    /// in a frame of several methods, the mixed frame's own overhead
    /// (`render/groups/merge.rs`). What measures the overhead reads this,
    /// never the pass's label.
    pub merge: bool,
}

impl<'a> Pass<'a> {
    pub fn new(name: impl Into<String>, role: PassRole) -> Self {
        Pass {
            name: name.into(),
            role,
            images: Vec::new(),
            buffers: Vec::new(),
            sets: Vec::new(),
            cost: None,
            record: Box::new(|_| {}),
            group: None,
            merge: false,
        }
    }

    /// An image the pass uses other than as an attachment (a copy, a clear,
    /// a set's read or storage: never an attachment's access, which only
    /// [`Pass::color`] and [`Pass::depth_stencil`] declare, with their load
    /// ops), once.
    fn image(&mut self, id: ImageId, access: AccessKind) {
        if !self.images.contains(&(id, access)) {
            self.images.push((id, access));
        }
    }

    fn buffer(&mut self, id: BufferId, access: AccessKind) {
        if !self.buffers.contains(&(id, access)) {
            self.buffers.push((id, access));
        }
    }

    /// The source of a copy.
    pub fn transfer_src(&mut self, id: ImageId) -> ImageRef<TransferSrc> {
        self.image(id, AccessKind::TransferRead);
        ImageRef::new(id, AccessKind::TransferRead)
    }

    /// The destination of a copy that writes every texel.
    pub fn transfer_dst(&mut self, id: ImageId) -> ImageRef<TransferDst> {
        self.image(id, AccessKind::TransferWrite);
        ImageRef::new(id, AccessKind::TransferWrite)
    }

    /// The destination of a copy into part of the image: the rest keeps its
    /// contents, so its barrier discards neither them nor the layout.
    pub fn transfer_dst_part(&mut self, id: ImageId) -> ImageRef<TransferDst> {
        self.image(id, AccessKind::TransferWritePartial);
        ImageRef::new(id, AccessKind::TransferWritePartial)
    }

    /// An image cleared whole by `vkCmdClearColorImage`.
    pub fn clear_dst(&mut self, id: ImageId) -> ImageRef<ClearDst> {
        self.image(id, AccessKind::ClearWrite);
        ImageRef::new(id, AccessKind::ClearWrite)
    }

    /// A tracked buffer a copy or fill writes.
    pub fn transfer_dst_buffer(&mut self, id: BufferId) -> BufferRef<TransferDst> {
        self.buffer(id, AccessKind::TransferWrite);
        BufferRef::new(id, AccessKind::TransferWrite)
    }

    /// A tracked buffer the pass's draws read as vertices (one a compute
    /// pass wrote: the deform pass's).
    pub fn vertex_input(mut self, id: BufferId) -> Self {
        self.buffer(id, AccessKind::VertexInputRead);
        self
    }

    /// A tracked buffer the host reads after the fence (no command of the
    /// pass uses it: the pass is the host-visibility step).
    pub fn host_read(mut self, id: BufferId) -> Self {
        self.buffer(id, AccessKind::HostRead);
        self
    }

    /// Declares every frame image and buffer `set` binds, in its binding
    /// order (ones this pass already declared alike are not declared again),
    /// and hands back what the record closure binds.
    pub fn set(&mut self, set: &GraphSet) -> SetRef {
        for &(id, access) in &set.images {
            self.image(id, access);
        }
        for &(id, access) in &set.buffers {
            self.buffer(id, access);
        }
        self.sets.push(set.raw);
        SetRef { raw: set.raw }
    }

    /// An image the fragment shader samples, declared here, where the order
    /// of the pass's declarations (which reports keep) puts it, ahead of the
    /// set that binds it ([`Pass::set`] then declares it no second time).
    pub fn sampled(mut self, id: ImageId) -> Self {
        self.image(id, AccessKind::FragmentSampledRead);
        self
    }

    fn raster(&mut self) -> &mut Raster {
        if self.cost.is_none() {
            self.cost = Some(Cost::Raster(Raster::default()));
        }
        match &mut self.cost {
            Some(Cost::Raster(r)) => r,
            _ => panic!(
                "pass '{}' declares attachments and another kind of work",
                self.name
            ),
        }
    }

    /// A colour attachment (attachment index: the order of these calls).
    pub fn color(mut self, target: ColorTarget) -> Self {
        self.images.push((target.image, target.access()));
        if let Some(single) = target.resolve {
            self.images.push((single, AccessKind::ColorResolveWrite));
        }
        self.raster().colors.push(target);
        self
    }

    /// The depth/stencil attachment.
    pub fn depth_stencil(mut self, ds: DepthStencil) -> Self {
        self.images.push((ds.image, ds.access()));
        if let Some(single) = ds.resolve {
            assert!(
                ds.clear.is_some(),
                "pass '{}' resolves a depth/stencil attachment it does not write",
                self.name
            );
            self.images
                .push((single, AccessKind::DepthStencilResolveWrite));
        }
        let r = self.raster();
        assert!(r.depth.is_none(), "one depth/stencil attachment per pass");
        assert!(
            ds.clear.is_some() || !(ds.depth_write || ds.stencil_write),
            "a test-only depth/stencil attachment is never written"
        );
        r.depth = Some(ds);
        self
    }

    /// Renders `extent` from the origin instead of the whole first attachment
    /// (render area, viewport and scissor).
    pub fn render_area(mut self, extent: vk::Extent2D) -> Self {
        self.raster().area = Some(extent);
        self
    }

    /// Renders each colour target alone, one after another (the record closure
    /// runs once per target); its work counts one colour write per fragment
    /// over the targets' stacked area.
    pub fn each_target_alone(mut self) -> Self {
        self.raster().each_target_alone = true;
        self
    }

    /// The draws: `shader` runs per shaded fragment (`None`: depth-only), and
    /// the pass submits `triangles` per frame.
    pub fn draws(mut self, shader: Option<ShaderWork>, triangles: u64) -> Self {
        self.raster().draws = Some((shader, triangles));
        self
    }

    /// A compute dispatch of `groups` workgroups of `group_size` invocations
    /// (the executor dispatches after the record closure binds and pushes).
    pub fn dispatch(mut self, shader: ShaderWork, groups: [u32; 3], group_size: u32) -> Self {
        assert!(
            self.cost.is_none(),
            "pass '{}' declares work twice",
            self.name
        );
        self.cost = Some(Cost::Dispatch {
            shader,
            groups,
            group_size,
        });
        self
    }

    /// A compute dispatch whose workgroup counts a GPU pass wrote into the
    /// tracked buffer `args` (three u32 at byte `offset`: the indirect
    /// arguments, read with their own access kind, so the barrier from their
    /// writer is derived as every other), at most `most` workgroups of
    /// `group_size` invocations (what the declared work counts). The
    /// executor dispatches after the record closure binds and pushes.
    pub fn dispatch_indirect(
        mut self,
        shader: ShaderWork,
        (args, offset): (BufferId, u64),
        most: [u32; 3],
        group_size: u32,
    ) -> Self {
        assert!(
            self.cost.is_none(),
            "pass '{}' declares work twice",
            self.name
        );
        assert!(
            offset % 4 == 0,
            "pass '{}': indirect arguments at byte {offset}, not a multiple of 4",
            self.name
        );
        self.buffer(args, AccessKind::IndirectCommandRead);
        self.cost = Some(Cost::DispatchIndirect {
            shader,
            args,
            offset,
            most,
            group_size,
        });
        self
    }

    /// The work of a copy or clear (raster and compute work is derived from
    /// their declarations).
    pub fn work(mut self, work: Work) -> Self {
        assert!(
            matches!(work, Work::Copy { .. } | Work::Clear { .. }),
            "pass '{}': raster and compute work is declared with draws() and dispatch()",
            self.name
        );
        assert!(
            self.cost.is_none(),
            "pass '{}' declares work twice",
            self.name
        );
        self.cost = Some(Cost::Other(work));
        self
    }

    pub fn record(mut self, f: impl Fn(&PassContext) + 'a) -> Self {
        self.record = Box::new(f);
        self
    }

    /// What the pass costs per unit of work, filled from its declaration and
    /// the images' descriptions; `None` for a pass that records nothing.
    pub fn declared_work(&self, res: &Resources) -> Option<Work> {
        Some(match self.cost.as_ref()? {
            Cost::Other(w) => w.clone(),
            Cost::Dispatch {
                shader,
                groups,
                group_size,
            }
            | Cost::DispatchIndirect {
                shader,
                most: groups,
                group_size,
                ..
            } => Work::Compute {
                shader: shader.clone(),
                invocations: groups.iter().map(|&g| g as u64).product::<u64>() * *group_size as u64,
            },
            Cost::Raster(r) => {
                let (shader, triangles) = r.draws.clone().unwrap_or_else(|| {
                    panic!("pass '{}' declares attachments but no draws", self.name)
                });
                let (width, height) = if r.each_target_alone {
                    let first = self.area(r, res, 0);
                    let height = (0..r.colors.len())
                        .map(|i| {
                            let e = self.area(r, res, i);
                            assert_eq!(
                                e.width, first.width,
                                "pass '{}' stacks targets of different widths",
                                self.name
                            );
                            e.height
                        })
                        .sum();
                    (first.width, height)
                } else {
                    let e = self.area(r, res, 0);
                    (e.width, e.height)
                };
                let mut color: Vec<ColorWrite> = r
                    .colors
                    .iter()
                    .map(|c| ColorWrite {
                        format: res.texel_format(c.image),
                        blend: c.blend,
                    })
                    .collect();
                if r.each_target_alone {
                    // One target at a time: one write per fragment.
                    color.truncate(1);
                }
                let clears = r
                    .colors
                    .iter()
                    .filter(|c| matches!(c.load, Load::Clear(_)))
                    .map(|c| res.texel_format(c.image))
                    .chain(
                        r.depth
                            .iter()
                            .filter(|d| d.clear.is_some())
                            .map(|d| res.texel_format(d.image)),
                    )
                    .collect();
                Work::Raster {
                    shader,
                    color,
                    depth_stencil: r.depth.map(|d| DepthStencilUse {
                        format: res.texel_format(d.image),
                        depth_test: d.depth_test,
                        depth_write: d.depth_write,
                        stencil_test: d.stencil_ref.is_some(),
                        stencil_write: d.stencil_write,
                    }),
                    width,
                    height,
                    triangles,
                    // The attachments' samples per pixel (one count for all:
                    // Vulkan renders every attachment of a pass at one).
                    msaa: r
                        .colors
                        .first()
                        .map(|c| c.image)
                        .or(r.depth.map(|d| d.image))
                        .map_or(1, |id| res.samples(id)),
                    clears,
                }
            }
        })
    }

    /// The render area of rendering `i` (the `i`th target alone, or all at once).
    pub(super) fn area(&self, r: &Raster, res: &Resources, i: usize) -> vk::Extent2D {
        if let Some(a) = r.area {
            return a;
        }
        r.colors
            .get(i)
            .map(|c| c.image)
            .or(r.depth.map(|d| d.image))
            .map(|id| res.extent(id))
            .unwrap_or_else(|| panic!("pass '{}' renders without an attachment", self.name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::work::Format;
    use crate::graph::{Binding, ImageDesc, Storage};
    use crate::vk::pipeline::{Bind, Pipeline};

    fn image(res: &mut Resources, name: &str, w: u32, h: u32, format: vk::Format) -> ImageId {
        res.declare(ImageDesc::new(
            name,
            vk::Extent2D {
                width: w,
                height: h,
            },
            format,
        ))
    }

    // The load op is the one fact: access kinds (so barriers and layouts)
    // follow from it.
    #[test]
    fn accesses_follow_from_the_load_ops() {
        let mut res = Resources::default();
        let c = image(&mut res, "c", 8, 8, vk::Format::R16G16B16A16_SFLOAT);
        let ds = image(&mut res, "ds", 8, 8, vk::Format::D24_UNORM_S8_UINT);
        type A = AccessKind;
        for (target, access) in [
            (ColorTarget::new(c, Load::Keep), A::ColorAttachmentLoadWrite),
            (ColorTarget::new(c, Load::DontCare), A::ColorAttachmentWrite),
            (
                ColorTarget::new(c, Load::Clear([0.0; 4])),
                A::ColorAttachmentWrite,
            ),
            (
                ColorTarget::new(c, Load::Clear([0.0; 4])).persistent(),
                A::ColorAttachmentLoadWrite,
            ),
        ] {
            let p = Pass::new("p", PassRole::Sss).color(target);
            assert_eq!(p.images, vec![(c, access)], "{target:?}");
        }
        let p = Pass::new("p", PassRole::Sss).depth_stencil(DepthStencil::cleared(ds, 1.0));
        assert_eq!(p.images, vec![(ds, A::DepthStencilWrite)]);
        let p = Pass::new("p", PassRole::Sss).depth_stencil(DepthStencil::test_only(ds));
        assert_eq!(p.images, vec![(ds, A::DepthStencilReadOnly)]);
    }

    // Colour writes, clears, depth/stencil use and extent come from the
    // attachments; images keep their declaration order.
    #[test]
    fn raster_work_is_filled_from_the_declaration() {
        let mut res = Resources::default();
        let src = image(&mut res, "src", 64, 32, vk::Format::R32_SFLOAT);
        let a = image(&mut res, "a", 64, 32, vk::Format::R16G16B16A16_SFLOAT);
        let b = image(&mut res, "b", 64, 32, vk::Format::R8G8B8A8_SRGB);
        let ds = image(&mut res, "ds", 64, 32, vk::Format::D32_SFLOAT_S8_UINT);
        let p = Pass::new("p", PassRole::Sss)
            .sampled(src)
            .color(ColorTarget::new(a, Load::Clear([1.0; 4])))
            .depth_stencil(
                DepthStencil::cleared(ds, 1.0)
                    .depth_write(false)
                    .stencil_test(Some(1)),
            )
            .color(ColorTarget::new(b, Load::Keep).blended())
            .draws(None, 7);
        assert_eq!(
            p.images.iter().map(|i| i.0).collect::<Vec<_>>(),
            vec![src, a, ds, b]
        );
        let Some(Work::Raster {
            shader,
            color,
            depth_stencil,
            width,
            height,
            triangles,
            msaa,
            clears,
        }) = p.declared_work(&res)
        else {
            panic!("a raster pass")
        };
        assert!(shader.is_none());
        assert_eq!(
            color,
            vec![
                ColorWrite {
                    format: Format::Rgba16Float,
                    blend: false
                },
                ColorWrite {
                    format: Format::Rgba8Srgb,
                    blend: true
                }
            ]
        );
        assert_eq!(
            depth_stencil,
            Some(DepthStencilUse {
                format: Format::D32FloatS8Uint,
                depth_test: true,
                depth_write: false,
                stencil_test: true,
                stencil_write: false,
            })
        );
        assert_eq!((width, height, triangles, msaa), (64, 32, 7, 1));
        assert_eq!(clears, vec![Format::Rgba16Float, Format::D32FloatS8Uint]);
        // A render area overrides the attachments' extent.
        let q = Pass::new("q", PassRole::Sss)
            .color(ColorTarget::new(a, Load::DontCare))
            .render_area(vk::Extent2D {
                width: 16,
                height: 16,
            })
            .draws(None, 1);
        assert!(matches!(
            q.declared_work(&res),
            Some(Work::Raster { width: 16, height: 16, ref clears, .. }) if clears.is_empty()
        ));
    }

    #[test]
    fn targets_rendered_alone_stack_and_dispatches_count_invocations() {
        let mut res = Resources::default();
        let a = image(&mut res, "a", 64, 3, vk::Format::R32G32B32A32_SFLOAT);
        let b = image(&mut res, "b", 64, 5, vk::Format::R32G32B32A32_SFLOAT);
        let p = Pass::new("p", PassRole::Sss)
            .each_target_alone()
            .color(ColorTarget::new(a, Load::DontCare))
            .color(ColorTarget::new(b, Load::DontCare))
            .draws(None, 2);
        assert!(matches!(
            p.declared_work(&res),
            Some(Work::Raster { width: 64, height: 8, ref color, .. }) if color.len() == 1
        ));
        let c = Pass::new("c", PassRole::Sss).dispatch(ShaderWork::default(), [3, 2, 1], 64);
        assert!(matches!(
            c.declared_work(&res),
            Some(Work::Compute {
                invocations: 384,
                ..
            })
        ));
        // An indirect dispatch declares its arguments' read (so the barrier
        // from the pass that wrote them is derived) and counts its bound.
        let args = res.add_buffer("args", vk::Buffer::null());
        let i = Pass::new("i", PassRole::Sss).dispatch_indirect(
            ShaderWork::default(),
            (args, 0),
            [4, 4, 1],
            64,
        );
        assert_eq!(i.buffers, [(args, AccessKind::IndirectCommandRead)]);
        assert!(matches!(
            i.declared_work(&res),
            Some(Work::Compute {
                invocations: 1024,
                ..
            })
        ));
        assert!(Pass::new("n", PassRole::Readback)
            .declared_work(&res)
            .is_none());
    }

    // `--msaa`: a multisampled pass declares its resolve targets as resolve
    // writes (their barriers and usages), its work at the attachments'
    // samples, and its reports name the resolved images as resolve targets.
    #[test]
    fn a_multisampled_pass_resolves_and_declares_its_samples() {
        let mut res = Resources::default();
        let extent = vk::Extent2D {
            width: 8,
            height: 4,
        };
        let ms = |res: &mut Resources, name: &str, f| {
            res.declare(ImageDesc::new(name, extent, f).with_samples(4))
        };
        let c4 = ms(&mut res, "c 4x", vk::Format::R16G16B16A16_SFLOAT);
        let d4 = ms(&mut res, "d 4x", vk::Format::D32_SFLOAT_S8_UINT);
        let c = image(&mut res, "c", 8, 4, vk::Format::R16G16B16A16_SFLOAT);
        let d = image(&mut res, "d", 8, 4, vk::Format::D32_SFLOAT_S8_UINT);
        let p = Pass::new("p", PassRole::Geometry)
            .color(ColorTarget::new(c4, Load::Clear([0.0; 4])).resolved_into(c))
            .depth_stencil(DepthStencil::cleared(d4, 1.0).resolved_into(d))
            .draws(None, 2);
        type A = AccessKind;
        assert_eq!(
            p.images,
            vec![
                (c4, A::ColorAttachmentWrite),
                (c, A::ColorResolveWrite),
                (d4, A::DepthStencilWrite),
                (d, A::DepthStencilResolveWrite),
            ]
        );
        assert!(matches!(
            p.declared_work(&res),
            Some(Work::Raster {
                msaa: 4,
                width: 8,
                height: 4,
                ..
            })
        ));
        let kinds: Vec<_> = res.image_uses(&p.images).iter().map(|u| u.kind).collect();
        use crate::work::ImageUseKind as K;
        assert_eq!(
            kinds,
            vec![
                K::ColorTarget,
                K::ResolveTarget,
                K::DepthTarget,
                K::ResolveTarget
            ]
        );
        // The 4x images count four samples a texel.
        assert_eq!(res.declared_bytes(), 8 * 4 * (8 * 4 + 8 * 4 + 8 + 8));
        res.allow(&p.images);
        assert!(res
            .usage(d)
            .contains(vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT));
    }

    // A command's use hands back a reference and declares the access it
    // names, once however often it is asked for.
    #[test]
    fn references_declare_their_access() {
        let mut res = Resources::default();
        let a = image(&mut res, "a", 4, 4, vk::Format::R16G16B16A16_SFLOAT);
        let b = image(&mut res, "b", 4, 4, vk::Format::R16G16B16A16_SFLOAT);
        let buf = res.add_buffer("buf", vk::Buffer::null());
        type A = AccessKind;
        let mut p = Pass::new("p", PassRole::Setup);
        let src = p.transfer_src(a);
        let dst = p.transfer_dst_part(b);
        assert_eq!(
            (src.access(), dst.access()),
            (A::TransferRead, A::TransferWritePartial)
        );
        p.transfer_src(a);
        let whole = p.transfer_dst(b);
        let clear = p.clear_dst(a);
        assert_eq!(
            (whole.access(), clear.access()),
            (A::TransferWrite, A::ClearWrite)
        );
        p.transfer_dst_buffer(buf);
        let p = p.host_read(buf);
        assert_eq!(
            p.images,
            vec![
                (a, A::TransferRead),
                (b, A::TransferWritePartial),
                (b, A::TransferWrite),
                (a, A::ClearWrite)
            ]
        );
        assert_eq!(p.buffers, vec![(buf, A::TransferWrite), (buf, A::HostRead)]);
    }

    // A set declares what it binds, in its binding order, at the access its
    // pipeline's stage implies (a chain as every level, one image bound
    // twice once); reads a pass declared ahead keep their place.
    #[test]
    fn a_set_declares_its_images_and_buffers() {
        let mut res = Resources::default();
        let c = image(&mut res, "c", 8, 8, vk::Format::R8G8B8A8_SRGB);
        let chain = res.declare(
            ImageDesc::new(
                "chain",
                vk::Extent2D {
                    width: 8,
                    height: 8,
                },
                vk::Format::R16G16B16A16_SFLOAT,
            )
            .with_levels(3),
        );
        let out = image(&mut res, "out", 8, 8, vk::Format::R32G32B32A32_SFLOAT);
        let buf = res.add_buffer("samples", vk::Buffer::null());
        let pipeline = |name: &str, bind_point| {
            let mut p = Pipeline::default();
            p.name = name.into();
            p.bind_point = bind_point;
            p
        };
        let raster = pipeline("raster", vk::PipelineBindPoint::GRAPHICS);
        let set = GraphSet::new(
            &res,
            &raster,
            0,
            vec![
                ("colorTex", Binding::Sampled(c)),
                ("lumaTex", Binding::SampledUnorm(c)),
                ("chain", Binding::SampledLevels(chain)),
                (
                    "linearClamp",
                    Binding::Fixed(Bind::Sampler(vk::Sampler::null())),
                ),
            ],
        );
        type A = AccessKind;
        let levels = res.levels(chain);
        let mut p = Pass::new("p", PassRole::Sss).sampled(levels[1]);
        p.set(&set);
        assert_eq!(
            p.images,
            vec![
                (levels[1], A::FragmentSampledRead),
                (c, A::FragmentSampledRead),
                (levels[0], A::FragmentSampledRead),
                (levels[2], A::FragmentSampledRead)
            ]
        );
        assert!(set.reads(c) && set.reads(levels[2]) && !set.reads(out));
        let compute = pipeline("compute", vk::PipelineBindPoint::COMPUTE);
        let set = GraphSet::new(
            &res,
            &compute,
            0,
            vec![
                ("src", Binding::Sampled(c)),
                ("out", Binding::StorageImage(out, Storage::Write)),
                (
                    "samples",
                    Binding::StorageBuffer {
                        id: buf,
                        offset: 0,
                        size: 64,
                        storage: Storage::Read,
                    },
                ),
            ],
        );
        let mut q = Pass::new("q", PassRole::Sss);
        q.set(&set);
        assert_eq!(
            q.images,
            vec![(c, A::ComputeSampledRead), (out, A::ComputeStorageWrite)]
        );
        assert_eq!(q.buffers, vec![(buf, A::ComputeStorageRead)]);
        assert!(!set.reads(out));
    }

    #[test]
    #[should_panic(expected = "never written")]
    fn a_test_only_depth_is_not_written() {
        let mut res = Resources::default();
        let ds = image(&mut res, "ds", 4, 4, vk::Format::D24_UNORM_S8_UINT);
        let _ = Pass::new("p", PassRole::Sss)
            .depth_stencil(DepthStencil::test_only(ds).depth_write(true));
    }
}
