#version 450
// `render --character-ids`: each head drawn again with the geometry pass's
// vertex shader, depth-tested EQUAL against the frame's depth, writes its
// character's frame index + 1 (0 stays: no skin). R32F holds it exactly.
// It fetches nothing, so its fetch-counting build counts nothing either.
layout(push_constant) uniform Push { float id; } pc;
// The vertex shader's outputs, read so the interfaces match (the R32F
// target stores the red channel alone: the id).
layout(location = 0) in vec3 vWorldPos;
layout(location = 1) in vec3 vNormal;
layout(location = 2) in vec4 vTangent;
layout(location = 3) in vec2 vUv;
layout(location = 4) in float vViewDepth;
layout(location = 5) flat in vec4 vZones0;
layout(location = 6) flat in vec4 vZones1;
layout(location = 0) out vec4 outId;
void main() {
    float unused = vWorldPos.x + vNormal.x + vTangent.x + vUv.x + vViewDepth + vZones0.x + vZones1.x;
    outId = vec4(pc.id, unused, 0.0, 1.0);
}
