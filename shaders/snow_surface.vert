#version 330 core
// Snow surface (docs/effects.md, "Snow"): a grid over the ring top displaced by the
// displacement map (vertex texture fetch).  Each vertex is a map texel
// (a_cell) and fetches it exactly (texelFetch: no filtering, the cheap
// fetch on a software rasteriser); cells -1 and size are the ring's edge
// at the edge texel's height, -2 and size + 1 the skirt down to the ring
// top (y = 0), so the snow ends in a wall.  The grid's rows and columns:
// r_fx_snow.c, grid_axis.
#include "snow_common.glsl"
layout(location = 0) in ivec2 a_cell; // map texel (column, row), or an edge code
uniform sampler2D u_map, u_untouched, u_trampled; // heights (m), same layout
uniform sampler2D u_silhouette; // its blurred mip chain
uniform sampler2D u_key;        // 1x1: the key light's colour (snow_key.frag)
uniform float u_sil_top;        // the most blurred level
uniform int u_shadows;          // 1 when this frame's silhouette passes ran
uniform float u_half;      // the ring spans -u_half..u_half in x and z
uniform mat4 u_view_proj;
// the blurred mipmap projection shadow, as scene.vert's STAGE variant
uniform mat4 u_light_proj;
uniform vec3 u_light_dir;
uniform vec3 u_waist[2];
uniform float u_lod_start, u_lod_scale;

out vec3 v_world;
out vec2 v_uv;       // map (and light texture) coordinates
out float v_fresh;   // 1 untouched .. 0 fully trampled
out vec3 v_proj;     // projector uv, z: > 0 where the shadow may fall
out float v_lod;
flat out vec3 v_key;  // the key light's colour

invariant gl_Position;

void main()
{
    int size = textureSize(u_map, 0).x;
    bvec2 lo = lessThan(a_cell, ivec2(-1)), hi = greaterThan(a_cell, ivec2(size));
    bool skirt = any(lo) || any(hi);
    ivec2 texel = clamp(a_cell, 0, size - 1);
    vec2 uv = clamp((vec2(a_cell) + 0.5) / float(size), 0.0, 1.0); // texel centres; the edges at 0 and 1
    float h = snow_height(texelFetch(u_map, texel, 0).r);
    float hu = snow_height(texelFetch(u_untouched, texel, 0).r);
    float ht = snow_height(texelFetch(u_trampled, texel, 0).r);
    // how pressed down this vertex is, between the untouched and the
    // fully trampled heights: picks the colour and the specular strength
    v_fresh = snow_fresh(h, hu, ht);
    vec3 world = vec3(-u_half + 2.0 * u_half * uv.x, skirt ? 0.0 : h, -u_half + 2.0 * u_half * uv.y);
    v_world = world;
    v_uv = uv;

    vec3 nrm = vec3(0.0, 1.0, 0.0); // the shadow test needs only which way the surface faces
    if (skirt)
        nrm = lo.x ? vec3(-1.0, 0.0, 0.0) : hi.x ? vec3(1.0, 0.0, 0.0) : lo.y ? vec3(0.0, 0.0, -1.0) : vec3(0.0, 0.0, 1.0);
    vec3 w = distance(world, u_waist[0]) < distance(world, u_waist[1]) ? u_waist[0] : u_waist[1];
    vec4 lp = u_light_proj * vec4(world, 1.0);
    bool facing = dot(nrm, u_light_dir) > 0.0;
    bool behind = dot(world - w, u_light_dir) > 0.0;
    v_proj = vec3(lp.xy * 0.5 + 0.5, 0.0);
    // where the shadow may fall: the widest, most blurred level reaches
    // past every sharper one by more than the grid's spacing, so pixels
    // between vertices where it is 0 skip the silhouette (most of them)
    if (u_shadows == 1 && facing && !behind)
        v_proj.z = textureLod(u_silhouette, v_proj.xy, u_sil_top).r;
    v_lod = clamp((distance(world, w) - u_lod_start) * u_lod_scale, 0.0, u_sil_top);
    v_key = texelFetch(u_key, ivec2(0), 0).rgb;
    gl_Position = u_view_proj * vec4(world, 1.0);
}
