#ifndef IBL_COMMON_GLSL
#define IBL_COMMON_GLSL
// Image-based lighting (docs/renderer.md, "Image-based lighting"): six
// prefiltered cube maps, diffuse and specular exponents 16 and 128, each with
// and without the key-light area.  `key` (1 lit, 0 shadowed) blends the two;
// exponents between 16 and 128 interpolate the two specular maps linearly.
uniform samplerCube u_diffuse_on, u_diffuse_off;
uniform samplerCube u_spec16_on, u_spec16_off;
uniform samplerCube u_spec128_on, u_spec128_off;

vec3 ibl_diffuse(vec3 n, float key)
{
    return mix(texture(u_diffuse_off, n).rgb, texture(u_diffuse_on, n).rgb, key);
}

// exponent 16 alone: ibl_specular(r, 16.0, key) without the 128 maps' taps
vec3 ibl_specular16(vec3 r, float key)
{
    return mix(texture(u_spec16_off, r).rgb, texture(u_spec16_on, r).rgb, key);
}

vec3 ibl_specular128(vec3 r, float key)
{
    return mix(texture(u_spec128_off, r).rgb, texture(u_spec128_on, r).rgb, key);
}

vec3 ibl_specular(vec3 r, float exponent, float key)
{
    vec3 s16 = mix(texture(u_spec16_off, r).rgb, texture(u_spec16_on, r).rgb, key);
    vec3 s128 = mix(texture(u_spec128_off, r).rgb, texture(u_spec128_on, r).rgb, key);
    return mix(s16, s128, clamp((exponent - 16.0) / 112.0, 0.0, 1.0));
}
#endif
