//! The character-id pass (`--character-ids`): after the frame, every
//! character's skin again, depth-tested EQUAL against the frame's depth,
//! writing its frame index + 1. A child of `frame`, whose fields it reads.

use super::*;

/// Push constants of the character-id pass: the id.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct IdPush {
    id: f32,
}

const IDS_SHADER: &str = "geometry_ids.frag";

impl Frame {
    /// Adds the character-id pass (`--character-ids`) writing into `ids`
    /// (before the usages are derived: the pass declares its target).
    pub fn enable_character_ids(
        &mut self,
        ctx: &Context,
        res: &Resources,
        ids: ImageId,
    ) -> Result<()> {
        let ds_format = res.format(self.targets.depth_stencil);
        // The geometry pass's vertex shader, so positions match its depth exactly.
        self.ids_pipeline = Pipeline::graphics(
            ctx,
            &GraphicsDesc {
                name: "character ids".into(),
                vert: GEOMETRY_VERT,
                frag: Some(IDS_SHADER),
                color_formats: vec![res.format(ids)],
                depth_format: Some(ds_format),
                stencil_format: Some(ds_format),
                vertex_input: VertexInput::Mesh,
                cull: vk::CullModeFlags::BACK,
                depth_test: true,
                depth_write: false,
                depth_compare: vk::CompareOp::EQUAL,
                stencil: None,
                depth_bias: None,
                blend: Blend::None,
            },
        )?;
        // The frame's uniforms alone (the id shader reads nothing else).
        self.ids_set = GraphSet::new(res, &self.ids_pipeline, 0, self.frame_binds()[..1].to_vec());
        self.character_ids = Some(ids);
        self.write_instances(ctx)
    }

    /// After the frame (`--character-ids`): every head again, depth-tested
    /// EQUAL against the frame's depth, writing its frame index + 1 into
    /// `ids`. Set-up work, not frame cost; only the flag adds it.
    pub(super) fn character_ids<'a>(
        &'a self,
        passes: &mut Vec<Pass<'a>>,
        ids: ImageId,
        depth_stencil: ImageId,
    ) {
        let mut pass = self.reads_vertices(Pass::new("character ids", PassRole::Setup));
        let set = pass.set(&self.ids_set);
        passes.push(
            pass.color(ColorTarget::new(ids, Load::Clear([0.0; 4])))
                .depth_stencil(DepthStencil::test_only(depth_stencil).depth_test(true))
                .draws(None, self.triangles(|k| k == ObjectKind::Skin))
                .record(move |pc: &PassContext| {
                    let (ctx, cmd) = (pc.ctx, pc.cmd);
                    let p = &self.ids_pipeline;
                    pc.bind(p, &[set]);
                    p.bind_sets(ctx, cmd, 2, &[self.ids_instance_set]);
                    let slots = &self.instance_buffer.character_slots;
                    // Skin only: an id marks a character's skin pixels
                    // (its parts fail the EQUAL test where they cover it).
                    for obj in self.objects.iter().filter(|o| o.kind == ObjectKind::Skin) {
                        for (c, &slot) in slots.iter().enumerate() {
                            p.push(ctx, cmd, &IdPush { id: (c + 1) as f32 });
                            obj.draw_instances(ctx, cmd, slot, 1);
                        }
                    }
                }),
        );
    }
}
