#version 330 core
#include "cap_yuv.glsl"
// Y plane at full output size from the downscaled (already flipped) frame,
// or from the rendered frame itself at 1:1 (u_flip: its height, bottom-up).
uniform sampler2D u_rgb;
uniform int u_flip; // 0: u_rgb is top row first
out vec4 o_y;

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    if (u_flip > 0)
        p.y = u_flip - 1 - p.y;
    o_y = vec4(luma709(texelFetch(u_rgb, p, 0).rgb), 0.0, 0.0, 1.0);
}
