#version 330 core
// Water (docs/effects.md, "Water"): the reflection map's simple model.  The fighters
// drawn with scene.vert through the camera mirrored about the water plane
// (the view-projection does the mirroring, so v_world is the unmirrored
// point): plain diffuse IBL in the bone colours, no normal or specular
// maps, no shadows.  What is under the water is not reflected.
#include "ibl_common.glsl"
#include "water_common.glsl"
in vec3 v_world;
in vec3 v_normal;
in vec4 v_color;
uniform float u_level; // the water plane
out vec4 o_color;
void main()
{
    if (v_world.y < u_level)
        discard;
    vec3 n = normalize(v_normal);
    o_color = vec4(water_hdr(v_color.rgb * ibl_diffuse(n, 1.0)), 1.0);
}
