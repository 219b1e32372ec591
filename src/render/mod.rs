//! The renderer: the frame (`frame.rs`) around one SSS method (`crate::method`),
//! set up in the graph's three steps (declare images, derive their usages from
//! the passes, create them and write the descriptor sets), then recorded,
//! submitted and measured frame by frame.

pub mod counting;
pub mod frame;
pub mod inputs;
pub mod readback;
pub mod scene_gpu;
pub mod settings;
pub mod targets;

use anyhow::{bail, Context as _, Result};
use ash::vk;

use crate::graph::work::PassRole;
use crate::graph::{record_passes, ImageId, Pass, PassSample, Resources};
use crate::method::region::PixelRect;
use crate::method::{MethodBind, MethodSetup, SssMethod};
use crate::scene::framing::{frame as frame_scene, Shot};
use crate::scene::Scene;
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::profiler::Profiler;
use frame::{skin_material_binds, Frame};
use readback::{to_rgba_f32, DumpedImage, ReadbackPlan};
pub use settings::RenderSettings;

/// A finished frame read back to the host.
pub struct Capture {
    /// sRGB-encoded RGBA8, row-major, top row first.
    pub ldr: Vec<u8>,
    pub width: u32,
    pub height: u32,
    /// Every pass output (with `dump`), linear float.
    pub dumps: Vec<DumpedImage>,
    pub samples: Vec<PassSample>,
    /// The diffuse light after SSS (what the composite reads), linear float;
    /// alpha is the SSS strength, so alpha > 0 marks skin.
    pub diffuse: Vec<[f32; 4]>,
    /// Linear view depth of every pixel, scene units (where the accuracy
    /// bands find depth steps).
    pub depth: Vec<f32>,
    /// Texels of the HDR composite (what the tone map reads) that are NaN or
    /// infinite: the tone map turns them into black pixels of `ldr`.
    pub hdr_nonfinite: usize,
}

/// The submission objects of a renderer.
struct Submit {
    profiler: Profiler,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
}

impl Submit {
    fn new(ctx: &Context, slots: u32) -> Result<Self> {
        // Each is guarded until the submit holds them all.
        let profiler = Guard::new(ctx, Profiler::new(ctx, slots)?);
        let cmd = ctx.create("frame commands", |d| unsafe {
            d.allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(ctx.command_pool)
                    .command_buffer_count(1),
            )
        })?[0];
        let cmd = Guard::new(ctx, cmd);
        ctx.name(*cmd, "frame commands");
        let fence = ctx.create("frame fence", |d| unsafe {
            d.create_fence(&vk::FenceCreateInfo::default(), None)
        })?;
        ctx.name(fence, "frame fence");
        Ok(Submit {
            profiler: profiler.keep(),
            cmd: cmd.keep(),
            fence,
        })
    }
}

impl Destroy for Submit {
    fn destroy(&mut self, ctx: &Context) {
        self.fence.destroy(ctx);
        self.cmd.destroy(ctx);
        Destroy::destroy(&mut self.profiler, ctx);
    }
}

impl Destroy for Frame {
    fn destroy(&mut self, ctx: &Context) {
        Frame::destroy(self, ctx)
    }
}

impl Destroy for Resources {
    fn destroy(&mut self, ctx: &Context) {
        Resources::destroy(self, ctx)
    }
}

/// The renderer's parts. Set-up guards each as it is made (a failed step
/// frees, newest first, what exists: every set-up submission has waited on
/// its fence by then); the renderer's drop frees them in the same order
/// after the device is idle.
pub struct Renderer<'c> {
    pub ctx: &'c Context,
    pub frame: Frame,
    pub method: Box<dyn SssMethod>,
    pub resources: Resources,
    submit: Submit,
}

/// Refuses a frame whose images (and the readback of its output) would take
/// more than half the device's memory: the allocation would fail late, or on a
/// CPU device succeed and then exhaust the host. Checked before any image exists.
fn check_memory(ctx: &Context, res: &Resources, extent: vk::Extent2D) -> Result<()> {
    let pixels = extent.width as u64 * extent.height as u64;
    // Readback of the tone-mapped frame (RGBA8) and the diffuse light (RGBA16F
    // staged, then f32 on the host).
    let need = res.declared_bytes() + pixels * (4 + 8 + 16);
    let have = ctx.facts.device_local_bytes;
    if have > 0 && need > have / 2 {
        bail!(
            "a {}x{} frame needs {:.1} GB of images, more than half of this device's {:.1} GB; lower --width/--height or --shadow-size",
            extent.width,
            extent.height,
            need as f64 / 1e9,
            have as f64 / 1e9
        );
    }
    Ok(())
}

