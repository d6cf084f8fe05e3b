#version 330 core
// Snow surface (docs/effects.md, "Snow"): the colour, fresh or trampled by how far
// the vertex is pressed down, times the texture-space lighting blurred by
// snow_light_blur (fake subsurface scattering, step 3; snow_light.frag
// says what it holds).  The fighters' blurred silhouette takes the key
// light's share away as it does on the ring.  Output: linear HDR, alpha 0
// (not a fighter).
#include "snow_common.glsl"
in vec3 v_world;
in vec2 v_uv;
in float v_fresh;
in vec3 v_proj;
in float v_lod;
flat in vec3 v_key;
uniform sampler2D u_light;    // rgb: key-off light, a: the key's share
uniform sampler2D u_colors;   // r, g: fresh and trampled brightness (fx_snow_tex.h), tiling
uniform sampler2D u_silhouette;
uniform float u_color_tile;   // metres per repeat of the colour texture
uniform float u_flash;        // lightning: extra light, 0..1
out vec4 o_color;

void main()
{
    float key = 1.0;
    if (v_proj.z > 0.0) // (snow_surface.vert)
        key = 1.0 - textureLod(u_silhouette, v_proj.xy, v_lod).r * 0.85;
    vec4 l = texture(u_light, v_uv);
    vec3 light = l.rgb + key * l.a * v_key;
    vec2 t = texture(u_colors, v_world.xz / u_color_tile).rg;
    vec3 albedo = mix(SNOW_TRAMPLED * t.g, SNOW_FRESH * t.r, v_fresh);
    vec3 lit = albedo * (light + u_flash * 2.0);
    o_color = vec4(snow_hdr(lit), 0.0);
}
