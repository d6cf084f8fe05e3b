#version 330 core
// variants: FIGHTER STAGE FIGHTER+SHADOWS+FX_FOG+FX_LSPSM STAGE+SHADOWS+FX_FOG+FX_LSPSM STAGE+MATERIAL=1 STAGE+MATERIAL=2+SHADOWS+FX_LSPSM STAGE+MATERIAL=3+SHADOWS FIGHTER+SHADOWS+FX_LSPSM_STATIC STAGE+MATERIAL=1+SHADOWS+FX_LSPSM_STATIC STAGE+MATERIAL=2+SHADOWS+FX_LSPSM_STATIC STAGE+MATERIAL=3+SHADOWS+FX_FOG+FX_LSPSM_STATIC
// The HDR scene pass (docs/renderer.md: "HDR, materials, mask", "Image-based
// lighting", "Shadows"): image-based lighting only, no ambient term.  Every
// surface blends its key-on and key-off IBL results by its shadow factor: the
// filtered screen-space mask for the fighters (SSFSM), the blurred silhouette
// mip chain for the stage. Output: linear HDR, alpha = the fighters' mask.  On
// a stage with a fog map (FX_FOG) the result is mixed with the fog's light
// last.  On a stage with LSPSM (FX_LSPSM) the key light is blocked further by the
// large-world shadow map: the stage where its scenery casts, the fighters
// where the ray to the light leaves their own box (no self-shadow) and never
// below u_lspsm_keep, so they keep their directional shading in shadow.
// Compiled per look (r_game.c, build_look_programs): SHADOWS, FX_FOG and
// FX_LSPSM when the stage uses them, MATERIAL for the stage's surfaces, so
// that no pixel runs code for what its stage or surface does not have (a
// software rasteriser runs both sides of a branch).  The flat surfaces
// (MATERIAL 0-2) get the diffuse light from the vertex shader: with one
// normal per face it is the same value, and two cube-map taps a pixel fewer;
// the planks and the paving have exponent 16 alone, so they tap those two
// specular maps and not the 128 ones.
#include "ibl_common.glsl"
#include "fog_common.glsl"
#include "lspsm_common.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_uv;
in vec4 v_color;
#ifdef STAGE
#ifndef MATERIAL
#define MATERIAL 0 // 0 planks; 1 planks, paving on the ground; 2 a building; 3 a hole's inside (R_MAT_*)
#endif
in vec3 v_proj;
in float v_lod;
#if MATERIAL != 3
flat in vec3 v_diff_on, v_diff_off; // the face's ibl_diffuse maps (scene.vert)
#endif
#ifdef FX_LSPSM_STATIC
in vec3 v_lspsm, v_lspsm_n; // the static layers' coordinates of v_world and of the normal (scene.vert)
#endif
uniform sampler2D u_silhouette;
uniform vec3 u_ring_color;
#endif
#ifdef FIGHTER
uniform sampler2D u_normal_map;
uniform sampler2D u_spec_map;
uniform sampler2D u_mask;
uniform vec2 u_mask_uv; // 1 / the render size: the mask may be half size (linear filtered)
in float v_fog;
#endif
uniform vec3 u_eye;
uniform int u_shadows;   // 1 when this frame's shadow passes ran
uniform float u_flash;   // lightning: extra light, 0..1

out vec4 o_color;

vec3 hdr_out(vec3 c)
{
    // never let a value reach fp16 Inf, nor a NaN through
    return mix(clamp(c, vec3(0.0), vec3(65504.0)), vec3(0.0), isnan(c));
}

#ifdef STAGE
// The procedural patterns below, box-filtered over the pixel's footprint
// (hw: half its width along the pattern's axis, from fwidth): their
// periodic functions' integrals, differenced across the footprint, so a
// window, a joint or a seam narrower than a pixel gives its share of the
// pixel, not a hit or a miss that crawls from frame to frame.  The shift
// by floor(x) keeps the difference exact far from the origin.
// fract(x) in [a, b]: its integral from 0
float pulse_int(float x, float a, float b)
{
    return floor(x) * (b - a) + clamp(fract(x) - a, 0.0, b - a);
}

