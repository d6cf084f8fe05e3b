#ifndef SNOW_COMMON_GLSL
#define SNOW_COMMON_GLSL
// Shared by the snow shaders (docs/effects.md, "Snow"; runtime/fx/fx_snow.c).

// the snow's sheen: an IBL specular exponent (the spec16 maps)
const float SNOW_EXPONENT = 16.0;
// albedo of fresh and of fully trampled snow (linear), times the colour
// texture's brightness (fx_snow_tex.h)
const vec3 SNOW_FRESH = vec3(0.90, 0.92, 0.96);
const vec3 SNOW_TRAMPLED = vec3(0.70, 0.72, 0.76);
// specular strength of fresh snow and inside a trampled dent (packed snow
// is duller)
const float SNOW_SPEC_FRESH = 0.12;
const float SNOW_SPEC_TRAMPLED = 0.02;

// never let a value reach fp16 Inf, nor a NaN through (as scene.frag)
vec3 snow_hdr(vec3 c)
{
    return mix(clamp(c, vec3(0.0), vec3(65504.0)), vec3(0.0), isnan(c));
}

float snow_hdr(float c)
{
    return isnan(c) ? 0.0 : clamp(c, 0.0, 65504.0);
}

float snow_luma(vec3 c)
{
    return dot(c, vec3(0.2126, 0.7152, 0.0722));
}

// a map height, finite and within the snow's reach whatever the texture holds
float snow_height(float h)
{
    return isnan(h) ? 0.0 : clamp(h, 0.0, 1.0);
}

// how far a height is pressed down: 1 untouched .. 0 fully trampled
float snow_fresh(float h, float untouched, float trampled)
{
    return clamp((h - trampled) / max(untouched - trampled, 1e-4), 0.0, 1.0);
}

// the key light's colour on a surface facing it: what the IBL's key-on
// diffuse map adds to the key-off one towards the key (its irradiance / pi)
// (needs ibl_common.glsl)
#ifdef IBL_COMMON_GLSL
vec3 snow_key_color(vec3 light_dir)
{
    return max(ibl_diffuse(light_dir, 1.0) - ibl_diffuse(light_dir, 0.0), vec3(0.0));
}
#endif
#endif
