/* io_msh.c - the mesh as Gmsh MSH 4.1 ASCII: entities (a surface per region, a curve per
 * domain side) with their physical groups, nodes, elements, and on a periodic domain the
 * periodic curves with their node pairs. */
#include <stdlib.h>

#include "grainpack/io_mesh.h"
#include "io_mesh_plan.h"

/* Gmsh element types (MSH format reference, "elm-type"). */
#define MSH_LINE2 1
#define MSH_TRI3 2
#define MSH_QUAD4 3
#define MSH_LINE3 8
#define MSH_TRI6 9
#define MSH_QUAD8 16

/* The surface entity and physical tag of region r; curve entities and groups 1..4 are
 * the sides, in gp_mesh_side order. */
static int64_t surface_tag(int32_t region)
{
    return (int64_t)region + 1;
}

/* The region name as Gmsh's physical group: grain_<id>, grain_boundary, matrix. */
static void region_name(gp_out *o, const gp_mesh *m, int32_t region)
{
    gp_mesh_phase phase = gp_mesh_region_phase(m, region);
    gp_out_char(o, '"');
    if (phase == GP_PHASE_GRAIN) {
        gp_out_puts(o, "grain_");
        gp_out_int(o, region);
    } else {
        gp_out_puts(o, gp_mesh_phase_name(phase));
    }
    gp_out_char(o, '"');
}

static void bounding_box(gp_out *o, const gp_domain *d)
{
    gp_out_puts(o, "0 0 0 ");
    gp_out_double(o, d->width);
    gp_out_char(o, ' ');
    gp_out_double(o, d->height);
    gp_out_puts(o, " 0");
}

static void element_block(gp_out *o, int dim, int64_t entity, int type, size_t count)
{
    gp_out_int(o, dim);
    gp_out_char(o, ' ');
    gp_out_int(o, entity);
    gp_out_char(o, ' ');
    gp_out_int(o, type);
    gp_out_char(o, ' ');
    gp_out_uint(o, count);
    gp_out_char(o, '\n');
}

static void element(gp_out *o, uint64_t *tag, const int32_t *nodes, int n)
{
    gp_out_uint(o, ++*tag);
    for (int k = 0; k < n; k++) {
        gp_out_char(o, ' ');
        gp_out_int(o, (int64_t)nodes[k] + 1);
    }
    gp_out_char(o, '\n');
}

/* The $Periodic section (MSH 4.1) of a periodic domain: curve `right` is the periodic
 * copy of curve `left`, `top` of `bottom`, by the translation of one period (the 4 x 4
 * affine matrix, by rows, maps the master's points to the copy's), with every node pair,
 * corners included (gp_mesh_periodic_pairs). Nothing on a walled domain. */
static int periodic_section(gp_writer *w, gp_out *o)
{
    const gp_domain *d = &w->spec->domain;
    int32_t *pairs[2] = {NULL, NULL};
    size_t n[2] = {0, 0}, links = 0;
    int rc = 0;
    for (int axis = 0; axis < 2 && rc == 0; axis++) {
        rc = gp_mesh_plan_pairs(w, o, axis, &pairs[axis], &n[axis]);
        links += n[axis] > 0;
    }
    if (rc == 0 && links) {
        gp_out_puts(o, "$Periodic\n");
        gp_out_uint(o, links);
        gp_out_char(o, '\n');
        for (int axis = 0; axis < 2; axis++) {
            if (!n[axis])
                continue;
            /* the copy (right, top) and its master (left, bottom), as curve tags */
            int copy = (axis == 0 ? GP_SIDE_RIGHT : GP_SIDE_TOP) + 1;
            int master = (axis == 0 ? GP_SIDE_LEFT : GP_SIDE_BOTTOM) + 1;
            double shift[2] = {axis == 0 ? d->width : 0.0, axis == 1 ? d->height : 0.0};
            gp_out_puts(o, "1 ");
            gp_out_int(o, copy);
            gp_out_char(o, ' ');
            gp_out_int(o, master);
            gp_out_puts(o, "\n16");
            for (int r = 0; r < 4; r++)
                for (int c = 0; c < 4; c++) {
                    gp_out_char(o, ' ');
                    if (c == 3 && r < 2)
                        gp_out_double(o, shift[r]);
                    else
                        gp_out_int(o, r == c);
                }
            gp_out_char(o, '\n');
            gp_out_uint(o, n[axis]);
            gp_out_char(o, '\n');
            for (size_t k = 0; k < n[axis]; k++) {
                gp_out_int(o, (int64_t)pairs[axis][2 * k + 1] + 1);
                gp_out_char(o, ' ');
                gp_out_int(o, (int64_t)pairs[axis][2 * k] + 1);
                gp_out_char(o, '\n');
            }
        }
        gp_out_puts(o, "$EndPeriodic\n");
    }
    free(pairs[0]);
    free(pairs[1]);
    return rc;
}

