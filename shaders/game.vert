#version 330 core
// Plain renderer: rigid skinning, one matrix per bone (index -1: world).
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_tangent; // for the normal maps of the renderer-core work
layout(location = 3) in vec2 a_uv;
layout(location = 4) in float a_bone;

uniform mat4 u_view_proj;
uniform mat4 u_bones[16];
uniform vec3 u_bone_color[16];
uniform vec3 u_color; // used when a_bone < 0

out vec3 v_world;
out vec3 v_normal;
out vec3 v_color;

void main()
{
    int b = int(a_bone + 0.5);
    mat4 m = a_bone < -0.5 ? mat4(1.0) : u_bones[b];
    vec4 world = m * vec4(a_pos, 1.0);
    v_world = world.xyz;
    v_normal = mat3(m) * a_normal; // rigid: rotation only, no scale
    v_color = a_bone < -0.5 ? u_color : u_bone_color[b];
    gl_Position = u_view_proj * world;
}
