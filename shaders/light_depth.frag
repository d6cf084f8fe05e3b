#version 330 core
// variants: - SILHOUETTE LSPSM
// Shadow map (depth only) and silhouette (1 where a caster is) from the
// key light; SILHOUETTE selects the second.  LSPSM: the large-world map's
// depth plus its caster flag (u_flag: 1 for a fighter, 0 for scenery).
#if defined(SILHOUETTE) || defined(LSPSM)
out vec4 o_color;
#endif
#ifdef LSPSM
uniform float u_flag;
#endif
void main()
{
#ifdef SILHOUETTE
    o_color = vec4(1.0);
#endif
#ifdef LSPSM
    o_color = vec4(u_flag);
#endif
}
