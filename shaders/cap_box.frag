#version 330 core
// variants: - FACTOR2
// Area-average downscale (a box filter of the exact footprint).  Output
// GL row r holds image row r counted from the top (the source is read
// flipped), so the readback comes out top row first.  Each output pixel
// averages the source texels it covers, weighted by coverage.
uniform sampler2D u_src;
uniform ivec2 u_src_size;
uniform ivec2 u_dst_size;
out vec4 o_color;

const int MAX_TAPS = 10; // footprints up to 8 texels wide (plus partial edges)

void main()
{
    ivec2 p = ivec2(gl_FragCoord.xy); // p.y: image row from the top
#ifdef FACTOR2
    // exactly 2x in both axes: one bilinear tap at the centre of the 2x2
    // block is its average (the sampler filters linearly)
    vec2 c = vec2(2 * p.x + 1, float(u_src_size.y) - float(2 * p.y + 1));
    o_color = texture(u_src, c / vec2(u_src_size));
    return;
#endif
    vec2 scale = vec2(u_src_size) / vec2(u_dst_size);
    vec2 lo = vec2(p) * scale, hi = lo + scale;
    vec4 sum = vec4(0.0);
    float wsum = 0.0;
    ivec2 first = ivec2(floor(lo));
    for (int j = 0; j < MAX_TAPS; j++) {
        float y0 = float(first.y + j);
        if (y0 >= hi.y)
            break;
        float wy = min(hi.y, y0 + 1.0) - max(lo.y, y0);
        for (int i = 0; i < MAX_TAPS; i++) {
            float x0 = float(first.x + i);
            if (x0 >= hi.x)
                break;
            float wx = min(hi.x, x0 + 1.0) - max(lo.x, x0);
            ivec2 t = ivec2(first.x + i, u_src_size.y - 1 - (first.y + j)); // source is bottom-up
            sum += texelFetch(u_src, t, 0) * (wx * wy);
            wsum += wx * wy;
        }
    }
    o_color = sum / wsum;
}
