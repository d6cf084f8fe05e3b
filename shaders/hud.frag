#version 330 core
in vec2 v_uv;
in vec4 v_color;

uniform sampler2D u_font;

out vec4 o_color;

void main()
{
    float a = v_uv.x < 0.0 ? 1.0 : texture(u_font, v_uv).r;
    if (a < 0.5)
        discard;
    o_color = v_color;
}
