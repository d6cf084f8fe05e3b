#version 330 core
// variants: - GLOW AA GLOW+AA SCALED GLOW+SCALED SCALED+AA GLOW+SCALED+AA
// Tone map (docs/renderer.md, "Tone map, bloom, flare"), one full-screen pass:
//   1. RGB -> Y, Cb, Cr (CbCr unnormalised: B - Y and R - Y)
//   2. Y' from the curve ((1 - exp(-x^2))^1.5)^(1/gamma) in a float table
//   3. CbCr scaled by Y'/Y (guarded near 0) and by the saturation
//   4. back to RGB
// Bloom and the sun flare are added in HDR before step 1 (GLOW): one image
// at bloom's size that bloom's last blur makes (u_bloom x its levels + the
// flare, blur.frag), or the flare pass's own when bloom did not run; the
// variant exists only when one of them ran this frame.  With the
// AA pass after it (AA), it writes the image's luma beside it, as the AA
// pass's early out reads it (fxaa.frag).  SCALED: the scene was drawn
// smaller than the output (r_quality.scene_pct) and the AA pass follows;
// this pass runs at the output's size and reads it bilinearly, so the AA
// pass and the HUD are at the output's size.  Without the AA pass a
// smaller scene is tone mapped at its own size and blitted up (r_post.c).
uniform sampler2D u_hdr;
uniform sampler1D u_lut;
uniform int u_lut_size;
uniform float u_lut_inv_power; // 1 / r_tone_index_power(gamma): 0.5 up to gamma 4
uniform float u_exposure;
uniform float u_saturation;
uniform int u_write_mask; // alpha = the fighters' mask, else 1
#ifdef GLOW
uniform sampler2D u_glow; // bloom and flare, already scaled (HDR)
#endif
#ifdef SCALED
uniform vec2 u_out; // the output's size, pixels
#endif
layout(location = 0) out vec4 o_color;
#ifdef AA
layout(location = 1) out vec4 o_luma;
#endif

const vec3 LUMA = vec3(0.2126, 0.7152, 0.0722);
const float X_MAX = 4.0; // R_TONE_X_MAX

float curve(float x)
{
    // u = (x / X_MAX)^(1/m); linear interpolation done here in full float
    // (texture units filter with 8-bit weights)
    float f = pow(clamp(x / X_MAX, 0.0, 1.0), u_lut_inv_power) * float(u_lut_size - 1);
    int i = min(int(f), u_lut_size - 2);
    float t = f - float(i);
    return mix(texelFetch(u_lut, i, 0).r, texelFetch(u_lut, i + 1, 0).r, t);
}

void main()
{
#ifdef SCALED
    vec2 uv = gl_FragCoord.xy / u_out;
    vec4 hdr = textureLod(u_hdr, uv, 0.0);
#else
    ivec2 p = ivec2(gl_FragCoord.xy);
    vec4 hdr = texelFetch(u_hdr, p, 0);
    vec2 uv = (gl_FragCoord.xy) / vec2(textureSize(u_hdr, 0));
#endif
    vec3 c = hdr.rgb * u_exposure;
#ifdef GLOW
    c += texture(u_glow, uv).rgb;
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
#ifdef AA
    o_luma = vec4(dot(o_color.rgb, vec3(0.299, 0.587, 0.114)), 0.0, 0.0, 1.0); // fxaa.frag's luma()
#endif
}
