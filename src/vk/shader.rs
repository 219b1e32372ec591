//! Embedded SPIR-V (compiled from `shaders/` by build.rs) and the reflection that
//! builds descriptor-set layouts and push-constant ranges. No layout is typed by
//! hand: it is read off the modules.

use std::collections::BTreeMap;

use anyhow::{anyhow, bail, Context as _, Result};
use ash::vk;
use spirv_reflect::types::{ReflectDescriptorType, ReflectShaderStageFlags};

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

/// SPIR-V bytes of the shader file `name` (e.g. "separable_blur.frag").
pub fn spirv(name: &str) -> Result<&'static [u8]> {
    SHADERS
        .iter()
        .find(|(n, _)| *n == name)
        .map(|(_, b)| *b)
        .ok_or_else(|| anyhow!("no shader named '{name}' was built from shaders/"))
}

/// SPIR-V as 32-bit words (the embedded bytes carry no alignment guarantee).
pub fn words(bytes: &[u8]) -> Result<Vec<u32>> {
    if bytes.len() % 4 != 0 {
        bail!("SPIR-V size {} is not a multiple of 4", bytes.len());
    }
    Ok(bytes
        .chunks_exact(4)
        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect())
}

/// One descriptor binding as the shaders declare it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BindingInfo {
    pub set: u32,
    pub binding: u32,
    /// Variable name (or block type name for an anonymous uniform block).
    pub name: String,
    pub descriptor_type: vk::DescriptorType,
    pub count: u32,
    pub stages: vk::ShaderStageFlags,
}

/// The merged interface of the stages of one pipeline.
#[derive(Clone, Debug, Default)]
pub struct Reflection {
    pub bindings: Vec<BindingInfo>,
    /// One range covering every stage's push constants (offset, size, stages).
    pub push_constants: Option<(u32, u32, vk::ShaderStageFlags)>,
}

fn stage_flags(s: ReflectShaderStageFlags) -> vk::ShaderStageFlags {
    let mut f = vk::ShaderStageFlags::empty();
    if s.contains(ReflectShaderStageFlags::VERTEX) {
        f |= vk::ShaderStageFlags::VERTEX;
    }
    if s.contains(ReflectShaderStageFlags::FRAGMENT) {
        f |= vk::ShaderStageFlags::FRAGMENT;
    }
    if s.contains(ReflectShaderStageFlags::COMPUTE) {
        f |= vk::ShaderStageFlags::COMPUTE;
    }
    f
}

fn descriptor_type(t: ReflectDescriptorType) -> Result<vk::DescriptorType> {
    Ok(match t {
        ReflectDescriptorType::Sampler => vk::DescriptorType::SAMPLER,
        ReflectDescriptorType::SampledImage => vk::DescriptorType::SAMPLED_IMAGE,
        ReflectDescriptorType::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
        ReflectDescriptorType::UniformBuffer => vk::DescriptorType::UNIFORM_BUFFER,
        ReflectDescriptorType::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
        other => bail!("descriptor type {other:?} is not used by dermis"),
    })
}

