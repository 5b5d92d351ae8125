/* io_vtu.c - the result as a VTK XML unstructured grid (ASCII), which ParaView, VTK and
 * meshio read: the mesh with its cell data, or without a mesh the grains themselves
 * (cells as polygons, or disk centres as vertices), each written window by window. */
#include <math.h>
#include <stdlib.h>

#include "grainpack/io_mesh.h"
#include "io_mesh_plan.h"
#include "vtu_array.h"

/* VTK cell types (vtkCellType.h). */
#define VTK_VERTEX 1
#define VTK_TRIANGLE 5
#define VTK_POLYGON 7
#define VTK_QUAD 9
#define VTK_QUADRATIC_TRIANGLE 22
#define VTK_QUADRATIC_QUAD 23
/* The mesh, window by window: the state carries the data array being written (its
 * values so far, for the line breaks) and the grains' window of the radii. */
typedef struct vtu_state {
    vtu_array a;
    gp_grain_window grains;
} vtu_state;

/* The arrays of the elements' cell data, in the order they are written. */
enum { CONNECTIVITY, OFFSETS, TYPES, REGION, PHASE, GRAIN_RADIUS, QUALITY, ARRAYS };
static const struct {
    const char *type, *name;
} cell_array[ARRAYS] = {
    {"Int64", "connectivity"}, {"Int64", "offsets"}, {"UInt8", "types"}, {"Int32", "region"},
    {"Int32", "phase"}, {"Float64", "grain_radius"}, {"Float64", "quality"},
};

/* Opens data array `param` after closing the one before it (what separates them). */
static void next_array(gp_writer *w, gp_out *o, int param)
{
    vtu_state *st = w->state;
    if (param == CONNECTIVITY) {
        vtu_close_array(&st->a);
        gp_out_puts(o, "</Points>\n<Cells>\n");
    } else {
        vtu_close_array(&st->a);
        if (param == REGION)
            gp_out_puts(o, "</Cells>\n<CellData Scalars=\"region\">\n");
    }
    st->a = vtu_open_array(o, cell_array[param].type, cell_array[param].name, 1);
}

static void head(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    vtu_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    if (gp_mesh_plan_check(w, o))
        return;
    vtu_header(o, m->nnodes, m->ntri + m->nquad);
    st->a = vtu_open_array(o, "Float64", "Points", 3);
}

static void point(gp_writer *w, gp_out *o, size_t k, int param)
{
    (void)param;
    vtu_state *st = w->state;
    const double *xy = gp_writer_mesh(w, o, GP_MESH_XY, k);
    if (!xy)
        return;
    vtu_double(&st->a, xy[0]);
    vtu_double(&st->a, xy[1]);
    vtu_int(&st->a, 0);
}

static void connectivity(gp_writer *w, gp_out *o, size_t e, int quad)
{
    vtu_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    int n = quad ? gp_mesh_quad_nodes(m->order) : gp_mesh_tri_nodes(m->order);
    const int32_t *c = gp_writer_mesh(w, o, quad ? GP_MESH_QUAD : GP_MESH_TRI, e);
    for (int k = 0; c && k < n; k++)
        vtu_int(&st->a, c[k]);
}

/* The radius of grain r (a region that is a grain), from the grains' window that holds
 * it: the regions grow along the elements, so the windows follow one another. */
static double grain_radius(gp_writer *w, gp_out *o, size_t r)
{
    vtu_state *st = w->state;
    gp_grain_window *g = &st->grains;
    if (!g->disks || r < g->first || r - g->first >= g->count) {
        int rc = w->source.load(w->source.ctx, GP_GRAINS_DISKS, r, g);
        if (rc || !g->disks) {
            g->disks = NULL;
            if (!o->err)
                o->err = rc ? rc : GP_EINVAL;
            return 0.0;
        }
    }
    return g->disks[r - g->first].r;
}

