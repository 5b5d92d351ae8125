/* io_svg_mesh.c - the mesh over the picture of a meshed job: every element edge once, as
 * one thin path above the regions (which io_svg.c colours by phase and grain). */
#include "grainpack/io_mesh.h"
#include "io_svg_mesh.h"

/* Beyond this many edges the picture would weigh tens of megabytes and show a grey
 * felt: the caption says the mesh is too fine to draw instead. */
#define SVG_MESH_MAX_EDGES ((size_t)600000)

int gp_svg_mesh_drawable(const gp_mesh *mesh)
{
    /* each interior edge is in two elements: about three edges a triangle over two */
    return 3 * mesh->ntri / 2 + 2 * mesh->nquad <= SVG_MESH_MAX_EDGES;
}

static void edges(gp_out *o, const gp_mesh *m, const int32_t *conn, size_t count, int corners,
                  int nodes, double H, int dec)
{
    for (size_t e = 0; e < count; e++) {
        const int32_t *c = conn + (size_t)nodes * e;
        for (int k = 0; k < corners; k++) {
            int32_t u = c[k], v = c[(k + 1) % corners];
            /* an inner edge is in two elements, run both ways: drawn from one of them */
            if (u > v)
                continue;
            gp_out_char(o, 'M');
            gp_out_fixed(o, m->xy[2 * u], dec);
            gp_out_char(o, ' ');
            gp_out_fixed(o, H - m->xy[2 * u + 1], dec);
            gp_out_char(o, 'L');
            gp_out_fixed(o, m->xy[2 * v], dec);
            gp_out_char(o, ' ');
            gp_out_fixed(o, H - m->xy[2 * v + 1], dec);
        }
        gp_out_char(o, '\n');
    }
}

int gp_svg_mesh(gp_out *o, const gp_result *result, double H, int decimals)
{
    const gp_mesh *m = &result->mesh;
    if (!result->has_mesh || !gp_svg_mesh_drawable(m))
        return gp_out_flush(o);
    gp_out_puts(o, "<path fill=\"none\" stroke=\"#f8f8f8\" stroke-opacity=\"0.7\" "
                   "stroke-width=\"0.4\" vector-effect=\"non-scaling-stroke\" d=\"");
    edges(o, m, m->tri, m->ntri, 3, gp_mesh_tri_nodes(m->order), H, decimals);
    edges(o, m, m->quad, m->nquad, 4, gp_mesh_quad_nodes(m->order), H, decimals);
    gp_out_puts(o, "\"/>\n");
    return gp_out_flush(o);
}
