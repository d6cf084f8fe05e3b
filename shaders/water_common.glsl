#ifndef WATER_COMMON_GLSL
#define WATER_COMMON_GLSL
// Water (techniques A6): what the water shaders share.

// An HDR value the RGBA16F buffers can hold: no NaN, nothing past the
// largest finite fp16 (65504), nothing negative.
vec3 water_hdr(vec3 c)
{
    return mix(clamp(c, vec3(0.0), vec3(65504.0)), vec3(0.0), isnan(c));
}

// A simulated height made safe: NaN -> 0, clamped to +-h_max.
float water_height(float h, float h_max)
{
    return isnan(h) ? 0.0 : clamp(h, -h_max, h_max);
}
#endif
