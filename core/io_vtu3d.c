/* io_vtu3d.c - the 3D result as a VTK XML unstructured grid (ASCII): the Laguerre
 * polyhedra as VTK_POLYHEDRON cells, or without cells the sphere centres as vertices,
 * with the grains' data on the cells. ParaView, VTK and meshio read it. Written window
 * by window (writer3d.h): each data array is one pass over the grains, carrying only a
 * running offset from one to the next. */
#include <math.h>

#include "vtu_array.h"
#include "writer3d.h"

/* VTK cell types (vtkCellType.h). */
#define VTK_VERTEX 1
#define VTK_POLYHEDRON 42

/* The data arrays, in the order they are written. With cells: connectivity = each cell's
 * own vertices; "faces" = per cell its face count then each face's size and point ids,
 * "faceoffsets" = where each cell's stream ends in "faces" (VTK's polyhedron layout
 * before VTK 9.4, which 9.4 still reads). */
enum { POINTS, CONNECTIVITY, OFFSETS, TYPES, FACES, FACEOFFSETS, GRAIN, RADIUS, PACKING_RADIUS,
       VOLUME, F, ARRAYS };
static const struct {
    const char *type, *name;
} array[ARRAYS] = {
    {"Float64", "Points"}, {"Int64", "connectivity"}, {"Int64", "offsets"}, {"UInt8", "types"},
    {"Int64", "faces"},   {"Int64", "faceoffsets"},  {"Int32", "grain"},   {"Float64", "r"},
    {"Float64", "R"},     {"Float64", "volume"},     {"Float64", "F"},
};

typedef struct vtu3d_state {
    gp_state3d base;
    vtu_array a;     /* the data array being written */
    int64_t end;     /* faceoffsets: where the last cell's stream ended in "faces" */
} vtu3d_state;

/* Opens data array `param` after closing the one before it (what separates them). */
static void open_array(gp_writer *w, gp_out *o, int param)
{
    vtu3d_state *st = w->state;
    const gp_result3d *r = st->base.result;
    if (param == POINTS)
        vtu_header(o, r->has_cells ? r->cell_stats.vertices : r->packing.count, r->packing.count);
    else
        vtu_close_array(&st->a);
    if (param == CONNECTIVITY)
        gp_out_puts(o, "</Points>\n<Cells>\n");
    else if (param == GRAIN)
        gp_out_puts(o, "</Cells>\n<CellData Scalars=\"grain\">\n");
    st->end = 0;
    st->a = vtu_open_array(o, array[param].type, array[param].name, param == POINTS ? 3 : 1);
}

static void tail(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    vtu3d_state *st = w->state;
    vtu_close_array(&st->a);
    gp_out_puts(o, "</CellData>\n");
    int rc = vtu_footer(o);
    if (rc && !o->err)
        o->err = rc;
}

/* Item k's value k + param (point indices, grain ids, a vertex's offset). */
static void index_value(gp_writer *w, gp_out *o, size_t k, int param)
{
    (void)o;
    vtu3d_state *st = w->state;
    vtu_int(&st->a, (int64_t)k + param);
}

/* The VTK cell type `param`, once per item. */
static void cell_type(gp_writer *w, gp_out *o, size_t k, int param)
{
    (void)o;
    (void)k;
    vtu3d_state *st = w->state;
    vtu_int(&st->a, param);
}

/* What each array reads of a window. */
static unsigned needs(const gp_result3d *r, int param)
{
    switch (param) {
    case POINTS: return r->has_cells ? GP_W3_CELLS | GP_W3_XYZ : GP_W3_SPHERES;
    case OFFSETS: return GP_W3_CELLS;
    case FACES:
    case FACEOFFSETS: return GP_W3_CELLS | GP_W3_FACES;
    case VOLUME: return GP_W3_CELLS | GP_W3_VOLUME;
    case F: return GP_W3_F;
    default: return GP_W3_SPHERES;
    }
}

/* Grain i's values in array `param`. */
static void grain_value(gp_writer *w, gp_out *o, size_t i, int param)
{
    vtu3d_state *st = w->state;
    const gp_window3d *win = gp_state3d_window(w, o, needs(st->base.result, param), i);
    if (!win)
        return;
    size_t j = i - win->first;
    const gp_cells3d *c = win->cells;
    vtu_array *a = &st->a;
    switch (param) {
    case POINTS:
        if (!c) {
            vtu_double(a, win->spheres[j].x);
            vtu_double(a, win->spheres[j].y);
            vtu_double(a, win->spheres[j].z);
            break;
        }
        for (size_t k = 3 * c->vstart[j]; k < 3 * c->vstart[j + 1]; k++)
            vtu_double(a, c->xyz[k]);
        break;
    case OFFSETS: vtu_int(a, (int64_t)(win->vertex_base + c->vstart[j + 1])); break;
    case FACES:
        vtu_int(a, (int64_t)(c->fstart[j + 1] - c->fstart[j]));
        for (size_t f = c->fstart[j]; f < c->fstart[j + 1]; f++) {
            vtu_int(a, (int64_t)(c->fvstart[f + 1] - c->fvstart[f]));
            for (size_t k = c->fvstart[f]; k < c->fvstart[f + 1]; k++)
                vtu_int(a, (int64_t)(win->vertex_base + c->vstart[j] + c->fverts[k]));
        }
        break;
    case FACEOFFSETS:
        st->end += 1;
        for (size_t f = c->fstart[j]; f < c->fstart[j + 1]; f++)
            st->end += 1 + (int64_t)(c->fvstart[f + 1] - c->fvstart[f]);
        vtu_int(a, st->end);
        break;
    case RADIUS: vtu_double(a, win->spheres[j].r); break;
    case PACKING_RADIUS: vtu_double(a, win->spheres[j].R); break;
    case VOLUME: vtu_double(a, c->volume[j]); break;
    default: vtu_double(a, isnan(win->F[j]) ? VTU_NO_QUALITY : win->F[j]); break;
    }
}

int gp_plan_vtu3d(gp_writer *w, const gp_plan3d_args *a)
{
    int rc = gp_plan3d_state(w, a, sizeof(vtu3d_state));
    if (rc)
        return rc;
    const gp_result3d *r = a->result;
    size_t n = r->packing.count;
    int cells = r->has_cells;
    gp_writer_text(w, open_array, POINTS);
    gp_writer_items(w, grain_value, n, POINTS);
    gp_writer_text(w, open_array, CONNECTIVITY);
    gp_writer_items(w, index_value, cells ? r->cell_stats.vertices : n, 0);
    gp_writer_text(w, open_array, OFFSETS);
    if (cells)
        gp_writer_items(w, grain_value, n, OFFSETS);
    else
        gp_writer_items(w, index_value, n, 1);
    gp_writer_text(w, open_array, TYPES);
    gp_writer_items(w, cell_type, n, cells ? VTK_POLYHEDRON : VTK_VERTEX);
    for (int k = cells ? FACES : GRAIN; k < ARRAYS; k++) {
        if ((k == VOLUME && !cells) || (k == F && !r->has_balance))
            continue;
        gp_writer_text(w, open_array, k);
        if (k == GRAIN)
            gp_writer_items(w, index_value, n, 0);
        else
            gp_writer_items(w, grain_value, n, k);
    }
    gp_writer_text(w, tail, 0);
    return 0;
}

int gp_write_vtu3d(gp_out *o, const gp_result3d *result)
{
    return gp_write3d_memory(o, GP_FORMAT3D_VTU, NULL, result);
}
