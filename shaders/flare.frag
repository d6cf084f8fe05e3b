#version 330 core
// The sun flare (docs/renderer.md, "Tone map, bloom, flare") at quarter size:
// a glow round the sun and ghosts along the axis from the sun through the
// screen centre, each a tap of the flare texture, scaled by how much of the
// sun is visible.  Runs only when the sun is on screen; the tone map adds the
// result in HDR.
uniform sampler2D u_flare;
uniform sampler2D u_sun_vis;
uniform vec2 u_size;        // this target, pixels
uniform vec2 u_sun_uv;      // the sun's position in uv
uniform vec3 u_flare_color; // intensity and tint
uniform float u_aspect;
out vec4 o_color;
void main()
{
    float vis = texelFetch(u_sun_vis, ivec2(0), 0).r;
    vec2 uv = gl_FragCoord.xy / u_size;
    vec2 axis = vec2(0.5) - u_sun_uv;
    vec3 f = vec3(0.0);
    const float pos[6] = float[6](0.0, 0.45, 0.8, 1.15, 1.5, 2.1);
    const float size[6] = float[6](0.35, 0.05, 0.09, 0.04, 0.14, 0.07);
    const vec3 tint[6] = vec3[6](vec3(1.0, 0.9, 0.7), vec3(0.4, 0.8, 1.0), vec3(1.0, 0.6, 0.3),
                                 vec3(0.5, 1.0, 0.5), vec3(0.6, 0.5, 1.0), vec3(1.0, 0.8, 0.6));
    for (int k = 0; k < 6; k++) {
        vec2 d = (uv - (u_sun_uv + axis * pos[k])) * vec2(u_aspect, 1.0) / size[k];
        f += tint[k] * texture(u_flare, d * 0.5 + 0.5).rgb * (k == 0 ? 1.0 : 0.35);
    }
    o_color = vec4(min(f * u_flare_color * vis, vec3(65504.0)), 1.0);
}