/// Query slots a frame may need: its passes, and with `--dump` one readback
/// pass per image each pass writes (see `ReadbackPlan::interleave`), the
/// copies of a capture's final images and the host-visibility step.
fn profiler_slots(passes: &[Pass]) -> u32 {
    let writes: usize = passes
        .iter()
        .map(|p| p.images.iter().filter(|(_, a)| a.is_write()).count())
        .sum();
    (passes.len() + writes + CAPTURED_IMAGES + 1) as u32
}

/// Images a capture reads back after the frame: the tone-mapped frame, the
/// method's output, the linear depth and the HDR composite.
const CAPTURED_IMAGES: usize = 4;

impl<'c> Renderer<'c> {
    pub fn new(ctx: &'c Context, scene: &Scene, settings: &RenderSettings) -> Result<Self> {
        settings.validate(ctx.facts.max_image_dimension_2d)?;
        let extent = vk::Extent2D {
            width: settings.width,
            height: settings.height,
        };
        let entry = settings.method;
        let opts = entry.opts(&settings.options);
        let needs = (entry.needs)(&opts, extent);
        // 1. Declare the frame's and the method's images.
        let mut resources = Guard::<Resources>::null(ctx);
        let targets = targets::declare(ctx, &mut resources, extent, settings.shadow_size, needs)?;
        let framing = frame_scene(
            scene,
            &Shot {
                layout: settings.layout,
                heads: settings.heads,
                distance_heads: settings.distance_heads,
                fovy_deg: settings.fovy_deg,
                aspect: settings.width as f32 / settings.height as f32,
                light_dir: settings.light.direction_to_light(scene.forward),
            },
        );
        let mut frame = Guard::new(
            ctx,
            Frame::new(
                ctx,
                scene,
                settings,
                targets,
                framing,
                &resources,
                needs.geometry_transmittance,
            )?,
        );
        let depth_stencil_format = resources.format(frame.targets.depth_stencil);
        let method = (entry.build)(&mut MethodSetup {
            ctx,
            res: &mut resources,
            targets: &frame.targets,
            samplers: &frame.samplers,
            options: opts,
            view: frame.view_info(),
            depth_stencil_format,
            scene,
            instances: &frame.instances,
        })
        .with_context(|| format!("setting up {}", entry.name))?;
        let mut method = Guard::new(ctx, method);
        let region = frame.region_for(scene, &**method);
        frame.set_region(region);
        // 2. Every image's usage from the passes that touch it: the frame's, and
        //    the uploads and fills the renderer offers (tests, set-up).
        let passes = frame.passes(&**method, &resources);
        let mut accesses: Vec<(ImageId, AccessKind)> = passes
            .iter()
            .flat_map(|q| q.images.iter().copied())
            .collect();
        let slots = profiler_slots(&passes);
        drop(passes);
        accesses.extend(inputs::upload_accesses(&frame.targets));
        accesses.extend(
            method
                .intermediates()
                .into_iter()
                .map(|i| (i, inputs::FILL_ACCESS)),
        );
        resources.allow(&accesses);
        check_memory(ctx, &resources, extent)?;
        // 3. Create the images and write what reads them.
        resources.create(ctx)?;
        frame.bind(ctx, &resources, method.output())?;
        method.bind(&MethodBind {
            ctx,
            res: &resources,
            pool: &frame.pool,
            samplers: &frame.samplers,
            targets: &frame.targets,
            frame_binds: frame.frame_binds(&resources),
            skin_material_binds: skin_material_binds(&frame),
        })?;
        let submit = Submit::new(ctx, slots)?;
        // Complete: the renderer owns (and frees, in its drop) every part.
        let mut r = Renderer {
            ctx,
            frame: frame.keep(),
            method: method.keep(),
            resources: resources.keep(),
            submit,
        };
        // Texels of the intermediates outside the region are never written: zero
        // them once so a dump of an intermediate shows black there, not old memory.
        let full = PixelRect::full(extent.width, extent.height);
        if r.frame.region_px != [full] {
            r.fill_intermediates(0.0)?;
        }
        ctx.check_validation("while setting up the renderer")?;
        Ok(r)
    }

