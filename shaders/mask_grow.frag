#version 330 core
// SSFSM step 3a: grow the dark area by one pixel (3x3 minimum), so the
// blur that follows softens the shadow's edge instead of its aliasing.
uniform sampler2D u_src;
out vec4 o_mask;
void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy), hi = textureSize(u_src, 0) - 1;
    float m = 1.0;
    for (int y = -1; y <= 1; y++)
        for (int x = -1; x <= 1; x++)
            m = min(m, texelFetch(u_src, clamp(p + ivec2(x, y), ivec2(0), hi), 0).r);
    o_mask = vec4(m);
}
