#version 330 core
// variants: - MONO
// Movie frames: Y, Cb and Cr in three R8 textures -> RGB (player/mv_csp.h).
// Chroma is sampled bilinearly at the luma pixel's position on the chroma
// grid, which depends on the stream's siting: u_chroma_pos is where chroma
// sample 0 sits, in luma pixels (0.5 for centred 4:2:0, 0 for co-sited).
in vec2 v_uv;
uniform sampler2D u_y;
uniform sampler2D u_cb;
uniform sampler2D u_cr;
uniform mat3 u_m;       // column-major, range scaling folded in
uniform vec3 u_offset;  // black / zero-chroma levels in sample units
uniform vec2 u_luma_size;
uniform vec2 u_chroma_size;
uniform vec2 u_chroma_sub; // 1, 2 or 4 luma pixels per chroma sample
uniform vec2 u_chroma_pos;
out vec4 o_color;

void main()
{
    float y = texture(u_y, v_uv).r;
#ifdef MONO
    vec2 c = u_offset.yz;
#else
    vec2 x = v_uv * u_luma_size - 0.5;          // luma pixel coordinate
    vec2 t = (x - u_chroma_pos) / u_chroma_sub; // chroma sample coordinate
    vec2 cuv = (t + 0.5) / u_chroma_size;
    vec2 c = vec2(texture(u_cb, cuv).r, texture(u_cr, cuv).r);
#endif
    vec3 rgb = u_m * (vec3(y, c) - u_offset);
    o_color = vec4(clamp(rgb, 0.0, 1.0), 1.0);
}
