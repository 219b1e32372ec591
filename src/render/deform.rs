//! The deform pass: each deforming object's morph targets blended, then its
//! skin's joints applied, into the vertex buffer every draw of the frame
//! reads (`deform.comp`; the CPU's twin is `scene::morph::deformed`), with
//! its positions at the previous frame's weights and joints beside them
//! (velocity, for the temporal anti-aliasing).
//!
//! A compute pass, not the vertex shader: the frame draws a character's
//! mesh in the shadow map, the geometry pass and the id pass (and a method
//! may draw it again), so blending in the vertex shader would redo the
//! targets and joints once per draw; written once, every draw reads plain
//! vertices (the thesis' stream-out pass, ch. 8, in today's form). An object
//! without a skin whose weights are all 0 is its rest mesh: no pass.

use anyhow::Result;
use ash::vk;

use crate::graph::{Binding, BufferId, GraphSet, Pass, PassContext, Resources, Storage};
use crate::scene::morph::Morph;
use crate::scene::skin::{Skin, SLOTS};
use crate::vk::barrier::AccessKind;
use crate::vk::context::Context;
use crate::vk::guard::Guard;
use crate::vk::memory::Buffer;
use crate::vk::pipeline::{Bind, DescriptorPool, Pipeline};
use crate::vk::shader_stats::alu_estimate;
use crate::vk::upload::device_buffer;
use crate::work::{PassRole, ShaderWork};
use bytemuck::Zeroable;
use glam::Mat4;
use gpu_allocator::MemoryLocation;

pub const SHADER: &str = "deform.comp";
/// Invocations per workgroup (`local_size_x` of the shader).
const GROUP: u32 = crate::shader_constants::DEFORM_GROUP_SIZE;
/// Floats per vertex (`Vertex`: position, normal, uv, tangent).
const VERTEX_FLOATS: u64 = 12;
/// A copy's list count meaning every vertex (deform.comp's ALL).
const ALL: u32 = u32::MAX;

/// std430 `Target` of the shader.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct TargetRow {
    first: u32,
    count: u32,
    offset: u32,
    flags: u32,
}

/// std430 `Influence` of the shader: joints of both sets, then weights.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct InfluenceRow {
    joints: [u32; SLOTS],
    weights: [f32; SLOTS],
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct DeformPush {
    vertex_count: u32,
    target_count: u32,
    /// 0 (no skin), 4 or 8.
    skin_slots: u32,
    /// Where the previous pose's matrices start in `Joints`.
    joint_count: u32,
    /// Copies deformed (one per crowd character, else 1).
    copies: u32,
    /// Matrices between one copy's palette and the next's in `Joints`: 0
    /// when the copies share one, else twice `joint_count`.
    joint_stride: u32,
}

/// Each copy's pose (a crowd's characters, in instance-slot order): its
/// morph weights and its skin's joint matrices, each list empty (every copy
/// the object's own) or one per copy.
#[derive(Default)]
pub struct Copies {
    pub weights: Vec<Vec<f32>>,
    pub joints: Vec<Vec<Mat4>>,
}

impl Copies {
    /// How many copies: the longer list's length, at least 1.
    pub fn count(&self) -> usize {
        self.weights.len().max(self.joints.len()).max(1)
    }
}

/// Which vertices each copy deforms: copy `c` (instance slot `c`) those of
/// level `copy_levels[c]` (`level_vertices`: sorted, once each).
pub struct Lists<'a> {
    pub copy_levels: &'a [u8],
    pub level_vertices: &'a [Vec<u32>],
}

/// The `Lists` buffer of the shader: a (first, count) pair per copy (count
/// `ALL`: every vertex, no list read), then each used level's vertices
/// once; the most vertices a copy deforms; and their sum over the copies.
fn flatten_lists(lists: Option<Lists>, copies: u32, vertex_count: u32) -> (Vec<u32>, u32, u64) {
    let Some(l) = lists else {
        let out = (0..copies).flat_map(|_| [0, ALL]).collect();
        return (
            out,
            vertex_count,
            u64::from(vertex_count) * u64::from(copies),
        );
    };
    let mut out = vec![0u32; 2 * copies as usize];
    let mut first_of: Vec<Option<u32>> = vec![None; l.level_vertices.len()];
    let (mut most, mut sum) = (0u32, 0u64);
    for c in 0..copies as usize {
        let level = l.copy_levels.get(c).map_or(0, |&x| x as usize);
        let level = level.min(l.level_vertices.len() - 1);
        let verts = &l.level_vertices[level];
        let first = match first_of[level] {
            Some(f) => f,
            None => {
                let f = out.len() as u32;
                out.extend_from_slice(verts);
                first_of[level] = Some(f);
                f
            }
        };
        out[2 * c] = first;
        out[2 * c + 1] = verts.len() as u32;
        most = most.max(verts.len() as u32);
        sum += verts.len() as u64;
    }
    (out, most, sum)
}

