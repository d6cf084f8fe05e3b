#ifndef SMOKE_COMMON_GLSL
#define SMOKE_COMMON_GLSL
// Byte-exact test pattern: red = x mod 256, green = y mod 256 (window
// pixels), so a CPU reference can predict every pixel.  k / 255.0 converts
// back to exactly k in an 8-bit target.
vec2 smoke_grid(vec2 frag_coord)
{
    return mod(floor(frag_coord), 256.0) / 255.0;
}
#endif
