#version 330 core
// The fog map (docs/effects.md, "Fog map"): one sprite per mist particle, top-down.
// An instanced quad rather than a GL point: a point whose centre lies
// outside the viewport is dropped whole, and sprites crossing the map's
// edge are drawn again on the other side (the mist wraps round).
layout(location = 0) in vec3 a_particle; // x, z (m), weight
uniform float u_half;   // the map covers +-half metres
uniform float u_radius; // sprite radius, m
uniform float u_amp;    // weight -> density: the map's mean is 1
out vec2 v_q;           // -1..1 across the sprite
out float v_w;
void main()
{
    vec2 corner = vec2(float(gl_VertexID & 1), float(gl_VertexID >> 1)) * 2.0 - 1.0; // a strip of 4
    v_q = corner;
    v_w = a_particle.z * u_amp;
    gl_Position = vec4((a_particle.xy + corner * u_radius) / u_half, 0.0, 1.0);
}