float pulse_cover(float x, float hw, float a, float b)
{
    x -= floor(x);
    hw = max(hw, 1e-4);
    return (pulse_int(x + hw, a, b) - pulse_int(x - hw, a, b)) / (2.0 * hw);
}

// clamp(fract(x) / a, 0, 1): a ramp up from each integer (a seam on one side)
float ramp_int(float x, float a)
{
    float f = fract(x);
    return floor(x) * (1.0 - 0.5 * a) + (f < a ? f * f / (2.0 * a) : f - 0.5 * a);
}

float ramp_cover(float x, float hw, float a)
{
    x -= floor(x);
    hw = max(hw, 1e-4);
    return (ramp_int(x + hw, a) - ramp_int(x - hw, a)) / (2.0 * hw);
}

#if MATERIAL == 1
// clamp(min(fract(x), 1 - fract(x)) / a, 0, 1): a joint on both sides of each integer
float joint_int(float x, float a)
{
    float f = fract(x), g = 1.0 - f;
    return floor(x) * (1.0 - a) + (f < a ? f * f / (2.0 * a) : g < a ? 1.0 - a - g * g / (2.0 * a) : f - 0.5 * a);
}

float joint_cover(float x, float hw, float a)
{
    x -= floor(x);
    hw = max(hw, 1e-4);
    return (joint_int(x + hw, a) - joint_int(x - hw, a)) / (2.0 * hw);
}
#endif
#endif

