#version 330 core
// A soft round sprite, (1 - r^2)^2 (integral pi R^2 / 3), added up in
// half float (blend ONE, ONE).
in vec2 v_q;
in float v_w;
out vec4 o_density;
void main()
{
    float q = max(1.0 - dot(v_q, v_q), 0.0);
    o_density = vec4(v_w * q * q, 0.0, 0.0, 0.0);
}
