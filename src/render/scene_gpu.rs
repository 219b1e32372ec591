//! The scene on the GPU: vertex/index buffers, material textures and uniforms.

use anyhow::Result;
use ash::vk;

use crate::graph::mesh::GpuMesh;
use crate::scene::mesh::{Material, Object, Texture};
use crate::scene::texel_params;
use crate::vk::context::Context;
use crate::vk::guard::{Destroy, Guard};
use crate::vk::memory::{Buffer, Image};
use crate::vk::pipeline::{Bind, DescriptorPool, Pipeline, Samplers};
use crate::vk::upload::texture;

/// std140 layout of `MaterialUniforms` in geometry.frag.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct MaterialUniforms {
    pub base_color: [f32; 4],
    pub params: [f32; 4],
    /// x: 1 when specTex's G holds a roughness map (`scene::texel_params`);
    /// y: 1 when the material has wrinkle maps (`scene::wrinkle_maps`).
    pub maps: [f32; 4],
}

/// What an object is to the frame: how often it is drawn and whether it
/// writes the skin stencil.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObjectKind {
    /// A character's scattered skin: every character, its group's stencil code.
    Skin,
    /// A character's other part (eyes, teeth, cloth; or a head without skin):
    /// every character, stencil 0.
    Part,
    /// Drawn once, stencil 0.
    Backdrop,
}

impl ObjectKind {
    /// Drawn once per character (skin and parts), not once per frame.
    pub fn per_character(self) -> bool {
        self != ObjectKind::Backdrop
    }
}

pub struct GpuObject {
    pub name: String,
    pub mesh: GpuMesh,
    pub kind: ObjectKind,
    /// Its vertex buffer as the graph tracks it, when the deform pass writes
    /// it (`Frame::enable_deform`): every draw of it declares the read.
    pub deformed: Option<crate::graph::BufferId>,
    /// Each level of detail's error (object units), the full mesh's 0 first;
    /// empty without levels.
    pub level_errors: Vec<f32>,
    /// Each level's vertices (sorted, once each): what the deform pass
    /// writes for a copy drawn at that level.
    pub level_vertices: Vec<Vec<u32>>,
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
    let Some(t) = tex else {
        let one = vk::Extent2D {
            width: 1,
            height: 1,
        };
        return texture(ctx, name, one, format, &fallback);
    };
    let max = ctx.facts.max_image_dimension_2d;
    let fitted = fit_to_device(name, t, max);
    let t = fitted.as_ref().unwrap_or(t);
    texture(
        ctx,
        name,
        vk::Extent2D {
            width: t.width,
            height: t.height,
        },
        format,
        &t.rgba8,
    )
}

/// A copy of `t` box-filtered down to `max` texels a side when it is larger
/// (a device cannot create a bigger image), with a warning; `None` when it fits.
pub fn fit_to_device(name: &str, t: &Texture, max: u32) -> Option<Texture> {
    if t.width <= max && t.height <= max {
        return None;
    }
    let mut small = t.clone();
    small.downscale_to_fit(max);
    eprintln!(
        "warning: texture '{name}' is {}x{}, more than this device's {max} texels a side: downscaled to {}x{}",
        t.width, t.height, small.width, small.height
    );
    Some(small)
}

impl GpuObject {
    /// Uploads `object`; on an error, the guard destroys whatever was made.
    pub fn new(
        ctx: &Context,
        name: &str,
        kind: ObjectKind,
        // The object, the copies of its vertices (`GpuMesh::copies`),
        // whether it gets levels of detail (`scene::lod`), and whether its
        // wrinkle maps are read (a character's expression weighs a zone).
        (object, copies, lod, wrinkled): (&Object, u32, bool, bool),
        pool: &DescriptorPool,
        geometry: &Pipeline,
        samplers: &Samplers,
    ) -> Result<Self> {
        let mut g = Guard::new(
            ctx,
            GpuObject {
                name: name.to_string(),
                mesh: GpuMesh::default(),
                kind,
                deformed: None,
                level_errors: Vec::new(),
                level_vertices: Vec::new(),
                textures: Vec::new(),
                uniforms: Buffer::default(),
                material_set: vk::DescriptorSet::null(),
            },
        );
        g.upload(
            ctx,
            (object, copies, lod, wrinkled),
            pool,
            geometry,
            samplers,
        )?;
        Ok(g.keep())
    }

