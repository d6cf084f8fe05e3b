#version 330 core
#include "light_common.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec3 v_color;

uniform vec3 u_eye;
uniform float u_flash;     // lightning: 0..1
uniform float u_specular;  // 0 for matte surfaces

out vec4 o_color;

void main()
{
    vec3 n = normalize(v_normal);
    vec3 v = normalize(u_eye - v_world);
    vec3 lit = plain_light(n, v, v_color, u_specular);
    o_color = vec4(lit + u_flash * 0.6 * v_color, 1.0);
}
