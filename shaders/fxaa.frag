#version 330 core
// variants: - MARK MARK+GATHER
#ifdef GATHER
#extension GL_ARB_texture_gather : require
#endif
// Post-process anti-aliasing (r_quality.aa = R_AA_FXAA) on the tone-mapped
// LDR image, one full-screen pass, before the HUD:
//   1. luma of the pixel and its 4 neighbours; a small contrast (most of
//      the picture) returns the pixel untouched, byte for byte
//   2. the corners: a sub-pixel blend from how far the pixel is off its
//      3x3 neighbourhood (single-pixel features, thin lines)
//   3. the edge's direction (the larger second difference), the side it
//      lies on, and a short walk both ways along it (3 steps, 2 taps each)
//      to find where it ends: pixels near an end of a long stair step are
//      blended across the edge more than pixels near its middle
//   4. one bilinear tap offset across the edge by the larger of 2 and 3
// Alpha (the fighters' mask under --mask) is the pixel's own.
// MARK: the early out alone, as a pass of its own before this one
// (r_aa.c): it discards the pixels whose 4 neighbours are surely flat and
// marks the others in the stencil, read from the tone map's 8-bit luma
// image (two textureGather calls with GATHER, else five fetches).  Its
// test is step 1's with a margin for that luma's rounding (each value
// within 2/255 of step 1's), so every pixel it leaves unmarked is one that
// step 1 returns untouched; the filter then runs on the marked pixels over
// a copy of the image, and the output is one full pass's, byte for byte.
// (Why two passes: llvmpipe runs the rest of a shader for pixels that
// discarded or branched away, but skips shading a block that fails the
// stencil test before the shader.)
uniform sampler2D u_src;  // RGBA8, the render's size, linear filter, clamped
uniform sampler2D u_luma; // R8, the same size: luma(u_src) before rounding
out vec4 o_color;

const float EDGE_MIN = 0.0625; // contrast below this is no edge (dark areas)
const float EDGE_REL = 0.125;  // nor below this fraction of the brightest luma
const float SUB_AMOUNT = 0.75; // how much of the sub-pixel blend to apply

// gamma-encoded luma: edges are judged as they are seen
float luma(vec4 c)
{
    return dot(c.rgb, vec3(0.299, 0.587, 0.114));
}

// the 3x3 by texelFetch (no filtering: a third of a bilinear tap's cost on
// llvmpipe, which runs both sides of a branch, so the early out saves little)
#define LUMA_AT(x, y) luma(texelFetch(u_src, clamp(ip + ivec2(x, y), ivec2(0), last), 0))

