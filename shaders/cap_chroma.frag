#version 330 core
#include "cap_yuv.glsl"
// Cb and Cr planes at half size, packed into the w x h/2 rows above the Y
// plane of one R8 image (capture/cap.c, gpu_setup): byte j of that region
// (j = row * w + column) is Cb sample j while j < (w/2)(h/2), else Cr
// sample j - (w/2)(h/2); sample k of a plane lies at row k / (w/2), column
// k % (w/2).  Read back bottom row first, the image is the I420 frame.
// Each sample is the mean of a 2x2 block (chroma sited at the centre, as in
// JPEG/MPEG-1 "C420jpeg").
uniform sampler2D u_rgb;
uniform ivec2 u_size; // the output's w, h (both even)
uniform int u_flip;   // u_rgb's height when it is the rendered frame (bottom-up, 1:1), else 0
out vec4 o_c;

void main()
{
    // j = y * w + x with w = 2 cw: row j / cw = 2y + (x >= cw), no division
    // (a software rasteriser has no vector integer divide)
    int cw = u_size.x / 2, ch = u_size.y / 2;
    ivec2 q = ivec2(gl_FragCoord.xy) - ivec2(0, u_size.y);
    bool right = q.x >= cw;
    int row = 2 * q.y + (right ? 1 : 0);
    bool cr = row >= ch;
    if (cr)
        row -= ch;
    ivec2 p = ivec2(right ? q.x - cw : q.x, row) * 2;
    int dy = 1;
    if (u_flip > 0) { // image rows 2k, 2k+1 are GL rows h-1-2k, h-2-2k
        p.y = u_flip - 1 - p.y;
        dy = -1;
    }
    // the same four texels, added in the same order, as from a flipped copy
    vec3 rgb = (texelFetch(u_rgb, p, 0).rgb + texelFetch(u_rgb, p + ivec2(1, 0), 0).rgb +
                texelFetch(u_rgb, p + ivec2(0, dy), 0).rgb + texelFetch(u_rgb, p + ivec2(1, dy), 0).rgb) * 0.25;
    vec2 c = chroma709(rgb);
    o_c = vec4(cr ? c.y : c.x, 0.0, 0.0, 1.0);
}
