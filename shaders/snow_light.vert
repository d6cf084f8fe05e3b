#version 330 core
// Snow, texture-space lighting: one triangle over the light texture, and
// the key light's strength, the same for every texel, fetched here once:
// what the IBL's key-on maps add to the key-off ones towards the key
// (diffuse: its irradiance / pi; specular: the peak of its lobe).  The
// analytic key terms of snow_light.frag then match the ring's lighting.
#include "ibl_common.glsl"
#include "snow_common.glsl"
uniform vec3 u_light_dir; // towards the key light, unit
flat out float v_key_spec; // the specular peak, in units of the key's diffuse colour
void main()
{
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
    vec3 l = u_light_dir;
    vec3 kd = snow_key_color(l);
    vec3 ks = max(ibl_specular(l, SNOW_EXPONENT, 1.0) - ibl_specular(l, SNOW_EXPONENT, 0.0), vec3(0.0));
    v_key_spec = snow_luma(kd) > 1e-6 ? snow_hdr(snow_luma(ks) / snow_luma(kd)) : 0.0;
}
