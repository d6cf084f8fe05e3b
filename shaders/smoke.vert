#version 330 core
// Smoke scene: shapes given in window pixels, converted to clip space.
uniform vec2 u_size;
layout(location = 0) in vec2 a_pos;

void main()
{
    gl_Position = vec4(a_pos / u_size * 2.0 - 1.0, 0.0, 1.0);
}
