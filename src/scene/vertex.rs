//! The vertex as the GPU's vertex buffers hold it (the frame's meshes, the
//! deform pass's input and output).

/// One vertex exactly as the vertex buffer holds it (48 bytes, no padding), so a
/// `&[Vertex]` can be uploaded with `bytemuck::cast_slice` without repacking.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub uv: [f32; 2],
    /// xyz: tangent along +u; w: handedness (+1 or -1) so the shader can rebuild the
    /// bitangent as `cross(normal, tangent.xyz) * tangent.w` (mirrored UVs flip it).
    pub tangent: [f32; 4],
}