void main()
{
    vec3 n = normalize(v_normal);
#if defined(STAGE) && MATERIAL == 3
    n = -n; // the crater is the sphere's inside
#endif
    vec3 v = normalize(u_eye - v_world);
#ifdef FIGHTER
    // normal map in tangent space (capsule uv: u around, v along the bone)
    vec3 t = normalize(v_tangent.xyz - n * dot(n, v_tangent.xyz));
    vec3 bt = cross(n, t) * v_tangent.w;
    vec2 uv = v_uv * vec2(3.0, 4.0);
    vec3 tn = texture(u_normal_map, uv).xyz * 2.0 - 1.0;
    n = normalize(t * tn.x + bt * tn.y + n * tn.z);
    vec4 sm = texture(u_spec_map, uv);
    vec3 spec_color = sm.rgb * v_color.a;
    float exponent = 16.0 + 112.0 * sm.a;
#ifdef SHADOWS
    float key = u_shadows == 1 ? texture(u_mask, gl_FragCoord.xy * u_mask_uv).r : 1.0;
#else
    float key = 1.0;
#endif
#ifdef FX_LSPSM
    if (u_lspsm_on == 1)
        key *= mix(u_lspsm_keep, 1.0, lspsm_fighter_visibility(v_world));
#endif
    vec3 albedo = v_color.rgb;
    float alpha = 1.0;
#endif
#ifdef STAGE
    // planks: a procedural albedo variation, matte with a faint sheen
    float px = v_world.x * 2.5;
    float plank = floor(px);
    float grain = 0.85 + 0.15 * fract(sin(plank * 12.9898) * 43758.5453);
    float seam = ramp_cover(px, 0.5 * fwidth(px), 0.02) * 0.3 + 0.7;
    vec3 albedo = u_ring_color * grain * seam;
    vec3 spec_color = vec3(0.04);
    float exponent = 16.0;
#if MATERIAL == 1
    if (v_world.y < -2.95) {
        // paving: 1 m slabs, each a little different, dark joints
        vec2 slab = floor(v_world.xz), hw = 0.5 * fwidth(v_world.xz);
        float tone = 0.85 + 0.15 * fract(sin(dot(slab, vec2(12.9898, 78.233))) * 43758.5453);
        // where a pixel spans several slabs, their mean (what a box filter
        // of many random tones gives) instead of one slab's tone at random
        tone = mix(tone, 0.925, smoothstep(0.5, 2.0, 2.0 * max(hw.x, hw.y)));
        float joint = joint_cover(v_world.x, hw.x, 0.03) * joint_cover(v_world.z, hw.y, 0.03);
        albedo = vec3(0.46, 0.44, 0.41) * tone * (0.6 + 0.4 * joint);
    }
#elif MATERIAL == 3
    // broken boards over packed earth and rubble, darker deeper down
    vec3 cell = floor(v_world * 9.0);
    float grit = fract(sin(dot(cell, vec3(12.9898, 78.233, 37.719))) * 43758.5453);
    float depth = clamp(-v_world.y / 0.4, 0.0, 1.0);
    albedo = mix(u_ring_color * 0.8, vec3(0.42, 0.36, 0.29), smoothstep(0.0, 0.12, depth));
    albedo *= (0.7 + 0.3 * grit) * mix(1.0, 0.6, depth);
#elif MATERIAL == 2
    // concrete with a grid of glass windows (3.5 m floors, 2.5 m bays)
    // glass: the share of the pixel on a window pane (both materials are
    // shaded and mixed by it below)
    vec2 cell = vec2((abs(n.x) > 0.5 ? v_world.z : v_world.x) / 2.5, (v_world.y + 3.0) / 3.5);
    vec2 hw = 0.5 * fwidth(cell);
    float glass = abs(n.y) < 0.5 ? clamp((v_world.y + 1.0) / (7.0 * max(hw.y, 1e-5)) + 0.5, 0.0, 1.0) : 0.0; // walls above -1 m
    glass *= pulse_cover(cell.x, hw.x, 0.18, 0.82) * pulse_cover(cell.y, hw.y, 0.28, 0.86);
    vec3 block = floor(v_world / 12.0);
    float tone = 0.8 + 0.2 * fract(sin(dot(block, vec3(12.9898, 78.233, 37.719))) * 43758.5453);
    albedo = mix(vec3(0.56, 0.53, 0.49) * tone, vec3(0.03, 0.035, 0.04), glass);
#endif
    float key = 1.0;
#if MATERIAL == 2
    // the buildings are always drawn with u_shadows 0 (fx_lspsm.c,
    // run_buildings: the fighters' silhouette stops short of them, the
    // LSPSM map casts the fighters there): a constant, so their program
    // has no silhouette tap, which llvmpipe would run (and throw away) on
    // every building pixel
    const bool ssfsm = false;
#else
    bool ssfsm = u_shadows == 1;
#endif
#ifdef SHADOWS
    if (ssfsm && v_proj.z > 0.5)
        key = 1.0 - textureLod(u_silhouette, v_proj.xy, v_lod).r * 0.85;
#endif
#ifdef FX_LSPSM
    if (u_lspsm_on == 1) { // with the SSFSM shadows on, the map has no fighters: theirs come from the silhouette
        float offset = 0.02 + 0.006 * distance(v_world, u_eye);
#ifdef FX_LSPSM_STATIC
        key *= lspsm_static_visibility(v_world, v_lspsm + v_lspsm_n * offset);
#else
        key *= lspsm_visibility(v_world, n, offset);
#endif
    }
#endif
    float alpha = 0.0;
#endif
    vec3 r = reflect(-v, n);
    float ndv = max(dot(n, v), 0.0);
    float fresnel = 0.25 + 0.75 * pow(1.0 - ndv, 5.0);
#if defined(STAGE) && MATERIAL != 3
    vec3 diffuse = mix(v_diff_off, v_diff_on, key);
#else
    vec3 diffuse = ibl_diffuse(n, key);
#endif
#if defined(STAGE) && MATERIAL < 2
    vec3 specular = ibl_specular16(r, key);
#elif defined(STAGE) && MATERIAL == 2
    // concrete (0.03, exponent 16) and glass (0.6, exponent 128) by their shares
    vec3 specular = mix(0.03 * ibl_specular16(r, key), 0.6 * ibl_specular128(r, key), glass);
    spec_color = vec3(1.0);
#else
    vec3 specular = ibl_specular(r, exponent, key);
#endif
    vec3 lit = albedo * diffuse + spec_color * fresnel * specular;
    lit += u_flash * 2.0 * albedo;
#ifdef FX_FOG
    if (u_fog_on == 1) {
#ifdef STAGE
        // the ring and the ground are a few huge triangles (the ground is
        // 80 m across): a fog factor interpolated between their corners
        // would never see the map, so the stage integrates per pixel
        float tau = fog_depth(v_world);
#else
        float tau = v_fog;
#endif
        lit = fog_apply(lit, tau, -v);
    }
#endif
    o_color = vec4(hdr_out(lit), alpha);
}
