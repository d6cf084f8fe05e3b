#version 330 core
// Water (docs/effects.md, "Water"): the normal map derived from the simulation,
// central differences over the 256x256 grid, into RGBA8 (unorm8 fetches
// are the cheap ones on a software renderer): xyz = the unit normal * 0.5
// + 0.5, w = the height * 0.5 / h_max + 0.5 (the turbidity blend reads
// it per pixel).
#include "water_common.glsl"
uniform sampler2D u_state;
uniform float u_dx;     // metres per cell
uniform float u_h_max;
out vec4 o_normal;

float height_at(ivec2 p)
{
    return water_height(texelFetch(u_state, p, 0).r, u_h_max);
}

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(u_state, 0) - 1;
    float l = height_at(ivec2(max(p.x - 1, 0), p.y)), r = height_at(ivec2(min(p.x + 1, last.x), p.y));
    float d = height_at(ivec2(p.x, max(p.y - 1, 0))), u = height_at(ivec2(p.x, min(p.y + 1, last.y)));
    vec3 n = normalize(vec3((l - r) / (2.0 * u_dx), 1.0, (d - u) / (2.0 * u_dx)));
    o_normal = vec4(n * 0.5 + 0.5, height_at(p) * 0.5 / u_h_max + 0.5);
}
