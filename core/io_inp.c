/* io_inp.c - the mesh as an Abaqus input file: nodes, elements of the plane stress or
 * plane strain family, an element set per grain and one for the second phase, a node set
 * per domain side (on a periodic axis, the two sides' sets in matching order). */
#include <stdlib.h>
#include <string.h>

#include "grainpack/io_mesh.h"
#include "io_mesh_plan.h"

/* Abaqus data lines hold at most 16 entries. */
#define INP_PER_LINE 16

/* The Abaqus element type: CPS or CPE, 3, 6, 4 or 8 nodes, R for reduced quads. */
static void element_type(gp_out *o, const gp_mesh_params *p, int nodes, int quad)
{
    gp_out_puts(o, p->plane == GP_MESH_PLANE_STRAIN ? "CPE" : "CPS");
    gp_out_int(o, nodes);
    if (quad && p->reduced)
        gp_out_char(o, 'R');
}

static void ids(gp_out *o, const uint64_t *list, size_t n)
{
    for (size_t k = 0; k < n; k++) {
        gp_out_uint(o, list[k]);
        gp_out_puts(o, (k + 1) % INP_PER_LINE == 0 || k + 1 == n ? "\n" : ", ");
    }
}

static int by_value(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The node set of a periodic side, in the order of its pairs (gp_mesh_periodic_pairs:
 * along the side, corners first and last), so that the k-th node of `left` pairs with the
 * k-th of `right` (`bottom` with `top`) for *EQUATION; "unsorted" keeps that order. */
static int periodic_set(gp_writer *w, gp_out *o, gp_mesh_side side, int axis)
{
    int32_t *pairs;
    size_t n;
    int rc = gp_mesh_plan_pairs(w, o, axis, &pairs, &n);
    if (rc)
        return rc;
    uint64_t *list = malloc((n ? n : 1) * sizeof *list);
    if (!list) {
        free(pairs);
        return GP_ENOMEM;
    }
    int high = side == GP_SIDE_RIGHT || side == GP_SIDE_TOP;
    for (size_t k = 0; k < n; k++)
        list[k] = (uint64_t)pairs[2 * k + high] + 1;
    gp_out_puts(o, "*Nset, nset=");
    gp_out_puts(o, gp_mesh_side_name(side));
    gp_out_puts(o, ", unsorted\n");
    ids(o, list, n);
    free(list);
    free(pairs);
    return 0;
}

/* The writer's state: the layout, the last element's tag. */
typedef struct inp_state {
    gp_mesh_layout layout;
    uint64_t tag;
} inp_state;

static void drop(void *state)
{
    gp_mesh_layout_free(&((inp_state *)state)->layout);
}

static void head(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    inp_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    if (gp_mesh_plan_check(w, o) || gp_mesh_layout_read(w, o, &st->layout))
        return;
    gp_out_puts(o, "*Heading\ngrainpack mesh: ");
    gp_out_uint(o, m->ngrains);
    gp_out_puts(o, " grains, ");
    gp_out_uint(o, m->ntri + m->nquad);
    gp_out_puts(o, " elements, seed ");
    gp_out_uint(o, w->spec->seed);
    gp_out_puts(o, "\n*Node\n");
}

static void node(gp_writer *w, gp_out *o, size_t k, int param)
{
    (void)param;
    const double *xy = gp_writer_mesh(w, o, GP_MESH_XY, k);
    if (!xy)
        return;
    gp_out_uint(o, k + 1);
    gp_out_puts(o, ", ");
    gp_out_double(o, xy[0]);
    gp_out_puts(o, ", ");
    gp_out_double(o, xy[1]);
    gp_out_char(o, '\n');
}

/* The element header of the triangles (quad 0) or the quadrilaterals (1), if any. */
static void element_head(gp_writer *w, gp_out *o, int quad)
{
    const gp_mesh *m = &w->result->mesh;
    if (!(quad ? m->nquad : m->ntri))
        return;
    gp_out_puts(o, "*Element, type=");
    element_type(o, &w->spec->mesh, quad ? gp_mesh_quad_nodes(m->order) : gp_mesh_tri_nodes(m->order),
                 quad);
    gp_out_char(o, '\n');
}

static void element(gp_writer *w, gp_out *o, size_t e, int quad)
{
    inp_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    int nodes = quad ? gp_mesh_quad_nodes(m->order) : gp_mesh_tri_nodes(m->order);
    const int32_t *conn = gp_writer_mesh(w, o, quad ? GP_MESH_QUAD : GP_MESH_TRI, e);
    if (!conn)
        return;
    gp_out_uint(o, ++st->tag);
    for (int k = 0; k < nodes; k++) {
        gp_out_puts(o, ", ");
        gp_out_int(o, (int64_t)conn[k] + 1);
    }
    gp_out_char(o, '\n');
}

/* Region r's element set: its elements are one run of tags (triangles sorted by region,
 * and the quadrilaterals, all in the last region, right after the last triangles). */
static void elset(gp_writer *w, gp_out *o, size_t r, int param)
{
    (void)param;
    const inp_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    size_t first = st->layout.tri_start[r], last = first + gp_mesh_layout_elements(m, &st->layout, r);
    if (last == first)
        return;
    gp_mesh_phase phase = gp_mesh_region_phase(m, (int32_t)r);
    gp_out_puts(o, "*Elset, elset=");
    if (phase == GP_PHASE_GRAIN) {
        gp_out_puts(o, "grain_");
        gp_out_uint(o, r);
    } else {
        gp_out_puts(o, gp_mesh_phase_name(phase));
    }
    gp_out_puts(o, ", generate\n");
    gp_out_uint(o, first + 1);
    gp_out_puts(o, ", ");
    gp_out_uint(o, last);
    gp_out_puts(o, ", 1\n");
}

/* A walled side's node set: the nodes of its boundary edges, sorted, once each (the
 * side's edges only are held: a few per element along the side). */
static int side_set(gp_writer *w, gp_out *o, gp_mesh_side side)
{
    const gp_mesh *m = &w->result->mesh;
    const inp_state *st = w->state;
    int stride = m->order + 1;
    size_t n = 0;
    uint64_t *list = malloc(((size_t)stride * st->layout.side_count[side] + 1) * sizeof *list);
    if (!list)
        return GP_ENOMEM;
    for (size_t e = 0; e < m->nbedges; e++) {
        const uint8_t *s = gp_writer_mesh(w, o, GP_MESH_BEDGE_SIDE, e);
        const int32_t *nodes = s && *s == side ? gp_writer_mesh(w, o, GP_MESH_BEDGE, e) : NULL;
        if (o->err) {
            free(list);
            return o->err;
        }
        for (int k = 0; nodes && k < stride; k++)
            list[n++] = (uint64_t)nodes[k] + 1;
    }
    if (n) {
        qsort(list, n, sizeof *list, by_value);
        size_t kept = 0;
        for (size_t k = 0; k < n; k++)
            if (kept == 0 || list[kept - 1] != list[k])
                list[kept++] = list[k];
        gp_out_puts(o, "*Nset, nset=");
        gp_out_puts(o, gp_mesh_side_name(side));
        gp_out_char(o, '\n');
        ids(o, list, kept);
    }
    free(list);
    return 0;
}

static void node_sets(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    int rc = 0;
    for (int s = 0; s < GP_SIDE_COUNT && rc == 0; s++) {
        int axis = s == GP_SIDE_LEFT || s == GP_SIDE_RIGHT ? 0 : 1;
        if (w->spec->domain.periodic & (axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y))
            rc = periodic_set(w, o, (gp_mesh_side)s, axis);
        else
            rc = side_set(w, o, (gp_mesh_side)s);
    }
    if (rc && !o->err)
        o->err = rc;
}

int gp_plan_inp(gp_writer *w)
{
    if (!(w->state = calloc(1, sizeof(inp_state))))
        return GP_ENOMEM;
    w->drop = drop;
    const gp_mesh *m = &w->result->mesh;
    gp_writer_text(w, head, 0);
    gp_writer_items(w, node, m->nnodes, 0);
    gp_writer_text(w, element_head, 0);
    gp_writer_items(w, element, m->ntri, 0);
    gp_writer_text(w, element_head, 1);
    gp_writer_items(w, element, m->nquad, 1);
    gp_writer_items(w, elset, w->result->has_mesh ? m->ngrains + 1 : 0, 0);
    gp_writer_text(w, node_sets, 0);
    return 0;
}

int gp_write_inp(gp_out *o, const gp_spec *spec, const gp_result *result)
{
    int checked = gp_mesh_result_check(result, GP_FORMAT_INP, NULL);
    return checked ? checked : gp_write_result(o, GP_FORMAT_INP, spec, result);
}
