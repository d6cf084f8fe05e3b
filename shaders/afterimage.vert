#version 330 core
// Afterimage motion blur (docs/effects.md, "Afterimage motion blur"): the
// stretched copy of a fighter.
// Each vertex is transformed by the current and the previous tick's
// matrices; V = cur - prev, in view space (camera motion blurs too) or in
// world space (u_world = 1: only the fighters' own motion).  A vertex
// facing away from the motion (N.V < 0) goes back to where it was,
// cur - stretch * V (stretch 1: the old position), so the copy is the
// model smeared along its path.  Alpha fades with speed:
// 1 - |V| / (radius / 2), radius = the bone mesh's largest vertex distance
// from its origin.  Bones slower than the threshold are not drawn
// (u_fast[b] = 0: the whole triangle is moved outside the clip volume).
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 4) in float a_bone;

uniform mat4 u_view, u_view_prev, u_proj;
uniform mat4 u_bones[16];      // where the model is drawn (interpolated between ticks)
uniform mat4 u_bones_tick[16], u_bones_prev[16]; // the current and previous whole ticks: V
uniform vec4 u_bone_color[16];
uniform float u_radius[16];
uniform float u_fast[16];
uniform float u_stretch;
uniform int u_world;

out vec3 v_world;
out vec3 v_normal;
out vec4 v_color;

void main()
{
    int b = int(a_bone + 0.5);
    if (a_bone < -0.5 || u_fast[b] < 0.5) {
        gl_Position = vec4(0.0, 0.0, -2.0, 1.0); // clipped: z < -w
        v_world = vec3(0.0), v_normal = vec3(0.0, 1.0, 0.0), v_color = vec4(0.0);
        return;
    }
    vec4 cur = u_bones[b] * vec4(a_pos, 1.0);
    vec4 tick = u_bones_tick[b] * vec4(a_pos, 1.0);
    vec4 prev = u_bones_prev[b] * vec4(a_pos, 1.0);
    vec3 n = mat3(u_bones[b]) * a_normal;
    vec3 pos_v;  // the vertex in view space
    vec3 vel;    // V in the chosen space
    vec3 nrm;
    if (u_world != 0) {
        vel = tick.xyz - prev.xyz;
        nrm = n;
        vec3 p = dot(nrm, vel) < 0.0 ? cur.xyz - u_stretch * vel : cur.xyz;
        pos_v = (u_view * vec4(p, 1.0)).xyz;
        v_world = p;
    } else {
        vec3 cv = (u_view * cur).xyz;
        vel = (u_view * tick).xyz - (u_view_prev * prev).xyz;
        nrm = mat3(u_view) * n;
        pos_v = dot(nrm, vel) < 0.0 ? cv - u_stretch * vel : cv;
        v_world = (inverse(u_view) * vec4(pos_v, 1.0)).xyz;
    }
    v_normal = n;
    float speed = length(vel);
    float alpha = clamp(1.0 - speed / (0.5 * u_radius[b]), 0.0, 1.0);
    v_color = vec4(u_bone_color[b].rgb, alpha);
    gl_Position = u_proj * vec4(pos_v, 1.0);
}