/// One morphing object's buffers on the GPU.
#[derive(Default)]
pub struct DeformObject {
    name: String,
    rest: Buffer,
    targets: Buffer,
    weights: Buffer,
    deltas: Buffer,
    influences: Buffer,
    joints: Buffer,
    lists: Buffer,
    previous: Buffer,
    /// The object's vertex buffer (written here, drawn by the frame).
    pub vertices: BufferId,
    previous_id: BufferId,
    set: GraphSet,
    vertex_count: u32,
    target_count: u32,
    skin_slots: u32,
    joint_count: u32,
    joint_stride: u32,
    copies: u32,
    /// The most vertices a copy deforms (the dispatch's width), and the
    /// share of the dispatched invocations that deform one.
    listed_most: u32,
    listed_share: f64,
    /// Offsets read per vertex, on average (what the work declares).
    offsets_per_vertex: f64,
}

/// A morphing object's vertices as the deform pass wrote them
/// (`Deform::read_back`): 12 floats a vertex (`Vertex`), and 3 a previous
/// position.
pub struct Deformed {
    pub name: String,
    pub vertices: Vec<f32>,
    pub previous: Vec<f32>,
}

/// Every morphing object's pass.
#[derive(Default)]
pub struct Deform {
    pipeline: Pipeline,
    pub objects: Vec<DeformObject>,
}

/// The offsets of `morph`, flattened as the shader reads them (per target:
/// positions, then normals, then tangents, 3 floats each), and its table.
fn flatten(morph: &Morph) -> (Vec<f32>, Vec<TargetRow>) {
    let mut deltas = Vec::new();
    let mut rows = Vec::new();
    for t in &morph.targets {
        let offset = deltas.len() as u32;
        for part in [&t.position, &t.normal, &t.tangent] {
            deltas.extend(part.iter().flatten());
        }
        rows.push(TargetRow {
            first: t.first as u32,
            count: t.len() as u32,
            offset,
            flags: u32::from(!t.normal.is_empty()) | (u32::from(!t.tangent.is_empty()) << 1),
        });
    }
    // A storage buffer may not be empty: a skin without targets binds one
    // row that covers no vertex, and one float.
    if deltas.is_empty() {
        deltas.push(0.0);
    }
    if rows.is_empty() {
        rows.push(TargetRow::zeroed());
    }
    (deltas, rows)
}

/// Each copy's weights as the shader reads them: (this frame's, the
/// previous frame's) per target, copy after copy; with no frame before the
/// first, the previous are these. One zero pair without targets.
fn flatten_weights(morph: &Morph, copies: &[Vec<f32>]) -> Vec<[f32; 2]> {
    let one = [morph.weights.clone()];
    let copies = if copies.is_empty() { &one[..] } else { copies };
    let mut out: Vec<[f32; 2]> = copies
        .iter()
        .flat_map(|w| w.iter().map(|&w| [w, w]))
        .collect();
    if out.is_empty() {
        out.push([0.0; 2]);
    }
    out
}

/// A skin's influences as the shader reads them, and its matrices (the
/// pose's, then the previous pose's; per copy, copy after copy, when the
/// copies have their own, the previous then the copy's own); one zero row
/// each without a skin.
fn flatten_skin(skin: Option<&Skin>, copies: &[Vec<Mat4>]) -> (Vec<InfluenceRow>, Vec<[f32; 16]>) {
    let Some(skin) = skin else {
        return (vec![InfluenceRow::zeroed()], vec![[0.0; 16]]);
    };
    let rows = skin
        .joints
        .iter()
        .zip(&skin.weights)
        .map(|(&joints, &weights)| InfluenceRow { joints, weights })
        .collect();
    let matrices = if copies.is_empty() {
        skin.matrices
            .iter()
            .chain(&skin.previous)
            .map(|m| m.to_cols_array())
            .collect()
    } else {
        copies
            .iter()
            .flat_map(|c| c.iter().chain(c))
            .map(|m| m.to_cols_array())
            .collect()
    };
    (rows, matrices)
}

