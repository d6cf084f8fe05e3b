#version 330 core
// Water: the under-water pass's triangle covering the viewport (as
// cap_fullscreen.vert), plus the light of the murk, the IBL's diffuse
// light from straight up (docs/renderer.md, "Image-based lighting"): one
// fetch per vertex instead of one per pixel.
uniform samplerCube u_diffuse_on;
flat out vec3 v_sky;
void main()
{
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    v_sky = textureLod(u_diffuse_on, vec3(0.0, 1.0, 0.0), 0.0).rgb;
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
