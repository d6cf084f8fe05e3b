#version 330 core
// variants: - BLOOM FLARE BLOOM+FLARE
// Tone map (techniques A3), one full-screen pass:
//   1. RGB -> Y, Cb, Cr (CbCr unnormalised: B - Y and R - Y)
//   2. Y' from the curve ((1 - exp(-x^2))^1.5)^(1/gamma) in a float table
//   3. CbCr scaled by Y'/Y (guarded near 0) and by the saturation
//   4. back to RGB
// Bloom (BLOOM) and the sun flare (FLARE) are added in HDR before step 1;
// those variants exist only when their passes ran this frame.
uniform sampler2D u_hdr;
uniform sampler1D u_lut;
uniform int u_lut_size;
uniform float u_exposure;
uniform float u_saturation;
uniform int u_write_mask; // alpha = the fighters' mask, else 1
#ifdef BLOOM
uniform sampler2D u_bloom0, u_bloom1;
uniform float u_bloom;
#endif
#ifdef FLARE
uniform sampler2D u_flare;
uniform sampler2D u_sun_vis;
uniform vec2 u_sun_uv;      // the sun's position in uv
uniform vec3 u_flare_color; // intensity and tint
uniform float u_aspect;
#endif
out vec4 o_color;

const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);
const float X_MAX = 4.0; // R_TONE_X_MAX

float curve(float x)
{
    // u = sqrt(x / X_MAX); linear interpolation done here in full float
    // (texture units filter with 8-bit weights)
    float f = sqrt(clamp(x / X_MAX, 0.0, 1.0)) * float(u_lut_size - 1);
    int i = min(int(f), u_lut_size - 2);
    float t = f - float(i);
    return mix(texelFetch(u_lut, i, 0).r, texelFetch(u_lut, i + 1, 0).r, t);
}

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 hdr = texelFetch(u_hdr, p, 0);
    vec3 c = hdr.rgb * u_exposure;
    vec2 uv = (gl_FragCoord.xy) / vec2(textureSize(u_hdr, 0));
#ifdef BLOOM
    c += u_bloom * (texture(u_bloom0, uv).rgb + texture(u_bloom1, uv).rgb);
#endif
#ifdef FLARE
    float vis = texelFetch(u_sun_vis, ivec2(0), 0).r;
    if (vis > 0.0) {
        vec2 axis = vec2(0.5) - u_sun_uv;
        vec3 f = vec3(0.0);
        // the glow round the sun, then ghosts along the axis through the centre
        const float pos[6] = float[6](0.0, 0.45, 0.8, 1.15, 1.5, 2.1);
        const float size[6] = float[6](0.35, 0.05, 0.09, 0.04, 0.14, 0.07);
        const vec3 tint[6] = vec3[6](vec3(1.0, 0.9, 0.7), vec3(0.4, 0.8, 1.0), vec3(1.0, 0.6, 0.3),
                                     vec3(0.5, 1.0, 0.5), vec3(0.6, 0.5, 1.0), vec3(1.0, 0.8, 0.6));
        for (int k = 0; k < 6; k++) {
            vec2 d = (uv - (u_sun_uv + axis * pos[k])) * vec2(u_aspect, 1.0) / size[k];
            f += tint[k] * texture(u_flare, d * 0.5 + 0.5).rgb * (k == 0 ? 1.0 : 0.35);
        }
        c += f * u_flare_color * vis;
    }
#endif
    c = mix(clamp(c, vec3(0.0), vec3(65504.0)), vec3(0.0), isnan(c));
    float y = dot(c, LUMA);
    float cb = c.b - y, cr = c.r - y;
    float y2 = curve(y);
    float s = y > 1e-6 ? y2 / y * u_saturation : 0.0;
    cb *= s;
    cr *= s;
    float r = y2 + cr, b = y2 + cb;
    float g = (y2 - LUMA.r * r - LUMA.b * b) / LUMA.g;
    o_color = vec4(clamp(vec3(r, g, b), 0.0, 1.0), u_write_mask == 1 ? hdr.a : 1.0);
}
