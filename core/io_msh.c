/* io_msh.c - the mesh as Gmsh MSH 4.1 ASCII: entities (a surface per region, a curve per
 * domain side) with their physical groups, nodes, elements, and on a periodic domain the
 * periodic curves with their node pairs. */
#include <stdlib.h>

#include "grainpack/io_mesh.h"
#include "writer.h"

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

/* Elements of each region: triangles [tri_start[r], tri_start[r+1]) (they are sorted by
 * region), and the quadrilaterals, all in the last region. */
static void region_ranges(const gp_mesh *m, size_t *tri_start)
{
    size_t nregions = m->ngrains + 1, t = 0;
    for (size_t r = 0; r <= nregions; r++) {
        while (t < m->ntri && (size_t)m->tri_region[t] < r)
            t++;
        tri_start[r] = t;
    }
}

static size_t region_elements(const gp_mesh *m, const size_t *tri_start, size_t r)
{
    return tri_start[r + 1] - tri_start[r] + (r == m->ngrains ? m->nquad : 0);
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
static int periodic_section(gp_out *o, const gp_domain *d, const gp_mesh *m)
{
    int32_t *pairs[2] = {NULL, NULL};
    size_t n[2] = {0, 0}, links = 0;
    int rc = 0;
    for (int axis = 0; axis < 2 && rc == 0; axis++) {
        rc = gp_mesh_periodic_pairs(m, d, axis, &pairs[axis], &n[axis]);
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

int gp_write_msh(gp_out *o, const gp_spec *spec, const gp_result *result)
{
    int checked = gp_mesh_result_check(result, GP_FORMAT_MSH, NULL);
    if (checked)
        return checked;
    const gp_mesh *m = &result->mesh;
    size_t nregions = m->ngrains + 1;
    size_t *tri_start = malloc((nregions + 1) * sizeof *tri_start);
    if (!tri_start)
        return GP_ENOMEM;
    region_ranges(m, tri_start);
    size_t side_count[GP_SIDE_COUNT] = {0}, surfaces = 0;
    for (size_t e = 0; e < m->nbedges; e++)
        side_count[m->bedge_side[e]]++;
    for (size_t r = 0; r < nregions; r++)
        surfaces += region_elements(m, tri_start, r) > 0;
    size_t curves = 0;
    for (int s = 0; s < GP_SIDE_COUNT; s++)
        curves += side_count[s] > 0;

    gp_out_puts(o, "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n");
    gp_out_uint(o, surfaces + curves);
    gp_out_char(o, '\n');
    for (int s = 0; s < GP_SIDE_COUNT; s++) {
        if (!side_count[s])
            continue;
        gp_out_puts(o, "1 ");
        gp_out_int(o, s + 1);
        gp_out_puts(o, " \"");
        gp_out_puts(o, gp_mesh_side_name((gp_mesh_side)s));
        gp_out_puts(o, "\"\n");
    }
    for (size_t r = 0; r < nregions; r++) {
        if (!region_elements(m, tri_start, r))
            continue;
        gp_out_puts(o, "2 ");
        gp_out_int(o, surface_tag((int32_t)r));
        gp_out_char(o, ' ');
        region_name(o, m, (int32_t)r);
        gp_out_char(o, '\n');
    }
    gp_out_puts(o, "$EndPhysicalNames\n$Entities\n0 ");
    gp_out_uint(o, curves);
    gp_out_char(o, ' ');
    gp_out_uint(o, surfaces);
    gp_out_puts(o, " 0\n");
    for (int s = 0; s < GP_SIDE_COUNT; s++) {
        if (!side_count[s])
            continue;
        gp_out_int(o, s + 1);
        gp_out_char(o, ' ');
        bounding_box(o, &spec->domain);
        gp_out_puts(o, " 1 ");
        gp_out_int(o, s + 1);
        gp_out_puts(o, " 0\n");
    }
    for (size_t r = 0; r < nregions; r++) {
        if (!region_elements(m, tri_start, r))
            continue;
        gp_out_int(o, surface_tag((int32_t)r));
        gp_out_char(o, ' ');
        bounding_box(o, &spec->domain);
        gp_out_puts(o, " 1 ");
        gp_out_int(o, surface_tag((int32_t)r));
        gp_out_puts(o, " 0\n");
    }
    /* every node in one block, on the first surface: elements refer to nodes by tag,
       whatever entity holds them */
    int64_t first = 1;
    for (size_t r = 0; r < nregions; r++)
        if (region_elements(m, tri_start, r)) {
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
    for (size_t k = 0; k < m->nnodes; k++) {
        gp_out_uint(o, k + 1);
        gp_out_char(o, '\n');
    }
    for (size_t k = 0; k < m->nnodes; k++) {
        gp_out_double(o, m->xy[2 * k]);
        gp_out_char(o, ' ');
        gp_out_double(o, m->xy[2 * k + 1]);
        gp_out_puts(o, " 0\n");
    }
    size_t blocks = curves + (m->nquad > 0), elements = m->nbedges + m->ntri + m->nquad;
    for (size_t r = 0; r < nregions; r++)
        blocks += tri_start[r + 1] > tri_start[r];
    gp_out_puts(o, "$EndNodes\n$Elements\n");
    gp_out_uint(o, blocks);
    gp_out_char(o, ' ');
    gp_out_uint(o, elements);
    gp_out_puts(o, " 1 ");
    gp_out_uint(o, elements);
    gp_out_char(o, '\n');
    uint64_t tag = 0;
    int line_nodes = m->order + 1, tri_nodes = gp_mesh_tri_nodes(m->order);
    for (int s = 0; s < GP_SIDE_COUNT; s++) {
        if (!side_count[s])
            continue;
        element_block(o, 1, s + 1, m->order == 2 ? MSH_LINE3 : MSH_LINE2, side_count[s]);
        for (size_t e = 0; e < m->nbedges; e++)
            if (m->bedge_side[e] == s)
                element(o, &tag, m->bedge + (size_t)line_nodes * e, line_nodes);
    }
    for (size_t r = 0; r < nregions; r++) {
        size_t nt = tri_start[r + 1] - tri_start[r];
        if (nt) {
            element_block(o, 2, surface_tag((int32_t)r), m->order == 2 ? MSH_TRI6 : MSH_TRI3, nt);
            for (size_t t = tri_start[r]; t < tri_start[r + 1]; t++)
                element(o, &tag, m->tri + (size_t)tri_nodes * t, tri_nodes);
        }
        if (r == m->ngrains && m->nquad) {
            int quad_nodes = gp_mesh_quad_nodes(m->order);
            element_block(o, 2, surface_tag((int32_t)r), m->order == 2 ? MSH_QUAD8 : MSH_QUAD4, m->nquad);
            for (size_t q = 0; q < m->nquad; q++)
                element(o, &tag, m->quad + (size_t)quad_nodes * q, quad_nodes);
        }
    }
    gp_out_puts(o, "$EndElements\n");
    free(tri_start);
    int rc = periodic_section(o, &spec->domain, m);
    int flushed = gp_out_flush(o);
    return rc ? rc : flushed;
}