impl Deform {
    /// The pass's pipeline (made once, whether or not anything morphs).
    pub fn new(ctx: &Context) -> Result<Self> {
        Ok(Deform {
            pipeline: Pipeline::compute(ctx, "deform", SHADER)?,
            objects: Vec::new(),
        })
    }

    /// Adds an object drawn from `vertices` (a vertex and storage buffer of
    /// the rest mesh's size) morphing by `morph`: its static buffers, and
    /// the vertex buffer tracked, so the draws that read it wait for the
    /// pass; `copies`: each copy's weights (a crowd's characters, in
    /// instance-slot order; empty: one copy at `morph`'s). Returns its
    /// tracked id.
    pub fn add(
        &mut self,
        ctx: &Context,
        res: &mut Resources,
        (name, vertices): (&str, vk::Buffer),
        morph: &Morph,
        copies: &Copies,
        lists: Option<Lists>,
    ) -> Result<BufferId> {
        let n = morph.rest.len() as u64;
        let (deltas, rows) = flatten(morph);
        let c = copies.count() as u64;
        let one = vec![morph.weights.clone(); c as usize];
        let weights = flatten_weights(
            morph,
            if copies.weights.is_empty() && c > 1 {
                &one
            } else {
                &copies.weights
            },
        );
        let (list_words, listed_most, listed_sum) = flatten_lists(lists, c as u32, n as u32);
        let joint_count = morph.skin.as_ref().map_or(0, |s| s.matrices.len() as u32);
        if let Some(bad) = copies
            .joints
            .iter()
            .find(|j| j.len() != joint_count as usize)
        {
            anyhow::bail!(
                "{name}: a copy has {} joint matrices for {joint_count}",
                bad.len()
            );
        }
        let (influences, joints) = flatten_skin(morph.skin.as_ref(), &copies.joints);
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        // Read back by tests (`read_back`).
        let readable = usage | vk::BufferUsageFlags::TRANSFER_SRC;
        let read = AccessKind::ComputeStorageRead;
        let mut o = DeformObject {
            name: name.to_string(),
            vertex_count: n as u32,
            target_count: morph.targets.len() as u32,
            skin_slots: morph.skin.as_ref().map_or(0, |s| s.slots as u32),
            joint_count,
            joint_stride: if copies.joints.is_empty() {
                0
            } else {
                2 * joint_count
            },
            copies: c as u32,
            listed_most,
            listed_share: listed_sum as f64
                / (u64::from(listed_most.div_ceil(GROUP) * GROUP) * c).max(1) as f64,
            offsets_per_vertex: rows.iter().map(|r| r.count as f64).sum::<f64>() / n.max(1) as f64,
            ..Default::default()
        };
        let upload = |what: &str, bytes: &[u8]| {
            device_buffer(ctx, &format!("{name} {what}"), bytes, usage, read)
        };
        o.rest = upload("rest vertices", bytemuck::cast_slice(&morph.rest))?;
        o.targets = upload("morph targets", bytemuck::cast_slice(&rows))?;
        // Host-visible: a frame stepping through a clip rewrites it between
        // frames (`set_weights`).
        o.weights = Buffer::with_data(
            ctx,
            &format!("{name} morph weights"),
            bytemuck::cast_slice(&weights),
            usage,
        )?;
        o.deltas = upload("morph offsets", bytemuck::cast_slice(&deltas))?;
        o.influences = upload("joint influences", bytemuck::cast_slice(&influences))?;
        // Host-visible too (`set_joints`).
        o.joints = Buffer::with_data(
            ctx,
            &format!("{name} joint matrices"),
            bytemuck::cast_slice(&joints),
            usage,
        )?;
        o.lists = upload("vertex lists", bytemuck::cast_slice(&list_words))?;
        let zeros = vec![0f32; (3 * n * c) as usize];
        o.previous = device_buffer(
            ctx,
            &format!("{name} previous positions"),
            bytemuck::cast_slice(&zeros),
            readable,
            read,
        )?;
        o.vertices = res.add_buffer(&format!("{name} vertices"), vertices);
        res.set_buffer_uploaded(o.vertices, AccessKind::VertexInputRead);
        o.previous_id = res.add_buffer(&format!("{name} previous positions"), o.previous.raw);
        res.set_buffer_uploaded(o.previous_id, read);
        let whole = |b: &Buffer, bytes: u64| {
            Binding::Fixed(Bind::Uniform {
                buffer: b.raw,
                size: bytes,
            })
        };
        o.set = GraphSet::new(
            res,
            &self.pipeline,
            0,
            vec![
                ("Rest", whole(&o.rest, 4 * VERTEX_FLOATS * n)),
                (
                    "Targets",
                    whole(
                        &o.targets,
                        (rows.len() * std::mem::size_of::<TargetRow>()) as u64,
                    ),
                ),
                ("Weights", whole(&o.weights, 8 * weights.len() as u64)),
                ("Deltas", whole(&o.deltas, 4 * deltas.len() as u64)),
                (
                    "Influences",
                    whole(
                        &o.influences,
                        (influences.len() * std::mem::size_of::<InfluenceRow>()) as u64,
                    ),
                ),
                ("Joints", whole(&o.joints, 64 * joints.len() as u64)),
                ("Lists", whole(&o.lists, 4 * list_words.len() as u64)),
                (
                    "Deformed",
                    Binding::StorageBuffer {
                        id: o.vertices,
                        offset: 0,
                        size: 4 * VERTEX_FLOATS * n * c,
                        storage: Storage::Write,
                    },
                ),
                (
                    "Previous",
                    Binding::StorageBuffer {
                        id: o.previous_id,
                        offset: 0,
                        size: 12 * n * c,
                        storage: Storage::Write,
                    },
                ),
            ],
        );
        let id = o.vertices;
        self.objects.push(o);
        Ok(id)
    }

