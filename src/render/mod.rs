//! The renderer: the frame (`frame.rs`) around its SSS methods
//! (`crate::method`): one in a single-method frame, one per group of
//! characters in a frame of several (`groups/`), set up in the
//! graph's three steps (declare images, derive their usages from
//! the passes, create them and write the descriptor sets), then recorded,
//! submitted and measured frame by frame.

pub mod counting;
pub mod deform;
pub mod frame;
pub mod groups;
pub mod inputs;
pub mod instances;
pub mod post_only;
pub mod readback;
pub mod request;
pub mod scene_gpu;
pub mod settings;
mod submit;
pub mod targets;
pub mod uniforms;

use anyhow::{bail, Context as _, Result};
use ash::vk;

use crate::graph::work::PassRole;
use crate::graph::{record_passes, ImageId, Pass, PassSample, Resources};
use crate::method::region::PixelRect;
use crate::scene::framing::frame as frame_scene;
use crate::scene::Scene;
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use frame::Frame;
use groups::merge::{self, Merge};
use groups::setup::{bind_groups, build_groups};
use groups::{frame_needs, GroupMethod};
use instances::SkinGroup;
use readback::{to_rgba_f32, DumpedImage, ReadbackPlan};
pub use request::FrameRequest;
pub use settings::RenderSettings;
use submit::Submit;

/// A finished frame read back to the host.
pub struct Capture {
    /// sRGB-encoded RGBA8, row-major, top row first.
    pub ldr: Vec<u8>,
    pub width: u32,
    pub height: u32,
    /// Every pass output (with `dump`), linear float.
    pub dumps: Vec<DumpedImage>,
    pub samples: Vec<PassSample>,
    /// The diffuse light after SSS (what the composite reads; with
    /// post-scatter texturing times the albedo, as the composite applies
    /// it), linear float; alpha is the SSS strength, so alpha > 0 marks skin
    /// that scatters (a texel of strength 0 reads as not skin: the scores
    /// leave it out).
    pub diffuse: Vec<[f32; 4]>,
    /// Linear view depth of every pixel, scene units (where the accuracy
    /// bands find depth steps).
    pub depth: Vec<f32>,
    /// Texels of the HDR composite (what the tone map reads) that are NaN or
    /// infinite: the tone map turns them into black pixels of `ldr`.
    pub hdr_nonfinite: usize,
    /// With `--character-ids`: each pixel's character (frame index + 1; 0: no skin).
    pub character_ids: Option<Vec<u32>>,
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
    /// One method instance per group, in group order (one in a
    /// single-method frame).
    pub groups: Vec<GroupMethod>,
    /// The copies of a frame of several into the diffuse target (empty otherwise).
    merge: Merge,
    pub resources: Resources,
    submit: Submit,
    last_record_ms: f64,
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
/// method's output, the linear depth and the HDR composite (and the character
/// ids with `--character-ids`).
const CAPTURED_IMAGES: usize = 5;

impl<'c> Renderer<'c> {
    /// Checks `settings` in `scene` ([`FrameRequest::new`]) and builds the
    /// renderer of that frame (tests and tools that hold no request).
    pub fn new(ctx: &'c Context, scene: &Scene, settings: &RenderSettings) -> Result<Self> {
        Self::build(ctx, &FrameRequest::new(scene, settings.clone())?)
    }

