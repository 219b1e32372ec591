//! Animations: a glTF file's clips read into `crate::scene::animation`'s
//! channels, every sampler checked (times increasing and finite, values
//! matching them, a node that exists, weights as many as its mesh's
//! targets), each error one line naming the animation and the channel.

use anyhow::{anyhow, bail, Result};
use gltf::animation::{Interpolation as GltfInterpolation, Property};

use crate::scene::animation::{Channel, Clip, Interpolation, Path};
use crate::scene::gltf_accessor::{read_floats, Use};
use crate::scene::gltf_source::{short, Source};

/// Every animation of the file, in file order.
pub(super) fn clips(src: &Source) -> Result<Vec<Clip>> {
    src.doc
        .animations()
        .map(|a| {
            let name = a
                .name()
                .map(short)
                .unwrap_or_else(|| format!("#{}", a.index()));
            let channels = a
                .channels()
                .enumerate()
                .map(|(k, c)| channel(src, &c, &format!("animation '{name}' channel {k}")))
                .collect::<Result<Vec<_>>>()?;
            Ok(Clip { name, channels })
        })
        .collect()
}

fn channel(src: &Source, c: &gltf::animation::Channel, what: &str) -> Result<Channel> {
    let target = c.target();
    let node = target.node();
    let path = match target.property() {
        Property::Translation => Path::Translation,
        Property::Rotation => Path::Rotation,
        Property::Scale => Path::Scale,
        Property::MorphTargetWeights => Path::Weights,
    };
    let sampler = c.sampler();
    let interpolation = match sampler.interpolation() {
        GltfInterpolation::Linear => Interpolation::Linear,
        GltfInterpolation::Step => Interpolation::Step,
        GltfInterpolation::CubicSpline => Interpolation::CubicSpline,
    };
    let times = read_floats(
        src,
        &sampler.input(),
        Use::KeyTimes,
        &format!("{what}: input"),
    )?;
    let usage = match path {
        Path::Translation | Path::Scale => Use::KeyVec3,
        Path::Rotation => Use::KeyVec4,
        Path::Weights => Use::KeyScalar,
    };
    let values = read_floats(src, &sampler.output(), usage, &format!("{what}: output"))?;
    let width = match path {
        Path::Translation | Path::Scale => 3,
        Path::Rotation => 4,
        Path::Weights => {
            let mesh = node.mesh().ok_or_else(|| {
                anyhow!(
                    "{what} animates the morph weights of node {}, which has no mesh",
                    node.index()
                )
            })?;
            let targets = mesh
                .primitives()
                .map(|p| p.morph_targets().count())
                .max()
                .unwrap_or(0);
            if targets == 0 {
                bail!(
                    "{what} animates the morph weights of mesh {}, which has no morph targets",
                    mesh.index()
                );
            }
            targets
        }
    };
    let ch = Channel {
        node: node.index(),
        path,
        interpolation,
        times,
        values,
        width,
    };
    ch.check(what)?;
    Ok(ch)
}
