//! Texture-space diffusion's set-up: the checks of `Tsd::new`, the characters
//! placed (eq. 3.1-3.2's sizes, the culling predictions), their uniforms and
//! the atlas uploaded, the head uploaded with its islands, the shared maps
//! declared.

use anyhow::{bail, Result};
use ash::vk;
use glam::Vec4;

use super::pipelines::{make_pipelines, Pipelines};
use super::sets::SharedSets;
use super::{
    square, uv_max, Character, CharacterUniforms, Config, Cull, Maps, Tsd, CHARACTER_STRIDE,
    MAP_FORMAT, MAX_ISLANDS, STRETCH_FORMAT,
};
use crate::graph::mesh::GpuMesh;
use crate::graph::{GraphSet, ImageDesc, Resources};
use crate::method::MethodSetup;
use crate::scene::mesh::Vertex;
use crate::skin::tsd::{
    atlas, box_outside, clip_planes, depth_scale, map_size, nearest_corner_distance, projected_px,
    reference_distance, tsd_gaussians, CULL_COS, NO_CLIP,
};
use crate::skin::wrinkles;
use crate::vk::guard::Guard;
use crate::vk::memory::Buffer;
use crate::vk::pipeline::DescriptorPool;

impl Tsd {
    pub(super) fn new(s: &mut MethodSetup, optimised: bool) -> Result<Self> {
        let config = Config::parse(&s.options, optimised)?;
        let head = &s.scene.head;
        if !head.material.skin {
            bail!("texture-space diffusion needs a skin head to unwrap");
        }
        let atlas = atlas(&head.mesh, s.view.mm_per_unit);
        if atlas.transforms.len() > MAX_ISLANDS {
            bail!(
                "the head's UVs overlap and it has {} islands; texture-space diffusion packs at most {MAX_ISLANDS}",
                atlas.transforms.len()
            );
        }
        let f = &s.ctx.facts;
        if !f.shader_clip_distance {
            bail!("texture-space diffusion clips its unwrapped meshes with clip distances, which device '{}' does not support", f.name);
        }
        if config.size > f.max_image_dimension_2d {
            bail!(
                "--irradiance-size {} exceeds this device's largest image ({})",
                config.size,
                f.max_image_dimension_2d
            );
        }
        let n = s.instances.len() as u64;
        let side = config.size as u64;
        let need = side * side * (8 * (n + 3) + 8 + 5);
        if need > f.device_local_bytes / 2 {
            bail!(
                "{n} characters' texture-space maps at {side}^2 need {:.1} GB, more than half of this device's memory ({:.1} GB); lower --irradiance-size or --heads",
                need as f64 / 1e9,
                f.device_local_bytes as f64 / 1e9
            );
        }
        let t = Tsd {
            config,
            optimised,
            characters: Vec::new(),
            maps: declare_maps(s.res, &config, s.depth_stencil_format),
            atlas,
            gaussians: tsd_gaussians(),
            d_ref_units: 0.0,
            pipelines: Pipelines::default(),
            pool: DescriptorPool::default(),
            mesh: GpuMesh::default(),
            character_ubo: Buffer::default(),
            atlas_ubo: Buffer::default(),
            sets: SharedSets::default(),
            diffuse: s.targets.diffuse,
            shadow: s.targets.shadow,
            mask_format: s.depth_stencil_format,
            frame: 0,
            updating: vec![true; s.instances.len()],
            has_map: vec![false; s.instances.len()],
        };
        // Filled in by `build`: on an error, the guard frees what exists.
        let mut t = Guard::new(s.ctx, t);
        t.build(s)?;
        Ok(t.keep())
    }

