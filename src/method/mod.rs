//! The subsurface-scattering methods: one module each, behind one trait, listed
//! in one registry.
//!
//! Adding a method takes four files: its module here (the trait impl, its
//! options and its `ENTRY`), its shader(s) in `shaders/`, one row in
//! [`METHODS`], and its test. The frame (`render`) knows nothing of any method:
//! it declares the targets the method says it [`Needs`], builds it from one
//! [`MethodSetup`], records the passes it returns and composites whatever image
//! it names as its output. The CLI, `eval` (its sweep and the dolly chart's
//! lines), the bench matrix and the tests iterate [`METHODS`]; the scripts in
//! `tools/` read it through `dermis methods --json` ([`listing`]).

pub mod gather;
pub mod jittered;
pub mod none;
pub mod options;
pub mod path;
pub mod poisson;
pub mod profile;
pub mod reference;
pub mod region;
pub mod screen;
pub mod separable;
pub mod ssg;
pub mod tiles;
pub mod tsd;

use std::any::Any;

use anyhow::{bail, Result};
use ash::vk;
use glam::Mat4;

use crate::graph::{Binding, GraphSet, ImageId, Pass, Resources};
use crate::scene::camera::Camera;
use crate::scene::Scene;
use crate::vk::context::Context;
use crate::vk::guard::Destroy;
use crate::vk::pipeline::{Bind, DescriptorPool, Pipeline, Samplers};
pub use options::{MethodOptions, OptKind, OptSpec, Opts};
use region::ReachScale;

/// The stencil bit the geometry pass sets on skin pixels, written only here:
/// what a single-method frame writes and tests, and group 0's code (a mix's
/// codes, `mix::stencil_code`, put the group index above it).
pub const STENCIL_SKIN: u32 = 1;

/// Stencil state of every stencil-masked SSS pass: shade only where the stencil
/// holds the pass's group code. The whole 8 bits are compared (a group's code
/// is the skin bit and the group index above it, `mix::stencil_code`); the
/// reference is dynamic state the executor sets from the pass's declaration
/// (`FrameView::stencil`). In a single-method frame the stencil holds only 0
/// and 1, so the full mask tests what the skin bit alone did.
pub fn skin_stencil_test() -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: vk::StencilOp::KEEP,
        depth_fail_op: vk::StencilOp::KEEP,
        compare_op: vk::CompareOp::EQUAL,
        compare_mask: 0xff,
        write_mask: 0,
        reference: STENCIL_SKIN,
    }
}

/// The frame's targets, as graph ids (levels through `Resources::level`).
#[derive(Clone, Copy, Debug)]
pub struct FrameTargets {
    pub shadow: ImageId,
    /// Diffuse light (RGBA16F, alpha = per-pixel SSS strength): what SSS blurs.
    pub diffuse: ImageId,
    pub specular: ImageId,
    /// Linear view depth (R32F, scene units).
    pub linear_depth: ImageId,
    /// View-space normals (only when a method needs them).
    pub normals: Option<ImageId>,
    /// Each pixel's albedo (rgb), with post-scatter texturing only
    /// (`render::settings::Texturing`): the composite multiplies the
    /// scattered light by it.
    pub albedo: Option<ImageId>,
    /// Depth/stencil with the skin bit.
    pub depth_stencil: ImageId,
    pub hdr: ImageId,
    pub ldr: ImageId,
    /// With `--msaa N` (N > 1): the geometry pass's multisampled attachments,
    /// resolved into the single-sample targets above when it ends, so every
    /// method reads what it reads at 1x.
    pub multisampled: Option<MsaaTargets>,
}

/// The geometry pass's attachments at `samples` samples per pixel, one per
/// single-sample target it resolves into (docs/aa.md, "MSAA with the SSS
/// pipeline").
#[derive(Clone, Copy, Debug)]
pub struct MsaaTargets {
    pub samples: u32,
    pub diffuse: ImageId,
    pub specular: ImageId,
    pub linear_depth: ImageId,
    pub normals: Option<ImageId>,
    pub albedo: Option<ImageId>,
    pub depth_stencil: ImageId,
}

/// What a method needs the frame to provide, known before anything is built.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Needs {
    /// A view-space normal target written by the geometry pass (MRT).
    pub normals: bool,
    /// Mip levels of the diffuse, linear-depth (and normal) targets (1: none).
    pub mip_levels: u32,
    /// Transmittance (thesis eq. 5.12) added in the geometry pass. The ground
    /// truth turns it off: its light through thin parts comes from the integral.
    pub geometry_transmittance: bool,
}

