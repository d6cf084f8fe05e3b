#version 330 core
// One axis of a separable Lanczos-3 downscale.  u_axis (1,0): source
// (sw x sh) -> (w x sh); (0,1): (w x sh) -> (w x h) with the vertical flip
// that puts the top row first.  The kernel is stretched by the scale so it
// low-passes as it shrinks; weights are normalised per pixel.
uniform sampler2D u_src;
uniform ivec2 u_src_size;
uniform ivec2 u_dst_size;
uniform ivec2 u_axis;
uniform int u_flip;
out vec4 o_color;

const float PI = 3.14159265358979;
const int MAX_TAPS = 50; // 2 * 3 lobes * scale 8, plus edges

float lanczos3(float x)
{
    x = abs(x);
    if (x < 1e-5)
        return 1.0;
    if (x >= 3.0)
        return 0.0;
    float px = PI * x;
    return 3.0 * sin(px) * sin(px / 3.0) / (px * px);
}

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy);
    int along = u_axis.x == 1 ? p.x : p.y;
    int n_src = u_axis.x == 1 ? u_src_size.x : u_src_size.y;
    int n_dst = u_axis.x == 1 ? u_dst_size.x : u_dst_size.y;
    float scale = float(n_src) / float(n_dst);
    float centre = (float(along) + 0.5) * scale; // in source texels
    float support = 3.0 * max(scale, 1.0);
    int first = int(floor(centre - support));
    vec4 sum = vec4(0.0);
    float wsum = 0.0;
    for (int k = 0; k < MAX_TAPS; k++) {
        int i = first + k;
        if (float(i) > centre + support)
            break;
        float w = lanczos3((float(i) + 0.5 - centre) / max(scale, 1.0));
        int ic = clamp(i, 0, n_src - 1);
        ivec2 t = u_axis.x == 1 ? ivec2(ic, p.y) : ivec2(p.x, ic);
        if (u_flip == 1 && u_axis.y == 1)
            t.y = n_src - 1 - t.y;
        sum += texelFetch(u_src, t, 0) * w;
        wsum += w;
    }
    // the horizontal pass keeps its under- and overshoot (RGBA16F); only
    // the final pass is clamped
    o_color = u_axis.y == 1 ? clamp(sum / wsum, 0.0, 1.0) : sum / wsum;
}