    /// Builds the renderer of a checked frame: only the device's own limits
    /// are checked here (the request checked everything else).
    pub fn build(ctx: &'c Context, request: &FrameRequest) -> Result<Self> {
        let (scene, settings) = (request.scene(), request.settings());
        settings.check_device_limits(ctx.facts.max_image_dimension_2d)?;
        crate::checks::ran("device limits");
        let extent = vk::Extent2D {
            width: settings.width,
            height: settings.height,
        };
        let specs = request.groups().to_vec();
        let needs = frame_needs(&specs, extent);
        let mixed = request.mixed();
        // 1. Declare the frame's and the methods' images.
        let mut resources = Guard::<Resources>::null(ctx);
        let targets = targets::declare(ctx, &mut resources, settings, needs)?;
        let ids = settings.character_ids.then(|| {
            resources.declare(crate::graph::ImageDesc::new(
                "character ids",
                extent,
                vk::Format::R32_SFLOAT,
            ))
        });
        let framing = frame_scene(scene, &groups::shot(scene, settings));
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
        if let Some(ids) = ids {
            frame.enable_character_ids(ctx, &resources, ids)?;
        }
        frame.enable_post(ctx, &mut resources)?;
        frame.set_skin_groups(
            ctx,
            specs
                .iter()
                .map(|g| SkinGroup {
                    stencil: g.stencil(),
                    characters: g.characters.clone(),
                })
                .collect(),
        )?;
        // After the groups: a crowd's copies are in their instance slots;
        // the levels first, so a copy deforms only its level's vertices.
        frame.choose_geometry(scene);
        frame.enable_deform(ctx, scene, &mut resources)?;
        let groups = build_groups(ctx, &mut resources, &frame, scene, specs)?;
        let mut groups = Guard::new(ctx, groups);
        let sss_output = groups::passes::output(&groups, &frame.targets);
        frame.composite_from(&resources, sss_output);
        let mut merge = Guard::new(ctx, Merge::default());
        if mixed && merge::needs_any(&groups, &frame.targets) {
            *merge = Merge::new(ctx, &resources, &frame.targets, &groups)?;
        }
        // 2. Every image's usage from the passes that touch it: the frame's, and
        //    the uploads and fills the renderer offers (tests, set-up).
        let passes = frame.passes(&groups, &merge, &resources);
        let mut accesses: Vec<(ImageId, AccessKind)> = passes
            .iter()
            .flat_map(|q| q.images.iter().copied())
            .collect();
        let slots = profiler_slots(&passes);
        drop(passes);
        accesses.extend(inputs::upload_accesses(&frame.targets));
        accesses.extend(
            groups
                .iter()
                .flat_map(|g| g.intermediates())
                .map(|i| (i, inputs::FILL_ACCESS)),
        );
        resources.allow(&accesses);
        check_memory(ctx, &resources, extent)?;
        // 3. Create the images and write what reads them.
        resources.create(ctx)?;
        frame.bind(ctx, &resources)?;
        merge.bind(ctx, &frame.pool, &resources)?;
        bind_groups(ctx, &resources, &frame, &mut groups)?;
        let submit = Submit::new(ctx, slots)?;
        // Complete: the renderer owns (and frees, in its drop) every part.
        let mut r = Renderer {
            ctx,
            frame: frame.keep(),
            groups: groups.keep(),
            merge: merge.keep(),
            resources: resources.keep(),
            submit,
            last_record_ms: 0.0,
        };
        // Texels of the intermediates outside the region are never written: zero
        // them once so a dump of an intermediate shows black there, not old memory.
        let full = PixelRect::full(extent.width, extent.height);
        if r.groups.iter().any(|g| {
            g.region_px != [full] || g.fade.as_ref().is_some_and(|f| f.region_px != [full])
        }) {
            r.fill_intermediates(0.0)?;
        }
        ctx.check_validation("while setting up the renderer")?;
        Ok(r)
    }

    /// Every morphing object's vertices and previous positions as the last
    /// frame's deform pass wrote them (empty when nothing morphs).
    pub fn deformed(&mut self) -> Result<Vec<deform::Deformed>> {
        self.frame.deform.read_back(self.ctx, &mut self.resources)
    }

    /// The SSS region of every group, one after another (one group's in a
    /// single-method frame).
    pub fn region_px(&self) -> Vec<PixelRect> {
        self.groups
            .iter()
            .flat_map(|g| g.region_px.iter().copied())
            .collect()
    }

    /// Sets every group's SSS region (tests that upload their own inputs).
    pub fn set_region(&mut self, px: Vec<PixelRect>) {
        for g in &mut self.groups {
            g.set_region(px.clone());
            if let Some(f) = &mut g.fade {
                f.set_region(px.clone());
            }
        }
    }

    /// Calls every group's `begin_frame` (once before a frame's passes are built).
    fn begin_frame(&mut self) {
        for g in &mut self.groups {
            g.method.begin_frame();
            if let Some(f) = &mut g.fade {
                f.method.begin_frame();
            }
        }
    }

    /// The first group's method (a single-method frame's only one) as its
    /// concrete type (tests that inspect one method's state).
    pub fn method_as<T: 'static>(&self) -> Option<&T> {
        self.groups[0].method.as_any().downcast_ref::<T>()
    }

