//! The scene on the GPU: vertex/index buffers, material textures and uniforms.

use anyhow::Result;
use ash::vk;

use crate::scene::mesh::{Material, Object, Texture};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::memory::{Buffer, Image};
use crate::vk::pipeline::{Bind, DescriptorPool, Pipeline, Samplers};
use crate::vk::upload::{device_buffer, texture};

/// std140 layout of `MaterialUniforms` in geometry.frag.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaterialUniforms {
    pub base_color: [f32; 4],
    pub params: [f32; 4],
}

pub struct GpuObject {
    pub name: String,
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
    pub skin: bool,
    textures: Vec<Image>,
    uniforms: Buffer,
    pub material_set: vk::DescriptorSet,
}

fn upload_texture(
    ctx: &Context,
    name: &str,
    tex: Option<&Texture>,
    fallback: [u8; 4],
    format: vk::Format,
) -> Result<Image> {
    match tex {
        Some(t) => texture(
            ctx,
            name,
            vk::Extent2D {
                width: t.width,
                height: t.height,
            },
            format,
            &t.rgba8,
        ),
        None => texture(
            ctx,
            name,
            vk::Extent2D {
                width: 1,
                height: 1,
            },
            format,
            &fallback,
        ),
    }
}

impl GpuObject {
    pub fn new(
        ctx: &Context,
        name: &str,
        object: &Object,
        pool: &DescriptorPool,
        geometry: &Pipeline,
        samplers: &Samplers,
    ) -> Result<Self> {
        let mesh = &object.mesh;
        let vertices = device_buffer(
            ctx,
            &format!("{name} vertices"),
            bytemuck::cast_slice(&mesh.vertices),
            vk::BufferUsageFlags::VERTEX_BUFFER,
            AccessKind::VertexInputRead,
        )?;
        let indices = device_buffer(
            ctx,
            &format!("{name} indices"),
            bytemuck::cast_slice(&mesh.indices),
            vk::BufferUsageFlags::INDEX_BUFFER,
            AccessKind::VertexInputRead,
        )?;
        let m: &Material = &object.material;
        // Missing maps fall back to neutral 1x1 textures so one shader serves all.
        let albedo = upload_texture(
            ctx,
            &format!("{name} albedo"),
            m.base_color.as_ref(),
            [255; 4],
            vk::Format::R8G8B8A8_SRGB,
        )?;
        let normal = upload_texture(
            ctx,
            &format!("{name} normal map"),
            m.normal_map.as_ref(),
            [128, 128, 255, 255],
            vk::Format::R8G8B8A8_UNORM,
        )?;
        let spec = upload_texture(
            ctx,
            &format!("{name} specular map"),
            m.specular_map.as_ref(),
            [255; 4],
            vk::Format::R8G8B8A8_UNORM,
        )?;
        let u = MaterialUniforms {
            base_color: [
                m.base_color_factor[0],
                m.base_color_factor[1],
                m.base_color_factor[2],
                1.0,
            ],
            params: [
                m.roughness,
                m.specular_intensity,
                m.sss_strength,
                if m.skin { 1.0 } else { 0.0 },
            ],
        };
        let uniforms = Buffer::with_data(
            ctx,
            &format!("{name} material"),
            bytemuck::bytes_of(&u),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let material_set = pool.write_set(
            ctx,
            geometry,
            1,
            &[
                ("albedoTex", Bind::Texture(albedo.view)),
                ("normalTex", Bind::Texture(normal.view)),
                ("specTex", Bind::Texture(spec.view)),
                ("materialSampler", Bind::Sampler(samplers.linear_repeat)),
                (
                    "material",
                    Bind::Uniform {
                        buffer: uniforms.raw,
                        size: std::mem::size_of::<MaterialUniforms>() as u64,
                    },
                ),
            ],
        )?;
        Ok(GpuObject {
            name: name.to_string(),
            vertices,
            indices,
            index_count: mesh.indices.len() as u32,
            skin: m.skin,
            textures: vec![albedo, normal, spec],
            uniforms,
            material_set,
        })
    }

    /// The material's bindings (set 1 of the shaders that include lighting.glsl).
    pub fn material_binds(&self, samplers: &Samplers) -> Vec<(&'static str, Bind)> {
        vec![
            ("albedoTex", Bind::Texture(self.textures[0].view)),
            ("normalTex", Bind::Texture(self.textures[1].view)),
            ("specTex", Bind::Texture(self.textures[2].view)),
            ("materialSampler", Bind::Sampler(samplers.linear_repeat)),
            (
                "material",
                Bind::Uniform {
                    buffer: self.uniforms.raw,
                    size: std::mem::size_of::<MaterialUniforms>() as u64,
                },
            ),
        ]
    }

    pub fn bind_and_draw(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        unsafe {
            ctx.device
                .cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.raw], &[0]);
            ctx.device
                .cmd_bind_index_buffer(cmd, self.indices.raw, 0, vk::IndexType::UINT32);
            ctx.device
                .cmd_draw_indexed(cmd, self.index_count, 1, 0, 0, 0);
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.vertices.destroy(ctx);
        self.indices.destroy(ctx);
        self.uniforms.destroy(ctx);
        for t in &mut self.textures {
            t.destroy(ctx);
        }
    }
}
