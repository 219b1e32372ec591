//! The groups' stage of the frame: after the geometry pass, every group's
//! method's passes (a frame of several names them `#N ...`), then in a frame
//! of several the merges; with a fading character, first the keep of the
//! light before SSS (`#N fade keep`, before any group writes the diffuse
//! target in place), its old setting's passes (`#N fade ...`) after the
//! groups', and its blend after the merges. It hands the composite the
//! image holding the diffuse light after SSS.

use super::merge::Merge;
use super::{is_mixed, GroupMethod};
use crate::graph::{ImageId, Pass};
use crate::method::{FrameTargets, FrameView};

/// What group `g`'s passes are built against: the frame's view (`frame`)
/// with its region, skin depths and stencil code.
pub fn group_view<'a, 'r>(frame: &FrameView<'a, 'r>, g: &'a GroupMethod) -> FrameView<'a, 'r> {
    FrameView {
        region: &g.scissors,
        depths: &g.depths,
        stencil: g.spec.stencil(),
        ..*frame
    }
}

/// The groups' passes in the frame's order, appended to `passes`; returns
/// the diffuse light after SSS (the composite's input). `frame` is the
/// frame's own view: its targets as the geometry pass left them.
pub fn sss<'a>(
    passes: &mut Vec<Pass<'a>>,
    frame: &FrameView<'a, '_>,
    groups: &'a [GroupMethod],
    merge: &'a Merge,
) -> ImageId {
    let mixed = is_mixed(groups.len(), groups.iter().any(|g| g.fade.is_some()));
    let fades = || {
        groups
            .iter()
            .filter_map(|g| g.fade.as_ref().map(|f| (g, f)))
    };
    for (g, f) in fades() {
        passes.push(f.keep_pass(&group_view(frame, g), g.spec.index));
    }
    for g in groups {
        let i = g.spec.index;
        for mut p in g.method.passes(&group_view(frame, g)) {
            p.group = Some(i);
            if mixed {
                p.name = format!("#{i} {}", p.name);
            }
            passes.push(p);
        }
    }
    for (g, f) in fades() {
        passes.extend(f.passes(&group_view(frame, g), g.spec.index));
    }
    if mixed {
        for g in groups {
            let view = group_view(frame, g);
            passes.extend(merge.pass(&view, g.spec.index, g.method.output()));
        }
        for (g, f) in fades() {
            // The blend writes the frame's diffuse target (not the keep)
            // in the old setting's region.
            let view = FrameView {
                region: &f.scissors,
                ..group_view(frame, g)
            };
            passes.extend(merge.fade_pass(&view, g.spec.index, f.method.output(), f.spec.weight));
        }
    }
    output(groups, frame.targets)
}

/// What the composite reads: the one group's output, or the diffuse
/// target every group's result is merged into.
pub fn output(groups: &[GroupMethod], targets: &FrameTargets) -> ImageId {
    match groups {
        [one] => one.method.output(),
        _ => targets.diffuse,
    }
}
