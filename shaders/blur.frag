#version 330 core
// variants: - REACH=1 REACH=2 REACH=3 REACH=4 REACH=4+RGBE REACH=4+RGBE+GLOW REACH=4+RGBE+GLOW+LEVEL2 REACH=4+RGBE+GLOW+FLARE REACH=4+RGBE+GLOW+LEVEL2+FLARE
// Separable Gaussian (9 taps, sigma 2 texels, as 5 bilinear fetches) along
// u_dir (one texel of the source in uv units).  Used by the shadow mask,
// the silhouette mip chain and bloom.  The output has the source's size.
// RGBE: the source and the output are bloom's RGBA8 levels (rgbe_common.glsl),
// read texel by texel (REACH) and decoded.
// GLOW: bloom's last blur also makes the one image the tone map adds (the
// glow, r_post.c): u_bloom x (this blur + the second level, LEVEL2) + the
// sun's flare (FLARE), so the tone map taps one texture a pixel, not three;
// the glow itself is RGBA16F (the tone map filters it).
#ifdef RGBE
#include "rgbe_common.glsl"
#endif
#if defined(GLOW) && !defined(RGBE)
#error "GLOW reads bloom's RGBE levels"
#endif
uniform sampler2D u_src;
uniform vec2 u_dir;
#ifdef REACH
// The same blur as texels, for steps of at most one texel (r_blur_into):
// the weight of the texels 0..REACH away along u_axis, off the edges as
// the sampler is (clamped, or a zero border).  Each texel is read once where each paired
// bilinear fetch reads four, which on llvmpipe is the cheaper way for
// 8-bit targets (the silhouette's levels, the shadow mask); the taps are
// unrolled, as a loop to a uniform count and an array indexed by it cost
// more than they save there.
uniform ivec2 u_axis; // (1, 0) or (0, 1)
uniform float u_w[REACH + 1];
uniform int u_zero_border;
#endif
uniform float u_lod;
#ifdef GLOW
uniform float u_bloom;
#ifdef LEVEL2
uniform sampler2D u_level2; // the second level, half this size
#endif
#ifdef FLARE
uniform sampler2D u_flare_img; // the flare pass's image (quarter of the render, HDR)
#endif
#endif
out vec4 o_color;
void main()
{
    vec2 uv = gl_FragCoord.xy / vec2(textureSize(u_src, int(u_lod)));
#ifdef REACH
    int l = int(u_lod);
    ivec2 p = ivec2(gl_FragCoord.xy), hi = textureSize(u_src, l) - 1;
    // a texel off the edge: the edge's (u_zero_border 0) or zero (1, as
    // the silhouette's CLAMP_TO_BORDER with a zero border)
    int along = u_axis.x != 0 ? p.x : p.y, last = u_axis.x != 0 ? hi.x : hi.y;
#ifdef RGBE
#define FETCH(q) vec4(rgbe_texel(u_src, q, hi, l), 1.0)
#define SIDE(q, j) FETCH(q) // bloom's levels: clamped at the edge
#else
#define FETCH(q) texelFetch(u_src, clamp(q, ivec2(0), hi), l)
#define SIDE(q, j) FETCH(q) * (u_zero_border == 1 && (j < 0 || j > last) ? 0.0 : 1.0)
#endif
#define TAP(i) (SIDE(p + i * u_axis, along + i) + SIDE(p - i * u_axis, along - i)) * u_w[i]
    vec4 c = FETCH(p) * u_w[0] + TAP(1);
#if REACH > 1
    c += TAP(2);
#endif
#if REACH > 2
    c += TAP(3);
#endif
#if REACH > 3
    c += TAP(4);
#endif
#else
    // weights of taps 0, +-1..4 (sigma 2), paired into linear fetches
    // (r_blur_kernel in r_gl.c has the same numbers)
    const float w0 = 0.2042, w1 = 0.3040, w2 = 0.0931;
    const float o1 = 1.3846, o2 = 3.2308;
    vec4 c = textureLod(u_src, uv, u_lod) * w0;
    c += (textureLod(u_src, uv + u_dir * o1, u_lod) + textureLod(u_src, uv - u_dir * o1, u_lod)) * w1;
    c += (textureLod(u_src, uv + u_dir * o2, u_lod) + textureLod(u_src, uv - u_dir * o2, u_lod)) * w2;
#endif
#if !defined(GLOW) && defined(RGBE)
    o_color = rgbe_encode(c.rgb);
#elif !defined(GLOW)
    o_color = c;
#else
    vec3 g = c.rgb;
#ifdef LEVEL2
    g += rgbe_bilinear(u_level2, uv, 0);
#endif
    g *= u_bloom;
#ifdef FLARE
    g += texture(u_flare_img, uv).rgb;
#endif
    o_color = vec4(min(g, vec3(65504.0)), 1.0);
#endif
}