/* Element e's value in the cell array `param`. */
static void cell_value(gp_writer *w, gp_out *o, size_t e, int param)
{
    vtu_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    int tn = gp_mesh_tri_nodes(m->order), qn = gp_mesh_quad_nodes(m->order);
    int tri = e < m->ntri;
    switch (param) {
    case OFFSETS:
        vtu_int(&st->a, tri ? (int64_t)(tn * (e + 1)) : (int64_t)(tn * m->ntri + qn * (e + 1 - m->ntri)));
        return;
    case TYPES:
        vtu_int(&st->a, tri ? (m->order == 2 ? VTK_QUADRATIC_TRIANGLE : VTK_TRIANGLE)
                            : (m->order == 2 ? VTK_QUADRATIC_QUAD : VTK_QUAD));
        return;
    case QUALITY: {
        const double *q = gp_writer_mesh(w, o, GP_MESH_QUALITY, e);
        if (q)
            vtu_double(&st->a, *q);
        return;
    }
    default:
        break;
    }
    int32_t r = gp_mesh_plan_region(w, o, e);
    if (r < 0)
        return;
    if (param == REGION)
        vtu_int(&st->a, r);
    else if (param == PHASE)
        vtu_int(&st->a, gp_mesh_region_phase(m, r));
    else
        vtu_double(&st->a, (size_t)r < m->ngrains ? grain_radius(w, o, (size_t)r) : 0.0);
}

static void tail(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    vtu_state *st = w->state;
    vtu_close_array(&st->a);
    gp_out_puts(o, "</CellData>\n");
    int rc = vtu_footer(o);
    if (rc && !o->err)
        o->err = rc;
}

/* --- the grains without a mesh, window by window: polygons (with cells) or vertices --- */

/* The data arrays of the grains, in the order they are written. */
enum { G_POINTS, G_CONNECTIVITY, G_OFFSETS, G_TYPES, G_ID, G_RADIUS, G_PACKING_RADIUS, G_AREA,
       G_NEIGHBOURS, G_F, G_ARRAYS };
static const struct {
    const char *type, *name;
} grain_array[G_ARRAYS] = {
    {"Float64", "Points"}, {"Int64", "connectivity"}, {"Int64", "offsets"}, {"UInt8", "types"},
    {"Int64", "grain_id"}, {"Float64", "radius"}, {"Float64", "packing_radius"}, {"Float64", "area"},
    {"Int32", "neighbours"}, {"Float64", "F"},
};

/* Opens grain array `param` after closing the one before it (what separates them). */
static void grain_array_open(gp_writer *w, gp_out *o, int param)
{
    vtu_state *st = w->state;
    if (param == G_POINTS) {
        const gp_result *r = w->result;
        size_t n = r->packing.count;
        vtu_header(o, r->has_cells ? w->source.vertex_count : n, n);
    } else {
        vtu_close_array(&st->a);
    }
    if (param == G_CONNECTIVITY)
        gp_out_puts(o, "</Points>\n<Cells>\n");
    else if (param == G_ID)
        gp_out_puts(o, w->result->has_cells ? "</Cells>\n<CellData Scalars=\"radius\">\n"
                                            : "</Cells>\n<PointData Scalars=\"radius\">\n");
    st->a = vtu_open_array(o, grain_array[param].type, grain_array[param].name, param == G_POINTS ? 3 : 1);
}

static void grains_end(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    vtu_state *st = w->state;
    vtu_close_array(&st->a);
    gp_out_puts(o, w->result->has_cells ? "</CellData>\n" : "</PointData>\n");
    int rc = vtu_footer(o);
    if (rc && !o->err)
        o->err = rc;
}

/* A grain's points: its cell's vertices, or its disk's centre. */
static void grain_points(gp_writer *w, gp_out *o, const gp_grain_window *win, size_t j, int param)
{
    (void)o;
    (void)param;
    vtu_state *st = w->state;
    if (!w->result->has_cells) {
        vtu_double(&st->a, win->disks[j].x);
        vtu_double(&st->a, win->disks[j].y);
        vtu_int(&st->a, 0);
        return;
    }
    for (size_t k = win->start[j]; k < win->start[j + 1]; k++) {
        vtu_double(&st->a, win->xy[2 * (k - win->vertex_base)]);
        vtu_double(&st->a, win->xy[2 * (k - win->vertex_base) + 1]);
        vtu_int(&st->a, 0);
    }
}

/* Item k's value k + param (point indices, grain ids, a vertex's offset). */
static void index_value(gp_writer *w, gp_out *o, size_t k, int param)
{
    (void)o;
    vtu_state *st = w->state;
    vtu_int(&st->a, (int64_t)k + param);
}

