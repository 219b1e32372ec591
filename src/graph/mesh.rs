//! A triangle mesh on the GPU, drawn by raster passes: the one upload and
//! draw of vertex and index buffers (the frame's objects, tsd's unwrapped head).

use anyhow::Result;
use ash::vk;

use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::memory::Buffer;
use crate::vk::upload::device_buffer;

/// A triangle mesh on the GPU: vertex and index buffers (u32 indices) and one
/// way to draw it. The frame's objects and the methods that draw a mesh of
/// their own (tsd's unwrapped head) share it.
#[derive(Default)]
pub struct GpuMesh {
    pub vertices: Buffer,
    pub indices: Buffer,
    pub index_count: u32,
    /// Vertices of one copy of the mesh.
    pub vertex_count: u32,
    /// Copies of the vertices the buffer holds, one per instance slot when
    /// more than one (a crowd whose characters each deform their own: the
    /// deform pass writes them); 0 or 1: one shared by every instance.
    pub copies: u32,
    /// Its levels of detail (`scene::lod`): each level's first index and
    /// index count in the index buffer, the full mesh first; empty: the full
    /// mesh only.
    pub levels: Vec<(u32, u32)>,
    /// The level each instance slot draws (set by the frame once it knows
    /// where each character stands); empty: every slot the full mesh.
    pub slot_levels: Vec<u8>,
}

impl GpuMesh {
    /// Uploads `vertices` and `indices` into device-local buffers named after
    /// `name`; on an error nothing is left behind.
    pub fn upload<V: bytemuck::Pod>(
        ctx: &Context,
        name: &str,
        vertices: &[V],
        indices: &[u32],
    ) -> Result<Self> {
        Self::upload_with(ctx, name, vertices, indices, vk::BufferUsageFlags::empty())
    }

    /// [`GpuMesh::upload`] with a vertex buffer also usable as `extra` (a
    /// storage buffer the deform pass writes).
    pub fn upload_with<V: bytemuck::Pod>(
        ctx: &Context,
        name: &str,
        vertices: &[V],
        indices: &[u32],
        extra: vk::BufferUsageFlags,
    ) -> Result<Self> {
        Self::upload_copies(ctx, name, vertices, indices, extra, 1)
    }

    /// [`GpuMesh::upload_with`] with `copies` copies of the vertices, one
    /// per instance slot (`draw_instances` draws slot i from copy i).
    pub fn upload_copies<V: bytemuck::Pod>(
        ctx: &Context,
        name: &str,
        vertices: &[V],
        indices: &[u32],
        extra: vk::BufferUsageFlags,
        copies: u32,
    ) -> Result<Self> {
        let copies = copies.max(1);
        let all: Vec<V> = if copies > 1 {
            vertices.repeat(copies as usize)
        } else {
            vertices.to_vec()
        };
        let vertex_buffer = Guard::new(
            ctx,
            device_buffer(
                ctx,
                &format!("{name} vertices"),
                bytemuck::cast_slice(&all),
                vk::BufferUsageFlags::VERTEX_BUFFER | extra,
                AccessKind::VertexInputRead,
            )?,
        );
        let index_buffer = device_buffer(
            ctx,
            &format!("{name} indices"),
            bytemuck::cast_slice(indices),
            vk::BufferUsageFlags::INDEX_BUFFER,
            AccessKind::VertexInputRead,
        )?;
        Ok(GpuMesh {
            vertices: vertex_buffer.keep(),
            indices: index_buffer,
            index_count: indices.len() as u32,
            vertex_count: vertices.len() as u32,
            copies,
            levels: Vec::new(),
            slot_levels: Vec::new(),
        })
    }

    /// Triangles of one draw of the full mesh.
    pub fn triangles(&self) -> u64 {
        self.index_count as u64 / 3
    }

    /// Triangles instance slot `slot` draws (its level's).
    pub fn slot_triangles(&self, slot: usize) -> u64 {
        match self.slot_levels.get(slot) {
            Some(&l) => self.levels[l as usize].1 as u64 / 3,
            None => self.triangles(),
        }
    }

    /// The (first index, index count) slot `slot` draws.
    fn slot_range(&self, slot: u32) -> (u32, u32) {
        match self.slot_levels.get(slot as usize) {
            Some(&l) => self.levels[l as usize],
            None => (0, self.index_count),
        }
    }

    /// Binds the buffers and draws every triangle once.
    pub fn bind_and_draw(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        self.bind_and_draw_copy(ctx, cmd, 0);
    }

    /// [`GpuMesh::bind_and_draw`] from copy `copy` of the vertices (a mesh
    /// of several copies: each character its own pose); the one copy when
    /// there are no others.
    pub fn bind_and_draw_copy(&self, ctx: &Context, cmd: vk::CommandBuffer, copy: u32) {
        let offset = if self.copies > 1 {
            (copy * self.vertex_count) as i32
        } else {
            0
        };
        unsafe {
            ctx.device
                .cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.raw], &[0]);
            ctx.device
                .cmd_bind_index_buffer(cmd, self.indices.raw, 0, vk::IndexType::UINT32);
            ctx.device
                .cmd_draw_indexed(cmd, self.index_count, 1, 0, offset, 0);
        }
    }

    /// Binds the buffers and draws every triangle of instances
    /// `first..first + count` in one draw (the vertex shader reads each
    /// instance's model matrix by `gl_InstanceIndex`). Primitives are
    /// rasterised instance by instance, so this draws the same triangles in
    /// the same order as `count` draws of one instance each. A mesh of
    /// several copies draws each instance from its own copy (one draw each).
    pub fn draw_instances(&self, ctx: &Context, cmd: vk::CommandBuffer, first: u32, count: u32) {
        if count == 0 {
            return;
        }
        if self.copies > 1 || !self.slot_levels.is_empty() {
            unsafe {
                ctx.device
                    .cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.raw], &[0]);
                ctx.device
                    .cmd_bind_index_buffer(cmd, self.indices.raw, 0, vk::IndexType::UINT32);
            }
            // Runs of slots that draw the same range from the same vertices
            // in one instanced draw each.
            let mut i = first;
            while i < first + count {
                let range = self.slot_range(i);
                let mut n = 1;
                while self.copies <= 1 && i + n < first + count && self.slot_range(i + n) == range {
                    n += 1;
                }
                let offset = if self.copies > 1 {
                    (i * self.vertex_count) as i32
                } else {
                    0
                };
                unsafe {
                    ctx.device
                        .cmd_draw_indexed(cmd, range.1, n, range.0, offset, i);
                }
                i += n;
            }
            return;
        }
        unsafe {
            ctx.device
                .cmd_bind_vertex_buffers(cmd, 0, &[self.vertices.raw], &[0]);
            ctx.device
                .cmd_bind_index_buffer(cmd, self.indices.raw, 0, vk::IndexType::UINT32);
            ctx.device
                .cmd_draw_indexed(cmd, self.index_count, count, 0, 0, first);
        }
    }

    pub fn destroy(&mut self, ctx: &Context) {
        self.vertices.destroy(ctx);
        self.indices.destroy(ctx);
    }
}
