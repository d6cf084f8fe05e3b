#version 330 core
// variants: - RECT TAPS=2
// The HUD's quads with their coverage as alpha: the part of this pixel's
// square inside the rect, or the font texels' area under it (a box
// filter), so edges and glyphs that fall between pixels are softened the
// same way at any render size.  Rects have uv -2..-1 (r_hud.c) and are
// drawn with the RECT variant, glyphs with the others: llvmpipe runs both
// sides of a branch, so the glyphs' box filter ran on every pixel of the
// bars.  TAPS=2 is for glyphs drawn at a font pixel of at least one
// screen pixel (r_hud.c).
in vec2 v_uv;
in vec4 v_color;

uniform sampler2D u_font;

out vec4 o_color;

// overlap of the pixel [t - fw/2, t + fw/2] with [a, b], over fw
float span(float t, float fw, float a, float b)
{
    return clamp((min(t + fw * 0.5, b) - max(t - fw * 0.5, a)) / fw, 0.0, 1.0);
}

void main()
{
    float cov;
#ifdef RECT
    vec2 s = v_uv + 2.0, fw = max(fwidth(s), vec2(1e-6));
    cov = span(s.x, fw.x, 0.0, 1.0) * span(s.y, fw.y, 0.0, 1.0);
#else
    {
        ivec2 size = textureSize(u_font, 0);
        vec2 t = v_uv * vec2(size), fw = max(fwidth(t), vec2(1e-6));
        ivec2 i0 = ivec2(floor(t - fw * 0.5));
        cov = 0.0;
        // the pixel spans fw texels (fw < 1 at every HUD size from 640x360
        // up: TAPS=2; the general case reaches 3): texels past the span
        // weigh exactly 0, so both give the same sum
#ifndef TAPS
#define TAPS 3
#endif
        for (int y = 0; y < TAPS; y++)
            for (int x = 0; x < TAPS; x++) {
                ivec2 i = i0 + ivec2(x, y);
                if (any(lessThan(i, ivec2(0))) || any(greaterThanEqual(i, size)))
                    continue;
                float w = span(t.x, fw.x, float(i.x), float(i.x + 1)) * span(t.y, fw.y, float(i.y), float(i.y + 1));
                cov += w * texelFetch(u_font, i, 0).r;
            }
    }
#endif
    if (cov <= 0.0)
        discard;
    o_color = vec4(v_color.rgb, v_color.a * min(cov, 1.0));
}