/* The VTK cell type `param`, once per item. */
static void cell_type(gp_writer *w, gp_out *o, size_t k, int param)
{
    (void)o;
    (void)k;
    vtu_state *st = w->state;
    vtu_int(&st->a, param);
}

/* Grain j's value in grain array `param`. */
static void grain_value(gp_writer *w, gp_out *o, const gp_grain_window *win, size_t j, int param)
{
    (void)o;
    vtu_state *st = w->state;
    switch (param) {
    case G_OFFSETS: vtu_int(&st->a, (int64_t)win->start[j + 1]); break;
    case G_RADIUS: vtu_double(&st->a, win->disks[j].r); break;
    case G_PACKING_RADIUS: vtu_double(&st->a, win->disks[j].R); break;
    case G_AREA: vtu_double(&st->a, win->area[j]); break;
    case G_NEIGHBOURS: vtu_int(&st->a, (int64_t)(win->nstart[j + 1] - win->nstart[j])); break;
    default: vtu_double(&st->a, isnan(win->F[j]) ? VTU_NO_QUALITY : win->F[j]); break;
    }
}

static void plan_grains(gp_writer *w)
{
    const gp_result *r = w->result;
    size_t n = r->packing.count;
    int cells = r->has_cells;
    gp_writer_text(w, grain_array_open, G_POINTS);
    gp_writer_grains(w, grain_points, cells ? GP_GRAINS_POLYGONS : GP_GRAINS_DISKS, 0);
    gp_writer_text(w, grain_array_open, G_CONNECTIVITY);
    gp_writer_items(w, index_value, cells ? w->source.vertex_count : n, 0);
    gp_writer_text(w, grain_array_open, G_OFFSETS);
    if (cells)
        gp_writer_grains(w, grain_value, GP_GRAINS_POLYGONS, G_OFFSETS);
    else
        gp_writer_items(w, index_value, n, 1);
    gp_writer_text(w, grain_array_open, G_TYPES);
    gp_writer_items(w, cell_type, n, cells ? VTK_POLYGON : VTK_VERTEX);
    gp_writer_text(w, grain_array_open, G_ID);
    gp_writer_items(w, index_value, n, 0);
    const struct {
        int array, present;
        unsigned needs;
    } values[] = {
        {G_RADIUS, 1, GP_GRAINS_DISKS},
        {G_PACKING_RADIUS, 1, GP_GRAINS_DISKS},
        {G_AREA, cells, GP_GRAINS_AREA},
        {G_NEIGHBOURS, cells, GP_GRAINS_NEIGHBOURS},
        {G_F, r->has_balance, GP_GRAINS_F},
    };
    for (size_t v = 0; v < sizeof values / sizeof *values; v++)
        if (values[v].present) {
            gp_writer_text(w, grain_array_open, values[v].array);
            gp_writer_grains(w, grain_value, values[v].needs, values[v].array);
        }
    gp_writer_text(w, grains_end, 0);
}

int gp_plan_vtu(gp_writer *w)
{
    if (!(w->state = calloc(1, sizeof(vtu_state))))
        return GP_ENOMEM;
    if (!w->result->has_mesh) {
        plan_grains(w);
        return 0;
    }
    const gp_mesh *m = &w->result->mesh;
    size_t cells = m->ntri + m->nquad;
    gp_writer_text(w, head, 0);
    gp_writer_items(w, point, m->nnodes, 0);
    gp_writer_text(w, next_array, CONNECTIVITY);
    gp_writer_items(w, connectivity, m->ntri, 0);
    gp_writer_items(w, connectivity, m->nquad, 1);
    for (int a = OFFSETS; a < ARRAYS; a++) {
        gp_writer_text(w, next_array, a);
        gp_writer_items(w, cell_value, cells, a);
    }
    gp_writer_text(w, tail, 0);
    return 0;
}

int gp_write_vtu(gp_out *o, const gp_spec *spec, const gp_result *result)
{
    int checked = gp_mesh_result_check(result, GP_FORMAT_VTU, NULL);
    return checked ? checked : gp_write_result(o, GP_FORMAT_VTU, spec, result);
}
