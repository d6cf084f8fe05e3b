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
    int w = u_size.x, cw = u_size.x / 2, nc = cw * (u_size.y / 2);
    int j = (int(gl_FragCoord.y) - u_size.y) * w + int(gl_FragCoord.x);
    bool cr = j >= nc;
    if (cr)
        j -= nc;
    int row = j / cw;
    ivec2 p = ivec2(j - row * cw, row) * 2;
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
