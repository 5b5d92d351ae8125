/* io_inp.c - the mesh as an Abaqus input file: nodes, elements of the plane stress or
 * plane strain family, an element set per grain and one for the second phase, a node set
 * per domain side (on a periodic axis, the two sides' sets in matching order). */
#include <stdlib.h>
#include <string.h>

#include "grainpack/io_mesh.h"
#include "writer.h"

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

static void elements(gp_out *o, const int32_t *conn, int nodes, size_t from, size_t count,
                     uint64_t *tag)
{
    for (size_t e = from; e < from + count; e++) {
        gp_out_uint(o, ++*tag);
        for (int k = 0; k < nodes; k++) {
            gp_out_puts(o, ", ");
            gp_out_int(o, (int64_t)conn[(size_t)nodes * e + k] + 1);
        }
        gp_out_char(o, '\n');
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
static int periodic_set(gp_out *o, const gp_domain *d, const gp_mesh *m, gp_mesh_side side, int axis)
{
    int32_t *pairs;
    size_t n;
    int rc = gp_mesh_periodic_pairs(m, d, axis, &pairs, &n);
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

int gp_write_inp(gp_out *o, const gp_spec *spec, const gp_result *result)
{
    int checked = gp_mesh_result_check(result, GP_FORMAT_INP, NULL);
    if (checked)
        return checked;
    const gp_mesh *m = &result->mesh;
    const gp_mesh_params *p = &spec->mesh;
    uint64_t *list = malloc(((m->order + 1) * m->nbedges + 1) * sizeof *list);
    if (!list)
        return GP_ENOMEM;
    gp_out_puts(o, "*Heading\ngrainpack mesh: ");
    gp_out_uint(o, m->ngrains);
    gp_out_puts(o, " grains, ");
    gp_out_uint(o, m->ntri + m->nquad);
    gp_out_puts(o, " elements, seed ");
    gp_out_uint(o, spec->seed);
    gp_out_puts(o, "\n*Node\n");
    for (size_t k = 0; k < m->nnodes; k++) {
        gp_out_uint(o, k + 1);
        gp_out_puts(o, ", ");
        gp_out_double(o, m->xy[2 * k]);
        gp_out_puts(o, ", ");
        gp_out_double(o, m->xy[2 * k + 1]);
        gp_out_char(o, '\n');
    }
    uint64_t tag = 0;
    int tri_nodes = gp_mesh_tri_nodes(m->order), quad_nodes = gp_mesh_quad_nodes(m->order);
    if (m->ntri) {
        gp_out_puts(o, "*Element, type=");
        element_type(o, p, tri_nodes, 0);
        gp_out_char(o, '\n');
        elements(o, m->tri, tri_nodes, 0, m->ntri, &tag);
    }
    if (m->nquad) {
        gp_out_puts(o, "*Element, type=");
        element_type(o, p, quad_nodes, 1);
        gp_out_char(o, '\n');
        elements(o, m->quad, quad_nodes, 0, m->nquad, &tag);
    }
    /* each region's elements are one run of tags: triangles sorted by region, and the
       quadrilaterals (all in the last region) right after the last triangles */
    size_t t = 0;
    for (size_t r = 0; r <= m->ngrains; r++) {
        size_t first = t;
        while (t < m->ntri && (size_t)m->tri_region[t] == r)
            t++;
        size_t last = t + (r == m->ngrains ? m->nquad : 0);
        if (last == first)
            continue;
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
    int stride = m->order + 1, rc = 0;
    for (int s = 0; s < GP_SIDE_COUNT && rc == 0; s++) {
        int axis = s == GP_SIDE_LEFT || s == GP_SIDE_RIGHT ? 0 : 1;
        if (spec->domain.periodic & (axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y)) {
            rc = periodic_set(o, &spec->domain, m, (gp_mesh_side)s, axis);
            continue;
        }
        size_t n = 0;
        for (size_t e = 0; e < m->nbedges; e++)
            if (m->bedge_side[e] == s)
                for (int k = 0; k < stride; k++)
                    list[n++] = (uint64_t)m->bedge[(size_t)stride * e + k] + 1;
        if (!n)
            continue;
        qsort(list, n, sizeof *list, by_value);
        size_t w = 0;
        for (size_t k = 0; k < n; k++)
            if (w == 0 || list[w - 1] != list[k])
                list[w++] = list[k];
        gp_out_puts(o, "*Nset, nset=");
        gp_out_puts(o, gp_mesh_side_name((gp_mesh_side)s));
        gp_out_char(o, '\n');
        ids(o, list, w);
    }
    free(list);
    int flushed = gp_out_flush(o);
    return rc ? rc : flushed;
}
