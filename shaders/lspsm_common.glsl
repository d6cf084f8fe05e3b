#ifndef LSPSM_COMMON_GLSL
#define LSPSM_COMMON_GLSL
// Light space perspective shadow maps (docs/effects.md, "Shadows in a large
// world"): one 1024x1024 depth map of the key light, warped so texels crowd
// near the camera, drawn each frame by the lspsm_map pass (r_fx_lspsm.c) from
// the buildings' low-poly proxies, and the fighters when their own shadows
// (the blurred silhouette, SSFSM) are off: with them on, only the buildings
// look up a map with the fighters in it, bound in its place on the frames a
// fighter's shadow can reach one (fx_lspsm.c).  Only when u_lspsm_on == 1: lspsm_bind
// (runtime/fx/fx_lspsm.c) sets it with everything below, and it is 0 whenever
// the map was not drawn this frame.
// FX_LSPSM_STATIC (r_quality.lspsm_static): the casters and the light do
// not move, so the map is two orthographic layers of one array drawn
// once (layer 0 round the ring, layer 1 over everything within reach;
// r_lspsm.h): an affine lookup and one tap.
#ifdef FX_LSPSM_STATIC
#define FX_LSPSM 1
uniform sampler2DArrayShadow u_lspsm_map; // compare mode, bilinear: 2x2 PCF in hardware
uniform vec4 u_lspsm_fit[1];              // layer 0's (u, v) = the last layer's * .xy + .zw
#else
uniform sampler2DShadow u_lspsm_map; // compare mode, bilinear: 2x2 PCF in hardware
#endif
uniform int u_lspsm_on;
uniform float u_lspsm_texel;         // one texel of the map, in texture coordinates
uniform mat4 u_lspsm_shadow;         // world -> (u, v, depth, w)
uniform vec3 u_lspsm_eye;
uniform vec2 u_lspsm_fade;           // strength 1 up to .x metres from the eye, 0 from .y on
uniform vec3 u_lspsm_dir;            // towards the light
uniform float u_lspsm_bias;          // depth bias, window units
uniform vec3 u_lspsm_box[4];         // the fighters' boxes: lo 0, hi 0, lo 1, hi 1
uniform int u_fighter;               // which fighter is being drawn (r_draw_fighters)
uniform float u_lspsm_keep;          // a fighter in full shadow keeps this much of the key light

// Where the ray from p towards d leaves the box lo..hi (r_lspsm_box_exit's
// twin, the same arithmetic).
vec3 lspsm_box_exit(vec3 p, vec3 d, vec3 lo, vec3 hi)
{
    vec3 t = (mix(lo, hi, step(0.0, d)) - p) / d;
    t = mix(t, vec3(1e30), equal(d, vec3(0.0)));
    float te = max(min(min(t.x, t.y), t.z), 0.0);
    return te < 1e30 ? p + d * te : p;
}

#ifdef FX_LSPSM_STATIC
// The static layers at c, layer 1's (u, v, depth): layer 0 where its
// (u, v) and the tap's texels lie inside it.  No branch (llvmpipe would
// run both sides anyway); outside layer 1 its border (depth 1) is lit.
float lspsm_static_lit(vec3 c)
{
    vec2 c0 = c.xy * u_lspsm_fit[0].xy + u_lspsm_fit[0].zw;
    bool l0 = max(abs(c0.x - 0.5), abs(c0.y - 0.5)) < 0.5 - u_lspsm_texel;
    return texture(u_lspsm_map, vec4(l0 ? c0 : c.xy, l0 ? 0.0 : 1.0, c.z - u_lspsm_bias));
}

// lspsm_visibility for a stage surface whose layer coordinates (pushed
// along its normal) the vertex shader interpolated: c
float lspsm_static_visibility(vec3 p, vec3 c)
{
    if (u_lspsm_on != 1)
        return 1.0;
    float strength = 1.0 - smoothstep(u_lspsm_fade.x, u_lspsm_fade.y, distance(p, u_lspsm_eye));
    return mix(1.0, lspsm_static_lit(c), strength);
}
#endif

// Visibility of the key light at p (1 lit, 0 in shadow), already faded out
// towards the end of the shadow range; p is pushed along the normal n by
// `offset` metres against acne.
float lspsm_visibility(vec3 p, vec3 n, float offset)
{
    if (u_lspsm_on != 1)
        return 1.0;
    float strength = 1.0 - smoothstep(u_lspsm_fade.x, u_lspsm_fade.y, distance(p, u_lspsm_eye));
#ifdef FX_LSPSM_STATIC
    float lit = lspsm_static_lit((u_lspsm_shadow * vec4(p + n * offset, 1.0)).xyz);
#else
    if (!(strength > 0.0))
        return 1.0;
    vec4 s = u_lspsm_shadow * vec4(p + n * offset, 1.0);
    if (!(s.w > 0.0))
        return 1.0;
    vec3 c = s.xyz / s.w;
    if (any(lessThan(c, vec3(0.0))) || any(greaterThan(c, vec3(1.0))))
        return 1.0; // outside the map: nothing casts there
    // four bilinear (2x2 PCF) taps half a texel either way: a 3x3-texel
    // quadratic B-spline, smooth across texel edges, where one tap's tent
    // left the warp's long far texels as a staircase along shadow edges
    float h = 0.5 * u_lspsm_texel, z = c.z - u_lspsm_bias;
    float lit = 0.25 * (texture(u_lspsm_map, vec3(c.xy + vec2(-h, -h), z)) + texture(u_lspsm_map, vec3(c.xy + vec2(h, -h), z)) +
                        texture(u_lspsm_map, vec3(c.xy + vec2(-h, h), z)) + texture(u_lspsm_map, vec3(c.xy + vec2(h, h), z)));
#endif
    return mix(1.0, lit, strength);
}

// A fighter at p: no self-shadow, others' shadows received.  The map is
// looked up where the ray towards the light leaves the fighter's own box.
// (With the screen-space mask on, the map holds no fighters: the mask has
// the other fighter's shadow.)
float lspsm_fighter_visibility(vec3 p)
{
    int i = clamp(u_fighter, 0, 1);
    vec3 q = lspsm_box_exit(p, u_lspsm_dir, u_lspsm_box[2 * i], u_lspsm_box[2 * i + 1]);
    return lspsm_visibility(q, vec3(0.0), 0.0);
}
#endif