    /// Object `index`'s weights for the next frame: `now` and `previous`
    /// per copy (each a weight per target), between frames (no frame in
    /// flight: the buffer is host-visible).
    pub fn set_weights(
        &mut self,
        index: usize,
        now: &[Vec<f32>],
        previous: &[Vec<f32>],
    ) -> Result<()> {
        let o = &mut self.objects[index];
        let per_copy = o.target_count as usize;
        if let Some(w) = now.iter().chain(previous).find(|w| w.len() != per_copy) {
            anyhow::bail!("{}: {} weights for {per_copy} targets", o.name, w.len());
        }
        let pairs: Vec<[f32; 2]> = now
            .iter()
            .zip(previous)
            .flat_map(|(n, p)| n.iter().zip(p).map(|(&n, &p)| [n, p]))
            .collect();
        anyhow::ensure!(
            pairs.len() == (o.copies * o.target_count) as usize,
            "{}: {} weights for {} copies of {} targets",
            o.name,
            pairs.len(),
            o.copies,
            o.target_count
        );
        o.weights.write(bytemuck::cast_slice(&pairs))
    }

    /// Object `index`'s joint matrices for the next frame: `now` and
    /// `previous`, one palette per copy (or one, when the copies share it),
    /// between frames as [`Deform::set_weights`].
    pub fn set_joints(
        &mut self,
        index: usize,
        now: &[Vec<Mat4>],
        previous: &[Vec<Mat4>],
    ) -> Result<()> {
        let o = &mut self.objects[index];
        let palettes = if o.joint_stride == 0 { 1 } else { o.copies };
        anyhow::ensure!(
            now.len() == palettes as usize && previous.len() == now.len(),
            "{}: {} palettes ({} previous) for {palettes}",
            o.name,
            now.len(),
            previous.len()
        );
        if let Some(bad) = now
            .iter()
            .chain(previous)
            .find(|j| j.len() != o.joint_count as usize)
        {
            anyhow::bail!(
                "{}: {} joint matrices for {}",
                o.name,
                bad.len(),
                o.joint_count
            );
        }
        let m: Vec<[f32; 16]> = now
            .iter()
            .zip(previous)
            .flat_map(|(n, p)| n.iter().chain(p))
            .map(|m| m.to_cols_array())
            .collect();
        o.joints.write(bytemuck::cast_slice(&m))
    }

    /// Writes the objects' sets (once the frame's pool exists).
    pub fn bind(&mut self, ctx: &Context, pool: &DescriptorPool, res: &Resources) -> Result<()> {
        for o in &mut self.objects {
            o.set.write(ctx, pool, res, &self.pipeline)?;
        }
        Ok(())
    }

