#version 330 core
// Water (docs/effects.md, "Water"): the under-water part as its own texture.  Each
// pixel of the scene drawn so far (the ring floor, the fighters' legs) that
// lies under the water plane gets height fog: the view ray's path under
// the surface through a density that grows with depth (deeper = murkier).
// Pixels of something above the water (a fighter in front of it) get the
// murk's colour instead (alpha 0), so a refracted lookup that lands on one
// sees murky water, not the fighter: the surface needs no second fetch.
#include "water_common.glsl"
flat in vec3 v_sky;        // the diffuse light from above (water_under.vert)
uniform sampler2D u_hdr;
uniform sampler2D u_depth;
uniform mat4 u_inv_view_proj;
uniform vec3 u_eye;
uniform vec2 u_size;
uniform float u_level;
uniform vec2 u_half;       // the pool's half extent in x and z
uniform vec3 u_wall_color; // albedo of the pool's side (the ring's)
uniform float u_fog_base;  // density at the surface, 1/m
uniform float u_fog_depth; // density added per metre of depth, 1/m^2
uniform vec3 u_fog_color;  // albedo of the murk, lit by the sky above
out vec4 o_color;
void main()
{
    ivec2 px = ivec2(gl_FragCoord.xy);
    vec3 c = texelFetch(u_hdr, px, 0).rgb;
    float z = texelFetch(u_depth, px, 0).r;
    vec4 w = u_inv_view_proj * vec4(gl_FragCoord.xy / u_size * 2.0 - 1.0, z * 2.0 - 1.0, 1.0);
    vec3 p = w.xyz / w.w;
    vec3 fog = u_fog_color * v_sky;
    if (z >= 1.0 || !(p.y < u_level)) {
        o_color = vec4(water_hdr(fog), 0.0);
        return;
    }
    // where the view ray goes under the surface, and how far it travels there
    float t = clamp((u_eye.y - u_level) / max(u_eye.y - p.y, 1e-4), 0.0, 1.0);
    vec3 q = mix(u_eye, p, t);
    if (p.y < -1e-3) {
        // under the floor: the ray left the pool through its side, where the
        // scene has nothing (the ring's top face ends there): the wall
        vec3 dir = p - q;
        vec2 s = (sign(dir.xz) * u_half - q.xz) / mix(dir.xz, vec2(1e-6), equal(dir.xz, vec2(0.0)));
        float exit = clamp(min(s.x >= 0.0 ? s.x : 1.0, s.y >= 0.0 ? s.y : 1.0), 0.0, 1.0);
        p = q + dir * exit;
        c = u_wall_color * v_sky;
    }
    float path = distance(q, p), depth = max(u_level - p.y, 0.0);
    // density base + k * depth along a path whose depth runs linearly 0 -> depth
    float tau = path * (u_fog_base + u_fog_depth * 0.5 * depth);
    float murk = 1.0 - exp(-min(tau, 80.0));
    o_color = vec4(water_hdr(mix(c, fog, murk)), 1.0);
}
