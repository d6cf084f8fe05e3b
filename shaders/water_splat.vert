#version 330 core
// Water (docs/effects.md, "Water"): new waves.  The CPU finds where the fighters'
// bone capsules dip under the surface and how fast they move; each
// contact is one point drawn into the simulation texture (additive
// blending, red channel only), a cosine bump of radius a_splat.z cells and
// height a_splat.w (proportional to the speed).  The point sprite is a
// square a cell wider than the bump on every side.
layout(location = 0) in vec4 a_splat; // centre x, y in cells (texel k's centre at k + 0.5), radius, height
uniform vec2 u_grid;                  // the simulation's size in cells
flat out vec4 v_splat;
void main()
{
    v_splat = a_splat;
    gl_Position = vec4(a_splat.xy / u_grid * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = 2.0 * ceil(a_splat.z) + 2.0;
}