/* The writer's state: the layout, and where the element list is. */
typedef struct msh_state {
    gp_mesh_layout layout;
    size_t surfaces, curves;
    uint64_t tag;       /* of the last element written */
    int32_t region;     /* of the last triangle written */
} msh_state;

static void drop(void *state)
{
    gp_mesh_layout_free(&((msh_state *)state)->layout);
}

static int has_elements(gp_writer *w, size_t r)
{
    const msh_state *st = w->state;
    return gp_mesh_layout_elements(&w->result->mesh, &st->layout, r) > 0;
}

/* The header and the sides' physical names; the regions' follow (region_name_item). */
static void head(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    msh_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    if (gp_mesh_plan_check(w, o) || gp_mesh_layout_read(w, o, &st->layout))
        return;
    for (size_t r = 0; r <= m->ngrains; r++)
        st->surfaces += has_elements(w, r);
    for (int s = 0; s < GP_SIDE_COUNT; s++)
        st->curves += st->layout.side_count[s] > 0;
    gp_out_puts(o, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    gp_out_uint(o, st->surfaces + st->curves);
    gp_out_char(o, '\n');
    for (int s = 0; s < GP_SIDE_COUNT; s++) {
        if (!st->layout.side_count[s])
            continue;
        gp_out_puts(o, "1 ");
        gp_out_int(o, s + 1);
        gp_out_puts(o, " \"");
        gp_out_puts(o, gp_mesh_side_name((gp_mesh_side)s));
        gp_out_puts(o, "\"\n");
    }
}

static void physical_name(gp_writer *w, gp_out *o, size_t r, int param)
{
    (void)param;
    if (!has_elements(w, r))
        return;
    gp_out_puts(o, "2 ");
    gp_out_int(o, surface_tag((int32_t)r));
    gp_out_char(o, ' ');
    region_name(o, &w->result->mesh, (int32_t)r);
    gp_out_char(o, '\n');
}

/* The entities' header and the sides' curves; the regions' surfaces follow. */
static void entities(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    const msh_state *st = w->state;
    gp_out_puts(o, "$EndPhysicalNames\n$Entities\n0 ");
    gp_out_uint(o, st->curves);
    gp_out_char(o, ' ');
    gp_out_uint(o, st->surfaces);
    gp_out_puts(o, " 0\n");
    for (int s = 0; s < GP_SIDE_COUNT; s++) {
        if (!st->layout.side_count[s])
            continue;
        gp_out_int(o, s + 1);
        gp_out_char(o, ' ');
        bounding_box(o, &w->spec->domain);
        gp_out_puts(o, " 1 ");
        gp_out_int(o, s + 1);
        gp_out_puts(o, " 0\n");
    }
}

static void surface(gp_writer *w, gp_out *o, size_t r, int param)
{
    (void)param;
    if (!has_elements(w, r))
        return;
    gp_out_int(o, surface_tag((int32_t)r));
    gp_out_char(o, ' ');
    bounding_box(o, &w->spec->domain);
    gp_out_puts(o, " 1 ");
    gp_out_int(o, surface_tag((int32_t)r));
    gp_out_puts(o, " 0\n");
}

/* The nodes' header: every node in one block, on the first surface (elements refer to
 * nodes by tag, whatever entity holds them). */
static void nodes_head(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    const gp_mesh *m = &w->result->mesh;
    int64_t first = 1;
    for (size_t r = 0; r <= m->ngrains; r++)
        if (has_elements(w, r)) {
            first = surface_tag((int32_t)r);
            break;
        }
    gp_out_puts(o, "$EndEntities\n$Nodes\n1 ");
    gp_out_uint(o, m->nnodes);
    gp_out_puts(o, " 1 ");
    gp_out_uint(o, m->nnodes);
    gp_out_puts(o, "\n2 ");
    gp_out_int(o, first);
    gp_out_puts(o, " 0 ");
    gp_out_uint(o, m->nnodes);
    gp_out_char(o, '\n');
}

static void node_tag(gp_writer *w, gp_out *o, size_t k, int param)
{
    (void)w;
    (void)param;
    gp_out_uint(o, k + 1);
    gp_out_char(o, '\n');
}

static void node_xy(gp_writer *w, gp_out *o, size_t k, int param)
{
    (void)param;
    const double *xy = gp_writer_mesh(w, o, GP_MESH_XY, k);
    if (!xy)
        return;
    gp_out_double(o, xy[0]);
    gp_out_char(o, ' ');
    gp_out_double(o, xy[1]);
    gp_out_puts(o, " 0\n");
}

static void elements_head(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    const msh_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    size_t blocks = st->curves + (m->nquad > 0), elements = m->nbedges + m->ntri + m->nquad;
    for (size_t r = 0; r <= m->ngrains; r++)
        blocks += st->layout.tri_start[r + 1] > st->layout.tri_start[r];
    gp_out_puts(o, "$EndNodes\n$Elements\n");
    gp_out_uint(o, blocks);
    gp_out_char(o, ' ');
    gp_out_uint(o, elements);
    gp_out_puts(o, " 1 ");
    gp_out_uint(o, elements);
    gp_out_char(o, '\n');
}

/* Boundary edge e if it is on side `side` (a pass per side, the side's block first). */
static void side_edge(gp_writer *w, gp_out *o, size_t e, int side)
{
    msh_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    if (!st->layout.side_count[side])
        return;
    if (e == 0)
        element_block(o, 1, side + 1, m->order == 2 ? MSH_LINE3 : MSH_LINE2, st->layout.side_count[side]);
    const uint8_t *s = gp_writer_mesh(w, o, GP_MESH_BEDGE_SIDE, e);
    if (!s || *s != side)
        return;
    const int32_t *nodes = gp_writer_mesh(w, o, GP_MESH_BEDGE, e);
    if (nodes)
        element(o, &st->tag, nodes, m->order + 1);
}

/* Triangle t, after its region's block header when it is the region's first. */
static void triangle(gp_writer *w, gp_out *o, size_t t, int param)
{
    (void)param;
    msh_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    const int32_t *region = gp_writer_mesh(w, o, GP_MESH_TRI_REGION, t);
    if (!region)
        return;
    if (t == 0 || *region != st->region) {
        st->region = *region;
        size_t r = (size_t)*region;
        element_block(o, 2, surface_tag(*region), m->order == 2 ? MSH_TRI6 : MSH_TRI3,
                      st->layout.tri_start[r + 1] - st->layout.tri_start[r]);
    }
    const int32_t *nodes = gp_writer_mesh(w, o, GP_MESH_TRI, t);
    if (nodes)
        element(o, &st->tag, nodes, gp_mesh_tri_nodes(m->order));
}

/* Quadrilateral q, all in the last region's block, after its triangles. */
static void quad(gp_writer *w, gp_out *o, size_t q, int param)
{
    (void)param;
    msh_state *st = w->state;
    const gp_mesh *m = &w->result->mesh;
    if (q == 0)
        element_block(o, 2, surface_tag((int32_t)m->ngrains), m->order == 2 ? MSH_QUAD8 : MSH_QUAD4,
                      m->nquad);
    const int32_t *nodes = gp_writer_mesh(w, o, GP_MESH_QUAD, q);
    if (nodes)
        element(o, &st->tag, nodes, gp_mesh_quad_nodes(m->order));
}

static void tail(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    gp_out_puts(o, "$EndElements\n");
    int rc = periodic_section(w, o);
    if (rc && !o->err)
        o->err = rc;
}

int gp_plan_msh(gp_writer *w)
{
    if (!(w->state = calloc(1, sizeof(msh_state))))
        return GP_ENOMEM;
    w->drop = drop;
    const gp_mesh *m = &w->result->mesh;
    size_t regions = w->result->has_mesh ? m->ngrains + 1 : 0;
    gp_writer_text(w, head, 0);
    gp_writer_items(w, physical_name, regions, 0);
    gp_writer_text(w, entities, 0);
    gp_writer_items(w, surface, regions, 0);
    gp_writer_text(w, nodes_head, 0);
    gp_writer_items(w, node_tag, m->nnodes, 0);
    gp_writer_items(w, node_xy, m->nnodes, 0);
    gp_writer_text(w, elements_head, 0);
    for (int s = 0; s < GP_SIDE_COUNT; s++)
        gp_writer_items(w, side_edge, m->nbedges, s);
    gp_writer_items(w, triangle, m->ntri, 0);
    gp_writer_items(w, quad, m->nquad, 0);
    gp_writer_text(w, tail, 0);
    return 0;
}

int gp_write_msh(gp_out *o, const gp_spec *spec, const gp_result *result)
{
    int checked = gp_mesh_result_check(result, GP_FORMAT_MSH, NULL);
    return checked ? checked : gp_write_result(o, GP_FORMAT_MSH, spec, result);
}
