#ifndef CAP_YUV_GLSL
#define CAP_YUV_GLSL
// BT.709, limited ("TV") range: Y in 16..235, Cb and Cr in 16..240.
const vec3 BT709 = vec3(0.2126, 0.7152, 0.0722);

float luma709(vec3 rgb)
{
    return (16.0 + 219.0 * dot(rgb, BT709)) / 255.0;
}

vec2 chroma709(vec3 rgb)
{
    float y = dot(rgb, BT709);
    return vec2(128.0 + 224.0 * (rgb.b - y) / 1.8556, 128.0 + 224.0 * (rgb.r - y) / 1.5748) / 255.0;
}
#endif
