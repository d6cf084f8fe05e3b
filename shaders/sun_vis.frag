#version 330 core
// How much of the sun is visible: 32 depth samples on a disc around its
// screen position; sky (depth 1) counts, geometry occludes.  Runs only
// when the sun is on screen; the tone map's flare taps use the result.
uniform sampler2D u_depth;
uniform vec2 u_sun;     // pixels
uniform float u_radius; // pixels
out vec4 o_vis;
void main()
{
    ivec2 hi = textureSize(u_depth, 0) - 1;
    float vis = 0.0;
    for (int i = 0; i < 32; i++) {
        float a = float(i) * 2.39996, r = u_radius * sqrt((float(i) + 0.5) / 32.0);
        ivec2 p = ivec2(u_sun + r * vec2(cos(a), sin(a)));
        bool inside = all(greaterThanEqual(p, ivec2(0))) && all(lessThanEqual(p, hi));
        vis += inside && texelFetch(u_depth, p, 0).r >= 1.0 ? 1.0 : 0.0;
    }
    o_vis = vec4(vis / 32.0);
}
