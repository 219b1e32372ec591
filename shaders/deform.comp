#version 450
#extension GL_GOOGLE_include_directive : require
// The deform pass (issue 29): an object's morph targets blended, then its
// skin's joints applied (glTF's order), into the vertex buffer every draw of the frame reads (the thesis' stream-out pass,
// ch. 8, as a compute pass: written once a frame, drawn by the shadow map,
// the geometry pass and every method's mesh passes), and its positions at
// the previous frame's weights beside them (the velocity the temporal
// anti-aliasing reads). src/scene/morph.rs's `apply` and src/scene/skin.rs's
// `apply` are this, operation for operation: `precise` keeps each product and
// sum rounded alone, so the CPU's vertices are these to the bit.
// No fetch counter: it reads buffers only (the counting build counts
// texture fetches), so its counting build is this shader unchanged.
#include "shader_constants.glsl"
layout(local_size_x = DEFORM_GROUP_SIZE) in;

// The object's rest vertices: position 3, normal 3, uv 2, tangent 4 floats.
layout(set = 0, binding = 0, std430) readonly buffer Rest { float rest[]; };
struct Target {
    uint first;      // first vertex it covers
    uint count;      // vertices it covers
    uint offset;     // its offsets in `deltas` (floats): positions, then normals, tangents
    uint flags;      // 1: normals, 2: tangents
};
layout(set = 0, binding = 1, std430) readonly buffer Targets { Target targets[]; };
// Per copy (a crowd's characters, in instance-slot order), per target: this
// frame's weight and the previous frame's.
layout(set = 0, binding = 7, std430) readonly buffer Weights { vec2 weights[]; };
layout(set = 0, binding = 2, std430) readonly buffer Deltas { float deltas[]; };
// Copy after copy: each the object's vertex count long.
layout(set = 0, binding = 3, std430) buffer Deformed { float deformed[]; };
layout(set = 0, binding = 4, std430) buffer Previous { float previous[]; };
// Per vertex: its joints and their weights (two sets of four; unused 0).
struct Influence { uvec4 j0; uvec4 j1; vec4 w0; vec4 w1; };
layout(set = 0, binding = 5, std430) readonly buffer Influences { Influence influences[]; };
// The joint matrices at this frame's pose, then at the previous frame's;
// copy after copy (jointStride apart) when each copy has its own pose.
layout(set = 0, binding = 6, std430) readonly buffer Joints { mat4 joints[]; };
// Which vertices each copy deforms (a crowd's copy, drawn at a level of
// detail, only that level's): a (first, count) pair per copy, then the
// lists. Count ALL: every vertex, in order, no list read.
layout(set = 0, binding = 8, std430) readonly buffer Lists { uint lists[]; };
const uint ALL = 0xffffffffu;
// skinSlots: 0 (no skin), 4 or 8; jointCount: where the previous matrices
// start; jointStride: matrices from one copy's palette to the next (0: one
// palette shared).
layout(push_constant) uniform Push {
    uint vertexCount; uint targetCount; uint skinSlots; uint jointCount; uint copies;
    uint jointStride;
} pc;

const uint STRIDE = 12u;

vec3 delta(uint at) {
    return vec3(deltas[at], deltas[at + 1u], deltas[at + 2u]);
}

// m times (v, 1): the columns' products summed in order (skin.rs's `transform`).
vec3 point(mat4 m, vec3 v) {
    precise vec3 r = m[0].xyz * v.x;
    r = r + m[1].xyz * v.y;
    r = r + m[2].xyz * v.z;
    r = r + m[3].xyz;
    return r;
}

// m times (v, 0).
vec3 direction(mat4 m, vec3 v) {
    precise vec3 r = m[0].xyz * v.x;
    r = r + m[1].xyz * v.y;
    r = r + m[2].xyz * v.z;
    return r;
}

void main() {
    uint x = gl_GlobalInvocationID.x;
    uint copy = gl_GlobalInvocationID.y;
    uint listed = lists[2u * copy + 1u];
    uint v = x;
    if (listed == ALL) {
        if (v >= pc.vertexCount) return;
    } else {
        if (x >= listed) return;
        v = lists[lists[2u * copy] + x];
    }
    uint b = v * STRIDE;
    precise vec3 p = vec3(rest[b], rest[b + 1u], rest[b + 2u]);
    precise vec3 n = vec3(rest[b + 3u], rest[b + 4u], rest[b + 5u]);
    precise vec3 t = vec3(rest[b + 8u], rest[b + 9u], rest[b + 10u]);
    precise vec3 q = p;
    for (uint i = 0u; i < pc.targetCount; i++) {
        Target g = targets[i];
        vec2 w = weights[copy * pc.targetCount + i];
        if (v < g.first || v >= g.first + g.count) continue;
        uint k = v - g.first;
        uint at = g.offset + 3u * k;
        if (w.x != 0.0) {
            precise vec3 wp = w.x * delta(at);
            p = p + wp;
            if ((g.flags & 1u) != 0u) {
                precise vec3 wn = w.x * delta(at + 3u * g.count);
                n = n + wn;
            }
            if ((g.flags & 2u) != 0u) {
                uint tangents = at + 3u * g.count * (((g.flags & 1u) != 0u) ? 2u : 1u);
                precise vec3 wt = w.x * delta(tangents);
                t = t + wt;
            }
        }
        if (w.y != 0.0) {
            precise vec3 wq = w.y * delta(at);
            q = q + wq;
        }
    }
    if (pc.skinSlots != 0u) {
        Influence inf = influences[v];
        uint palette = copy * pc.jointStride;
        precise vec3 sp = vec3(0.0);
        precise vec3 sn = vec3(0.0);
        precise vec3 st = vec3(0.0);
        precise vec3 sq = vec3(0.0);
        for (uint s = 0u; s < pc.skinSlots; s++) {
            float w = s < 4u ? inf.w0[s] : inf.w1[s - 4u];
            if (w == 0.0) continue;
            uint j = s < 4u ? inf.j0[s] : inf.j1[s - 4u];
            mat4 m = joints[palette + j];
            precise vec3 a = point(m, p) * w;
            sp = sp + a;
            precise vec3 c = direction(m, n) * w;
            sn = sn + c;
            precise vec3 d = direction(m, t) * w;
            st = st + d;
            precise vec3 e = point(joints[palette + pc.jointCount + j], q) * w;
            sq = sq + e;
        }
        p = sp; n = sn; t = st; q = sq;
    }
    // Written into this copy's vertices.
    uint r = b;
    b = (copy * pc.vertexCount + v) * STRIDE;
    deformed[b] = p.x; deformed[b + 1u] = p.y; deformed[b + 2u] = p.z;
    deformed[b + 3u] = n.x; deformed[b + 4u] = n.y; deformed[b + 5u] = n.z;
    deformed[b + 6u] = rest[r + 6u]; deformed[b + 7u] = rest[r + 7u];
    deformed[b + 8u] = t.x; deformed[b + 9u] = t.y; deformed[b + 10u] = t.z;
    deformed[b + 11u] = rest[r + 11u];
    uint o = (copy * pc.vertexCount + v) * 3u;
    previous[o] = q.x; previous[o + 1u] = q.y; previous[o + 2u] = q.z;
}
