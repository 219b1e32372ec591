//! A pass: a name (a label, nothing else keys on it), its role, what it
//! declares (its attachments with their load ops, the images and buffers it
//! reads and writes, its draws or its dispatch), and a record closure; and the
//! executor that records a list of them.
//!
//! A pass states each fact once (Granite's `add_color_output`, kajiya's typed
//! pass builder): a colour target with its load op, a depth/stencil use, an
//! optional render area. From that one declaration the pass derives its access
//! kinds (so its barriers and layouts), the executor begins and ends dynamic
//! rendering around the record closure (or dispatches after it), and
//! [`Pass::declared_work`] fills the declared work's colour writes, clears,
//! depth/stencil use, extent and invocations. No record closure chooses a load
//! op or begins rendering, and no pass types a clear twice.
//!
//! Over 800 lines because 225 of them are the unit tests of the declaration
//! and the executor (multisampled passes and their resolves among them),
//! which read best beside the code they pin down.

use ash::vk;

use super::attach::{ColorTarget, DepthStencil, Load};
use super::resources::{BufferId, ImageId, Resources};
use super::work::{ColorWrite, DepthStencilUse, PassRole, ShaderWork, Work};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::memory::Image;
use crate::vk::profiler::{PassTiming, Profiler};

/// What a raster pass declares: its attachments, render area and draws.
#[derive(Clone, Debug, Default)]
struct Raster {
    colors: Vec<ColorTarget>,
    depth: Option<DepthStencil>,
    /// The render area from the origin; `None`: the whole first attachment.
    area: Option<vk::Extent2D>,
    /// Each colour target is rendered alone, one after the other, the record
    /// closure once for each ([`PassContext::target`] says which).
    each_target_alone: bool,
    /// The fragment shader's work per fragment (`None`: depth-only) and the
    /// triangles the pass submits; `None` until declared.
    draws: Option<(Option<ShaderWork>, u64)>,
}

/// What a pass costs, as declared.
enum Cost {
    Raster(Raster),
    /// `groups` workgroups of `group_size` invocations, dispatched by the
    /// executor after the record closure (which binds and pushes).
    Dispatch {
        shader: ShaderWork,
        groups: [u32; 3],
        group_size: u32,
    },
    /// Copies and clears: their work as written.
    Other(Work),
}

/// What a pass's record closure gets: the device, the command buffer, and the
/// graph's images as this pass declared them.
pub struct PassContext<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    pub res: &'a Resources,
    /// In a pass that renders each colour target alone: which one this call
    /// renders (0 otherwise).
    pub target: usize,
    pass: &'a str,
    images: &'a [(ImageId, AccessKind)],
}

impl PassContext<'_> {
    fn access(&self, id: ImageId) -> AccessKind {
        self.images
            .iter()
            .find(|(i, _)| *i == id)
            .map(|(_, a)| *a)
            .unwrap_or_else(|| {
                panic!(
                    "pass '{}' records with image '{}' it did not declare",
                    self.pass,
                    self.res.name(id)
                )
            })
    }

    /// The layout `id` is in during this pass: the one of the access the pass
    /// declared for it (never typed at the call site).
    pub fn layout(&self, id: ImageId) -> vk::ImageLayout {
        self.access(id).info().layout
    }

    /// The view of the level `id` names (declared by this pass).
    pub fn view(&self, id: ImageId) -> vk::ImageView {
        self.access(id);
        self.res.view(id)
    }

    /// The image behind `id` (declared by this pass).
    pub fn image(&self, id: ImageId) -> &Image {
        self.access(id);
        self.res.image(id)
    }
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
    /// `None` only for passes that record nothing (e.g. the host-visibility
    /// step of a readback).
    cost: Option<Cost>,
    pub record: Record<'a>,
    /// The method group the pass belongs to (`mix::Group::index`), `None` for
    /// the frame's own passes (shadow, geometry, composite, tone map).
    pub group: Option<usize>,
}

impl<'a> Pass<'a> {
    pub fn new(name: impl Into<String>, role: PassRole) -> Self {
        Pass {
            name: name.into(),
            role,
            images: Vec::new(),
            buffers: Vec::new(),
            cost: None,
            record: Box::new(|_| {}),
            group: None,
        }
    }

