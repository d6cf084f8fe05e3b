#version 330 core
// variants: - SILHOUETTE
// Shadow map (depth only) and silhouette (1 where a caster is) from the
// key light; SILHOUETTE selects the second.  The large-world map (LSPSM)
// is depth only, as the shadow map.
#ifdef SILHOUETTE
out vec4 o_color;
#endif
void main()
{
#ifdef SILHOUETTE
    o_color = vec4(1.0);
#endif
}
