//! Frames of several methods (issue 16), their GPU side in one room; which
//! method each character gets is `crate::mix` (pure: choices, fades, rules,
//! plan files).
//!
//! - here: the groups of a frame, resolved from the settings before any
//!   device opens ([`group_specs`]), what the targets must provide for all
//!   of them ([`frame_needs`]), and the built instances the renderer holds
//!   ([`GroupMethod`]);
//! - `setup.rs`: each group's method built over its own characters, under
//!   its image prefix, and bound;
//! - `region.rs`: where a group works (its SSS region and skin depths);
//! - `passes.rs`: the groups' stage of the frame, every group's passes in
//!   order with the merges and the fades, and the image the composite reads;
//! - `merge.rs`: a group's result drawn into the diffuse target on its own
//!   pixels (the copy `mix merge #N`, a fade's blend);
//! - `fade.rs`: a character cross-fading between two settings.
//!
//! A single-method frame is one group (index 0, stencil code 1: the skin
//! bit) holding every character, built from `RenderSettings::method` and its
//! options exactly as before groups existed. A frame with `--assign` or
//! `--plan` has one group per distinct resolved choice (`mix::Mix::groups`):
//! each gets its own method instance, built over its own characters, with its
//! own SSS region, image names prefixed `#N ` and stencil code
//! `mix::stencil_code(N)`.

pub mod fade;
pub mod merge;
pub mod passes;
pub mod region;
pub mod setup;

use anyhow::{bail, Context as _, Result};
use ash::vk;
use glam::Mat4;

use super::settings::{Assignment, RenderSettings};
use crate::graph::ImageId;
use crate::method::region::PixelRect;
use crate::method::{MethodEntry, MethodOptions, Needs, SssMethod};
use crate::mix::{stencil_code, Mix};
use crate::scene::framing::{frame as frame_scene, Framing, Shot};
use crate::scene::Scene;
use crate::vk::context::Context;
use crate::vk::guard::Destroy;
use fade::FadeMethod;
use region::scissors;

/// What a report calls the method of a frame of several (`Report::method`,
/// the budget's frame file `frames/mix.json`).
pub const MIX_NAME: &str = "mix";

/// One group as resolved from the settings (no device needed).
#[derive(Clone, Debug)]
pub struct GroupSpec {
    /// `mix::Group::index` (0 in a single-method frame).
    pub index: usize,
    /// The choice as `--assign` spells it (the method's name alone in a
    /// single-method frame).
    pub label: String,
    pub entry: &'static MethodEntry,
    pub options: MethodOptions,
    /// Frame indices of its characters, ascending.
    pub characters: Vec<usize>,
    /// The setting its one character fades from (`None`: no fade).
    pub fade: Option<FadeSpec>,
}

/// The old setting of a fading character, resolved like a group's.
#[derive(Clone, Debug)]
pub struct FadeSpec {
    pub label: String,
    pub entry: &'static MethodEntry,
    pub options: MethodOptions,
    /// The old setting's share of the character's result, in (0, 1).
    pub weight: f64,
}

impl GroupSpec {
    /// The stencil value of its skin pixels (what its passes test).
    pub fn stencil(&self) -> u32 {
        stencil_code(self.index)
    }
}

/// The shot of `settings` (what `scene::framing::frame` places).
pub fn shot(scene: &Scene, s: &RenderSettings) -> Shot {
    Shot {
        layout: s.layout,
        heads: s.heads,
        distance_heads: s.distance_heads,
        fovy_deg: s.fovy_deg,
        aspect: s.width as f32 / s.height as f32,
        light_dir: s.light.direction_to_light(scene.forward),
        walk_heads: s.walk_heads,
    }
}

/// Camera distance of every character's head centre, in head heights, in
/// the frame's order (what `--assign`'s distance bands select on).
pub fn character_distances_heads(scene: &Scene, framing: &Framing) -> Vec<f64> {
    let size = scene.head_size();
    let (centre, h) = (size.centre, size.height.max(f32::MIN_POSITIVE));
    framing
        .instances
        .iter()
        .map(|m| (m.transform_point3(centre).distance(framing.camera.eye) / h) as f64)
        .collect()
}

