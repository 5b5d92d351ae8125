/* mesh.c - the mesh stage: the geometry (mesh_geometry.c) refined by CGAL (mesh_cdt.cpp),
 * the band's strips filled with quadrilaterals, second-order nodes, the elements on the
 * domain's sides, and the statistics. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_internal.h"

/* The area CGAL's refinement gives a triangle, on average, for a size bound h: 0.2 h^2
 * (a 100 x 100 square at h = 0.3 gets 552,130 triangles). For progress only. */
#define TRIANGLE_AREA_PER_H2 0.2

/* The part of the stage's progress each step covers: the refinement is most of it. */
#define PROGRESS_GEOMETRY 0.05
#define PROGRESS_REFINED 0.9

static int oom(gp_error *err)
{
    return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the mesh");
}

static void report(const gp_progress *progress, double fraction)
{
    if (progress && progress->report)
        progress->report(progress->ctx, "mesh", fraction);
}

static int canceled(const gp_progress *progress, gp_error *err)
{
    if (progress && progress->cancel && atomic_load_explicit(progress->cancel, memory_order_relaxed))
        return gp_error_set(err, GP_ECANCELED, NULL, "mesh canceled");
    return 0;
}

static double quad_signed_area(const double *xy, const int32_t *q)
{
    double s = 0.0;
    for (int k = 0; k < 4; k++) {
        int32_t u = q[k], v = q[(k + 1) % 4];
        s += xy[2 * u] * xy[2 * v + 1] - xy[2 * v] * xy[2 * u + 1];
    }
    return 0.5 * s;
}

/* The strips' quadrilaterals, counter-clockwise, in the second phase's region: a grid of
 * `layers` rows between the sides as the refinement left them (the same number of nodes
 * on both), whose inner nodes are made here, on straight lines across. */
static int strip_quads(gp_mesh *mesh, const gp_mesh_geometry *geo, const gp_cdt_mesh *cdt,
                       gp_error *err)
{
    int n = geo->layers;
    size_t total = 0, inner = 0;
    for (size_t s = 0; s < geo->nstrips; s++) {
        size_t cols = (cdt->strip_start[s + 1] - cdt->strip_start[s]) / 2;
        total += (size_t)n * (cols - 1);
        inner += (size_t)(n - 1) * (cols - 2);
    }
    mesh->quad = malloc(4 * (total ? total : 1) * sizeof *mesh->quad);
    mesh->quad_region = malloc((total ? total : 1) * sizeof *mesh->quad_region);
    double *xy = realloc(mesh->xy, 2 * (mesh->nnodes + inner) * sizeof *xy);
    size_t row_cap = 0;
    int32_t *row = NULL, *next = NULL; /* the nodes of row r and r + 1 */
    if (!mesh->quad || !mesh->quad_region || !xy)
        return oom(err);
    mesh->xy = xy;
    size_t q = 0;
    int rc = 0;
    for (size_t s = 0; s < geo->nstrips && rc == 0; s++) {
        const int32_t *a = cdt->strip_sides + cdt->strip_start[s];
        size_t cols = (cdt->strip_start[s + 1] - cdt->strip_start[s]) / 2;
        const int32_t *b = a + cols;
        const int32_t *g = geo->strip_points + geo->strip_start[s];
        size_t gcols = (geo->strip_start[s + 1] - geo->strip_start[s]) / (size_t)(n + 1);
        if (gp_mesh_reserve((void **)&row, &row_cap, cols, sizeof *row) ||
            (next = realloc(next, cols * sizeof *next)) == NULL) {
            rc = oom(err);
            break;
        }
        memcpy(row, a, cols * sizeof *row);
        for (int r = 1; r <= n; r++) {
            if (r == n) {
                memcpy(next, b, cols * sizeof *next);
            } else {
                next[0] = cdt->point_node[g[(size_t)r * gcols]];
                next[cols - 1] = cdt->point_node[g[(size_t)r * gcols + gcols - 1]];
                for (size_t c = 1; c + 1 < cols; c++) {
                    double f = (double)r / n;
                    size_t k = mesh->nnodes++;
                    mesh->xy[2 * k] = mesh->xy[2 * a[c]] + f * (mesh->xy[2 * b[c]] - mesh->xy[2 * a[c]]);
                    mesh->xy[2 * k + 1] = mesh->xy[2 * a[c] + 1] + f * (mesh->xy[2 * b[c] + 1] - mesh->xy[2 * a[c] + 1]);
                    next[c] = (int32_t)k;
                }
            }
            for (size_t c = 0; c + 1 < cols; c++) {
                int32_t *e = mesh->quad + 4 * q;
                e[0] = row[c];
                e[1] = row[c + 1];
                e[2] = next[c + 1];
                e[3] = next[c];
                if (quad_signed_area(mesh->xy, e) < 0.0) {
                    int32_t t = e[1];
                    e[1] = e[3];
                    e[3] = t;
                }
                mesh->quad_region[q++] = (int32_t)mesh->ngrains;
            }
            memcpy(row, next, cols * sizeof *row);
        }
    }
    free(row);
    free(next);
    mesh->nquad = q;
    return rc;
}