impl Needs {
    pub const PLAIN: Needs = Needs {
        normals: false,
        mip_levels: 1,
        geometry_transmittance: true,
    };
}

/// The view a method is built for.
#[derive(Clone, Copy, Debug)]
pub struct ViewInfo {
    pub extent: vk::Extent2D,
    pub camera: Camera,
    pub mm_per_unit: f32,
}

impl ViewInfo {
    pub fn aspect(&self) -> f32 {
        self.extent.width as f32 / self.extent.height as f32
    }

    pub fn tan_half_fovy(&self) -> f32 {
        crate::view::tan_half(self.camera.fovy_rad)
    }

    /// Pixels per millimetre and its kin for this view (`crate::view`).
    pub fn scale(&self) -> crate::view::ViewScale {
        crate::view::ViewScale {
            height_px: self.extent.height,
            tan_half_fovy: self.tan_half_fovy(),
            mm_per_unit: self.mm_per_unit,
        }
    }

    /// The depth-buffer value of a surface at linear view depth `d`.
    pub fn ndc_depth(&self, d: f32) -> f32 {
        let c = self.camera.proj(self.aspect()) * glam::Vec4::new(0.0, 0.0, -d, 1.0);
        c.z / c.w
    }
}

/// Everything a method is built from.
pub struct MethodSetup<'a> {
    pub ctx: &'a Context,
    /// Declare the method's own images here (created after the usages are known;
    /// in a frame of several groups their names carry the group's prefix).
    pub res: &'a mut Resources,
    pub targets: &'a FrameTargets,
    pub samplers: &'a Samplers,
    pub options: Opts<'a>,
    pub view: ViewInfo,
    pub depth_stencil_format: vk::Format,
    /// The scene and the model matrix of every character this instance works
    /// on (all of them in a single-method frame; its group's in a mix). The
    /// ground truth samples the skin surface itself; tsd draws these heads.
    pub scene: &'a Scene,
    pub instances: &'a [Mat4],
    /// The frame index of each of `instances` (a moving crowd's character
    /// has its own pose: `Scene::character_head`).
    pub characters: &'a [usize],
    /// Set 0 of `lighting.glsl` (the frame: uniforms, shadow map, samplers,
    /// Beckmann), for methods that shade surfaces.
    pub frame_binds: Vec<(&'static str, Binding)>,
}

/// What a method's descriptor sets are written with, once the images exist
/// (the sets themselves, and so the frame images they bind, were stated
/// when the method was built: `graph::GraphSet`).
pub struct MethodBind<'a> {
    pub ctx: &'a Context,
    pub res: &'a Resources,
    pub pool: &'a DescriptorPool,
    /// Set 1 of `lighting.glsl` (the skin material: static textures), for
    /// methods that shade surfaces.
    pub skin_material_binds: Vec<(&'static str, Bind)>,
}

impl MethodBind<'_> {
    /// Writes `set`, made for `pipeline`, from the frame's pool.
    pub fn write(&self, set: &mut GraphSet, pipeline: &Pipeline) -> Result<()> {
        set.write(self.ctx, self.pool, self.res, pipeline)
    }
}

/// What a method's passes are recorded against in a frame.
/// (`'a`: what the passes may keep; `'r`: the graph's resources, read while
/// the passes are built, for formats and sizes in their declarations.)
#[derive(Clone, Copy)]
pub struct FrameView<'a, 'r> {
    pub targets: &'a FrameTargets,
    pub res: &'r Resources,
    pub extent: vk::Extent2D,
    /// Disjoint rectangles holding every skin pixel and every texel the method's
    /// taps read from one (see `region.rs`): seed copies and stencil-tested draws
    /// are limited to them.
    pub region: &'a [vk::Rect2D],
    /// Its characters' skin depths, `(share, view depth)` per skin cluster on
    /// screen: how wide a kernel is on screen (declared work).
    pub depths: &'a [(f64, f32)],
    /// One rectangle covering the screen.
    pub screen: &'a [vk::Rect2D],
    /// The stencil code of this instance's pixels (`mix::stencil_code` of its
    /// group; [`STENCIL_SKIN`] in a single-method frame): the reference of
    /// every stencil test of its passes.
    pub stencil: u32,
}

