#version 330 core
// Separable Gaussian (9 taps, sigma 2 texels, as 5 bilinear fetches) along
// u_dir (one texel of the source in uv units).  Used by the shadow mask,
// the silhouette mip chain and bloom.  The output has the source's size.
uniform sampler2D u_src;
uniform vec2 u_dir;
uniform float u_lod;
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
    o_color = c;
}