/* Orders the triangles by region (a stable counting sort): the writers give each grain
 * one contiguous block (Gmsh entities, Abaqus "generate" element sets). */
static int sort_by_region(gp_mesh *mesh, gp_error *err)
{
    size_t nregions = mesh->ngrains + 1, n = mesh->ntri;
    size_t *start = calloc(nregions + 1, sizeof *start);
    int32_t *tri = malloc(3 * (n ? n : 1) * sizeof *tri), *region = malloc((n ? n : 1) * sizeof *region);
    if (!start || !tri || !region) {
        free(start);
        free(tri);
        free(region);
        return oom(err);
    }
    for (size_t t = 0; t < n; t++)
        start[mesh->tri_region[t] + 1]++;
    for (size_t r = 0; r < nregions; r++)
        start[r + 1] += start[r];
    for (size_t t = 0; t < n; t++) {
        size_t k = start[mesh->tri_region[t]]++;
        memcpy(tri + 3 * k, mesh->tri + 3 * t, 3 * sizeof *tri);
        region[k] = mesh->tri_region[t];
    }
    free(start);
    free(mesh->tri);
    free(mesh->tri_region);
    mesh->tri = tri;
    mesh->tri_region = region;
    return 0;
}

/* The mid-edge node of edge {u, v}, made on first use. */
static int mid_node(gp_mesh *mesh, gp_pair_map *edges, size_t *xy_cap, int32_t u, int32_t v,
                    int32_t *out)
{
    int found;
    int64_t *at = gp_pair_map_get(edges, u, v, (int64_t)mesh->nnodes, &found);
    if (!at)
        return GP_ENOMEM;
    if (!found) {
        if (mesh->nnodes >= (size_t)INT32_MAX ||
            gp_mesh_reserve((void **)&mesh->xy, xy_cap, 2 * (mesh->nnodes + 1), sizeof *mesh->xy))
            return GP_ENOMEM;
        mesh->xy[2 * mesh->nnodes] = 0.5 * (mesh->xy[2 * u] + mesh->xy[2 * v]);
        mesh->xy[2 * mesh->nnodes + 1] = 0.5 * (mesh->xy[2 * u + 1] + mesh->xy[2 * v + 1]);
        mesh->nnodes++;
    }
    *out = (int32_t)*at;
    return 0;
}

/* Second order: every element gets the mid node of each edge, shared with its neighbour;
 * the connectivities are rewritten with 6 and 8 nodes. */
static int second_order(gp_mesh *mesh, gp_pair_map *edges, const gp_progress *progress,
                        gp_error *err)
{
    size_t xy_cap = mesh->nnodes;
    int32_t *tri = malloc(6 * (mesh->ntri ? mesh->ntri : 1) * sizeof *tri);
    int32_t *quad = malloc(8 * (mesh->nquad ? mesh->nquad : 1) * sizeof *quad);
    if (!tri || !quad || gp_pair_map_init(edges, 2 * mesh->ntri + 2 * mesh->nquad + 16)) {
        free(tri);
        free(quad);
        return oom(err);
    }
    int rc = 0;
    for (size_t t = 0; t < mesh->ntri && rc == 0; t++) {
        if ((t & 65535) == 65535 && (rc = canceled(progress, err)))
            break;
        const int32_t *c = mesh->tri + 3 * t;
        int32_t *e = tri + 6 * t;
        memcpy(e, c, 3 * sizeof *e);
        for (int k = 0; k < 3 && rc == 0; k++)
            rc = mid_node(mesh, edges, &xy_cap, c[k], c[(k + 1) % 3], &e[3 + k]) ? oom(err) : 0;
    }
    for (size_t q = 0; q < mesh->nquad && rc == 0; q++) {
        const int32_t *c = mesh->quad + 4 * q;
        int32_t *e = quad + 8 * q;
        memcpy(e, c, 4 * sizeof *e);
        for (int k = 0; k < 4 && rc == 0; k++)
            rc = mid_node(mesh, edges, &xy_cap, c[k], c[(k + 1) % 4], &e[4 + k]) ? oom(err) : 0;
    }
    free(mesh->tri);
    free(mesh->quad);
    mesh->tri = tri;
    mesh->quad = quad;
    mesh->order = 2;
    return rc;
}

