#version 330 core
#include "smoke_common.glsl"

uniform vec4 u_color; // rgba / 255
uniform int u_mode;   // 0: flat colour, 1: grid pattern with u_color.b
out vec4 o_color;

void main()
{
    if (u_mode == 1)
        o_color = vec4(smoke_grid(gl_FragCoord.xy), u_color.b, 1.0);
    else
        o_color = u_color;
}