/// Reflects the given stages and merges them into one interface.
pub fn reflect(stages: &[&str]) -> Result<Reflection> {
    let mut by_slot: BTreeMap<(u32, u32), BindingInfo> = BTreeMap::new();
    let mut pc: Option<(u32, u32, vk::ShaderStageFlags)> = None;
    for name in stages {
        let bytes = spirv(name)?;
        let module = spirv_reflect::ShaderModule::load_u8_data(bytes)
            .map_err(|e| anyhow!("reflecting {name}: {e}"))?;
        let stage = stage_flags(module.get_shader_stage());
        let bindings = module
            .enumerate_descriptor_bindings(None)
            .map_err(|e| anyhow!("reflecting bindings of {name}: {e}"))?;
        for b in bindings {
            let ty = descriptor_type(b.descriptor_type)
                .with_context(|| format!("binding {} of {name}", b.name))?;
            let mut nm = b.name.clone();
            if nm.is_empty() {
                if let Some(td) = &b.type_description {
                    nm = td.type_name.clone();
                }
            }
            let entry = by_slot.entry((b.set, b.binding)).or_insert(BindingInfo {
                set: b.set,
                binding: b.binding,
                name: nm.clone(),
                descriptor_type: ty,
                count: b.count.max(1),
                stages: vk::ShaderStageFlags::empty(),
            });
            if entry.descriptor_type != ty {
                bail!(
                    "set {} binding {} is {:?} in one stage and {ty:?} in {name}",
                    b.set,
                    b.binding,
                    entry.descriptor_type
                );
            }
            entry.stages |= stage;
        }
        let blocks = module
            .enumerate_push_constant_blocks(None)
            .map_err(|e| anyhow!("reflecting push constants of {name}: {e}"))?;
        for blk in blocks {
            let (lo, hi) = (blk.offset, blk.offset + blk.size);
            pc = Some(match pc {
                None => (lo, hi - lo, stage),
                Some((o, s, st)) => {
                    let nlo = o.min(lo);
                    let nhi = (o + s).max(hi);
                    (nlo, nhi - nlo, st | stage)
                }
            });
        }
    }
    Ok(Reflection {
        bindings: by_slot.into_values().collect(),
        push_constants: pc,
    })
}

impl Reflection {
    pub fn set_count(&self) -> u32 {
        self.bindings.iter().map(|b| b.set + 1).max().unwrap_or(0)
    }

    pub fn find(&self, set: u32, name: &str) -> Option<&BindingInfo> {
        self.bindings
            .iter()
            .find(|b| b.set == set && b.name == name)
    }

    /// Descriptor-set layouts, one per set index (empty layouts fill gaps).
    pub fn create_set_layouts(
        &self,
        ctx: &super::context::Context,
        label: &str,
    ) -> Result<Vec<vk::DescriptorSetLayout>> {
        // On an error, the guard frees the layouts made so far.
        let mut layouts = super::guard::Guard::new(ctx, Vec::new());
        for set in 0..self.set_count() {
            let bindings: Vec<vk::DescriptorSetLayoutBinding> = self
                .bindings
                .iter()
                .filter(|b| b.set == set)
                .map(|b| {
                    vk::DescriptorSetLayoutBinding::default()
                        .binding(b.binding)
                        .descriptor_type(b.descriptor_type)
                        .descriptor_count(b.count)
                        .stage_flags(b.stages)
                })
                .collect();
            let l = ctx.create(
                &format!("descriptor set layout {set} of '{label}'"),
                |d| unsafe {
                    d.create_descriptor_set_layout(
                        &vk::DescriptorSetLayoutCreateInfo::default().bindings(&bindings),
                        None,
                    )
                },
            )?;
            ctx.name(l, &format!("{label} set {set}"));
            layouts.push(l);
        }
        Ok(layouts.keep())
    }
}