    /// An image the pass reads or writes other than as an attachment (copies,
    /// clears, storage, host access): attachments are declared with
    /// [`Pass::color`] and [`Pass::depth_stencil`], which know their load ops.
    pub fn image(mut self, id: ImageId, access: AccessKind) -> Self {
        assert!(
            !matches!(
                access,
                AccessKind::ColorAttachmentWrite
                    | AccessKind::ColorAttachmentLoadWrite
                    | AccessKind::DepthStencilWrite
                    | AccessKind::DepthStencilReadOnly
                    | AccessKind::ColorResolveWrite
                    | AccessKind::DepthStencilResolveWrite
            ),
            "pass '{}' declares an attachment with image(): use color() or depth_stencil()",
            self.name
        );
        self.images.push((id, access));
        self
    }

    /// An image the fragment shader samples.
    pub fn sampled(self, id: ImageId) -> Self {
        self.image(id, AccessKind::FragmentSampledRead)
    }

    pub fn buffer(mut self, id: BufferId, access: AccessKind) -> Self {
        self.buffers.push((id, access));
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
    fn area(&self, r: &Raster, res: &Resources, i: usize) -> vk::Extent2D {
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

/// What the GPU measured for one pass in one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PassSample {
    pub name: String,
    pub role: PassRole,
    pub barrier_ms: f64,
    pub gpu_ms: f64,
    pub fragment_invocations: Option<u64>,
    pub samples_passed: u64,
}

impl PassSample {
    pub fn new(pass: &Pass, t: PassTiming) -> Self {
        PassSample {
            name: pass.name.clone(),
            role: pass.role,
            barrier_ms: t.barrier_ms,
            gpu_ms: t.gpu_ms,
            fragment_invocations: t.fragment_invocations,
            samples_passed: t.samples_passed,
        }
    }
}

/// The store op of a written attachment: STORE (every image a pass draws is
/// read later), but DONT_CARE for a multisampled one that the pass resolves:
/// nothing reads its samples after the resolve, which happens before the
/// store, so a tiler need not write them out.
fn store_op(resolved: bool) -> vk::AttachmentStoreOp {
    if resolved {
        vk::AttachmentStoreOp::DONT_CARE
    } else {
        vk::AttachmentStoreOp::STORE
    }
}

/// Begins dynamic rendering of `colors` and `depth` over `area` from the
/// origin, views and layouts from the pass's declared accesses, and sets
/// viewport, scissor and the stencil reference the declaration names.
fn begin_rendering(
    pc: &PassContext,
    colors: &[ColorTarget],
    depth: Option<DepthStencil>,
    area: vk::Extent2D,
) {
    let color_att: Vec<vk::RenderingAttachmentInfo> = colors
        .iter()
        .map(|c| {
            let (op, clear) = match c.load {
                Load::Keep => (vk::AttachmentLoadOp::LOAD, [0.0; 4]),
                Load::DontCare => (vk::AttachmentLoadOp::DONT_CARE, [0.0; 4]),
                Load::Clear(v) => (vk::AttachmentLoadOp::CLEAR, v),
            };
            let att = vk::RenderingAttachmentInfo::default()
                .image_view(pc.view(c.image))
                .image_layout(pc.layout(c.image))
                .load_op(op)
                .store_op(store_op(c.resolve.is_some()))
                .clear_value(vk::ClearValue {
                    color: vk::ClearColorValue { float32: clear },
                });
            // Every colour format dermis renders is float or UNORM, so the
            // resolve is the average of the samples (the box filter MSAA is).
            match c.resolve {
                Some(single) => att
                    .resolve_mode(vk::ResolveModeFlags::AVERAGE)
                    .resolve_image_view(pc.view(single))
                    .resolve_image_layout(pc.layout(single)),
                None => att,
            }
        })
        .collect();
    let ds_att = depth.map(|d| {
        let att = vk::RenderingAttachmentInfo::default()
            .image_view(pc.view(d.image))
            .image_layout(pc.layout(d.image));
        // Depth and stencil both from sample 0: the one mode every device
        // has for both (VK_KHR_depth_stencil_resolve), and one surface's
        // depth and group code together (docs/aa.md).
        let att = match d.resolve {
            Some(single) => att
                .resolve_mode(vk::ResolveModeFlags::SAMPLE_ZERO)
                .resolve_image_view(pc.view(single))
                .resolve_image_layout(pc.layout(single)),
            None => att,
        };
        match d.clear {
            Some((depth, stencil)) => att
                .load_op(vk::AttachmentLoadOp::CLEAR)
                .store_op(store_op(d.resolve.is_some()))
                .clear_value(vk::ClearValue {
                    depth_stencil: vk::ClearDepthStencilValue { depth, stencil },
                }),
            // Read-only depth/stencil: loaded for the tests, never stored.
            None => att
                .load_op(vk::AttachmentLoadOp::LOAD)
                .store_op(vk::AttachmentStoreOp::NONE),
        }
    });
    let rect = vk::Rect2D {
        offset: vk::Offset2D::default(),
        extent: area,
    };
    let mut info = vk::RenderingInfo::default()
        .render_area(rect)
        .layer_count(1)
        .color_attachments(&color_att);
    if let (Some(att), Some(d)) = (&ds_att, depth) {
        info = info.depth_attachment(att);
        if pc.res.texel_format(d.image).has_stencil() {
            info = info.stencil_attachment(att);
        }
    }
    let (device, cmd) = (&pc.ctx.device, pc.cmd);
    unsafe {
        device.cmd_begin_rendering(cmd, &info);
        device.cmd_set_viewport(
            cmd,
            0,
            &[vk::Viewport {
                x: 0.0,
                y: 0.0,
                width: area.width as f32,
                height: area.height as f32,
                min_depth: 0.0,
                max_depth: 1.0,
            }],
        );
        device.cmd_set_scissor(cmd, 0, &[rect]);
        // Set before the closure binds its pipeline: the stencil-testing
        // pipelines take their reference as dynamic state, which a bind keeps.
        if let Some(reference) = depth.and_then(|d| d.stencil_ref) {
            device.cmd_set_stencil_reference(cmd, vk::StencilFaceFlags::FRONT_AND_BACK, reference);
        }
    }
}

/// Records one pass's commands: dynamic rendering around its closure for a
/// raster pass, its dispatch after the closure for a compute pass.
fn record_one(ctx: &Context, cmd: vk::CommandBuffer, res: &Resources, pass: &Pass) {
    let pc = |target| PassContext {
        ctx,
        cmd,
        res,
        target,
        pass: &pass.name,
        images: &pass.images,
    };
    match &pass.cost {
        Some(Cost::Raster(r)) => {
            let renderings: Vec<Vec<ColorTarget>> = if r.each_target_alone {
                r.colors.iter().map(|&c| vec![c]).collect()
            } else {
                vec![r.colors.clone()]
            };
            for (i, colors) in renderings.iter().enumerate() {
                let pc = pc(i);
                begin_rendering(&pc, colors, r.depth, pass.area(r, res, i));
                (pass.record)(&pc);
                unsafe { ctx.device.cmd_end_rendering(cmd) };
            }
        }
        Some(Cost::Dispatch { groups, .. }) => {
            (pass.record)(&pc(0));
            unsafe {
                ctx.device
                    .cmd_dispatch(cmd, groups[0], groups[1], groups[2])
            };
        }
        Some(Cost::Other(_)) | None => (pass.record)(&pc(0)),
    }
}

/// Records `passes` into `cmd` in order. With a profiler, pass `i` uses query
/// slots `i`; the caller reads them after the fence.
pub fn record_passes(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    resources: &mut Resources,
    passes: &[Pass],
    profiler: Option<&Profiler>,
) {
    if let Some(p) = profiler {
        assert!(
            passes.len() as u32 <= p.max_passes,
            "{} passes but the profiler holds {}",
            passes.len(),
            p.max_passes
        );
        p.reset(ctx, cmd);
    }
    for (i, pass) in passes.iter().enumerate() {
        let i = i as u32;
        ctx.begin_label(cmd, &pass.name);
        if let Some(p) = profiler {
            p.stamp(ctx, cmd, i, 0);
        }
        resources.transition(ctx, cmd, &pass.images, &pass.buffers);
        if let Some(p) = profiler {
            p.stamp(ctx, cmd, i, 1);
            p.begin_stats(ctx, cmd, i);
        }
        record_one(ctx, cmd, resources, pass);
        if let Some(p) = profiler {
            p.end_stats(ctx, cmd, i);
            p.stamp(ctx, cmd, i, 2);
        }
        ctx.end_label(cmd);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::graph::work::Format;
    use crate::graph::ImageDesc;

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

    #[test]
    #[should_panic(expected = "use color() or depth_stencil()")]
    fn attachments_cannot_be_declared_without_their_load_op() {
        let mut res = Resources::default();
        let a = image(&mut res, "a", 4, 4, vk::Format::R16G16B16A16_SFLOAT);
        let _ = Pass::new("p", PassRole::Sss).image(a, AccessKind::ColorAttachmentWrite);
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
