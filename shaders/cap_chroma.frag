#version 330 core
#include "cap_yuv.glsl"
// Cb and Cr planes at half size: each sample is the mean of a 2x2 block
// (chroma sited at the centre, as in JPEG/MPEG-1 "C420jpeg").
uniform sampler2D u_rgb;
layout(location = 0) out vec4 o_cb;
layout(location = 1) out vec4 o_cr;

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy) * 2;
    vec3 rgb = (texelFetch(u_rgb, p, 0).rgb + texelFetch(u_rgb, p + ivec2(1, 0), 0).rgb +
                texelFetch(u_rgb, p + ivec2(0, 1), 0).rgb + texelFetch(u_rgb, p + ivec2(1, 1), 0).rgb) * 0.25;
    vec2 c = chroma709(rgb);
    o_cb = vec4(c.x, 0.0, 0.0, 1.0);
    o_cr = vec4(c.y, 0.0, 0.0, 1.0);
}
