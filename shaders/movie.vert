#version 330 core
// One triangle covering the viewport.  v_uv is (0,0) at the picture's
// top-left corner: texture row 0 is the movie's first (top) row.
out vec2 v_uv;
void main()
{
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    v_uv = vec2(p.x, 1.0 - p.y);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