void main()
{
#ifdef MARK
#ifdef GATHER
    vec2 lpx = 1.0 / vec2(textureSize(u_luma, 0));
    vec4 a = textureGather(u_luma, (gl_FragCoord.xy - 0.5) * lpx); // west, this, south, south-west
    vec4 b = textureGather(u_luma, (gl_FragCoord.xy + 0.5) * lpx); // north, north-east, east, this
    float qmax = max(max(a.x, a.y), max(a.z, max(b.x, b.z)));
    float qmin = min(min(a.x, a.y), min(a.z, min(b.x, b.z)));
#else
    ivec2 iq = ivec2(gl_FragCoord.xy), lq = textureSize(u_luma, 0) - 1;
    float q0 = texelFetch(u_luma, iq, 0).r;
    float q1 = texelFetch(u_luma, clamp(iq + ivec2(0, 1), ivec2(0), lq), 0).r;
    float q2 = texelFetch(u_luma, clamp(iq + ivec2(0, -1), ivec2(0), lq), 0).r;
    float q3 = texelFetch(u_luma, clamp(iq + ivec2(1, 0), ivec2(0), lq), 0).r;
    float q4 = texelFetch(u_luma, clamp(iq + ivec2(-1, 0), ivec2(0), lq), 0).r;
    float qmax = max(q0, max(max(q1, q2), max(q3, q4)));
    float qmin = min(q0, min(min(q1, q2), min(q3, q4)));
#endif
    if (qmax - qmin + 4.0 / 255.0 < max(EDGE_MIN, (qmax - 2.0 / 255.0) * EDGE_REL))
        discard;
    o_color = vec4(0.0); // colour writes are off: the stencil is the mark
#else
    vec2 px = 1.0 / vec2(textureSize(u_src, 0));
    vec2 uv = gl_FragCoord.xy * px;
    ivec2 ip = ivec2(gl_FragCoord.xy), last = textureSize(u_src, 0) - 1;
    vec4 c = texelFetch(u_src, ip, 0);
    float lc = luma(c);
    float ln = LUMA_AT(0, 1), ls = LUMA_AT(0, -1);
    float le = LUMA_AT(1, 0), lw = LUMA_AT(-1, 0);
    float lmax = max(lc, max(max(ln, ls), max(le, lw)));
    float range = lmax - min(lc, min(min(ln, ls), min(le, lw)));
    if (range < max(EDGE_MIN, lmax * EDGE_REL)) {
        o_color = c;
        return;
    }
    float lne = LUMA_AT(1, 1), lnw = LUMA_AT(-1, 1);
    float lse = LUMA_AT(1, -1), lsw = LUMA_AT(-1, -1);

    // 2. sub-pixel: the pixel against the weighted mean of its neighbours
    float mean = (2.0 * (ln + ls + le + lw) + (lne + lnw + lse + lsw)) / 12.0;
    float sub = clamp(abs(mean - lc) / range, 0.0, 1.0);
    sub = smoothstep(0.0, 1.0, sub);
    sub = sub * sub * SUB_AMOUNT;

    // 3. horizontal edge (it runs along x): the change is across y
    float across_y = 2.0 * abs(ln - 2.0 * lc + ls) + abs(lne - 2.0 * le + lse) + abs(lnw - 2.0 * lw + lsw);
    float across_x = 2.0 * abs(le - 2.0 * lc + lw) + abs(lne - 2.0 * ln + lnw) + abs(lse - 2.0 * ls + lsw);
    bool horz = across_y >= across_x;
    float l1 = horz ? ls : lw, l2 = horz ? ln : le; // the two sides: below/left, above/right
    float g1 = abs(l1 - lc), g2 = abs(l2 - lc);
    bool side1 = g1 >= g2;
    float step_len = horz ? px.y : px.x;
    if (side1)
        step_len = -step_len;
    float l_edge = 0.5 * (lc + (side1 ? l1 : l2)); // luma halfway across the edge
    float grad = 0.25 * max(g1, g2);
    vec2 along = horz ? vec2(px.x, 0.0) : vec2(0.0, px.y);
    vec2 mid = uv + (horz ? vec2(0.0, 0.5 * step_len) : vec2(0.5 * step_len, 0.0));

    // the walk: bilinear taps on the edge line read both sides' mean
    const float STEPS[3] = float[3](1.0, 3.0, 7.0);
    float d1 = STEPS[2] + 3.0, d2 = STEPS[2] + 3.0, e1 = 0.0, e2 = 0.0;
    bool done1 = false, done2 = false;
    for (int i = 0; i < 3; i++) {
        if (!done1) {
            e1 = luma(textureLod(u_src, mid - along * STEPS[i], 0.0)) - l_edge;
            if (abs(e1) >= grad)
                done1 = true, d1 = STEPS[i];
        }
        if (!done2) {
            e2 = luma(textureLod(u_src, mid + along * STEPS[i], 0.0)) - l_edge;
            if (abs(e2) >= grad)
                done2 = true, d2 = STEPS[i];
        }
        if (done1 && done2)
            break;
    }
    // the nearer end decides: blend only where the edge leans toward this pixel
    float e_near = d1 < d2 ? e1 : e2;
    bool leans = (lc - l_edge < 0.0) != (e_near < 0.0);
    float edge_off = leans ? 0.5 - min(d1, d2) / (d1 + d2) : 0.0;

    float off = max(edge_off, sub);
    vec2 o = horz ? vec2(0.0, off * step_len) : vec2(off * step_len, 0.0);
    o_color = vec4(textureLod(u_src, uv + o, 0.0).rgb, c.a);
#endif
}
