#version 330 core
// Half-size step: a 4x4 box from level u_lod of u_src (4 bilinear fetches
// on texel corners),
// used for the silhouette mip chain and the bloom pyramid.
uniform sampler2D u_src;
uniform float u_lod;
uniform float u_threshold; // bloom: subtract and clamp; < 0 = plain copy
uniform float u_scale;
out vec4 o_color;
void main()
{
    vec2 texel = 1.0 / vec2(textureSize(u_src, int(u_lod)));
    vec2 uv = gl_FragCoord.xy * 2.0 * texel;
    vec4 c = textureLod(u_src, uv + texel * vec2(-1.0, -1.0), u_lod) + textureLod(u_src, uv + texel * vec2(1.0, -1.0), u_lod)
           + textureLod(u_src, uv + texel * vec2(-1.0, 1.0), u_lod) + textureLod(u_src, uv + texel * vec2(1.0, 1.0), u_lod);
    c *= 0.25 * u_scale;
    if (u_threshold >= 0.0)
        c = vec4(max(c.rgb - vec3(u_threshold), vec3(0.0)), 1.0);
    o_color = min(c, vec4(65504.0)); // exposure up to 1000 must not make Inf in half float
}
