#version 330 core
// Snow: restart the displacement map from the untouched heights (same size).
uniform sampler2D u_src;
out vec4 o_height;
void main()
{
    o_height = vec4(texelFetch(u_src, ivec2(gl_FragCoord.xy), 0).r);
}
