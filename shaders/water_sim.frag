#version 330 core
// Water (docs/effects.md, "Water"): one step of the wave automaton on the 256x256
// RGBA32F simulation texture (r: height, g: the height a step earlier),
// drawn with cap_fullscreen.vert from one texture of the ping-pong pair
// into the other.  The CPU reference fx_water_sim_step_raw
// (runtime/render/fx_water_sim.c) computes the same, operation for
// operation; tests/test_fx_water.c compares the two.
//   h' = damping * ((2 h - h_prev) + C^2 * (hL + hR + hD + hU - 4 h))
// C (the Courant number) is capped below 1/sqrt(2) on the CPU.  The edges
// reflect: a missing neighbour reads the edge cell itself.  Heights under
// WATER_H_TINY read and write as 0, so no step meets a denormal.
#include "water_common.glsl"
uniform sampler2D u_state;
uniform float u_c2;      // C^2
uniform float u_damping; // amplitude kept per step
uniform float u_h_max;   // |height| clamp
out vec4 o_state;

float height_at(ivec2 p)
{
    return water_flush(texelFetch(u_state, p, 0).r);
}

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy), last = textureSize(u_state, 0) - 1;
    vec2 c = texelFetch(u_state, p, 0).rg;
    c = vec2(water_flush(c.r), water_flush(c.g));
    float l = height_at(ivec2(max(p.x - 1, 0), p.y)), r = height_at(ivec2(min(p.x + 1, last.x), p.y));
    float d = height_at(ivec2(p.x, max(p.y - 1, 0))), u = height_at(ivec2(p.x, min(p.y + 1, last.y)));
    float lap = ((l + r) + (d + u)) - 4.0 * c.r;
    float hn = u_damping * ((2.0 * c.r - c.g) + u_c2 * lap);
    // nothing that is not finite survives a step (NaN -> 0, Inf -> the clamp)
    o_state = vec4(water_height(hn, u_h_max), water_height(c.r, u_h_max), 0.0, 0.0);
}
