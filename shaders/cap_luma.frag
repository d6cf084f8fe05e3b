#version 330 core
#include "cap_yuv.glsl"
// Y plane at full output size from the downscaled (already flipped) frame.
uniform sampler2D u_rgb;
out vec4 o_y;

void main()
{
    o_y = vec4(luma709(texelFetch(u_rgb, ivec2(gl_FragCoord.xy), 0).rgb), 0.0, 0.0, 1.0);
}