    /// Each morphing object's pass, first in the frame.
    pub fn passes<'a>(&'a self, passes: &mut Vec<Pass<'a>>) {
        for o in &self.objects {
            let work = ShaderWork {
                shader: SHADER.into(),
                fetches: Vec::new(),
                alu: alu_estimate(SHADER, &[o.target_count, o.skin_slots]),
                // The rest vertex and the table, each covering target's
                // offsets (position, normal, tangent at most), the
                // influences and two matrices a slot (as many as are used:
                // the slots' count is the upper bound); the vertex and its
                // previous position written; with vertex lists, the list
                // entry too, and only for the invocations that deform one
                // (the rest of a copy's row return at once).
                storage_read_bytes: o.listed_share
                    * (8.0
                        + 4.0 * VERTEX_FLOATS as f64
                        + 24.0 * o.target_count as f64
                        + 36.0 * o.offsets_per_vertex
                        + if o.skin_slots > 0 {
                            std::mem::size_of::<InfluenceRow>() as f64 + 128.0 * o.skin_slots as f64
                        } else {
                            0.0
                        }),
                storage_write_bytes: o.listed_share * (4.0 * VERTEX_FLOATS as f64 + 12.0),
                shared_bytes: 0.0,
            };
            let push = DeformPush {
                vertex_count: o.vertex_count,
                target_count: o.target_count,
                skin_slots: o.skin_slots,
                joint_count: o.joint_count,
                copies: o.copies,
                joint_stride: o.joint_stride,
            };
            // Vertex work of the frame, with the geometry it feeds.
            let mut pass = Pass::new(format!("deform {}", o.name), PassRole::Geometry);
            let set = pass.set(&o.set);
            passes.push(
                pass.dispatch(work, [o.listed_most.div_ceil(GROUP), o.copies, 1], GROUP)
                    .record(move |pc: &PassContext| {
                        pc.bind(&self.pipeline, &[set]);
                        self.pipeline.push(pc.ctx, pc.cmd, &push);
                    }),
            );
        }
    }

    /// Every morphing object's vertices and previous positions as the last
    /// frame wrote them (for tests and dumps: after the frame's fence), with
    /// the object's name. The graph's barriers take each buffer from its
    /// last access to the copy.
    pub fn read_back(&self, ctx: &Context, res: &mut Resources) -> Result<Vec<Deformed>> {
        let mut out = Vec::new();
        for o in &self.objects {
            let n = o.vertex_count as u64 * o.copies as u64;
            let mut read = |id: BufferId, bytes: u64, what: &str| -> Result<Vec<f32>> {
                let name = format!("{} {what} read-back", o.name);
                let host = Guard::new(
                    ctx,
                    Buffer::new(
                        ctx,
                        &name,
                        bytes,
                        vk::BufferUsageFlags::TRANSFER_DST,
                        MemoryLocation::GpuToCpu,
                    )?,
                );
                let host_id = res.add_buffer(&name, host.raw);
                let src = res.raw_buffer(id);
                ctx.one_shot(&name, |cmd| {
                    res.transition(
                        ctx,
                        cmd,
                        &[],
                        &[
                            (id, AccessKind::TransferRead),
                            (host_id, AccessKind::TransferWrite),
                        ],
                    );
                    let region = [vk::BufferCopy {
                        src_offset: 0,
                        dst_offset: 0,
                        size: bytes,
                    }];
                    unsafe { ctx.device.cmd_copy_buffer(cmd, src, host.raw, &region) };
                    res.transition(ctx, cmd, &[], &[(host_id, AccessKind::HostRead)]);
                })?;
                res.truncate_buffers(host_id.0);
                Ok(bytemuck::cast_slice::<u8, f32>(&host.read()?[..bytes as usize]).to_vec())
            };
            let vertices = read(o.vertices, 4 * VERTEX_FLOATS * n, "vertices")?;
            let previous = read(o.previous_id, 12 * n, "previous positions")?;
            out.push(Deformed {
                name: o.name.clone(),
                vertices,
                previous,
            });
        }
        Ok(out)
    }

    pub fn destroy(&mut self, ctx: &Context) {
        for o in &mut self.objects {
            for b in [
                &mut o.rest,
                &mut o.targets,
                &mut o.weights,
                &mut o.deltas,
                &mut o.influences,
                &mut o.joints,
                &mut o.lists,
                &mut o.previous,
            ] {
                b.destroy(ctx);
            }
        }
        self.pipeline.destroy(ctx);
    }
}
