//! No subsurface scattering: the baseline every method is compared with. It
//! records no pass; the composite reads the geometry pass's diffuse light.

use std::any::Any;

use anyhow::Result;

use super::region::ReachScale;
use super::{EvalSetting, FrameView, MethodBind, MethodEntry, MethodSetup, Needs, SssMethod};
use crate::graph::{ImageId, Pass};
use crate::vk::context::Context;

pub static ENTRY: MethodEntry = MethodEntry {
    name: "none",
    aliases: &["off"],
    summary: "no subsurface scattering (the baseline)",
    options: &[],
    eval: &[EvalSetting {
        label: "-",
        options: &[],
    }],
    ground_truth: false,
    dolly: &["-"],
    needs: |_, _| Needs::PLAIN,
    check: |_| Ok(()),
    build: |s: &mut MethodSetup| {
        Ok(Box::new(NoSss {
            diffuse: s.targets.diffuse,
        }))
    },
    no_msaa: None,
    no_mix: |_| None,
    no_sss: true,
    poses_once: None,
};

pub struct NoSss {
    diffuse: ImageId,
}

impl SssMethod for NoSss {
    fn passes<'a>(&'a self, _f: &FrameView<'a, '_>) -> Vec<Pass<'a>> {
        Vec::new()
    }

    fn output(&self) -> ImageId {
        self.diffuse
    }

    /// No passes, no region: reported as the whole screen.
    fn reach_px(&self, _depth: f32, _scale: &ReachScale) -> Option<f32> {
        None
    }

    fn bind(&mut self, _b: &MethodBind) -> Result<()> {
        Ok(())
    }

    fn destroy(&mut self, _ctx: &Context) {}

    fn as_any(&self) -> &dyn Any {
        self
    }
}