/* The sides of the domain node k lies on, a bit (1 << side) for each. */
static unsigned node_sides(const gp_mesh *mesh, const gp_domain *d, size_t k)
{
    double x = mesh->xy[2 * k], y = mesh->xy[2 * k + 1];
    return (unsigned)(x == 0.0) << GP_SIDE_LEFT | (unsigned)(x == d->width) << GP_SIDE_RIGHT |
           (unsigned)(y == 0.0) << GP_SIDE_BOTTOM | (unsigned)(y == d->height) << GP_SIDE_TOP;
}

/* The side of the domain an edge lies on (the first, in the order of gp_mesh_side, that
 * both its nodes are on), or -1. */
static int edge_side(const uint8_t *sides, int32_t u, int32_t v)
{
    unsigned both = sides[u] & sides[v];
    for (int side = 0; both; side++, both >>= 1)
        if (both & 1u)
            return side;
    return -1;
}

/* The element edges on the domain's sides (both nodes on one side: the domain is
 * convex, so such an edge lies along it), in the elements' counter-clockwise order. */
static int boundary_edges(gp_mesh *mesh, const gp_domain *d, const gp_pair_map *edges,
                          gp_error *err)
{
    size_t cap = 0, n = 0, side_cap = 0;
    int stride = mesh->order + 1;
    uint8_t *sides = malloc(mesh->nnodes ? mesh->nnodes : 1);
    if (!sides)
        return oom(err);
    for (size_t k = 0; k < mesh->nnodes; k++)
        sides[k] = (uint8_t)node_sides(mesh, d, k);
    for (int quads = 0; quads < 2; quads++) {
        size_t count = quads ? mesh->nquad : mesh->ntri;
        int corners = quads ? 4 : 3, nodes = quads ? gp_mesh_quad_nodes(mesh->order) : gp_mesh_tri_nodes(mesh->order);
        const int32_t *conn = quads ? mesh->quad : mesh->tri;
        for (size_t e = 0; e < count; e++) {
            const int32_t *c = conn + (size_t)nodes * e;
            for (int k = 0; k < corners; k++) {
                int32_t u = c[k], v = c[(k + 1) % corners];
                int side = edge_side(sides, u, v);
                if (side < 0)
                    continue;
                if (gp_mesh_reserve((void **)&mesh->bedge, &cap, (size_t)stride * (n + 1), sizeof *mesh->bedge) ||
                    gp_mesh_reserve((void **)&mesh->bedge_side, &side_cap, n + 1, sizeof *mesh->bedge_side)) {
                    free(sides);
                    return oom(err);
                }
                mesh->bedge[stride * n] = u;
                mesh->bedge[stride * n + 1] = v;
                if (mesh->order == 2)
                    mesh->bedge[stride * n + 2] = (int32_t)*gp_pair_map_find(edges, u, v);
                mesh->bedge_side[n++] = (uint8_t)side;
            }
        }
    }
    free(sides);
    mesh->nbedges = n;
    return 0;
}

/* The node pairs across each periodic side, counted into the statistics: the refinement
 * made the sides' nodes translates of each other, checked here once more on the mesh as
 * written (second-order nodes included). */
static int count_pairs(gp_mesh *mesh, const gp_domain *d, gp_error *err)
{
    for (int axis = 0; axis < 2; axis++) {
        int32_t *pairs;
        int rc = gp_mesh_periodic_pairs(mesh, d, axis, &pairs, &mesh->stats.periodic_pairs[axis]);
        free(pairs);
        if (rc == GP_ENOMEM)
            return oom(err);
        if (rc)
            return gp_error_set(err, GP_EINTERNAL, NULL,
                                "mesh: the nodes of the periodic sides along %c do not pair up",
                                axis == 0 ? 'x' : 'y');
    }
    return 0;
}

