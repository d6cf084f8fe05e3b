#version 330 core
// variants: FIGHTER STAGE LENS LIGHT_VIEW LIGHT_VIEW+SILHOUETTE FIGHTER+FX_FOG LENS+FX_FOG STAGE+MATERIAL=1 STAGE+MATERIAL=2 STAGE+MATERIAL=3 STAGE+MATERIAL=1+FX_LSPSM_STATIC STAGE+MATERIAL=3+FX_LSPSM_STATIC
// Scene geometry for every pass that draws it: rigid skinning, one matrix
// per bone (bone index -1: world space).  Variants by #define:
//   FIGHTER, STAGE, LENS   the HDR scene pass (scene.frag)
//   LIGHT_VIEW             shadow map / silhouette from the key light
// FIGHTER and LENS compute the fog map's optical depth per vertex (when
// FX_FOG); STAGE leaves it to the fragment shader (scene.frag says
// why), and gives the flat surfaces (MATERIAL 0-2) their diffuse light.
#include "fog_common.glsl"
#include "ibl_common.glsl"

layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_tangent;
layout(location = 3) in vec2 a_uv;
layout(location = 4) in float a_bone;

uniform mat4 u_view_proj; // camera, or the light's projection for LIGHT_VIEW
uniform mat4 u_bones[16];
uniform vec4 u_bone_color[16]; // rgb albedo, a: specular strength
uniform float u_lens_side;     // LENS: +1 / -1, which side of the head is the face
#ifdef LENS
uniform vec3 u_eye;
// The visor lies just inside the head (r_build_lens), so it can never cover
// a pixel outside the head's silhouette; its depth alone is pulled this far
// towards the eye so it wins the depth test over the face in front of it
// (the deepest the face gets in front of the visor, at its edge, is 2.8 cm).
const float LENS_PULL = 0.035;
#endif

#ifdef STAGE
uniform mat4 u_light_proj;     // the silhouette projector
uniform vec3 u_light_dir;      // towards the key light
uniform vec3 u_waist[2];       // the casters' waists
uniform float u_lod_start, u_lod_scale;
uniform sampler2D u_silhouette; // scene.frag's: its size scales the level
#ifndef MATERIAL
#define MATERIAL 0             // 3: a hole's inside, seen from within the sphere
#endif
out vec3 v_proj;               // projector uv, z: 1 when this vertex may receive
out float v_lod;
#if MATERIAL != 3
// a face's diffuse light with the key light on and off: its vertices share
// one normal, so this is what scene.frag would fetch at each of its pixels
flat out vec3 v_diff_on, v_diff_off;
#endif
#ifdef FX_LSPSM_STATIC
// the static shadow layers' map is affine (lspsm_common.glsl): this point's
// (u, v, depth) and its normal's, interpolated exactly, so the pixel only
// adds its offset along the normal
uniform mat4 u_lspsm_shadow;
out vec3 v_lspsm, v_lspsm_n;
#endif
#endif

out vec3 v_world;
out vec3 v_normal;
out vec4 v_tangent;
out vec2 v_uv;
out vec4 v_color;
#if defined(FIGHTER) || defined(LENS)
out float v_fog; // optical depth from the eye
#endif

invariant gl_Position; // the z-prepass and the scene pass must agree exactly

void main()
{
    int b = int(a_bone + 0.5);
    mat4 m = a_bone < -0.5 ? mat4(1.0) : u_bones[b];
    vec3 p = a_pos, n = a_normal, t = a_tangent.xyz;
#ifdef LENS
    p.y *= u_lens_side;
    n.y *= u_lens_side;
    t.y *= u_lens_side;
#endif
    vec4 world = m * vec4(p, 1.0);
    v_world = world.xyz;
    v_normal = mat3(m) * n; // rigid: rotation only
    v_tangent = vec4(mat3(m) * t, a_tangent.w);
    v_uv = a_uv;
    v_color = a_bone < -0.5 ? vec4(1.0) : u_bone_color[b];
#ifdef STAGE
    // Blurred mipmap projection shadow: the mip level grows with the
    // distance to the nearest caster's waist (near = sharp, far = soft);
    // receivers facing away from the light or on its side of the caster
    // (behind the projector) are rejected here.
    vec3 w = distance(world.xyz, u_waist[0]) < distance(world.xyz, u_waist[1]) ? u_waist[0] : u_waist[1];
    float d = distance(world.xyz, w);
    vec4 lp = u_light_proj * world;
    bool facing = dot(MATERIAL == 3 ? -v_normal : v_normal, u_light_dir) > 0.0;
    bool behind = dot(world.xyz - w, u_light_dir) > 0.0;
    v_proj = vec3(lp.xy * 0.5 + 0.5, facing && !behind ? 1.0 : 0.0);
    // the levels are tuned for a 512 silhouette: a smaller one is already
    // blurrier by a level per halving (r_quality.sil_size)
    float lod = (d - u_lod_start) * u_lod_scale - log2(512.0 / float(textureSize(u_silhouette, 0).x));
    v_lod = clamp(lod, 0.0, 4.0);
#ifdef FX_LSPSM_STATIC
    v_lspsm = (u_lspsm_shadow * world).xyz;
    v_lspsm_n = mat3(u_lspsm_shadow) * (MATERIAL == 3 ? -v_normal : v_normal);
#endif
#if MATERIAL != 3
    vec3 fn = normalize(v_normal);
    v_diff_on = textureLod(u_diffuse_on, fn, 0.0).rgb;
    v_diff_off = textureLod(u_diffuse_off, fn, 0.0).rgb;
#endif
#endif
#if defined(FIGHTER) || defined(LENS)
#ifdef FX_FOG
    v_fog = u_fog_on == 1 ? fog_depth(world.xyz) : 0.0;
#else
    v_fog = 0.0;
#endif
#endif
    gl_Position = u_view_proj * world;
#ifdef LENS
    vec4 q = u_view_proj * vec4(world.xyz + normalize(u_eye - world.xyz) * LENS_PULL, 1.0);
    gl_Position.z = q.z / q.w * gl_Position.w;
#endif
}