    fn upload(
        &mut self,
        ctx: &Context,
        (object, copies, lod, wrinkled): (&Object, u32, bool, bool),
        pool: &DescriptorPool,
        geometry: &Pipeline,
        samplers: &Samplers,
    ) -> Result<()> {
        let name = self.name.clone();
        let mesh = &object.mesh;
        // A morphing object's vertices are written by the deform pass too.
        let extra = if object.morph.at_rest() && copies <= 1 {
            vk::BufferUsageFlags::empty()
        } else {
            // Written by the deform pass, read back by tests.
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC
        };
        // With levels: every level's indices in one buffer, the full mesh's
        // first.
        let levels = if lod {
            crate::scene::lod::levels(mesh)
        } else {
            Vec::new()
        };
        let all: Vec<u32> = levels
            .iter()
            .flat_map(|l| l.indices.iter().copied())
            .collect();
        let indices = if levels.is_empty() {
            &mesh.indices
        } else {
            &all
        };
        self.mesh = GpuMesh::upload_copies(ctx, &name, &mesh.vertices, indices, extra, copies)?;
        if !levels.is_empty() {
            let mut first = 0u32;
            for l in &levels {
                self.mesh.levels.push((first, l.indices.len() as u32));
                first += l.indices.len() as u32;
            }
            self.mesh.index_count = mesh.indices.len() as u32;
            self.level_errors = levels.iter().map(|l| l.error).collect();
            self.level_vertices = levels
                .iter()
                .map(|l| {
                    let mut v = l.indices.clone();
                    v.sort_unstable();
                    v.dedup();
                    v
                })
                .collect();
        }
        let m: &Material = &object.material;
        // The per-texel parameters in one texture, read in one fetch.
        let packed = texel_params::pack(
            m.specular_map.as_ref(),
            m.roughness_map.as_ref(),
            m.sss_map.as_ref(),
        );
        // Missing maps fall back to neutral 1x1 textures so one shader serves all.
        let unorm = vk::Format::R8G8B8A8_UNORM;
        let maps = [
            (
                "albedo",
                m.base_color.as_ref(),
                [255; 4],
                vk::Format::R8G8B8A8_SRGB,
            ),
            (
                "normal map",
                m.normal_map.as_ref(),
                [128, 128, 255, 255],
                unorm,
            ),
            (
                "texel parameters",
                packed.as_ref().map(|p| &p.texture),
                [255; 4],
                unorm,
            ),
        ];
        // The wrinkle map and its masks, when they are read; else the shader
        // returns before any fetch of them, and their bindings take the
        // albedo (`material_binds`).
        let wrinkles = m.wrinkles.as_ref().filter(|_| wrinkled).map(|w| {
            [
                ("wrinkle map", &w.wrinkle),
                ("wrinkle mask 0", &w.masks[0]),
                ("wrinkle mask 1", &w.masks[1]),
            ]
            .map(|(what, t)| (what, Some(t), [0; 4], unorm))
        });
        for (what, tex, fallback, format) in maps.into_iter().chain(wrinkles.into_iter().flatten())
        {
            let t = upload_texture(ctx, &format!("{name} {what}"), tex, fallback, format)?;
            self.textures.push(t);
        }
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
            maps: [
                if packed.is_some_and(|p| p.roughness_from_map) {
                    1.0
                } else {
                    0.0
                },
                if wrinkles.is_some() { 1.0 } else { 0.0 },
                0.0,
                0.0,
            ],
        };
        self.uniforms = Buffer::with_data(
            ctx,
            &format!("{name} material"),
            bytemuck::bytes_of(&u),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        self.material_set = pool.write_set(ctx, geometry, 1, &self.material_binds(samplers))?;
        Ok(())
    }

    /// The material's bindings (set 1 of the shaders that include lighting.glsl).
    pub fn material_binds(&self, samplers: &Samplers) -> Vec<(&'static str, Bind)> {
        vec![
            ("albedoTex", Bind::Texture(self.textures[0].view)),
            ("normalTex", Bind::Texture(self.textures[1].view)),
            ("specTex", Bind::Texture(self.textures[2].view)),
            ("wrinkleTex", Bind::Texture(self.wrinkle_view(0))),
            ("wrinkleMask0", Bind::Texture(self.wrinkle_view(1))),
            ("wrinkleMask1", Bind::Texture(self.wrinkle_view(2))),
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

    /// The wrinkle texture `k` (the map, mask 0, mask 1), or the albedo where
    /// there are none (the material's `maps.y` is then 0: never fetched).
    fn wrinkle_view(&self, k: usize) -> vk::ImageView {
        self.textures.get(3 + k).unwrap_or(&self.textures[0]).view
    }

    pub fn bind_and_draw(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        self.mesh.bind_and_draw(ctx, cmd);
    }

    /// Instances `first..first + count` in one draw (`GpuMesh::draw_instances`).
    pub fn draw_instances(&self, ctx: &Context, cmd: vk::CommandBuffer, first: u32, count: u32) {
        self.mesh.draw_instances(ctx, cmd, first, count);
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.mesh.destroy(ctx);
        self.uniforms.destroy(ctx);
        for t in &mut self.textures {
            t.destroy(ctx);
        }
    }
}

impl Destroy for GpuObject {
    fn destroy(&mut self, ctx: &Context) {
        GpuObject::destroy(self, ctx)
    }
}
