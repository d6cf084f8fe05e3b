#version 330 core
// LSPSM auto-focus (docs/effects.md, "Shadows in a large world"): the 20x16
// tilted sample pattern of the frame's depth buffer, one sample per texel of
// a 20x16 target that is then read back asynchronously and used next
// frame.  The pattern is r_lspsm_focus_point's, in the same integer
// arithmetic.
uniform sampler2D u_depth;
out vec4 o_depth;
void main()
{
    ivec2 c = ivec2(gl_FragCoord.xy); // (i, j): sample k = j * 20 + i
    ivec2 size = textureSize(u_depth, 0);
    int x = ((16 * c.x + c.y) * 2 + 1) * size.x / 640;
    int y = ((20 * c.y + c.x) * 2 + 1) * size.y / 640;
    o_depth = vec4(texelFetch(u_depth, ivec2(x, y), 0).r);
}