    /// The frame's passes as they are recorded (tests, reports).
    pub fn passes(&self) -> Vec<Pass<'_>> {
        self.frame
            .passes(&self.groups, &self.merge, &self.resources)
    }

    /// Records, submits and waits for one frame; returns its per-pass samples.
    /// [`Renderer::last_record_ms`] is then its CPU recording time.
    fn run_frame(&mut self, plan: Option<&mut ReadbackPlan>) -> Result<Vec<PassSample>> {
        // A run stepping through the motion poses this frame first.
        self.frame.advance()?;
        let start = std::time::Instant::now();
        self.begin_frame();
        let mut passes = self
            .frame
            .passes(&self.groups, &self.merge, &self.resources);
        let built_ms = start.elapsed().as_secs_f64() * 1e3;
        if let Some(plan) = plan {
            passes = plan.interleave(self.ctx, &mut self.resources, passes)?;
        }
        let samples = submit_passes(
            self.ctx,
            &self.submit,
            &mut self.resources,
            &passes,
            true,
            "during the frame",
        )?;
        self.last_record_ms = built_ms + self.submit.record_ms.get();
        Ok(samples)
    }

    /// CPU milliseconds the last frame took to build its passes and record
    /// them (the submission and the wait left out).
    pub fn last_record_ms(&self) -> f64 {
        self.last_record_ms
    }

    /// Renders `n` frames and returns each frame's pass samples and CPU
    /// recording time (ms).
    pub fn frames_timed(
        &mut self,
        n: usize,
        mut progress: impl FnMut(usize),
    ) -> Result<(Vec<Vec<PassSample>>, Vec<f64>)> {
        let mut all = Vec::new();
        let mut record = Vec::new();
        for i in 0..n {
            all.push(self.run_frame(None)?);
            record.push(self.last_record_ms);
            progress(i + 1);
        }
        Ok((all, record))
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
        let mut finals = vec![
            self.frame.output(),
            groups::passes::output(&self.groups, t),
            t.linear_depth,
            t.hdr,
        ];
        finals.extend(self.frame.character_ids);
        finals.extend(t.albedo);
        let mut plan = ReadbackPlan::new(dump, &finals);
        let samples = match self.run_frame(Some(&mut plan)) {
            Ok(s) => s,
            Err(e) => {
                plan.discard(self.ctx, &mut self.resources);
                return Err(e);
            }
        };
        let (finals, dumps) = plan.finish(self.ctx, &mut self.resources)?;
        let mut finals = finals.into_iter();
        let mut next = || {
            finals
                .next()
                .ok_or_else(|| anyhow::anyhow!("the capture read back too few images"))
        };
        let (ldr, diffuse, depth, hdr) = (next()?, next()?, next()?, next()?);
        let float = |(format, bytes): readback::RawImage| to_rgba_f32(format, &bytes);
        let character_ids = match self.frame.character_ids {
            Some(_) => Some(
                float(next()?)?
                    .iter()
                    .map(|p| p[0].max(0.0) as u32)
                    .collect(),
            ),
            None => None,
        };
        let hdr = float(hdr)?;
        let mut diffuse = float(diffuse)?;
        // Post-scatter texturing: the diffuse target holds the light alone;
        // the capture's diffuse is what the composite adds, the albedo
        // applied (so every consumer compares the same quantity either way).
        if self.frame.targets.albedo.is_some() {
            for (d, a) in diffuse.iter_mut().zip(float(next()?)?) {
                for c in 0..3 {
                    d[c] *= a[c];
                }
            }
        }
        Ok(Capture {
            ldr: ldr.1,
            width: self.frame.extent.width,
            height: self.frame.extent.height,
            dumps,
            samples: samples
                .into_iter()
                .filter(|s| s.role != PassRole::Readback)
                .collect(),
            diffuse,
            depth: float(depth)?.iter().map(|p| p[0]).collect(),
            hdr_nonfinite: hdr
                .iter()
                .filter(|p| !p.iter().all(|c| c.is_finite()))
                .count(),
            character_ids,
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

    /// Runs only the SSS passes (every group's, and the merges) on whatever
    /// the targets hold (tests) and reads back what the composite would read
    /// as f32 RGBA with the pass samples.
    pub fn run_sss_only(&mut self) -> Result<(Vec<[f32; 4]>, Vec<PassSample>)> {
        self.begin_frame();
        let mut passes = Vec::new();
        let view = self.frame.view(&self.resources);
        let output = groups::passes::sss(&mut passes, &view, &self.groups, &self.merge);
        if passes.is_empty() {
            bail!("the SSS-only run needs a method with passes");
        }
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
        Destroy::destroy(&mut self.merge, ctx);
        for g in &mut self.groups {
            g.destroy(ctx);
        }
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
    let start = std::time::Instant::now();
    record_passes(ctx, s.cmd, resources, passes, profiler);
    unsafe {
        ctx.device.end_command_buffer(s.cmd)?;
        s.record_ms.set(start.elapsed().as_secs_f64() * 1e3);
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