/// An SSS method as the frame sees it.
pub trait SssMethod {
    /// Advances the method's per-frame state, once before each frame's passes
    /// are built (bevy's `Node::update`), so that building and recording the
    /// passes has no side effects: [`SssMethod::passes`] only reads it.
    fn begin_frame(&mut self) {}
    /// The method's passes, in order (as many times as asked: reports, usage
    /// derivation and recording all build them).
    fn passes<'a>(&'a self, f: &FrameView<'a, '_>) -> Vec<Pass<'a>>;
    /// The image holding the diffuse light after SSS: what the composite reads.
    fn output(&self) -> ImageId;
    /// How far (pixels) the taps of a skin pixel at view depth `depth` reach
    /// into texels a seed copy must have written; `None` for a method that
    /// works on the whole screen.
    fn reach_px(&self, depth: f32, scale: &ReachScale) -> Option<f32>;
    /// Writes the descriptor sets (the images exist by now).
    fn bind(&mut self, b: &MethodBind) -> Result<()>;
    /// Intermediates that seed copies fill only inside the region (the rest is
    /// zeroed at set-up; tests poison it).
    fn intermediates(&self) -> Vec<ImageId> {
        Vec::new()
    }
    /// Facts of this instance for the report (kernel, fit, sample count...).
    fn details(&self) -> serde_json::Value {
        serde_json::Value::Null
    }
    /// Frees what the method created (the graph frees its images).
    fn destroy(&mut self, ctx: &Context);
    /// For tests that inspect one method's state.
    fn as_any(&self) -> &dyn Any;
}

/// A method is freed like any other Vulkan owner (a set-up `Guard` holds the
/// renderer's box until the renderer does).
impl Destroy for dyn SssMethod {
    fn destroy(&mut self, ctx: &Context) {
        SssMethod::destroy(self, ctx)
    }
}

/// One quality setting `eval` sweeps: a label and the options it sets.
#[derive(Clone, Copy, Debug)]
pub struct EvalSetting {
    pub label: &'static str,
    pub options: &'static [(&'static str, &'static str)],
}

/// A registry row: everything the CLI, `eval`, the bench matrix and the
/// renderer need to know of a method.
pub struct MethodEntry {
    /// The CLI name (`--method NAME`).
    pub name: &'static str,
    pub aliases: &'static [&'static str],
    pub summary: &'static str,
    pub options: &'static [OptSpec],
    /// The settings `eval` sweeps (empty for the ground truth).
    pub eval: &'static [EvalSetting],
    /// The ground truth the others are scored against.
    pub ground_truth: bool,
    /// Labels of the `eval` settings drawn as lines of the dolly chart (error
    /// against camera distance); each names one of `eval`.
    pub dolly: &'static [&'static str],
    pub needs: fn(&Opts, vk::Extent2D) -> Needs,
    /// Parses and checks the options before any device opens.
    pub check: fn(&Opts) -> Result<()>,
    pub build: fn(&mut MethodSetup) -> Result<Box<dyn SssMethod>>,
    /// Why the method cannot run on a multisampled frame (`--msaa` > 1), in
    /// one line; `None`: it reads the resolved targets like any 1x frame.
    pub no_msaa: Option<&'static str>,
    /// Why a setting of the method (its options, checked) cannot share a
    /// frame with other methods' characters, in one line; `None`: it can
    /// (its passes keep to its own group's stencil code).
    pub no_mix: fn(&Opts) -> Option<&'static str>,
    /// The method does no subsurface scattering: no pass, no reach, its
    /// output the diffuse target as the geometry pass left it (a frame of
    /// several gives its group no region, a fade from it blends the skin).
    pub no_sss: bool,
    /// Why the method cannot follow a run stepping through a motion
    /// (`--time-step`: it reads the characters' meshes once, as it is
    /// built); `None`: it reads only the frame's targets each frame.
    pub poses_once: Option<&'static str>,
}

impl MethodEntry {
    pub fn opts<'a>(&self, given: &'a MethodOptions) -> Opts<'a> {
        Opts {
            specs: self.options,
            given,
        }
    }
}

impl std::fmt::Debug for MethodEntry {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

impl PartialEq for MethodEntry {
    fn eq(&self, other: &Self) -> bool {
        self.name == other.name
    }
}

impl serde::Serialize for MethodEntry {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name)
    }
}

/// Every method, in the order the CLI lists them.
pub static METHODS: &[&MethodEntry] = &[
    &separable::ENTRY,
    &ssg::ENTRY,
    &jittered::ENTRY,
    &poisson::ENTRY,
    &gather::ENTRY,
    &tsd::ENTRY,
    &tsd::OPT_ENTRY,
    &reference::ENTRY,
    &none::ENTRY,
];