/// The mix `settings` assign to the characters of `framing` (`None` for a
/// single-method frame). Errors name the rule or plan entry that fails.
pub fn mix(scene: &Scene, settings: &RenderSettings, framing: &Framing) -> Result<Option<Mix>> {
    let n = framing.instances.len();
    Ok(match &settings.assignment {
        None => None,
        Some(Assignment::Rules(r)) => Some(r.resolve(&character_distances_heads(scene, framing))?),
        Some(Assignment::Plan(p)) => Some(p.mix(n).context("--plan")?),
    })
}

/// The groups of the frame `settings` describe in `scene`: one for a
/// single-method frame, one per distinct choice of a mix (at most
/// `mix::MAX_GROUPS`, or the one-line error of `Mix::groups`). Pure: the CLI
/// calls it before any device opens, the renderer again when it builds.
pub fn group_specs(scene: &Scene, settings: &RenderSettings) -> Result<Vec<GroupSpec>> {
    let framing = frame_scene(scene, &shot(scene, settings));
    let n = framing.instances.len();
    let Some(mix) = mix(scene, settings, &framing)? else {
        return Ok(vec![GroupSpec {
            index: 0,
            label: settings.method.name.to_string(),
            entry: settings.method,
            options: settings.options.clone(),
            characters: (0..n).collect(),
            fade: None,
        }]);
    };
    let mut specs = Vec::new();
    for g in mix.groups()? {
        let (entry, options) = mixed_choice(&g.choice, settings)?;
        let fade = match &g.fade {
            None => None,
            Some(f) => {
                let (entry, options) = mixed_choice(&f.from, settings)
                    .with_context(|| format!("character {}'s fade", g.characters[0]))?;
                Some(FadeSpec {
                    label: f.from.label(),
                    entry,
                    options,
                    weight: f.weight,
                })
            }
        };
        specs.push(GroupSpec {
            index: g.index,
            label: g.choice.label(),
            entry,
            options,
            characters: g.characters,
            fade,
        });
    }
    Ok(specs)
}

/// A choice of a frame of several, checked against what such a frame allows.
fn mixed_choice(
    c: &crate::mix::Choice,
    settings: &RenderSettings,
) -> Result<(&'static MethodEntry, MethodOptions)> {
    let entry = c.entry()?;
    let options = c.method_options();
    super::settings::check_msaa(settings.msaa, Some(entry))?;
    if let Some(why) = (entry.no_mix)(&entry.opts(&options)) {
        bail!("{}: {why}", c.label());
    }
    Ok((entry, options))
}

/// Whether `groups` groups, `fading` if any has a fade, make a frame of
/// several methods: more than one, or a fade (whose old setting is a second
/// instance).
pub fn is_mixed(groups: usize, fading: bool) -> bool {
    groups > 1 || fading
}

/// [`is_mixed`] of resolved groups.
pub fn specs_mixed(specs: &[GroupSpec]) -> bool {
    is_mixed(specs.len(), specs.iter().any(|g| g.fade.is_some()))
}

/// What the frame's targets must provide for every group: the normal target
/// if any needs it, the most mip levels any asks for, transmittance unless
/// one turns it off (only the ground truth does, and a mix never holds it).
pub fn frame_needs(specs: &[GroupSpec], extent: vk::Extent2D) -> Needs {
    let mut it = specs
        .iter()
        .flat_map(|g| {
            let old = g.fade.as_ref().map(|f| (f.entry, &f.options));
            std::iter::once((g.entry, &g.options)).chain(old)
        })
        .map(|(e, o)| (e.needs)(&e.opts(o), extent));
    let first = it.next().unwrap_or(Needs::PLAIN);
    it.fold(first, |a, b| Needs {
        normals: a.normals || b.normals,
        mip_levels: a.mip_levels.max(b.mip_levels),
        geometry_transmittance: a.geometry_transmittance && b.geometry_transmittance,
    })
}

