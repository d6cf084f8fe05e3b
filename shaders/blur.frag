#version 330 core
// variants: - GLOW GLOW+LEVEL2 GLOW+FLARE GLOW+LEVEL2+FLARE
// Separable Gaussian (9 taps, sigma 2 texels, as 5 bilinear fetches) along
// u_dir (one texel of the source in uv units).  Used by the shadow mask,
// the silhouette mip chain and bloom.  The output has the source's size.
// GLOW: bloom's last blur also makes the one image the tone map adds (the
// glow, r_post.c): u_bloom x (this blur + the second level, LEVEL2) + the
// sun's flare (FLARE), so the tone map taps one texture a pixel, not three.
uniform sampler2D u_src;
uniform vec2 u_dir;
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
    // weights of taps 0, +-1..4 (sigma 2), paired into linear fetches
    const float w0 = 0.2042, w1 = 0.3040, w2 = 0.0931;
    const float o1 = 1.3846, o2 = 3.2308;
    vec4 c = textureLod(u_src, uv, u_lod) * w0;
    c += (textureLod(u_src, uv + u_dir * o1, u_lod) + textureLod(u_src, uv - u_dir * o1, u_lod)) * w1;
    c += (textureLod(u_src, uv + u_dir * o2, u_lod) + textureLod(u_src, uv - u_dir * o2, u_lod)) * w2;
#ifndef GLOW
    o_color = c;
#else
    vec3 g = c.rgb;
#ifdef LEVEL2
    g += texture(u_level2, uv).rgb;
#endif
    g *= u_bloom;
#ifdef FLARE
    g += texture(u_flare_img, uv).rgb;
#endif
    o_color = vec4(min(g, vec3(65504.0)), 1.0);
#endif
}