    /// Places the characters, uploads the mesh and uniforms, makes the pipelines.
    fn build(&mut self, s: &mut MethodSetup) -> Result<()> {
        let cfg = self.config;
        let view = &s.view;
        let h = view.extent.height;
        self.d_ref_units = reference_distance(
            cfg.d_ref,
            view.mm_per_unit,
            h,
            view.camera.fovy_rad,
            cfg.size,
        );
        let vp = view.camera.view_proj(view.aspect());
        let frustum = clip_planes(vp);
        let planes = if cfg.clip { frustum } else { NO_CLIP };
        let bounds = s.scene.head.mesh.bounds();
        let head_height = s.scene.head_height_units();
        let mut uniforms = vec![0u8; CHARACTER_STRIDE as usize * s.instances.len()];
        for (k, &model) in s.instances.iter().enumerate() {
            let b = bounds.transformed(&model);
            let d = nearest_corner_distance(view.camera.eye, &b);
            let sc = if cfg.depth_sized {
                depth_scale(self.d_ref_units, d)
            } else {
                1.0
            };
            let size = map_size(sc, cfg.size);
            let head_px = projected_px(head_height, d, h, view.camera.fovy_rad);
            let zones = wrinkles::character_zones(s.scene, s.characters[k]);
            let u = CharacterUniforms {
                model: model.to_cols_array_2d(),
                planes: planes.map(|p: Vec4| p.to_array()),
                params: [
                    size as f32 / cfg.size as f32,
                    s.scene.head.material.sss_strength,
                    if cfg.cull == Cull::Alpha {
                        CULL_COS
                    } else {
                        -2.0
                    },
                    0.0,
                ],
                map_info: [1.0 / cfg.size as f32, uv_max(size, cfg.size), 0.0, 0.0],
                zones: wrinkles::zones_std430(zones),
            };
            let at = k * CHARACTER_STRIDE as usize;
            uniforms[at..at + std::mem::size_of::<CharacterUniforms>()]
                .copy_from_slice(bytemuck::bytes_of(&u));
            let map = s.res.declare(ImageDesc::new(
                &format!("tsd map c{k}"),
                square(cfg.size),
                MAP_FORMAT,
            ));
            self.characters.push(Character {
                wrinkled: zones.iter().any(|&z| z > 0.0),
                model,
                s: size as f32 / cfg.size as f32,
                size,
                d_nearest: d,
                head_px,
                outside: cfg.z_prepass && box_outside(&frustum, &b),
                far: cfg.z_prepass && head_px < cfg.far_px,
                map,
                uv_sets: [vk::DescriptorSet::null(); 4],
                final_set: GraphSet::default(),
            });
        }
        self.character_ubo = Buffer::with_data(
            s.ctx,
            "tsd characters",
            &uniforms,
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        let mut islands = vec![[0.0f32; 4]; MAX_ISLANDS];
        for (i, t) in self.atlas.transforms.iter().enumerate() {
            islands[i] = [t[0], t[1], t[2], 0.0];
        }
        self.atlas_ubo = Buffer::with_data(
            s.ctx,
            "tsd atlas",
            bytemuck::cast_slice(&islands),
            vk::BufferUsageFlags::UNIFORM_BUFFER,
        )?;
        self.upload_mesh(s)?;
        self.pipelines = make_pipelines(s.ctx, &cfg, self.mask_format, s.res.format(self.diffuse))?;
        self.pool = DescriptorPool::new(s.ctx, 16 + 6 * s.instances.len() as u32)?;
        self.describe_sets(s);
        Ok(())
    }

    /// The head's vertices with each tangent's w carrying its atlas island:
    /// one copy, or in a moving crowd one per character at its own pose
    /// (`Scene::character_head`: its stretch maps follow its expression),
    /// character k's drawn from copy k.
    fn upload_mesh(&mut self, s: &MethodSetup) -> Result<()> {
        let mesh = &s.scene.head.mesh;
        let own: Vec<Option<crate::scene::mesh::Mesh>> = s
            .characters
            .iter()
            .map(|&c| s.scene.character_head(c))
            .collect();
        let copies: Vec<&[Vertex]> = if own.iter().any(Option::is_some) {
            own.iter()
                .map(|m| m.as_ref().map_or(&mesh.vertices[..], |m| &m.vertices[..]))
                .collect()
        } else {
            vec![&mesh.vertices[..]]
        };
        let vertices: Vec<Vertex> = copies
            .iter()
            .flat_map(|c| c.iter().zip(&self.atlas.island_of))
            .map(|(v, &i)| {
                let hand = if v.tangent[3] < 0.0 { -1.0 } else { 1.0 };
                Vertex {
                    tangent: [
                        v.tangent[0],
                        v.tangent[1],
                        v.tangent[2],
                        hand * (1 + i) as f32,
                    ],
                    ..*v
                }
            })
            .collect();
        self.mesh = GpuMesh::upload(s.ctx, "tsd head", &vertices, &mesh.indices)?;
        self.mesh.vertex_count = mesh.vertices.len() as u32;
        self.mesh.copies = copies.len() as u32;
        Ok(())
    }
}

fn declare_maps(res: &mut Resources, cfg: &Config, mask_format: vk::Format) -> Maps {
    let e = square(cfg.size);
    Maps {
        irradiance: res.declare(ImageDesc::new("tsd irradiance", e, MAP_FORMAT)),
        temp: res.declare(ImageDesc::new("tsd temp", e, MAP_FORMAT)),
        pong: res.declare(ImageDesc::new("tsd pong", e, MAP_FORMAT)),
        stretch_u: res.declare(ImageDesc::new("tsd stretch u", e, STRETCH_FORMAT)),
        stretch_v: res.declare(ImageDesc::new("tsd stretch v", e, STRETCH_FORMAT)),
        mask: cfg
            .masked()
            .then(|| res.declare(ImageDesc::new("tsd mask", e, mask_format))),
    }
}
