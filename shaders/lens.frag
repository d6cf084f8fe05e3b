#version 330 core
// variants: - FX_FOG
// A fighter's visor: a low-alpha glass lens in HDR (docs/renderer.md, "HDR,
// materials, mask").  The blend is premultiplied (ONE, ONE_MINUS_SRC_ALPHA):
// the tint is scaled by alpha, the reflection is not, so a lens of alpha 0.15
// still shows the sun at full HDR strength.  The blend leaves the destination
// alpha (the mask) alone.  In fog (FX_FOG) the lens fades into the fog's light
// like the head behind it, so the two add up to the fogged head seen through
// the lens.
#include "ibl_common.glsl"
#include "fog_common.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_uv;
in vec4 v_color;
in float v_fog;
uniform vec3 u_eye;
uniform float u_lens_alpha;

out vec4 o_color;

void main()
{
    vec3 n = normalize(v_normal);
    vec3 v = normalize(u_eye - v_world);
    if (dot(n, v) < 0.0)
        n = -n;
    vec3 r = reflect(-v, n);
    float ndv = max(dot(n, v), 0.0);
    float fresnel = 0.04 + 0.96 * pow(1.0 - ndv, 5.0);
    vec3 tint = vec3(0.05, 0.07, 0.09) * ibl_diffuse(n, 1.0);
    vec3 refl = ibl_specular(r, 128.0, 1.0) * mix(0.3, 1.0, fresnel);
    vec3 c = tint * u_lens_alpha + refl;
#ifdef FX_FOG
    if (u_fog_on == 1) {
        float t = exp(-v_fog);
        c = c * t + fog_light(-v) * ((1.0 - t) * u_lens_alpha);
    }
#endif
    // blended result = c + (1 - alpha) * dst with dst <= 65504: keeping c
    // under 65504 * alpha keeps the sum finite in half float on any GPU
    c = min(c, vec3(65504.0 * u_lens_alpha));
    o_color = vec4(c, u_lens_alpha);
}
