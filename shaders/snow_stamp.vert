#version 330 core
// Snow footprints: one quad per bone capsule that dips into the snow,
// covering its footprint on the displacement map (x -> map x, z -> map
// y; the map spans -u_half..u_half both ways).  No vertex buffer: a
// 4-vertex strip per instance.
#ifndef MAX_STAMPS
#define MAX_STAMPS 60
#endif
uniform vec4 u_cap_a[MAX_STAMPS]; // end a, w: radius
uniform vec3 u_cap_b[MAX_STAMPS]; // end b
uniform float u_half;
uniform sampler2D u_trampled; // the map's size
out vec2 v_xz;
flat out vec4 v_a;
flat out vec3 v_b;
void main()
{
    v_a = u_cap_a[gl_InstanceID];
    v_b = u_cap_b[gl_InstanceID];
    // the capsule's box seen from above, a texel wider each way so that a
    // thin bone still covers the texel centres it reaches
    float texel = 2.0 * u_half / float(textureSize(u_trampled, 0).x);
    vec2 lo = min(v_a.xz, v_b.xz) - v_a.w - texel, hi = max(v_a.xz, v_b.xz) + v_a.w + texel;
    v_xz = mix(lo, hi, vec2(gl_VertexID & 1, gl_VertexID >> 1));
    gl_Position = vec4(v_xz / u_half, 0.0, 1.0);
}