    /// The method as its concrete type (tests that inspect one method's state).
    pub fn method_as<T: 'static>(&self) -> Option<&T> {
        self.method.as_any().downcast_ref::<T>()
    }

    /// The frame's passes as they are recorded (tests, reports).
    pub fn passes(&self) -> Vec<Pass<'_>> {
        self.frame.passes(self.method.as_ref(), &self.resources)
    }

    /// Records, submits and waits for one frame; returns its per-pass samples.
    fn run_frame(&mut self, plan: Option<&mut ReadbackPlan>) -> Result<Vec<PassSample>> {
        self.method.begin_frame();
        let mut passes = self.frame.passes(self.method.as_ref(), &self.resources);
        if let Some(plan) = plan {
            passes = plan.interleave(self.ctx, &mut self.resources, passes)?;
        }
        submit_passes(
            self.ctx,
            &self.submit,
            &mut self.resources,
            &passes,
            true,
            "during the frame",
        )
    }

    /// Renders `n` frames and returns each frame's pass samples (memory grows
    /// with `n`: the run bounds it, see `run::MAX_MEASURED_FRAMES`).
    pub fn frames(
        &mut self,
        n: usize,
        mut progress: impl FnMut(usize),
    ) -> Result<Vec<Vec<PassSample>>> {
        let mut all = Vec::new();
        for i in 0..n {
            all.push(self.run_frame(None)?);
            progress(i + 1);
        }
        Ok(all)
    }

    /// Renders `n` frames and keeps nothing of them (warm-up, soak): memory
    /// stays flat however large `n` is.
    pub fn run_frames(&mut self, n: usize, mut progress: impl FnMut(usize)) -> Result<()> {
        for i in 0..n {
            self.run_frame(None)?;
            progress(i + 1);
        }
        Ok(())
    }

    /// Renders one frame and reads back the tone-mapped image, and with `dump`
    /// every pass output.
    pub fn capture(&mut self, dump: bool) -> Result<Capture> {
        // Everything a capture returns, read back in the frame's own submission.
        let t = &self.frame.targets;
        let finals: [ImageId; CAPTURED_IMAGES] =
            [t.ldr, self.method.output(), t.linear_depth, t.hdr];
        let mut plan = ReadbackPlan::new(dump, &finals);
        let samples = match self.run_frame(Some(&mut plan)) {
            Ok(s) => s,
            Err(e) => {
                plan.discard(self.ctx, &mut self.resources);
                return Err(e);
            }
        };
        let (finals, dumps) = plan.finish(self.ctx, &mut self.resources)?;
        let [ldr, diffuse, depth, hdr] = <[_; 4]>::try_from(finals)
            .map_err(|_| anyhow::anyhow!("the capture read back the wrong number of images"))?;
        let float = |(format, bytes): readback::RawImage| to_rgba_f32(format, &bytes);
        let hdr = float(hdr)?;
        Ok(Capture {
            ldr: ldr.1,
            width: self.frame.extent.width,
            height: self.frame.extent.height,
            dumps,
            samples: samples
                .into_iter()
                .filter(|s| s.role != PassRole::Readback)
                .collect(),
            diffuse: float(diffuse)?,
            depth: float(depth)?.iter().map(|p| p[0]).collect(),
            hdr_nonfinite: hdr
                .iter()
                .filter(|p| !p.iter().all(|c| c.is_finite()))
                .count(),
        })
    }

    /// Runs `passes` (built from this renderer) once, without timing.
    pub(crate) fn submit_untimed(&mut self, passes: &[Pass], when: &str) -> Result<()> {
        submit_passes(
            self.ctx,
            &self.submit,
            &mut self.resources,
            passes,
            false,
            when,
        )
        .map(|_| ())
    }

    /// Reads one frame image back as linear float RGBA (after a frame: its
    /// contents stay until the next frame writes them).
    pub fn read_back(&mut self, id: ImageId) -> Result<Vec<[f32; 4]>> {
        let (ctx, submit) = (self.ctx, &self.submit);
        submit_and_read(
            ctx,
            submit,
            &mut self.resources,
            id,
            Vec::new(),
            false,
            "while reading back an image",
        )
        .map(|(img, _)| img)
    }

    /// The depth-buffer value of a surface at linear view depth `d` (this camera).
    pub fn ndc_depth(&self, d: f32) -> f32 {
        self.frame.view_info().ndc_depth(d)
    }

    /// Runs only the SSS passes on whatever the targets hold (tests) and reads
    /// back the method's output as f32 RGBA with the pass samples.
    pub fn run_sss_only(&mut self) -> Result<(Vec<[f32; 4]>, Vec<PassSample>)> {
        self.method.begin_frame();
        let passes = self.method.passes(&self.frame.view(&self.resources));
        if passes.is_empty() {
            bail!("the SSS-only run needs a method with passes");
        }
        let output = self.method.output();
        submit_and_read(
            self.ctx,
            &self.submit,
            &mut self.resources,
            output,
            passes,
            true,
            "during the SSS-only run",
        )
    }
}

