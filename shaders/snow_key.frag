#version 330 core
// Snow: the key light's colour, once a frame into a 1x1 target that the
// surface's vertex shader reads (four cube fetches there would be paid
// for every vertex): what the IBL's key-on diffuse map adds to the
// key-off one towards the key.
#include "ibl_common.glsl"
#include "snow_common.glsl"
uniform vec3 u_light_dir; // towards the key light, unit
out vec4 o_key;
void main()
{
    o_key = vec4(snow_hdr(snow_key_color(u_light_dir)), 1.0);
}
