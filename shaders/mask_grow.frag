#version 330 core
// SSFSM step 3a: grow the dark area (a minimum over a square), so the
// blur that follows softens the shadow's edge instead of its aliasing.
// The square's half side is u_radius mask pixels (1 at 720 rows, scaled
// with the frame): ceil(u_radius) taps each side, spread to reach it, the
// fractional ones bilinear (a partial grow).
uniform sampler2D u_src;
uniform float u_radius;
out vec4 o_mask;
void main()
{
    vec2 size = vec2(textureSize(u_src, 0));
    int n = max(int(ceil(u_radius - 1e-4)), 1);
    float step = u_radius / float(n);
    float m = 1.0;
    for (int y = -n; y <= n; y++)
        for (int x = -n; x <= n; x++)
            m = min(m, texture(u_src, (gl_FragCoord.xy + vec2(x, y) * step) / size).r);
    o_mask = vec4(m);
}
