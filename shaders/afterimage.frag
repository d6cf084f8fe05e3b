#version 330 core
// Afterimage motion blur (docs/effects.md, "Afterimage motion blur"): the
// translucent copy, lit by the diffuse IBL only (a smear has no highlights),
// premultiplied alpha over the HDR buffer; the destination alpha (the mask)
// is kept by the blend.
#include "ibl_common.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec4 v_color;
uniform float u_opacity; // the copy's alpha at rest (scaled by the fade)

out vec4 o_color;

void main()
{
    vec3 n = normalize(v_normal);
    float a = clamp(v_color.a * u_opacity, 0.0, 1.0);
    vec3 c = v_color.rgb * ibl_diffuse(n, 1.0);
    o_color = vec4(min(c * a, vec3(65504.0 * a)), a);
}
