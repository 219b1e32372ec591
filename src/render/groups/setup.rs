//! Building a frame's method instances: each group's method over its own
//! characters, under its image prefix, with its own SSS region and skin
//! depths (and a fading character's old setting beside it), and writing
//! their descriptor sets once the images exist.

use anyhow::{Context as _, Result};
use glam::Mat4;

use super::fade::FadeMethod;
use super::region::{depths_for, region_for};
use super::{specs_mixed, GroupMethod, GroupSpec};
use crate::graph::Resources;
use crate::method::{MethodBind, MethodSetup};
use crate::render::frame::{skin_material_binds, Frame};
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
    let mixed = specs_mixed(&specs);
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
        let fade_spec = spec.fade.clone();
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
            characters: &spec.characters,
            frame_binds: frame.frame_binds(),
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
            fade: None,
        };
        // A group with no SSS records no pass: in a mix it has no region.
        let region = if mixed && g.is_none() {
            Vec::new()
        } else {
            region_for(frame, scene, &*g.method, &g.instances)
        };
        g.set_region(region);
        g.depths = depths_for(frame, scene, &g.instances);
        if let Some(f) = fade_spec {
            // Pushed first so that an error below frees the new instance too.
            let i = g.spec.index;
            groups.push(g);
            let g = groups.last_mut().expect("just pushed");
            g.fade = Some(FadeMethod::build(
                ctx,
                res,
                frame,
                scene,
                i,
                f,
                (&g.instances, &g.spec.characters),
            )?);
        } else {
            groups.push(g);
        }
    }
    Ok(groups.keep())
}

/// Writes every group's descriptor sets (and its fade's) once the images
/// exist.
pub fn bind_groups(
    ctx: &Context,
    res: &Resources,
    frame: &Frame,
    groups: &mut [GroupMethod],
) -> Result<()> {
    let bind = MethodBind {
        ctx,
        res,
        pool: &frame.pool,
        skin_material_binds: skin_material_binds(frame),
    };
    for g in groups.iter_mut() {
        g.method.bind(&bind)?;
        if let Some(f) = &mut g.fade {
            f.method.bind(&bind)?;
        }
    }
    Ok(())
}
