#version 330 core
// Water (docs/effects.md, "Water"), drawn opaque (depth write on: translucent water
// would sort badly with the fighters' translucent parts).  It composites:
//   - the under-water texture (water_under.frag), refracted: its uv
//     perturbed by the normal map;
//   - the reflection map (the mirrored simple model and the sky), its uv
//     perturbed by the normal map, weighted by Fresnel;
//   - turbidity: a shallow and a deep colour texture blended by the
//     surface's height (the displacement the vertices get, read per pixel
//     from the normal map so the colours follow ripples finer than the
//     mesh), so waves stir the colours; their alpha is how much of the
//     under-water image they hide.
#include "water_common.glsl"
in vec3 v_world;
in vec2 v_uv;
in vec3 v_normal;
in vec3 v_light;
uniform sampler2D u_normal_map; // xyz = normal * 0.5 + 0.5, w = height * 0.5 / h_max + 0.5
uniform sampler2D u_under;      // rgb: the fogged under-water scene
uniform sampler2D u_refl;       // the reflection map
uniform sampler2D u_shallow, u_deep;
uniform vec3 u_eye;
uniform vec2 u_size;            // the screen
uniform float u_refract;        // screen uv offset per unit of normal tilt (refraction)
uniform float u_distort;        // the same for the reflection
uniform float u_turb_base;      // deep-texture share of flat water
uniform float u_turb_range;     // metres of height that take the share from 0 to 1
uniform float u_h_max;          // the height clamp (the normal map's w scale)
uniform float u_tile;           // colour-texture repeats per metre
out vec4 o_color;
void main()
{
    vec3 n = v_normal;
    float height = 0.0;
    if (dot(n, n) < 0.25) { // the surface (the skirt has its own normal)
        vec4 m = texture(u_normal_map, v_uv) * 2.0 - 1.0;
        n = dot(m.xyz, m.xyz) < 1e-6 ? vec3(0.0, 1.0, 0.0) : normalize(m.xyz);
        height = m.w * u_h_max;
    }
    vec3 v = normalize(u_eye - v_world);
    vec2 suv = gl_FragCoord.xy / u_size;
    // the camera looks down -z: world x is screen x, world -z is screen up
    vec2 tilt = vec2(n.x, -n.z);
    ivec2 last = ivec2(u_size) - 1;
    vec3 under = texelFetch(u_under, clamp(ivec2(gl_FragCoord.xy + tilt * u_refract * u_size), ivec2(0), last), 0).rgb;
    vec3 refl = texture(u_refl, suv + tilt * u_distort).rgb;
    float t = clamp(u_turb_base + height / u_turb_range, 0.0, 1.0);
    vec2 tuv = v_world.xz * u_tile;
    vec4 turb = mix(texture(u_shallow, tuv), texture(u_deep, tuv), t);
    vec3 body = mix(under, turb.rgb * v_light, turb.a);
    float k = 1.0 - clamp(dot(n, v), 0.0, 1.0), k2 = k * k;
    float fresnel = 0.02 + 0.98 * k2 * k2 * k; // Schlick, water's F0 = 0.02
    o_color = vec4(water_hdr(mix(body, refl, fresnel)), 0.0);
}
