#ifndef LIGHT_COMMON_GLSL
#define LIGHT_COMMON_GLSL
// The plain renderer's light: one key light and a sky/ground hemisphere.
// The renderer-core work replaces this with image-based lighting.
const vec3 KEY_DIR = normalize(vec3(-0.35, 0.8, 0.5));
const vec3 KEY_COLOR = vec3(1.0, 0.95, 0.85);
const vec3 SKY = vec3(0.32, 0.36, 0.45);
const vec3 GROUND = vec3(0.16, 0.12, 0.10);

vec3 plain_light(vec3 n, vec3 v, vec3 albedo, float specular)
{
    float diff = max(dot(n, KEY_DIR), 0.0);
    vec3 hemi = mix(GROUND, SKY, n.y * 0.5 + 0.5);
    vec3 h = normalize(KEY_DIR + v);
    float spec = specular * pow(max(dot(n, h), 0.0), 32.0) * step(0.0, dot(n, KEY_DIR));
    return albedo * (diff * KEY_COLOR + hemi) + spec * KEY_COLOR;
}
#endif
