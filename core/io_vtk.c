/* io_vtk.c - the result as VTK legacy polydata (ASCII), which ParaView and VTK read: the
 * Laguerre cells as polygons with the grain id, radii, area and neighbour count as cell
 * data, or, without cells, the disk centres as vertices with the same per-grain data. */
#include <math.h>

#include "writer.h"

/* F where it is not defined (centres on the convex hull or along the walls): legacy VTK
 * readers do not parse "nan", and F >= 0 otherwise. */
#define VTK_NO_QUALITY (-1.0)

/* The per-grain arrays, each a pass over the grains (the `param` of the steps). */
enum { ARRAY_ID, ARRAY_RADIUS, ARRAY_PACKING_RADIUS, ARRAY_AREA, ARRAY_NEIGHBOURS, ARRAY_F };

static const struct {
    const char *name, *type;
    unsigned needs;
} arrays[] = {
    [ARRAY_ID] = {"grain_id", "int", 0},
    [ARRAY_RADIUS] = {"radius", "double", GP_GRAINS_DISKS},
    [ARRAY_PACKING_RADIUS] = {"packing_radius", "double", GP_GRAINS_DISKS},
    [ARRAY_AREA] = {"area", "double", GP_GRAINS_AREA},
    [ARRAY_NEIGHBOURS] = {"neighbours", "int", GP_GRAINS_NEIGHBOURS},
    [ARRAY_F] = {"F", "double", GP_GRAINS_F},
};

static void head(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    const gp_result *r = w->result;
    GP_OUT_LITERAL(out, "# vtk DataFile Version 3.0\ngrainpack ");
    gp_out_puts(out, r->has_cells ? "cells: " : "disks: ");
    gp_out_uint(out, w->grains);
    GP_OUT_LITERAL(out, " grains in ");
    gp_out_double(out, w->spec->domain.width);
    GP_OUT_LITERAL(out, " x ");
    gp_out_double(out, w->spec->domain.height);
    GP_OUT_LITERAL(out, ", seed ");
    gp_out_uint(out, w->spec->seed);
    GP_OUT_LITERAL(out, "\nASCII\nDATASET POLYDATA\nPOINTS ");
    gp_out_uint(out, r->has_cells ? w->source.vertex_count : w->grains);
    GP_OUT_LITERAL(out, " double\n");
}

static void point(gp_out *out, double x, double y)
{
    gp_out_double(out, x);
    gp_out_char(out, ' ');
    gp_out_double(out, y);
    GP_OUT_LITERAL(out, " 0\n");
}

static void cell_points(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)w;
    (void)param;
    for (size_t k = win->start[j]; k < win->start[j + 1]; k++) {
        const double *v = &win->xy[2 * (k - win->vertex_base)];
        point(out, v[0], v[1]);
    }
}

static void centre(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)w;
    (void)param;
    point(out, win->disks[j].x, win->disks[j].y);
}

static void polygons_head(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    GP_OUT_LITERAL(out, "POLYGONS ");
    gp_out_uint(out, w->grains);
    gp_out_char(out, ' ');
    gp_out_uint(out, w->grains + w->source.vertex_count);
    gp_out_char(out, '\n');
}

static void polygon(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)w;
    (void)param;
    gp_out_uint(out, win->start[j + 1] - win->start[j]);
    for (size_t k = win->start[j]; k < win->start[j + 1]; k++) {
        gp_out_char(out, ' ');
        gp_out_uint(out, k);
    }
    gp_out_char(out, '\n');
}

static void vertices_head(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    GP_OUT_LITERAL(out, "VERTICES ");
    gp_out_uint(out, w->grains);
    gp_out_char(out, ' ');
    gp_out_uint(out, 2 * w->grains);
    gp_out_char(out, '\n');
}

static void vertex(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)w;
    (void)param;
    GP_OUT_LITERAL(out, "1 ");
    gp_out_uint(out, win->first + j);
    gp_out_char(out, '\n');
}

static void data_head(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    gp_out_puts(out, w->result->has_cells ? "CELL_DATA " : "POINT_DATA ");
    gp_out_uint(out, w->grains);
    gp_out_char(out, '\n');
}

static void array_head(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    GP_OUT_LITERAL(out, "SCALARS ");
    gp_out_puts(out, arrays[param].name);
    gp_out_char(out, ' ');
    gp_out_puts(out, arrays[param].type);
    GP_OUT_LITERAL(out, " 1\nLOOKUP_TABLE default\n");
}

static void value(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)w;
    switch (param) {
    case ARRAY_ID: gp_out_uint(out, win->first + j); break;
    case ARRAY_RADIUS: gp_out_double(out, win->disks[j].r); break;
    case ARRAY_PACKING_RADIUS: gp_out_double(out, win->disks[j].R); break;
    case ARRAY_AREA: gp_out_double(out, win->area[j]); break;
    case ARRAY_NEIGHBOURS: gp_out_uint(out, win->nstart[j + 1] - win->nstart[j]); break;
    case ARRAY_F: gp_out_double(out, isnan(win->F[j]) ? VTK_NO_QUALITY : win->F[j]); break;
    }
    gp_out_char(out, '\n');
}

static void array(gp_writer *w, int which)
{
    gp_writer_text(w, array_head, which);
    gp_writer_grains(w, value, arrays[which].needs, which);
}

int gp_plan_vtk(gp_writer *w)
{
    const gp_result *r = w->result;
    gp_writer_text(w, head, 0);
    if (r->has_cells) {
        gp_writer_grains(w, cell_points, GP_GRAINS_POLYGONS, 0);
        gp_writer_text(w, polygons_head, 0);
        gp_writer_grains(w, polygon, GP_GRAINS_POLYGONS, 0);
    } else {
        gp_writer_grains(w, centre, GP_GRAINS_DISKS, 0);
        gp_writer_text(w, vertices_head, 0);
        gp_writer_grains(w, vertex, 0, 0);
    }
    gp_writer_text(w, data_head, 0);
    array(w, ARRAY_ID);
    array(w, ARRAY_RADIUS);
    array(w, ARRAY_PACKING_RADIUS);
    if (r->has_cells) {
        array(w, ARRAY_AREA);
        array(w, ARRAY_NEIGHBOURS);
    }
    if (r->has_balance)
        array(w, ARRAY_F);
    return 0;
}