pub fn create_module(ctx: &super::context::Context, name: &str) -> Result<vk::ShaderModule> {
    let code = words(spirv(name)?)?;
    ctx.creation_step(&format!("shader module {name}"))?;
    let m = unsafe {
        ctx.device
            .create_shader_module(&vk::ShaderModuleCreateInfo::default().code(&code), None)
    }
    .map_err(super::error::Error::from)
    .with_context(|| format!("creating shader module {name}"))?;
    ctx.name(m, name);
    Ok(m)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every embedded module parses and validates with naga (an independent
    /// SPIR-V front end), so a glslang quirk can't slip into a driver.
    #[test]
    fn every_shader_validates_with_naga() {
        assert!(!SHADERS.is_empty());
        for (name, bytes) in SHADERS {
            let module =
                naga::front::spv::parse_u8_slice(bytes, &naga::front::spv::Options::default())
                    .unwrap_or_else(|e| panic!("naga cannot parse {name}: {e:?}"));
            let mut v = naga::valid::Validator::new(
                naga::valid::ValidationFlags::all(),
                naga::valid::Capabilities::all(),
            );
            v.validate(&module)
                .unwrap_or_else(|e| panic!("naga rejects {name}: {e:?}"));
        }
    }

    #[test]
    fn reflection_finds_sss_interface() {
        let r = reflect(&["fullscreen.vert", "separable_blur.frag"]).unwrap();
        let color = r.find(0, "colorTex").expect("colorTex binding");
        assert_eq!(color.descriptor_type, vk::DescriptorType::SAMPLED_IMAGE);
        let sampler = r.find(0, "linearClamp").expect("linearClamp binding");
        assert_eq!(sampler.descriptor_type, vk::DescriptorType::SAMPLER);
        assert_eq!(color.stages, vk::ShaderStageFlags::FRAGMENT);
        assert!(r.find(0, "depthTex").is_some());
        assert!(r
            .bindings
            .iter()
            .any(|b| b.descriptor_type == vk::DescriptorType::UNIFORM_BUFFER));
        let (_, size, stages) = r.push_constants.expect("push constants");
        assert!(size >= 16);
        assert!(stages.contains(vk::ShaderStageFlags::FRAGMENT));
    }

    /// Every resource binding naga finds in a module is in the reflected
    /// interface: a binding the layout lacks is undefined behaviour (lavapipe
    /// crashes in pipeline creation), and the validation layer may not get the
    /// chance to say so.
    #[test]
    fn reflection_sees_every_binding_naga_sees() {
        for (name, bytes) in SHADERS {
            let module =
                naga::front::spv::parse_u8_slice(bytes, &naga::front::spv::Options::default())
                    .unwrap();
            let r = reflect(&[name]).unwrap();
            for (_, var) in module.global_variables.iter() {
                if let Some(b) = &var.binding {
                    assert!(
                        r.bindings
                            .iter()
                            .any(|x| x.set == b.group && x.binding == b.binding),
                        "{name}: set {} binding {} ({:?}) is missing from the reflected layout",
                        b.group,
                        b.binding,
                        var.name
                    );
                }
            }
        }
    }

    /// Every compute module's workgroup, read back from its SPIR-V (naga's
    /// reflection), is the side the Rust dispatches divide by
    /// (`shader_constants::COMPUTE_GROUP_SIDE` for the ground truth's,
    /// `SSS_TILE_SIDE` for the compute path's tiles): a shader that wrote its
    /// own local size, or a dispatch sized by another, fails here.
    #[test]
    fn compute_workgroups_are_the_shared_side() {
        use crate::shader_constants::{COMPUTE_GROUP_SIDE, DEFORM_GROUP_SIZE, SSS_TILE_SIDE};
        let mut seen = 0;
        for (name, bytes) in SHADERS {
            let module =
                naga::front::spv::parse_u8_slice(bytes, &naga::front::spv::Options::default())
                    .unwrap();
            let size = if name.starts_with("reference_") {
                [COMPUTE_GROUP_SIDE, COMPUTE_GROUP_SIDE, 1]
            } else if name.starts_with("deform.") {
                [DEFORM_GROUP_SIZE, 1, 1]
            } else {
                [SSS_TILE_SIDE, SSS_TILE_SIDE, 1]
            };
            for e in &module.entry_points {
                if e.stage == naga::ShaderStage::Compute {
                    assert_eq!(e.workgroup_size, size, "{name}");
                    seen += 1;
                }
            }
        }
        // Seventeen shaders (three of the ground truth per profile, seven of
        // the compute path, the 2D gather, the compute ceiling probes of
        // fetches and of shared memory, the deform pass), each also in its
        // fetch-counting build.
        assert_eq!(seen, 34);
    }

    #[test]
    fn unknown_shader_is_an_error() {
        assert!(spirv("nope.frag").is_err());
    }
}
