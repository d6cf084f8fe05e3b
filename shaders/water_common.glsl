#ifndef WATER_COMMON_GLSL
#define WATER_COMMON_GLSL
// Water (docs/effects.md, "Water"): what the water shaders share.

// An HDR value the RGBA16F buffers can hold: no NaN, nothing past the
// largest finite fp16 (65504), nothing negative.
vec3 water_hdr(vec3 c)
{
    return mix(clamp(c, vec3(0.0), vec3(65504.0)), vec3(0.0), isnan(c));
}

// Heights under this are 0 wherever they are read or written
// (R_WATER_H_TINY in fx_water_sim.h says why: denormals).
#define WATER_H_TINY 1e-20

float water_flush(float h)
{
    return abs(h) < WATER_H_TINY ? 0.0 : h;
}

// A simulated height made safe: NaN -> 0, tiny -> 0, clamped to +-h_max.
float water_height(float h, float h_max)
{
    return isnan(h) ? 0.0 : clamp(water_flush(h), -h_max, h_max);
}
#endif
