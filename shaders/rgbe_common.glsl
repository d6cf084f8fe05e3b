// Bloom's levels in an RGBA8 image (docs/renderer.md, "Tone map, bloom,
// flare"): RGB a mantissa in [0.5, 1) for the largest channel, A the
// shared power of two as a byte k, the value rgb * 2^(k - 128).  The
// seed's maps were stored integer-encoded and decoded in the shader
// because filtering 16F images was slow; so is llvmpipe's (a bilinear tap
// of RGBA16F costs about three texel fetches of RGBA8 with this decode),
// and the levels are only read texel by texel: the blurs fetch each texel
// once, the one filtered read (a level from the next one down) filters by
// hand after decoding.  8 bits of mantissa: within 0.4 % of the largest
// channel; the exponent covers every half float.
// Both directions are bit operations on the float's exponent: no exp2 or
// log2 (which cost llvmpipe about as much as the fetch).

vec3 rgbe_decode(vec4 t)
{
    int k = max(int(t.a * 255.0 + 0.5), 1);     // 2^(k - 128): the float with biased exponent k - 1
    return t.rgb * intBitsToFloat((k - 1) << 23); // k 1: 0.0 (a zero texel)
}

vec4 rgbe_encode(vec3 c)
{
    c = clamp(c, vec3(0.0), vec3(65504.0)); // also NaN -> 0 (clamp's min/max)
    float m = max(max(c.r, c.g), c.b);
    // m in [2^(b - 127), 2^(b - 126)) for biased exponent b: scale by 2^-(b - 126)
    int k = clamp(((floatBitsToInt(m) >> 23) & 255) + 2, 2, 160);
    return vec4(c * intBitsToFloat((255 - k) << 23), float(k) / 255.0);
}

vec3 rgbe_texel(sampler2D s, ivec2 p, ivec2 hi, int lod)
{
    return rgbe_decode(texelFetch(s, clamp(p, ivec2(0), hi), lod));
}

// textureLod(s, uv, lod) with GL_LINEAR and GL_CLAMP_TO_EDGE, on the decoded values
vec3 rgbe_bilinear(sampler2D s, vec2 uv, int lod)
{
    ivec2 size = textureSize(s, lod), hi = size - 1;
    vec2 f = uv * vec2(size) - 0.5;
    vec2 b = floor(f), t = f - b;
    ivec2 i = ivec2(b);
    vec3 a = mix(rgbe_texel(s, i, hi, lod), rgbe_texel(s, i + ivec2(1, 0), hi, lod), t.x);
    vec3 c = mix(rgbe_texel(s, i + ivec2(0, 1), hi, lod), rgbe_texel(s, i + ivec2(1, 1), hi, lod), t.x);
    return mix(a, c, t.y);
}
