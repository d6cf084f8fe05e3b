#version 330 core
// The HUD's quads with their coverage as alpha: the part of this pixel's
// square inside the rect, or the font texels' area under it (a box
// filter), so edges and glyphs that fall between pixels are softened the
// same way at any render size.  Rects have uv -2..-1 (r_hud.c).
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
    if (v_uv.x < -0.5) {
        vec2 s = v_uv + 2.0, fw = max(fwidth(s), vec2(1e-6));
        cov = span(s.x, fw.x, 0.0, 1.0) * span(s.y, fw.y, 0.0, 1.0);
    } else {
        ivec2 size = textureSize(u_font, 0);
        vec2 t = v_uv * vec2(size), fw = max(fwidth(t), vec2(1e-6));
        ivec2 i0 = ivec2(floor(t - fw * 0.5));
        cov = 0.0;
        for (int y = 0; y < 3; y++)
            for (int x = 0; x < 3; x++) {
                ivec2 i = i0 + ivec2(x, y);
                if (any(lessThan(i, ivec2(0))) || any(greaterThanEqual(i, size)))
                    continue;
                float w = span(t.x, fw.x, float(i.x), float(i.x + 1)) * span(t.y, fw.y, float(i.y), float(i.y + 1));
                cov += w * texelFetch(u_font, i, 0).r;
            }
    }
    if (cov <= 0.0)
        discard;
    o_color = vec4(v_color.rgb, v_color.a * min(cov, 1.0));
}