/// One method as `dermis methods` lists it: the registry row as data (what the
/// scripts in `tools/` read with `--json` instead of naming methods themselves).
#[derive(Clone, Debug, serde::Serialize)]
pub struct MethodListing {
    pub name: &'static str,
    pub aliases: &'static [&'static str],
    pub summary: &'static str,
    pub ground_truth: bool,
    /// The frame's default method (`--method` left out).
    pub default: bool,
    pub options: Vec<OptionListing>,
    /// The settings `eval` sweeps, by label.
    pub eval: Vec<EvalListing>,
    /// Labels of the settings drawn on the dolly chart.
    pub dolly: &'static [&'static str],
}

/// One option of a method as listed: the flag as typed and its default.
#[derive(Clone, Debug, serde::Serialize)]
pub struct OptionListing {
    pub key: &'static str,
    /// The long flag without its dashes (`no-KEY` for a switch that turns KEY off).
    pub flag: String,
    /// `value` (the flag takes one) or `switch` (the flag alone sets KEY false).
    pub kind: &'static str,
    pub default: &'static str,
    pub help: &'static str,
}

/// One `eval` setting as listed.
#[derive(Clone, Debug, serde::Serialize)]
pub struct EvalListing {
    pub label: &'static str,
    pub options: Vec<(&'static str, &'static str)>,
}

/// The registry as `dermis methods` prints it, in [`METHODS`]' order.
pub fn listing() -> Vec<MethodListing> {
    METHODS
        .iter()
        .map(|m| MethodListing {
            name: m.name,
            aliases: m.aliases,
            summary: m.summary,
            ground_truth: m.ground_truth,
            default: *m == default_method(),
            options: m
                .options
                .iter()
                .map(|o| OptionListing {
                    key: o.key,
                    flag: o.flag(),
                    kind: match o.kind {
                        OptKind::Value | OptKind::Flagged(_) => "value",
                        OptKind::NoFlag => "switch",
                    },
                    default: o.default,
                    help: o.help,
                })
                .collect(),
            eval: m
                .eval
                .iter()
                .map(|e| EvalListing {
                    label: e.label,
                    options: e.options.to_vec(),
                })
                .collect(),
            dolly: m.dolly,
        })
        .collect()
}

/// The registry as text: one paragraph a method (name, aliases, summary, then
/// each option's flag, default and help).
pub fn listing_text() -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    for m in listing() {
        let mut tags = Vec::new();
        if !m.aliases.is_empty() {
            tags.push(format!("alias {}", m.aliases.join(", ")));
        }
        if m.default {
            tags.push("default".to_string());
        }
        if m.ground_truth {
            tags.push("ground truth".to_string());
        }
        let tags = if tags.is_empty() {
            String::new()
        } else {
            format!(" ({})", tags.join("; "))
        };
        let _ = writeln!(s, "{}{tags}: {}", m.name, m.summary);
        for o in &m.options {
            // A switch turns on by default what its `--no-` flag turns off.
            let (flag, default) = match o.kind {
                "value" => (format!("--{} VALUE", o.flag), o.default),
                _ => (format!("--{}", o.flag), "on"),
            };
            let default = if default.is_empty() { "-" } else { default };
            let _ = writeln!(s, "    {flag:<28} default {default:<8} {}", o.help);
        }
    }
    s
}

/// The default method.
pub fn default_method() -> &'static MethodEntry {
    &separable::ENTRY
}

/// The entry of no SSS (`MethodEntry::no_sss`: the baseline every err/none
/// is relative to).
pub fn none() -> &'static MethodEntry {
    METHODS
        .iter()
        .copied()
        .find(|m| m.no_sss)
        .expect("the registry has a method without SSS")
}

/// The ground truth's entry (the one method marked `ground_truth`).
pub fn ground_truth() -> &'static MethodEntry {
    METHODS
        .iter()
        .copied()
        .find(|m| m.ground_truth)
        .expect("the registry has a ground truth")
}

/// A method by CLI name or alias (case-insensitive).
pub fn lookup(name: &str) -> Result<&'static MethodEntry> {
    let n = name.trim().to_ascii_lowercase();
    match METHODS
        .iter()
        .find(|m| m.name == n || m.aliases.contains(&n.as_str()))
    {
        Some(m) => Ok(m),
        None => bail!(
            "unknown method '{name}' (valid: {})",
            METHODS
                .iter()
                .map(|m| m.name)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    }
}

/// Every option any method declares, once each (the CLI adds one flag per key).
pub fn all_options() -> Vec<(&'static MethodEntry, &'static OptSpec)> {
    let mut out: Vec<(&'static MethodEntry, &'static OptSpec)> = Vec::new();
    for m in METHODS {
        for o in m.options {
            if !out.iter().any(|(_, p)| p.key == o.key) {
                out.push((m, o));
            }
        }
    }
    out
}

