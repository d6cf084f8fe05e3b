#version 330 core
// SSFSM step 2 (docs/renderer.md, "Shadows"): the screen-space shadow mask of the
// fighters.  Each pixel the z-prepass covered is taken back to world
// space, into the key light's shadow map, and compared (2x2 PCF by the
// sampler).  1 = lit, 0 = shadowed; pixels without a fighter stay lit.
uniform sampler2D u_depth;
uniform sampler2DShadow u_shadow_map;
uniform mat4 u_inv_view_proj;
uniform mat4 u_light_proj;
uniform vec2 u_size;  // the render's size, pixels
uniform float u_step; // render pixels per mask pixel: 1, or 2 for a half-size mask
uniform float u_bias;
out vec4 o_mask;
void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy * u_step);
    float z = texelFetch(u_depth, p, 0).r;
    if (z >= 1.0) {
        o_mask = vec4(1.0);
        return;
    }
    vec4 ndc = vec4((vec2(p) + 0.5) / u_size * 2.0 - 1.0, z * 2.0 - 1.0, 1.0);
    vec4 world = u_inv_view_proj * ndc;
    world /= world.w;
    vec4 lp = u_light_proj * world;
    vec3 sc = lp.xyz / lp.w * 0.5 + 0.5;
    float lit = texture(u_shadow_map, vec3(sc.xy, sc.z - u_bias));
    o_mask = vec4(lit);
}