/// One built method instance of the frame.
pub struct GroupMethod {
    pub spec: GroupSpec,
    /// Model matrices of its characters (what its method was built over).
    pub instances: Vec<Mat4>,
    pub method: Box<dyn SssMethod>,
    /// Where its passes work (`method::region`): the region of its own
    /// characters with its own reach. Set with [`GroupMethod::set_region`].
    pub region_px: Vec<PixelRect>,
    pub scissors: Vec<vk::Rect2D>,
    /// Its skin's depths, `(share, view depth)` per skin cluster on screen
    /// (`view::region::skin_depths`): how wide its kernels are on screen.
    pub depths: Vec<(f64, f32)>,
    /// Its character's old setting while it fades.
    pub fade: Option<FadeMethod>,
}

impl GroupMethod {
    pub fn set_region(&mut self, px: Vec<PixelRect>) {
        self.scissors = scissors(&px);
        self.region_px = px;
    }

    /// The images its passes fill only inside a region (zeroed at set-up):
    /// its method's intermediates, and with a fade the keep and the old
    /// method's.
    pub fn intermediates(&self) -> Vec<ImageId> {
        let mut v = self.method.intermediates();
        if let Some(f) = &self.fade {
            v.push(f.keep);
            v.extend(f.method.intermediates());
        }
        v
    }

    /// Whether its method does no SSS (records no pass).
    pub fn is_none(&self) -> bool {
        self.spec.entry.no_sss
    }
}

impl Destroy for GroupMethod {
    fn destroy(&mut self, ctx: &Context) {
        SssMethod::destroy(self.method.as_mut(), ctx);
        if let Some(f) = &mut self.fade {
            SssMethod::destroy(f.method.as_mut(), ctx);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mixed(rules: &str, heads: u32) -> RenderSettings {
        RenderSettings {
            heads,
            width: 64,
            height: 36,
            assignment: Some(Assignment::Rules(rules.parse().unwrap())),
            ..RenderSettings::study()
        }
    }

    #[test]
    fn a_single_method_frame_is_group_zero_with_the_old_skin_code() {
        let scene = crate::scene::default_scene();
        let s = RenderSettings {
            heads: 3,
            ..RenderSettings::study()
        };
        let g = group_specs(&scene, &s).unwrap();
        assert_eq!(g.len(), 1);
        assert_eq!(g[0].characters, vec![0, 1, 2]);
        assert_eq!(g[0].stencil(), crate::method::STENCIL_SKIN);
        assert_eq!(g[0].label, "separable");
    }

    #[test]
    fn rules_resolve_into_groups_and_needs_are_their_union() {
        let scene = crate::scene::default_scene();
        let s = mixed("0=ssg,1=separable:preset=physical,2=none,*=ssg", 4);
        let g = group_specs(&scene, &s).unwrap();
        let labels: Vec<&str> = g.iter().map(|g| g.label.as_str()).collect();
        assert_eq!(labels, ["ssg", "separable:preset=physical", "none"]);
        assert_eq!(g[0].characters, vec![0, 3]);
        assert_eq!(
            g.iter().map(GroupSpec::stencil).collect::<Vec<_>>(),
            [1, 3, 5]
        );
        let extent = vk::Extent2D {
            width: 64,
            height: 36,
        };
        let ssg = (g[0].entry.needs)(&g[0].entry.opts(&g[0].options), extent);
        let n = frame_needs(&g, extent);
        assert_eq!(n.mip_levels, ssg.mip_levels);
        assert!(n.geometry_transmittance);
        // Distances grow along the crowd: a band takes the far ones.
        let framing = frame_scene(&scene, &shot(&scene, &s));
        let d = character_distances_heads(&scene, &framing);
        assert!((d[0] - s.distance_heads as f64).abs() < 0.5, "{d:?}");
        assert!(d[3] > d[0], "{d:?}");
    }

    #[test]
    fn a_character_that_does_not_exist_and_the_branch_mask_are_refused() {
        let scene = crate::scene::default_scene();
        let e = format!(
            "{:#}",
            group_specs(&scene, &mixed("0=ssg,5=none,*=none", 2)).unwrap_err()
        );
        assert!(e.contains("character 5 does not exist"), "{e}");
        let e = format!(
            "{:#}",
            group_specs(&scene, &mixed("0=ssg:mask=branch,*=none", 2)).unwrap_err()
        );
        assert!(e.contains("needs mask=stencil"), "{e}");
    }
}