impl Drop for Renderer<'_> {
    /// Frees every part after the device is idle (the GPU may still run the
    /// last submission when its wait failed), newest part first.
    fn drop(&mut self) {
        let ctx = self.ctx;
        unsafe {
            let _ = ctx.device.device_wait_idle();
        }
        self.submit.destroy(ctx);
        self.method.destroy(ctx);
        self.frame.destroy(ctx);
        self.resources.destroy(ctx);
    }
}

/// Submits `passes` followed by the readback of `id`; the image as f32 RGBA
/// and the pass samples (readback passes left out). On a failed submission
/// the readback buffers are freed before the error returns.
// The renderer's fields come apart so that passes borrowed from its method can
// be submitted.
fn submit_and_read(
    ctx: &Context,
    submit: &Submit,
    resources: &mut Resources,
    id: ImageId,
    passes: Vec<Pass>,
    timed: bool,
    when: &str,
) -> Result<(Vec<[f32; 4]>, Vec<PassSample>)> {
    let mut plan = ReadbackPlan::single(id);
    let done = plan
        .interleave(ctx, resources, passes)
        .and_then(|passes| submit_passes(ctx, submit, resources, &passes, timed, when));
    let samples = match done {
        Ok(s) => s,
        Err(e) => {
            plan.discard(ctx, resources);
            return Err(e);
        }
    };
    let img = plan.finish_single(ctx, resources)?;
    let samples = samples
        .into_iter()
        .filter(|s| s.role != PassRole::Readback)
        .collect();
    Ok((img, samples))
}

/// Records `passes` into the renderer's command buffer, submits them, waits on
/// its fence and checks the validation log: the one submission path of the
/// renderer. Returns the pass samples (empty when untimed).
fn submit_passes(
    ctx: &Context,
    s: &Submit,
    resources: &mut Resources,
    passes: &[Pass],
    timed: bool,
    when: &str,
) -> Result<Vec<PassSample>> {
    let profiler = timed.then_some(&s.profiler);
    unsafe {
        ctx.device
            .reset_command_buffer(s.cmd, vk::CommandBufferResetFlags::empty())?;
        ctx.device.begin_command_buffer(
            s.cmd,
            &vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT),
        )?;
    }
    record_passes(ctx, s.cmd, resources, passes, profiler);
    unsafe {
        ctx.device.end_command_buffer(s.cmd)?;
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(s.cmd)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
        ctx.device
            .queue_submit2(ctx.queue, &submit, s.fence)
            .with_context(|| format!("submitting {when}"))?;
        ctx.device
            .wait_for_fences(&[s.fence], true, u64::MAX)
            .with_context(|| format!("waiting {when} (device lost?)"))?;
        ctx.device.reset_fences(&[s.fence])?;
    }
    ctx.check_validation(when)?;
    match profiler {
        Some(p) => Ok(p
            .read(ctx, passes.len())?
            .into_iter()
            .zip(passes)
            .map(|(t, pass)| PassSample::new(pass, t))
            .collect()),
        None => Ok(Vec::new()),
    }
}
