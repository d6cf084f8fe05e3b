#version 330 core
// variants: - RGBE_OUT RGBE_IN+RGBE_OUT
// One step down the silhouette mip chain or the bloom pyramid: a box of
// the source from level u_lod of u_src, 4 bilinear fetches on texel
// corners.  At a ratio of 2 (a halving) the box is 4x4 texels; at other
// ratios (the bloom's one resample to its fixed row count) the taps move
// with it, so the box covers about twice the step in either direction.
// RGBE_OUT: the target is one of bloom's RGBA8 levels (rgbe_common.glsl);
// RGBE_IN: so is the source, each tap filtered by hand after decoding.
#if defined(RGBE_IN) || defined(RGBE_OUT)
#include "rgbe_common.glsl"
#endif
uniform sampler2D u_src;
uniform float u_lod;
uniform vec2 u_dst;        // this target's size, pixels
uniform float u_threshold; // bloom: subtract and clamp; < 0 = plain copy
uniform float u_scale;
out vec4 o_color;
void main()
{
    vec2 uv = gl_FragCoord.xy / u_dst;
    vec2 o = 0.5 / u_dst; // half a target pixel, in uv: one source texel at a ratio of 2
#ifdef RGBE_IN
    int l = int(u_lod);
    ivec2 size = textureSize(u_src, l);
    vec4 c = vec4(0.0);
    if (size == 2 * ivec2(u_dst)) { // a halving: the 4x4 box the taps below make, texel by texel
        ivec2 p = 2 * ivec2(gl_FragCoord.xy) - 1, hi = size - 1;
        for (int y = 0; y < 4; y++)
            for (int x = 0; x < 4; x++)
                c.rgb += rgbe_texel(u_src, p + ivec2(x, y), hi, l);
        c *= 0.25; // 16 texels at 1/16: as 4 taps of 1/4 each
    } else {
#define TAP(d) vec4(rgbe_bilinear(u_src, uv + o * d, l), 1.0)
        c = TAP(vec2(-1.0, -1.0)) + TAP(vec2(1.0, -1.0)) + TAP(vec2(-1.0, 1.0)) + TAP(vec2(1.0, 1.0));
    }
#else
#define TAP(d) textureLod(u_src, uv + o * d, u_lod)
    vec4 c = TAP(vec2(-1.0, -1.0)) + TAP(vec2(1.0, -1.0)) + TAP(vec2(-1.0, 1.0)) + TAP(vec2(1.0, 1.0));
#endif
    c *= 0.25 * u_scale;
    if (u_threshold >= 0.0)
        c = vec4(max(c.rgb - vec3(u_threshold), vec3(0.0)), 1.0);
#ifdef RGBE_OUT
    o_color = rgbe_encode(c.rgb);
#else
    o_color = min(c, vec4(65504.0)); // exposure up to 1000 must not make Inf in half float
#endif
}
