#version 330 core
// variants: - FX_FOG
// The stage's environment as seen, plus the sun disc (the sun is a delta
// light in the prefiltered maps, so it is drawn analytically here).  In
// fog (FX_FOG: the look's programs, r_game.c) the sky fades into the
// fog's light towards the horizon.
#include "fog_common.glsl"
in vec3 v_dir;
uniform samplerCube u_env;
uniform vec3 u_sun_dir;
uniform vec3 u_sun_radiance; // 0 when there is no sun
uniform float u_sun_cos;     // cos of the sun's angular radius
uniform float u_flash;
out vec4 o_color;
void main()
{
    vec3 d = normalize(v_dir);
    vec3 c = texture(u_env, d).rgb;
    float cs = dot(d, u_sun_dir);
    c += u_sun_radiance * smoothstep(u_sun_cos - (1.0 - u_sun_cos) * 0.3, u_sun_cos, cs);
    c += u_flash * vec3(1.5, 1.6, 2.0);
#ifdef FX_FOG
    if (u_fog_on == 1)
        c = fog_apply(c, fog_depth_sky(d), d);
#endif
    c = min(c, vec3(65504.0));
    o_color = vec4(c, 0.0);
}
