#version 330 core
// Snow footprints (docs/effects.md, "Snow"): drawn with a MIN blend into the
// displacement map.  The snow under a bone is pressed down to the bone's
// underside there (the deeper the bone reaches, the deeper the print) but
// never below the fully trampled minimum, so it never becomes flat.
uniform sampler2D u_trampled; // the minimum, same size as the map
in vec2 v_xz;
flat in vec4 v_a;
flat in vec3 v_b;
out vec4 o_height;
void main()
{
    float r = v_a.w;
    // the point of the bone above this texel: nearest seen from above, or
    // the lower end of a bone that stands upright
    vec2 ab = v_b.xz - v_a.xz;
    float l2 = dot(ab, ab);
    float t = l2 > 1e-8 ? clamp(dot(v_xz - v_a.xz, ab) / l2, 0.0, 1.0) : (v_a.y <= v_b.y ? 0.0 : 1.0);
    vec3 p = mix(v_a.xyz, v_b, t);
    vec2 d = v_xz - p.xz;
    float d2 = dot(d, d);
    if (!(d2 < r * r)) // also NaN
        discard;
    float under = p.y - sqrt(r * r - d2); // the capsule's underside
    float lowest = texelFetch(u_trampled, ivec2(gl_FragCoord.xy), 0).r;
    o_height = vec4(max(under, lowest));
}
