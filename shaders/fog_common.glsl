#ifndef FOG_COMMON_GLSL
#define FOG_COMMON_GLSL
// Fog map (docs/effects.md, "Fog map"): height fog whose density comes from a top-down
// map of mist particles (r_fx_fog.c draws it each frame), so the fog
// varies at equal height and no translucent sheets are drawn.  Density at
// a point p: map(p.xz) * exp(-max(p.y - base, 0) / height), times
// u_fog_density (extinction per metre where the map reads 1).
//
// Use: the vertex shader (or, for a few huge triangles, the fragment
// shader) takes tau = fog_depth(world), the optical depth from the eye
// (the sky: fog_depth_sky(dir)); the fragment shader mixes with
// fog_apply(lit, tau, dir).  Only when
// u_fog_on == 1: the fog module's bind hook (fog_bind, runtime/fx/fx_fog.c) sets it, with everything below, and it is 0
// whenever the fog_map pass did not run this frame.
#ifndef FOG_STEPS
#define FOG_STEPS 4 // samples along the view ray
#endif
uniform int u_fog_on;
uniform sampler2D u_fog_map;   // relative density, ~1 on average; wraps (GL_REPEAT)
uniform vec3 u_fog_eye;
uniform float u_fog_half;      // the map covers x, z in +-half metres
uniform float u_fog_density;   // 1/m
uniform float u_fog_base;      // m: densest at and below this height
uniform float u_fog_height;    // m: scale height above it
uniform vec3 u_fog_color;      // in-scattered radiance from the sky (HDR)
uniform vec3 u_fog_sun;        // the key light's irradiance x albedo (HDR)
uniform vec3 u_fog_sun_dir;    // towards the key light
uniform vec3 u_fog_phase;      // Henyey-Greenstein: (1 - g^2) / 4 pi, 1 + g^2, 2 g

// Density (relative) at p.  The map is half float: NaN and Inf stop here.
float fog_rho(vec3 p)
{
    float m = textureLod(u_fog_map, p.xz / (2.0 * u_fog_half) + 0.5, 0.0).r;
    m = isnan(m) ? 0.0 : clamp(m, 0.0, 1000.0);
    return m * exp(-max(p.y - u_fog_base, 0.0) / u_fog_height);
}

// Optical depth from the eye to w: the midpoint rule over FOG_STEPS
// samples of the map along the ray (a rough integral, as the technique's
// per-vertex fog is).
float fog_depth(vec3 w)
{
    vec3 d = w - u_fog_eye;
    float sum = 0.0;
    for (int i = 0; i < FOG_STEPS; i++)
        sum += fog_rho(u_fog_eye + d * ((float(i) + 0.5) / float(FOG_STEPS)));
    float tau = sum * u_fog_density * length(d) / float(FOG_STEPS);
    return isnan(tau) ? 0.0 : clamp(tau, 0.0, 64.0);
}

// Optical depth towards the sky (unit dir from the eye): the map's mean
// (1) all the way, the height profile integrated exactly.  Down to the
// horizon and below the ray never leaves the mist: the cap, all fog.
float fog_depth_sky(vec3 dir)
{
    float below = max(u_fog_base - u_fog_eye.y, 0.0);
    float layer = below + u_fog_height * exp(-max(u_fog_eye.y - u_fog_base, 0.0) / u_fog_height);
    float tau = u_fog_density * layer / max(dir.y, 1e-6);
    return isnan(tau) ? 64.0 : clamp(tau, 0.0, 64.0);
}

// The fog's own radiance seen along dir (unit, from the eye): the sky's
// light plus the key light scattered forward.
vec3 fog_light(vec3 dir)
{
    float k = max(u_fog_phase.y - u_fog_phase.z * dot(dir, u_fog_sun_dir), 1e-4);
    return u_fog_color + u_fog_sun * (u_fog_phase.x / (k * sqrt(k)));
}

vec3 fog_apply(vec3 lit, float tau, vec3 dir)
{
    return mix(fog_light(dir), lit, exp(-tau));
}
#endif
