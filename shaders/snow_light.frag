#version 330 core
// Snow, fake subsurface scattering step 1 (docs/effects.md, "Snow"): the snow's
// lighting rendered in texture space, one texel per point of the snow
// surface over the ring (the displacement map's layout).  Light and view
// vectors are taken into the tangent space of the displaced surface at
// the texel, where the crust's normal map lives; diffuse and specular
// come from the key light (analytic, as strong as the IBL's key-light
// area) and the rest of the sky (the IBL's key-off maps).  snow_light_blur
// blurs the result (light bleeding through the snow) and
// snow_surface.frag multiplies it by the snow's colour:
//   rgb  the key-off light: diffuse, plus specular divided by the albedo
//        (so that colour * light adds it unchanged)
//   a    the key light's share, in units of its diffuse colour (Lambert
//        plus specular); the surface adds colour * key * a * key colour,
//        key being 0 in the fighters' shadow
// Specular is weaker inside dents (the map against the untouched and
// trampled heights).
#include "ibl_common.glsl"
#include "snow_common.glsl"
uniform sampler2D u_map;      // heights (m) over the ring top
uniform sampler2D u_untouched, u_trampled;
uniform sampler2D u_detail;   // the crust: tangent-space normal map, tiling
uniform float u_half;         // the map spans -u_half..u_half in x and z
uniform float u_detail_tile;  // metres per repeat of u_detail
uniform vec2 u_size;          // of the light target
uniform vec3 u_eye;
uniform vec3 u_light_dir;
flat in float v_key_spec;
out vec4 o_light;

float height(vec2 uv)
{
    return snow_height(texture(u_map, uv).r);
}

void main()
{
    // this texel's point on the snow surface
    vec2 uv = gl_FragCoord.xy / u_size;
    vec2 size = vec2(textureSize(u_map, 0));
    float h = height(uv);
    vec3 pos = vec3(-u_half + 2.0 * u_half * uv.x, h, -u_half + 2.0 * u_half * uv.y);

    // the displaced surface's tangent frame from the map's slope (central
    // differences one map texel apart): T along +x, B along +z, N up
    vec2 du = vec2(1.0 / size.x, 0.0), dv = vec2(0.0, 1.0 / size.y);
    float step2 = 4.0 * u_half / size.x; // world distance between the two taps
    float sx = (height(uv + du) - height(uv - du)) / step2;
    float sz = (height(uv + dv) - height(uv - dv)) / step2;
    vec3 T = normalize(vec3(1.0, sx, 0.0));
    vec3 B = vec3(0.0, sz, 1.0);
    B = normalize(B - T * dot(B, T));
    vec3 N = cross(B, T);
    mat3 tbn = mat3(T, B, N); // tangent -> world; its transpose: world -> tangent

    // light and view vectors into texture (tangent) space
    vec3 l = u_light_dir * tbn;
    vec3 v = normalize(u_eye - pos) * tbn;
    vec3 n = normalize(texture(u_detail, pos.xz / u_detail_tile).xyz * 2.0 - 1.0);
    vec3 r = reflect(-v, n);
    float ndl = max(dot(n, l), 0.0);
    float ndv = max(dot(n, v), 0.0);
    float fresnel = 0.25 + 0.75 * pow(1.0 - ndv, 5.0);

    // fresh or pressed down: the albedo and the specular strength here
    float fresh = snow_fresh(h, snow_height(texture(u_untouched, uv).r), snow_height(texture(u_trampled, uv).r));
    float albedo = snow_luma(mix(SNOW_TRAMPLED, SNOW_FRESH, fresh));
    float spec = mix(SNOW_SPEC_TRAMPLED, SNOW_SPEC_FRESH, fresh) * fresnel / albedo;

    // the rest of the sky: the key-off maps (SNOW_EXPONENT is 16), looked
    // up in world space; specular tinted like the diffuse light
    vec3 env_d = texture(u_diffuse_off, tbn * n).rgb;
    float env_s = snow_luma(texture(u_spec16_off, tbn * r).rgb);
    vec3 off = env_d * (1.0 + spec * env_s / max(snow_luma(env_d), 1e-4));
    // the key light: Lambert and a normalised Phong lobe
    float key = ndl + spec * v_key_spec * pow(max(dot(r, l), 0.0), SNOW_EXPONENT) * step(0.0, dot(n, l));
    o_light = vec4(snow_hdr(off), snow_hdr(key));
}
