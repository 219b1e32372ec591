//! Building a frame's method instances: each group's method over its own
//! characters, under its image prefix, with its own SSS region (apart from
//! `groups.rs`, which `frame.rs` reads, so that the frame and the groups do
//! not import each other).

use anyhow::{Context as _, Result};
use glam::Mat4;

use super::frame::Frame;
use super::groups::{GroupMethod, GroupSpec};
use crate::graph::Resources;
use crate::method::MethodSetup;
use crate::scene::Scene;
use crate::vk::context::Context;
use crate::vk::guard::Guard;

/// Builds each group's method over its characters (images declared in
/// `res` under the group's prefix in a frame of several) with its region;
/// on an error the methods built so far are freed.
pub fn build_groups(
    ctx: &Context,
    res: &mut Resources,
    frame: &Frame,
    scene: &Scene,
    specs: Vec<GroupSpec>,
) -> Result<Vec<GroupMethod>> {
    let mixed = specs.len() > 1;
    let depth_stencil_format = res.format(frame.targets.depth_stencil);
    let mut groups = Guard::new(ctx, Vec::<GroupMethod>::new());
    for spec in specs {
        let instances: Vec<Mat4> = spec
            .characters
            .iter()
            .map(|&c| frame.instances[c])
            .collect();
        // Two groups of one method declare images of one name: each group's
        // carry its prefix (none in a single-method frame).
        res.set_name_prefix(&if mixed {
            format!("#{} ", spec.index)
        } else {
            String::new()
        });
        let method = (spec.entry.build)(&mut MethodSetup {
            ctx,
            res,
            targets: &frame.targets,
            samplers: &frame.samplers,
            options: spec.entry.opts(&spec.options),
            view: frame.view_info(),
            depth_stencil_format,
            scene,
            instances: &instances,
        })
        .with_context(|| format!("setting up {}", spec.label));
        res.set_name_prefix("");
        let mut g = GroupMethod {
            spec,
            instances,
            method: method?,
            region_px: Vec::new(),
            scissors: Vec::new(),
            depths: Vec::new(),
        };
        // A group with no SSS records no pass: in a mix it has no region.
        let region = if mixed && g.is_none() {
            Vec::new()
        } else {
            frame.region_for(scene, &*g.method, &g.instances)
        };
        g.set_region(region);
        g.depths = frame.depths_for(scene, &g.instances);
        groups.push(g);
    }
    Ok(groups.keep())
}
