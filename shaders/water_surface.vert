#version 330 core
// Water (docs/effects.md, "Water"): the surface mesh over the ring's top face,
// displaced by the simulation (vertex texture fetch), plus a skirt down to
// the ring floor along the edges so the water's side is closed.
#include "water_common.glsl"
uniform samplerCube u_diffuse_on; // the IBL's diffuse map (docs/renderer.md, "Image-based lighting")
layout(location = 0) in vec3 a_grid; // u, v in 0..1 over the pool; z: 0 surface, 1 skirt bottom, 2 skirt top
uniform mat4 u_view_proj;
uniform sampler2D u_state;
uniform vec2 u_half;   // the pool's half extent in x and z
uniform float u_level;
uniform float u_h_max;
out vec3 v_world;
out vec2 v_uv;
out vec3 v_normal;     // the skirt's outward normal (0 on the surface)
out vec3 v_light;      // diffuse light on the water's colour: per vertex, it hardly varies
void main()
{
    float h = water_height(textureLod(u_state, a_grid.xy, 0.0).r, u_h_max);
    vec2 xz = (a_grid.xy * 2.0 - 1.0) * u_half;
    v_world = vec3(xz.x, a_grid.z > 0.5 && a_grid.z < 1.5 ? 0.0 : u_level + h, xz.y);
    v_uv = a_grid.xy;
    vec2 e = a_grid.xy - 0.5;
    v_normal = a_grid.z < 0.5 ? vec3(0.0) : abs(e.x) > abs(e.y) ? vec3(sign(e.x), 0.0, 0.0) : vec3(0.0, 0.0, sign(e.y));
    v_light = textureLod(u_diffuse_on, a_grid.z < 0.5 ? vec3(0.0, 1.0, 0.0) : v_normal, 0.0).rgb;
    gl_Position = u_view_proj * vec4(v_world, 1.0);
}