/// Keys given in `options` that `method` does not read (the CLI warns about them).
pub fn foreign_options(method: &MethodEntry, options: &MethodOptions) -> Vec<String> {
    options
        .keys()
        .filter(|k| !method.options.iter().any(|o| o.key == *k))
        .map(|k| {
            let owner = METHODS
                .iter()
                .find(|m| m.options.iter().any(|o| o.key == k))
                .map_or("no method", |m| m.name);
            format!("--{k} (an option of {owner})")
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_found_by_alias() {
        let mut names: Vec<&str> = METHODS
            .iter()
            .flat_map(|m| std::iter::once(m.name).chain(m.aliases.iter().copied()))
            .collect();
        let n = names.len();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), n, "a name or alias is used twice");
        for m in METHODS {
            assert_eq!(lookup(&m.name.to_uppercase()).unwrap(), *m);
            for a in m.aliases {
                assert_eq!(lookup(a).unwrap(), *m);
            }
        }
        let e = lookup("ssg-typo").unwrap_err().to_string();
        assert!(e.contains("valid: separable, ssg"), "{e}");
        assert!(ground_truth().eval.is_empty());
        assert_eq!(METHODS.iter().filter(|m| m.ground_truth).count(), 1);
        assert_eq!(METHODS.iter().filter(|m| m.no_sss).count(), 1);
        assert!(none().options.is_empty());
    }

    // Two methods may share an option key only with the same meaning.
    #[test]
    fn shared_option_keys_agree_and_defaults_pass_their_own_checks() {
        for (m, o) in all_options() {
            for other in METHODS {
                if let Some(p) = other.options.iter().find(|p| p.key == o.key) {
                    assert_eq!(
                        p, o,
                        "{} and {} declare '{}' apart",
                        m.name, other.name, o.key
                    );
                }
            }
        }
        let none = MethodOptions::default();
        for m in METHODS {
            (m.check)(&m.opts(&none)).unwrap_or_else(|e| panic!("{}: {e:#}", m.name));
        }
    }

    // Every eval setting names options of its own method, with values its
    // checks accept, and labels are unique per method.
    #[test]
    fn eval_settings_are_valid() {
        for m in METHODS {
            let mut labels: Vec<&str> = m.eval.iter().map(|s| s.label).collect();
            labels.sort();
            labels.dedup();
            assert_eq!(labels.len(), m.eval.len(), "{}", m.name);
            for s in m.eval {
                for (k, _) in s.options {
                    assert!(
                        m.options.iter().any(|o| o.key == *k),
                        "{} '{}' sets '{k}', not an option of it",
                        m.name,
                        s.label
                    );
                }
                let given = MethodOptions::default().with(s.options);
                (m.check)(&m.opts(&given))
                    .unwrap_or_else(|e| panic!("{} '{}': {e:#}", m.name, s.label));
            }
        }
    }

    // The dolly chart's lines are eval settings of their method, and the
    // listing carries every registry row, option and setting.
    #[test]
    fn dolly_lines_are_eval_settings_and_the_listing_is_the_registry() {
        for m in METHODS {
            for d in m.dolly {
                assert!(
                    m.eval.iter().any(|e| e.label == *d),
                    "{}: dolly line '{d}' is not one of its eval settings",
                    m.name
                );
            }
        }
        let l = listing();
        assert_eq!(l.len(), METHODS.len());
        for (row, m) in l.iter().zip(METHODS) {
            assert_eq!(row.name, m.name);
            assert_eq!(row.options.len(), m.options.len());
            assert_eq!(row.eval.len(), m.eval.len());
            assert_eq!(row.default, row.name == default_method().name);
        }
        assert_eq!(l.iter().filter(|r| r.default).count(), 1);
        let json = serde_json::to_value(&l).unwrap();
        assert_eq!(
            json[0]["options"][0]["default"],
            METHODS[0].options[0].default
        );
        let text = listing_text();
        for m in METHODS {
            assert!(text.contains(m.name), "{text}");
            for o in m.options {
                assert!(text.contains(&format!("--{}", o.flag())), "{text}");
            }
        }
    }

    #[test]
    fn options_of_another_method_are_named() {
        let mut o = MethodOptions::default();
        o.set("samples", "9");
        let f = foreign_options(lookup("ssg").unwrap(), &o);
        assert_eq!(f, vec!["--samples (an option of separable)".to_string()]);
        assert!(foreign_options(lookup("separable").unwrap(), &o).is_empty());
    }
}
