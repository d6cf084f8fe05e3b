#version 330 core
// Water: a splat's bump, amp * (1 + cos(pi d / radius)) / 2 inside the
// radius (fx_water_sim_splat_weight on the CPU), added to the height only;
// a bump under WATER_H_TINY adds nothing.
#include "water_common.glsl"
flat in vec4 v_splat;
out vec4 o_add;
void main()
{
    float d = distance(gl_FragCoord.xy, v_splat.xy);
    float w = d < v_splat.z ? 0.5 + 0.5 * cos(3.14159265 * d / v_splat.z) : 0.0;
    o_add = vec4(water_flush(v_splat.w * w), 0.0, 0.0, 0.0);
}
