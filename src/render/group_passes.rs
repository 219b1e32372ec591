//! The groups' part of the frame (issue 16): where each group works (its SSS
//! region, [`Frame::region_for`], and skin depths), what its passes are
//! built against ([`Frame::view`], a fading character's old setting's
//! [`Frame::fade_view`]), the groups' passes in order with the merges and the
//! fades' keep and blend ([`Frame::group_passes`]), and what the composite
//! reads ([`Frame::composite_source`]). Apart from `frame.rs`, whose passes
//! read the frame's private pipelines: these only gather the groups'.

use glam::Mat4;

use super::frame::Frame;
use super::groups::{is_mixed, FadeMethod, GroupMethod};
use super::merge::Merge;
use crate::graph::{ImageId, Pass, Resources};
use crate::method::region::{scene_region, PixelRect, RegionMode, RegionView};
use crate::method::screen::seed_copy;
use crate::method::{FrameView, SssMethod};
use crate::scene::Scene;

impl Frame {
    /// Where `method`, working on the characters `instances`, has work in
    /// `scene` (the whole screen without a region).
    pub fn region_for(
        &self,
        scene: &Scene,
        method: &dyn SssMethod,
        instances: &[Mat4],
    ) -> Vec<PixelRect> {
        self.region_by(scene, instances, |d, scale| method.reach_px(d, scale))
    }

    /// The skin of the characters `instances` on screen, reaching no further
    /// (the whole screen with `--sss-region screen`): where a fade from no SSS
    /// copies and blends.
    pub fn skin_region(&self, scene: &Scene, instances: &[Mat4]) -> Vec<PixelRect> {
        self.region_by(scene, instances, |_, _| Some(0.0))
    }

    fn region_by(
        &self,
        scene: &Scene,
        instances: &[Mat4],
        reach: impl Fn(f32, &crate::method::region::ReachScale) -> Option<f32>,
    ) -> Vec<PixelRect> {
        let full = PixelRect::full(self.extent.width, self.extent.height);
        let s = &self.settings;
        let view = self.view_info();
        let probe = crate::method::region::ReachScale {
            height_px: self.extent.height,
            tan_half_fovy: view.tan_half_fovy(),
            mm_per_unit: self.mm_per_unit,
            max_strength: 1.0,
        };
        if s.sss_region == RegionMode::Screen || reach(1.0, &probe).is_none() {
            return vec![full];
        }
        let rv = self.region_view();
        scene_region(
            scene,
            instances,
            &rv,
            view.tan_half_fovy(),
            s.sss_region_tile,
            reach,
        )
    }

    /// Where the skin of the characters `instances` lies in depth
    /// (`view::region::skin_depths`).
    pub fn depths_for(&self, scene: &Scene, instances: &[Mat4]) -> Vec<(f64, f32)> {
        crate::view::region::skin_depths(scene, instances, &self.region_view())
    }

    /// The camera as the region code projects with it.
    fn region_view(&self) -> RegionView {
        let view = self.view_info();
        RegionView {
            view: self.camera.view(),
            proj: self.camera.proj(view.aspect()),
            near: self.camera.near,
            width: self.extent.width,
            height: self.extent.height,
        }
    }

    /// What group `g`'s passes are built against: its region and stencil code.
    pub fn view<'a, 'r>(&'a self, res: &'r Resources, g: &'a GroupMethod) -> FrameView<'a, 'r> {
        FrameView {
            targets: &self.targets,
            res,
            extent: self.extent,
            region: &g.scissors,
            depths: &g.depths,
            screen: &self.screen_rect,
            stencil: g.spec.stencil(),
        }
    }

    /// What the composite reads: the one group's output, or the diffuse
    /// target every group's result is merged into.
    pub fn composite_source(&self, groups: &[GroupMethod]) -> ImageId {
        match groups {
            [one] => one.method.output(),
            _ => self.targets.diffuse,
        }
    }

    /// What the old setting of group `g`'s fading character is built
    /// against: the keep as its diffuse target, its own region, the group's
    /// stencil code.
    pub fn fade_view<'a, 'r>(
        &'a self,
        res: &'r Resources,
        g: &'a GroupMethod,
        f: &'a FadeMethod,
    ) -> FrameView<'a, 'r> {
        FrameView {
            targets: &f.targets,
            region: &f.scissors,
            ..self.view(res, g)
        }
    }

    /// The passes of the groups' methods, each marked with its group (a
    /// frame of several names them `#N ...`), then the merges. With a fading
    /// character: first the keep of the light before SSS (`#N fade keep`,
    /// before any group writes the diffuse target in place), its old
    /// setting's passes (`#N fade ...`) after the groups', and its blend
    /// after the merges.
    pub fn group_passes<'a>(
        &'a self,
        groups: &'a [GroupMethod],
        merge: &'a Merge,
        res: &Resources,
    ) -> Vec<Pass<'a>> {
        let mixed = is_mixed(groups.len(), groups.iter().any(|g| g.fade.is_some()));
        let mut passes = Vec::new();
        let fades = || {
            groups
                .iter()
                .filter_map(|g| g.fade.as_ref().map(|f| (g, f)))
        };
        for (g, f) in fades() {
            let i = g.spec.index;
            let mut p = seed_copy(
                &format!("#{i} fade keep"),
                &self.fade_view(res, g, f),
                self.targets.diffuse,
                &f.scissors,
                &[f.keep],
            );
            p.group = Some(i);
            passes.push(p);
        }
        for g in groups {
            let i = g.spec.index;
            for mut p in g.method.passes(&self.view(res, g)) {
                p.group = Some(i);
                if mixed {
                    p.name = format!("#{i} {}", p.name);
                }
                passes.push(p);
            }
        }
        for (g, f) in fades() {
            let i = g.spec.index;
            for mut p in f.method.passes(&self.fade_view(res, g, f)) {
                p.group = Some(i);
                p.name = format!("#{i} fade {}", p.name);
                passes.push(p);
            }
        }
        if mixed {
            for g in groups {
                if let Some(p) = merge.pass(&self.view(res, g), g.spec.index, g.method.output()) {
                    passes.push(p);
                }
            }
            for (g, f) in fades() {
                // The blend writes the frame's diffuse target (not the keep)
                // in the old setting's region.
                let view = FrameView {
                    region: &f.scissors,
                    ..self.view(res, g)
                };
                if let Some(p) =
                    merge.fade_pass(&view, g.spec.index, f.method.output(), f.spec.weight)
                {
                    passes.push(p);
                }
            }
        }
        passes
    }
}