/* The triangles the refinement should end with, for its progress: the area over the
 * typical triangle of the size bound, at least a few per input point. */
static double expected_triangles(const gp_mesh_geometry *geo, const gp_domain *d, double h)
{
    double area = gp_domain_area(d) / (TRIANGLE_AREA_PER_H2 * h * h);
    double points = 4.0 * (double)geo->pslg.npoints;
    return area > points ? area : points;
}

int gp_mesh_build(const gp_mesh_input *in, const gp_mesh_params *params,
                  const gp_progress *progress, gp_mesh *out, gp_error *err)
{
    memset(out, 0, sizeof *out);
    gp_mesh_geometry geo;
    gp_cdt_mesh cdt;
    gp_pair_map edges;
    memset(&cdt, 0, sizeof cdt);
    memset(&edges, 0, sizeof edges);
    report(progress, 0.0);
    int rc = gp_mesh_geometry_build(in, params, progress, &geo, err);
    if (rc)
        return rc;
    report(progress, PROGRESS_GEOMETRY);
    double sine = sin(params->min_angle * M_PI / 180.0);
    gp_cdt_params cp = {
        .size_bound = params->element_size,
        .shape_bound = sine * sine,
        .graded_region = geo.kind == GP_MESH_GRAINS_AND_BAND && params->grading ? (int32_t)geo.ngrains : -1,
        .graded_size = params->band_size,
        .max_triangles = in->max_elements,
        .expected_triangles = expected_triangles(&geo, in->domain, params->element_size),
        .progress = progress,
        .progress_from = PROGRESS_GEOMETRY,
        .progress_to = PROGRESS_REFINED,
    };
    if ((rc = gp_cdt_refine(&geo.pslg, &cp, &cdt, err)))
        goto done;
    out->kind = geo.kind;
    out->order = 1;
    out->ngrains = geo.ngrains;
    out->nnodes = cdt.nnodes;
    out->xy = cdt.xy;
    out->ntri = cdt.ntri;
    out->tri = cdt.tri;
    out->tri_region = cdt.region;
    cdt.xy = NULL;
    cdt.tri = NULL;
    cdt.region = NULL;
    out->region_area = geo.region_area;
    geo.region_area = NULL;
    if ((rc = sort_by_region(out, err)) || (rc = strip_quads(out, &geo, &cdt, err)))
        goto done;
    if (in->max_elements && out->ntri + out->nquad > in->max_elements) {
        rc = gp_error_set(err, GP_ETOOBIG, NULL, "mesh: %zu elements, more than the limit of %zu",
                          out->ntri + out->nquad, in->max_elements);
        goto done;
    }
    if ((rc = canceled(progress, err)))
        goto done;
    if (params->order == 2 && (rc = second_order(out, &edges, progress, err)))
        goto done;
    if ((rc = boundary_edges(out, in->domain, &edges, err)))
        goto done;
    gp_mesh_compute_stats(out, params->min_angle, in->domain, geo.min_input_angle);
    out->stats.band_strips = geo.nstrips;
    for (size_t s = 0; s < geo.nstrips; s++) {
        double w = geo.strip_thickness[s];
        out->stats.band_thickness_min = s == 0 ? w : fmin(out->stats.band_thickness_min, w);
        out->stats.band_thickness_mean += w / (double)geo.nstrips;
    }
    out->stats.refused_refinements = cdt.dropped;
    out->stats.rounds = cdt.rounds;
    if ((rc = count_pairs(out, in->domain, err)))
        goto done;
    report(progress, 1.0);
done:
    gp_cdt_mesh_free(&cdt);
    gp_mesh_geometry_free(&geo);
    gp_pair_map_free(&edges);
    if (rc)
        gp_mesh_free(out);
    return rc;
}

void gp_mesh_free(gp_mesh *mesh)
{
    free(mesh->xy);
    free(mesh->tri);
    free(mesh->tri_region);
    free(mesh->quad);
    free(mesh->quad_region);
    free(mesh->bedge);
    free(mesh->bedge_side);
    free(mesh->region_area);
    memset(mesh, 0, sizeof *mesh);
}
