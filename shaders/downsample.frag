#version 330 core
// One step down the silhouette mip chain or the bloom pyramid: a box of
// the source from level u_lod of u_src, 4 bilinear fetches on texel
// corners.  At a ratio of 2 (a halving) the box is 4x4 texels; at other
// ratios (the bloom's one resample to its fixed row count) the taps move
// with it, so the box covers about twice the step in either direction.
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
    vec4 c = textureLod(u_src, uv + o * vec2(-1.0, -1.0), u_lod) + textureLod(u_src, uv + o * vec2(1.0, -1.0), u_lod)
           + textureLod(u_src, uv + o * vec2(-1.0, 1.0), u_lod) + textureLod(u_src, uv + o * vec2(1.0, 1.0), u_lod);
    c *= 0.25 * u_scale;
    if (u_threshold >= 0.0)
        c = vec4(max(c.rgb - vec3(u_threshold), vec3(0.0)), 1.0);
    o_color = min(c, vec4(65504.0)); // exposure up to 1000 must not make Inf in half float
}
