/* test_mesh.c - the mesh stage over the reference cases and many seeds, checked against
 * what a mesh must be rather than how it was made: every inner edge in exactly two
 * elements and every other on the domain side it is listed with; the element areas sum
 * to the domain's (1e-12 relative) and each region's to its polygon's; grain elements
 * inside their cell; the minimum angle asked for, except beside input corners sharper
 * than 60 degrees (where Delaunay refinement guarantees nothing); band_layers: convex
 * quadrilaterals, exactly n of them across every strip, triangles only where strips do
 * not reach; order 2 nodes at mid-edges; cancellation; the same spec, the same mesh. */
#include <jansson.h>
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "grainpack/pipeline.h"
#include "grainpack/spec.h"
#include "mesh_internal.h"

#define SEEDS 6
/* The element areas against the domain's and each region's polygon's: sums of 10^5
 * doubles, each exact to a few ulps. */
#define AREA_RTOL 1e-12
/* Delaunay refinement (and CGAL's clusters) promise the angle bound only away from input
 * angles below 60 degrees: CGAL's clusters leave bad triangles there, within a few
 * circumradii (the shells it splits the cluster's segments on). Likewise next to the
 * band strips' ends, which are never split. */
#define SMALL_INPUT_ANGLE 60.0
#define SUSPECT_REACH 3.0

/* What the run saw, printed at the end: triangles meshed and excused from the bound. */
static size_t all_triangles, all_excused;
/* A grain element's node may lie outside its cell by rounding of the welded vertices
 * (GP_LAGUERRE_EDGE_RTOL of R, see mesh_geometry.c). */
#define INSIDE_RTOL 1e-8

/* The spec of a reference law on a small domain, with a mesh. */
static int load(const char *json, gp_spec *spec)
{
    gp_error err;
    int rc = gp_spec_parse(json, strlen(json), NULL, spec, &err);
    CHECK_MSG(rc == 0, "%s: %s", err.pointer, err.message);
    return rc;
}

static int run(const gp_spec *spec, gp_result *result)
{
    gp_error err;
    gp_error_clear(&err);
    int rc = gp_pipeline_run(spec, 0, NULL, result, &err);
    CHECK_MSG(rc == 0, "%s", err.message);
    return rc;
}

static const int32_t *element(const gp_mesh *m, int quad, size_t e)
{
    return quad ? m->quad + (size_t)gp_mesh_quad_nodes(m->order) * e
                : m->tri + (size_t)gp_mesh_tri_nodes(m->order) * e;
}

/* Every element edge, with the elements on each side: value = 2 * element + quad flag,
 * or a second element packed above bit 32. */
typedef struct edge_use {
    gp_pair_map map;
    int64_t *second; /* the second element of each edge (-1: none), by first-use index */
    size_t n, cap;
} edge_use;

static int64_t code(int quad, size_t e)
{
    return 2 * (int64_t)e + quad;
}

static void edge_use_build(const gp_mesh *m, edge_use *u)
{
    memset(u, 0, sizeof *u);
    gp_pair_map_init(&u->map, 2 * (m->ntri + m->nquad));
    u->cap = 2 * (m->ntri + m->nquad) + 16;
    u->second = malloc(2 * u->cap * sizeof *u->second);
    for (int quad = 0; quad < 2; quad++) {
        size_t count = quad ? m->nquad : m->ntri;
        int corners = quad ? 4 : 3;
        for (size_t e = 0; e < count; e++) {
            const int32_t *c = element(m, quad, e);
            for (int k = 0; k < corners; k++) {
                int found;
                int64_t *at = gp_pair_map_get(&u->map, c[k], c[(k + 1) % corners], (int64_t)u->n, &found);
                if (!found) {
                    u->second[2 * u->n] = code(quad, e);
                    u->second[2 * u->n + 1] = -1;
                    u->n++;
                } else if (u->second[2 * *at + 1] < 0) {
                    u->second[2 * *at + 1] = code(quad, e);
                } else {
                    CHECK_MSG(0, "edge %d-%d in three elements", c[k], c[(k + 1) % corners]);
                }
            }
        }
    }
}

static void edge_use_free(edge_use *u)
{
    gp_pair_map_free(&u->map);
    free(u->second);
}

/* Conformity: an edge in one element only is on a domain side, with both nodes there,
 * and is one of the mesh's boundary edges, with that side. */
static void check_conforming(const gp_mesh *m, const gp_domain *d, const edge_use *u)
{
    size_t single = 0;
    gp_pair_map listed;
    gp_pair_map_init(&listed, m->nbedges);
    int stride = m->order + 1;
    for (size_t b = 0; b < m->nbedges; b++) {
        int found;
        *gp_pair_map_get(&listed, m->bedge[stride * b], m->bedge[stride * b + 1], m->bedge_side[b], &found) =
            m->bedge_side[b];
        CHECK(!found);
    }
    for (size_t k = 0; k < u->map.cap; k++) {
        if (u->map.keys[k] == GP_PAIR_EMPTY)
            continue;
        int64_t i = u->map.values[k];
        if (u->second[2 * i + 1] >= 0)
            continue;
        single++;
        int32_t a = (int32_t)(u->map.keys[k] >> 32), b = (int32_t)(u->map.keys[k] & 0xffffffffu);
        const int64_t *side = gp_pair_map_find(&listed, a, b);
        CHECK_MSG(side != NULL, "edge %d-%d in one element is not a boundary edge", a, b);
        if (!side)
            continue;
        double ax = m->xy[2 * a], ay = m->xy[2 * a + 1], bx = m->xy[2 * b], by = m->xy[2 * b + 1];
        int on = *side == GP_SIDE_LEFT ? ax == 0.0 && bx == 0.0
                 : *side == GP_SIDE_RIGHT ? ax == d->width && bx == d->width
                 : *side == GP_SIDE_BOTTOM ? ay == 0.0 && by == 0.0
                                           : ay == d->height && by == d->height;
        CHECK_MSG(on, "boundary edge (%g,%g)-(%g,%g) is not on side %s", ax, ay, bx, by,
                  gp_mesh_side_name((gp_mesh_side)*side));
    }
    CHECK_MSG(single == m->nbedges, "%zu edges in one element, %zu boundary edges", single, m->nbedges);
    gp_pair_map_free(&listed);
}

/* Neumaier's compensated sum (mesh_stats.c has its own: this one checks it). */
static void add(double *sum, double *carry, double x)
{
    double t = *sum + x;
    *carry += fabs(*sum) >= fabs(x) ? (*sum - t) + x : (x - t) + *sum;
    *sum = t;
}

/* Areas: every element counter-clockwise; the sum against the domain's, each region's
 * sum against its polygon's. */
static void check_areas(const gp_mesh *m, const gp_domain *d)
{
    double *sum = calloc(m->ngrains + 1, sizeof *sum), *sum_carry = calloc(m->ngrains + 1, sizeof *sum);
    double total = 0.0, carry = 0.0;
    for (int quad = 0; quad < 2; quad++) {
        size_t count = quad ? m->nquad : m->ntri;
        const int32_t *region = quad ? m->quad_region : m->tri_region;
        for (size_t e = 0; e < count; e++) {
            double a = gp_mesh_element_area(m, quad, e);
            CHECK_MSG(a > 0.0, "element %zu (quad %d) has area %g", e, quad, a);
            CHECK((size_t)region[e] <= m->ngrains);
            add(&sum[region[e]], &sum_carry[region[e]], a);
            add(&total, &carry, a);
        }
    }
    double domain = gp_domain_area(d);
    total += carry;
    CHECK_MSG(fabs(total - domain) <= AREA_RTOL * domain, "elements %.17g, domain %.17g", total, domain);
    for (size_t r = 0; r <= m->ngrains; r++)
        sum[r] += sum_carry[r];
    free(sum_carry);
    for (size_t r = 0; r <= m->ngrains; r++)
        CHECK_MSG(fabs(sum[r] - m->region_area[r]) <= AREA_RTOL * fmax(m->region_area[r], 1.0),
                  "region %zu: elements %.17g, polygon %.17g", r, sum[r], m->region_area[r]);
    free(sum);
}

/* Grain elements inside their cell (convex, counter-clockwise), all their nodes. */
static void check_inside_cells(const gp_mesh *m, const gp_domain *domain, const gp_result *res)
{
    if (!res->has_cells)
        return;
    const gp_cells *c = &res->cells;
    /* periodic: an outline vertex may have been put on a side's line, as far as this */
    double snap = 0.0;
    for (size_t g = 0; domain->periodic && g < res->packing.count; g++)
        snap += GP_MESH_SIDE_SNAP_RTOL * res->packing.disks[g].R / (double)res->packing.count;
    for (size_t t = 0; t < m->ntri; t++) {
        int32_t g = m->tri_region[t];
        if ((size_t)g >= m->ngrains)
            continue;
        const double *v = c->xy + 2 * c->start[g];
        size_t n = c->start[g + 1] - c->start[g];
        const gp_disk *d = &res->packing.disks[g];
        double tol = INSIDE_RTOL * d->R + snap;
        /* periodic: the translate of the triangle nearest its grain's centre (a piece of a
           cell across a side lies on the other side, the cell in unwrapped coordinates) */
        const int32_t *tc = element(m, 0, t);
        double cx = (m->xy[2 * tc[0]] + m->xy[2 * tc[1]] + m->xy[2 * tc[2]]) / 3.0;
        double cy = (m->xy[2 * tc[0] + 1] + m->xy[2 * tc[1] + 1] + m->xy[2 * tc[2] + 1]) / 3.0;
        double sx = cx - d->x, sy = cy - d->y;
        gp_domain_min_image(domain, &sx, &sy);
        sx = d->x + sx - cx;
        sy = d->y + sy - cy;
        for (int k = 0; k < gp_mesh_tri_nodes(m->order); k++) {
            double px = m->xy[2 * tc[k]] + sx, py = m->xy[2 * tc[k] + 1] + sy;
            for (size_t i = 0; i < n; i++) {
                double ax = v[2 * i], ay = v[2 * i + 1];
                double bx = v[2 * ((i + 1) % n)], by = v[2 * ((i + 1) % n) + 1];
                double len = hypot(bx - ax, by - ay);
                double side = ((bx - ax) * (py - ay) - (by - ay) * (px - ax)) / len;
                CHECK_MSG(side >= -tol, "node (%g, %g) of triangle %zu is %g outside grain %d", px,
                          py, t, -side, g);
            }
        }
    }
}

/* Where Delaunay refinement may leave bad triangles: the input points where two segments
 * meet at less than SMALL_INPUT_ANGLE (CGAL's clusters), and the ends of protected
 * segments (the strips' ends, never split). As x, y pairs; *n gets how many. */
static double *suspects(const gp_spec *spec, const gp_result *res, size_t *n)
{
    gp_rt *rt = NULL;
    gp_error err;
    gp_rt_build(res->packing.disks, res->packing.count, NULL, &rt, &err);
    gp_mesh_input in = {&spec->domain, res->packing.disks, res->packing.count,
                        res->has_cells ? &res->cells : NULL, rt, 0};
    gp_mesh_geometry g;
    int rc = gp_mesh_geometry_build(&in, &spec->mesh, NULL, &g, &err);
    CHECK(rc == 0);
    gp_rt_free(rt);
    *n = 0;
    if (rc)
        return NULL;
    const gp_pslg *p = &g.pslg;
    double *out = malloc(2 * (2 * p->nsegs + 1) * sizeof *out);
    for (size_t s = 0; s < p->nsegs; s++)
        for (int end = 0; end < 2; end++) {
            int32_t o = p->seg[2 * s + end];
            double ox = p->xy[2 * o], oy = p->xy[2 * o + 1];
            int32_t a = p->seg[2 * s + 1 - end];
            double a1 = atan2(p->xy[2 * a + 1] - oy, p->xy[2 * a] - ox), sharpest = 360.0;
            for (size_t t = 0; t < p->nsegs; t++)
                for (int e2 = 0; e2 < 2; e2++) {
                    if (t == s || p->seg[2 * t + e2] != o)
                        continue;
                    int32_t q = p->seg[2 * t + 1 - e2];
                    double d = fabs(a1 - atan2(p->xy[2 * q + 1] - oy, p->xy[2 * q] - ox)) * 180.0 / M_PI;
                    sharpest = fmin(sharpest, d > 180.0 ? 360.0 - d : d);
                }
            if (sharpest < SMALL_INPUT_ANGLE || p->seg_protected[s]) {
                out[2 * *n] = ox;
                out[2 * *n + 1] = oy;
                ++*n;
            }
        }
    gp_mesh_geometry_free(&g);
    return out;
}

/* Whether (x, y) lies within `reach` of the diametral circle of an element edge on a
 * periodic side of the mesh. */
static int near_periodic_side(const gp_mesh *m, const gp_domain *d, double x, double y, double reach)
{
    int stride = m->order + 1;
    for (size_t b = 0; b < m->nbedges; b++) {
        int side = m->bedge_side[b];
        unsigned axis = side == GP_SIDE_LEFT || side == GP_SIDE_RIGHT ? GP_PERIODIC_X : GP_PERIODIC_Y;
        if (!(d->periodic & axis))
            continue;
        const double *p = m->xy + 2 * m->bedge[stride * b], *q = m->xy + 2 * m->bedge[stride * b + 1];
        double half = 0.5 * hypot(q[0] - p[0], q[1] - p[1]);
        if (hypot(x - 0.5 * (p[0] + q[0]), y - 0.5 * (p[1] + q[1])) <= half + reach)
            return 1;
    }
    return 0;
}

/* The angle bound: a triangle below it lies within SUSPECT_REACH circumradii of a
 * suspect point, or of a periodic side (no more of those than refinements refused). Returns
 * how many were excused. */
static size_t check_angles(const gp_mesh *m, const gp_spec *spec, const gp_result *res)
{
    double *near = NULL;
    size_t nnear = 0, excused = 0, by_sides = 0;
    for (size_t t = 0; t < m->ntri; t++) {
        const int32_t *c = element(m, 0, t);
        double lo = 180.0, l[3];
        for (int k = 0; k < 3; k++) {
            double ax = m->xy[2 * c[(k + 1) % 3]] - m->xy[2 * c[k]], ay = m->xy[2 * c[(k + 1) % 3] + 1] - m->xy[2 * c[k] + 1];
            double bx = m->xy[2 * c[(k + 2) % 3]] - m->xy[2 * c[k]], by = m->xy[2 * c[(k + 2) % 3] + 1] - m->xy[2 * c[k] + 1];
            lo = fmin(lo, atan2(fabs(ax * by - ay * bx), ax * bx + ay * by) * 180.0 / M_PI);
            l[k] = hypot(ax, ay);
        }
        if (lo >= spec->mesh.min_angle - 1e-9)
            continue;
        if (!near)
            near = suspects(spec, res, &nnear);
        double R = l[0] * l[1] * l[2] / (4.0 * gp_mesh_element_area(m, 0, t));
        double x = m->xy[2 * c[0]], y = m->xy[2 * c[0] + 1];
        int found = 0;
        for (size_t k = 0; k < nnear && !found; k++)
            found = hypot(near[2 * k] - x, near[2 * k + 1] - y) <= SUSPECT_REACH * R + l[0] + l[2];
        /* periodic: the last round locks the sides, and the triangles whose circumcentre
           would encroach a side's edge (it lies in the edge's diametral circle) are left
           as they are (refused_refinements counts them) */
        if (!found && spec->domain.periodic && near_periodic_side(m, &spec->domain, x, y, SUSPECT_REACH * R + l[0] + l[2])) {
            found = 1;
            by_sides++;
        }
        CHECK_MSG(found, "triangle %zu at (%g, %g) has an angle of %g degrees, far from sharp input "
                  "corners, strip ends and periodic sides", t, x, y, lo);
        excused++;
    }
    CHECK_MSG(by_sides <= m->stats.refused_refinements, "%zu bad triangles by the periodic sides, "
              "%zu refused refinements", by_sides, m->stats.refused_refinements);
    free(near);
    return excused;
}

/* band_layers: quads convex and in the band; from every quad edge shared with a grain
 * triangle, walking across (to the opposite edge) takes exactly n quads to the facing
 * grain or the wall. */
static void check_layers(const gp_mesh *m, const edge_use *u, int n)
{
    for (size_t q = 0; q < m->nquad; q++) {
        const int32_t *c = element(m, 1, q);
        CHECK((size_t)m->quad_region[q] == m->ngrains);
        for (int k = 0; k < 4; k++) {
            double ax = m->xy[2 * c[(k + 1) % 4]] - m->xy[2 * c[k]], ay = m->xy[2 * c[(k + 1) % 4] + 1] - m->xy[2 * c[k] + 1];
            double bx = m->xy[2 * c[(k + 3) % 4]] - m->xy[2 * c[k]], by = m->xy[2 * c[(k + 3) % 4] + 1] - m->xy[2 * c[k] + 1];
            CHECK_MSG(ax * by - ay * bx > 0.0, "quad %zu is not convex at corner %d", q, k);
        }
    }
    size_t walks = 0;
    for (size_t q0 = 0; q0 < m->nquad; q0++) {
        const int32_t *c = element(m, 1, q0);
        for (int k = 0; k < 4; k++) {
            const int64_t *at = gp_pair_map_find(&u->map, c[k], c[(k + 1) % 4]);
            int64_t a = u->second[2 * *at], b = u->second[2 * *at + 1];
            int64_t other = a == code(1, q0) ? b : a;
            if (other < 0 || (other & 1) || (size_t)m->tri_region[other / 2] >= m->ngrains)
                continue; /* not against a grain triangle */
            /* walk across: the edge opposite (k + 2) each time */
            size_t q = q0;
            int edge = (k + 2) % 4, steps = 1;
            for (;;) {
                const int32_t *d = element(m, 1, q);
                int32_t x = d[edge], y = d[(edge + 1) % 4];
                const int64_t *e = gp_pair_map_find(&u->map, x, y);
                int64_t s0 = u->second[2 * *e], s1 = u->second[2 * *e + 1];
                int64_t next = s0 == code(1, q) ? s1 : s0;
                if (next < 0 || !(next & 1))
                    break; /* the wall, or a grain (a band triangle is checked below) */
                q = (size_t)(next / 2);
                const int32_t *f = element(m, 1, q);
                int j = 0;
                while (j < 4 && !((f[j] == y && f[(j + 1) % 4] == x) || (f[j] == x && f[(j + 1) % 4] == y)))
                    j++;
                edge = (j + 2) % 4;
                if (++steps > n + 1)
                    break;
            }
            CHECK_MSG(steps == n, "a strip is %d quadrilaterals across, not %d", steps, n);
            walks++;
        }
    }
    CHECK(walks > 0);
}

/* Every element's mid nodes at the middle of its corners. */
static void check_order2(const gp_mesh *m)
{
    for (int quad = 0; quad < 2; quad++) {
        size_t count = quad ? m->nquad : m->ntri;
        int corners = quad ? 4 : 3;
        for (size_t e = 0; e < count; e++) {
            const int32_t *c = element(m, quad, e);
            for (int k = 0; k < corners; k++) {
                int32_t a = c[k], b = c[(k + 1) % corners], mid = c[corners + k];
                CHECK(m->xy[2 * mid] == 0.5 * (m->xy[2 * a] + m->xy[2 * b]));
                CHECK(m->xy[2 * mid + 1] == 0.5 * (m->xy[2 * a + 1] + m->xy[2 * b + 1]));
            }
        }
    }
}

static int by_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The coordinates along the side of the nodes on the line where coordinate `axis` is c,
 * sorted; *n gets how many. */
static double *side_nodes(const gp_mesh *m, int axis, double c, size_t *n)
{
    double *along = malloc((m->nnodes + 1) * sizeof *along);
    *n = 0;
    for (size_t k = 0; k < m->nnodes; k++)
        if (m->xy[2 * k + axis] == c)
            along[(*n)++] = m->xy[2 * k + 1 - axis];
    qsort(along, *n, sizeof *along, by_double);
    return along;
}

/* The area a cell may lose or gain when its vertices within GP_MESH_SIDE_SNAP_RTOL mean
 * radii of a periodic side's line are put on it (mesh_geometry.c): the moves times the
 * cell's perimeter; 0 when no vertex is that close. */
static double snap_tolerance(const gp_result *res, const gp_domain *d, size_t g, double R_mean)
{
    const gp_cells *c = &res->cells;
    const double *v = c->xy + 2 * c->start[g];
    size_t n = c->start[g + 1] - c->start[g];
    double eps = GP_MESH_SIDE_SNAP_RTOL * R_mean, moved = 0.0, perimeter = 0.0;
    for (size_t k = 0; k < n; k++) {
        perimeter += hypot(v[2 * ((k + 1) % n)] - v[2 * k], v[2 * ((k + 1) % n) + 1] - v[2 * k + 1]);
        for (int axis = 0; axis < 2; axis++) {
            if (!(d->periodic & (axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y)))
                continue;
            double x = v[2 * k + axis], period = axis == 0 ? d->width : d->height;
            double off = fmin(fabs(x), fabs(x - period));
            if (off <= eps)
                moved += off;
        }
    }
    return moved * perimeter;
}

/* A periodic mesh: along each periodic axis, the nodes on the two sides are translates
 * of each other one to one, bit for bit, corners included (and the library's pairs are
 * those); each grain's elements cover its whole outline, whose pieces lie on both sides
 * of a periodic side: with cells, the area of its (unwrapped) cell; without, that of its
 * polygonised disk, under the circle's and above 90% of it (a piece lost across a side
 * would take more). A cell with a vertex put on a side's line (GP_MESH_SIDE_SNAP_RTOL)
 * may differ by that move times its perimeter: at most one grain in ten is. */
static void check_periodic(const gp_mesh *m, const gp_domain *d, const gp_result *res)
{
    for (int axis = 0; axis < 2; axis++) {
        if (!(d->periodic & (axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y)))
            continue;
        size_t nlo, nhi;
        double *lo = side_nodes(m, axis, 0.0, &nlo);
        double *hi = side_nodes(m, axis, axis == 0 ? d->width : d->height, &nhi);
        CHECK_MSG(nlo == nhi && nlo >= 2, "axis %d: %zu and %zu nodes on the sides", axis, nlo, nhi);
        for (size_t k = 0; k < nlo && k < nhi; k++) {
            CHECK_MSG(lo[k] == hi[k], "axis %d: node %zu at %.17g and %.17g", axis, k, lo[k], hi[k]);
            CHECK(k == 0 || lo[k] > lo[k - 1]);
        }
        CHECK(nlo > 0 && lo[0] == 0.0 && lo[nlo - 1] == (axis == 0 ? d->height : d->width));
        int32_t *pairs;
        size_t n;
        CHECK(gp_mesh_periodic_pairs(m, d, axis, &pairs, &n) == 0 && n == nlo);
        for (size_t k = 0; k < n && k < nlo; k++)
            CHECK(m->xy[2 * pairs[2 * k] + 1 - axis] == lo[k] &&
                  m->xy[2 * pairs[2 * k + 1] + 1 - axis] == lo[k]);
        CHECK((size_t)m->stats.periodic_pairs[axis] == nlo);
        free(pairs);
        free(lo);
        free(hi);
    }
    double R_mean = 0.0;
    size_t snapped_grains = 0;
    for (size_t g = 0; g < m->ngrains; g++)
        R_mean += res->packing.disks[g].R / (double)m->ngrains;
    double *area = calloc(m->ngrains + 1, sizeof *area);
    for (size_t t = 0; t < m->ntri; t++)
        area[m->tri_region[t]] += gp_mesh_element_area(m, 0, t);
    /* the outline is inscribed; its longest chord spans under four times the wedge angle
       (two contacts closer than their two minimum steps, 2 x 2 x 21.1 degrees: a cap of
       7.6% of the disk), the others at most 15.7 degrees (1.1% in all) */
    double poly = 0.9;
    for (size_t g = 0; g < m->ngrains; g++) {
        if (res->has_cells) {
            double tol = AREA_RTOL * fmax(res->cells.area[g], 1.0);
            double snapped = snap_tolerance(res, d, g, R_mean);
            CHECK_MSG(fabs(area[g] - res->cells.area[g]) <= tol + snapped,
                      "grain %zu: elements %.17g, cell %.17g", g, area[g], res->cells.area[g]);
            snapped_grains += snapped > 0.0;
        } else {
            double r = res->packing.disks[g].r, circle = M_PI * r * r;
            CHECK_MSG(area[g] <= circle * (1.0 + 1e-9) && area[g] >= poly * circle,
                      "grain %zu: elements %.17g, circle %.17g", g, area[g], circle);
        }
    }
    free(area);
    CHECK_MSG(snapped_grains * 10 <= m->ngrains, "%zu of %zu grains snapped to a side", snapped_grains, m->ngrains);
}

/* All the checks on one spec; returns the triangles excused from the angle bound. */
static size_t check_case(const char *json)
{
    gp_spec spec;
    gp_result res;
    if (load(json, &spec))
        return 0;
    if (run(&spec, &res)) {
        gp_spec_free(&spec);
        return 0;
    }
    const gp_mesh *m = &res.mesh;
    CHECK(res.has_mesh && m->ntri > 0);
    edge_use u;
    edge_use_build(m, &u);
    check_conforming(m, &spec.domain, &u);
    check_areas(m, &spec.domain);
    check_inside_cells(m, &spec.domain, &res);
    if (spec.domain.periodic)
        check_periodic(m, &spec.domain, &res);
    size_t excused = check_angles(m, &spec, &res);
    all_triangles += m->ntri;
    all_excused += excused;
    if (spec.mesh.band_layers)
        check_layers(m, &u, spec.mesh.band_layers);
    if (m->order == 2)
        check_order2(m);
    CHECK(m->stats.triangles == m->ntri && m->stats.quads == m->nquad && m->stats.nodes == m->nnodes);
    edge_use_free(&u);
    gp_result_free(&res);
    gp_spec_free(&spec);
    return excused;
}

static const char *const laws[] = {
    /* iron (the report's histogram, j = 2/r) */
    "\"domain\": {\"width\": 60, \"height\": 50}, \"distribution\": {\"kind\": \"histogram\", \"bins\": ["
    "{\"min\": 2.0, \"max\": 3.0, \"p\": 0.37}, {\"min\": 3.0, \"max\": 4.0, \"p\": 0.38},"
    "{\"min\": 4.0, \"max\": 6.0, \"p\": 0.23}, {\"min\": 6.0, \"max\": 8.0, \"p\": 0.02}]},"
    "\"joint\": {\"law\": \"inverse\", \"k\": 2.0}",
    /* fixed (constant radius, constant joint) */
    "\"domain\": {\"width\": 15, \"height\": 12}, \"distribution\": {\"kind\": \"constant\", \"radius\": 0.9},"
    "\"joint\": {\"law\": \"constant\", \"value\": 0.1}",
    /* figure 4.7 (three bins, constant joint) */
    "\"domain\": {\"width\": 10, \"height\": 10}, \"distribution\": {\"kind\": \"histogram\", \"bins\": ["
    "{\"min\": 0.2, \"max\": 0.4, \"p\": 0.3}, {\"min\": 0.4, \"max\": 0.6, \"p\": 0.2},"
    "{\"min\": 0.6, \"max\": 0.9, \"p\": 0.5}]}, \"joint\": {\"law\": \"constant\", \"value\": 0.1}",
};

static void mesh_cases(const char *extra, int seeds)
{
    char json[2048];
    for (size_t l = 0; l < sizeof laws / sizeof laws[0]; l++)
        for (int seed = 1; seed <= seeds; seed++) {
            snprintf(json, sizeof json, "{%s, \"seed\": %d, %s}", laws[l], seed, extra);
            check_case(json);
        }
}

static void test_mesh_grains_and_band_offset(void)
{
    mesh_cases("\"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {}", SEEDS);
}

static void test_mesh_grains_and_band_flush(void)
{
    mesh_cases("\"laguerre\": {\"shrink\": \"offset\", \"flush_boundary\": true}, \"mesh\": {\"min_angle\": 15}", 2);
}

static void test_mesh_grains_and_band_homothetic(void)
{
    mesh_cases("\"laguerre\": {\"shrink\": \"homothetic\"}, \"mesh\": {\"order\": 2}", 3);
}

static void test_mesh_cells_conform_across_cells(void)
{
    mesh_cases("\"laguerre\": {\"shrink\": \"none\"}, \"mesh\": {}", SEEDS);
}

static void test_mesh_disks_in_matrix(void)
{
    mesh_cases("\"mesh\": {}", 3);
    /* bagi's law without a joint: the disks touch, their outlines share a point */
    char json[512];
    for (int seed = 1; seed <= 3; seed++) {
        snprintf(json, sizeof json,
                 "{\"domain\": {\"width\": 6, \"height\": 5}, \"distribution\": {\"kind\": \"uniform\", "
                 "\"min\": 0.06, \"max\": 0.42}, \"seed\": %d, \"mesh\": {\"element_size\": 0.3}}", seed);
        check_case(json);
    }
}

static void test_mesh_band_layers(void)
{
    mesh_cases("\"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"band_layers\": 2}", SEEDS);
    mesh_cases("\"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"band_layers\": 1, \"order\": 2}", 2);
    mesh_cases("\"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": {\"band_layers\": 4, \"band_size\": 0.3}", 2);
}

/* The reference laws on periodic domains (a period of at least 12 largest packing radii,
 * docs/method.md §3.8), the torus and a strip periodic in x: iron, fixed, figure 4.7 and
 * bagi's. %s: the domain's "periodic". */
static const char *const periodic_laws[] = {
    "\"domain\": {\"width\": 100, \"height\": 100, \"periodic\": %s}, \"distribution\": {\"kind\": "
    "\"histogram\", \"bins\": [{\"min\": 2.0, \"max\": 3.0, \"p\": 0.37}, {\"min\": 3.0, \"max\": 4.0, \"p\": 0.38},"
    "{\"min\": 4.0, \"max\": 6.0, \"p\": 0.23}, {\"min\": 6.0, \"max\": 8.0, \"p\": 0.02}]},"
    "\"joint\": {\"law\": \"inverse\", \"k\": 2.0}, \"mesh\": {\"element_size\": 3",
    "\"domain\": {\"width\": 15, \"height\": 12, \"periodic\": %s}, \"distribution\": {\"kind\": "
    "\"constant\", \"radius\": 0.9}, \"joint\": {\"law\": \"constant\", \"value\": 0.1}, \"mesh\": {\"element_size\": 0.45",
    "\"domain\": {\"width\": 12, \"height\": 12, \"periodic\": %s}, \"distribution\": {\"kind\": "
    "\"histogram\", \"bins\": [{\"min\": 0.2, \"max\": 0.4, \"p\": 0.3}, {\"min\": 0.4, \"max\": 0.6, \"p\": 0.2},"
    "{\"min\": 0.6, \"max\": 0.9, \"p\": 0.5}]}, \"joint\": {\"law\": \"constant\", \"value\": 0.1}, \"mesh\": {\"element_size\": 0.25",
    "\"domain\": {\"width\": 6, \"height\": 6, \"periodic\": %s}, \"distribution\": {\"kind\": \"uniform\", "
    "\"min\": 0.06, \"max\": 0.42}, \"mesh\": {\"element_size\": 0.3",
};

/* Every periodic law on the torus and on an x strip, `seeds` seeds, with `stage` (the
 * cells, or none) and `mesh` (more of the mesh's members, after a comma, or ""). */
static void periodic_cases(const char *stage, const char *mesh, int seeds)
{
    const char *axes[] = {"true", "[\"x\"]"};
    for (size_t l = 0; l < sizeof periodic_laws / sizeof periodic_laws[0]; l++)
        for (size_t a = 0; a < 2; a++)
            for (int seed = 1; seed <= seeds; seed++) {
                char law[1024], json[2048];
                snprintf(law, sizeof law, periodic_laws[l], axes[a]);
                snprintf(json, sizeof json, "{%s%s}, \"seed\": %d%s}", law, mesh, seed, stage);
                check_case(json);
            }
}

static void test_mesh_periodic_cells(void)
{
    periodic_cases(", \"laguerre\": {\"shrink\": \"offset\"}", "", 3);
    periodic_cases(", \"laguerre\": {\"shrink\": \"none\"}", "", 2);
    periodic_cases(", \"laguerre\": {\"shrink\": \"homothetic\"}", ", \"order\": 2", 1);
}

static void test_mesh_periodic_disks_in_matrix(void)
{
    periodic_cases("", "", 3);
}

/* The reference cases of examples/, at full size, meshed as grains and band. */
static void test_mesh_reference_examples(void)
{
    const char *names[] = {"iron", "fixed", "figure47"};
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s.json", GP_EXAMPLES_DIR, names[i]);
        FILE *f = fopen(path, "rb");
        CHECK(f != NULL);
        if (!f)
            continue;
        char text[8192];
        size_t n = fread(text, 1, sizeof text - 1, f);
        fclose(f);
        text[n] = '\0';
        /* the spec with "laguerre" (offset) and "mesh" in place of its own */
        json_t *root = json_loads(text, 0, NULL);
        json_t *inputs = json_object_get(root, "inputs");
        json_object_set_new(inputs, "laguerre", json_pack("{s:s}", "shrink", "offset"));
        json_object_del(inputs, "balance");
        json_object_del(inputs, "picture");
        json_object_set_new(inputs, "mesh", json_pack("{s:i}", "band_layers", 2));
        char *spec = json_dumps(root, 0);
        check_case(spec);
        free(spec);
        json_decref(root);
    }
}

/* The mean edge length of the band's triangles (each edge counted per triangle), and of
 * the grains' interior edges (neither end on an outline: no band triangle there), of the
 * mesh of `json`; the result's statistics in *stats. Returns 0 or -1. */
static int phase_edges(const char *json, double *band_mean, double *grain_mean, gp_mesh_stats *stats)
{
    gp_spec spec;
    gp_result res;
    if (load(json, &spec))
        return -1;
    if (run(&spec, &res)) {
        gp_spec_free(&spec);
        return -1;
    }
    const gp_mesh *m = &res.mesh;
    char *outline = calloc(m->nnodes, 1);
    for (size_t t = 0; t < m->ntri; t++)
        if (gp_mesh_region_phase(m, m->tri_region[t]) != GP_PHASE_GRAIN)
            for (int k = 0; k < 3; k++)
                outline[element(m, 0, t)[k]] = 1;
    double sum[2] = {0, 0};
    size_t n[2] = {0, 0};
    for (size_t t = 0; t < m->ntri; t++) {
        const int32_t *c = element(m, 0, t);
        int band = gp_mesh_region_phase(m, m->tri_region[t]) != GP_PHASE_GRAIN;
        for (int k = 0; k < 3; k++) {
            int32_t u = c[k], v = c[(k + 1) % 3];
            if (!band && (outline[u] || outline[v]))
                continue;
            sum[band] += hypot(m->xy[2 * u] - m->xy[2 * v], m->xy[2 * u + 1] - m->xy[2 * v + 1]);
            n[band]++;
        }
    }
    free(outline);
    *grain_mean = n[0] ? sum[0] / (double)n[0] : 0.0;
    *band_mean = n[1] ? sum[1] / (double)n[1] : 0.0;
    *stats = m->stats;
    gp_result_free(&res);
    gp_spec_free(&spec);
    return 0;
}

/* Grains of radius 6 with a joint of 0.15 (a band about 0.3 thick), element_size 1.5. */
#define GRADED_LAW                                                                                   \
    "\"domain\": {\"width\": 48, \"height\": 48}, \"distribution\": {\"kind\": \"constant\", "        \
    "\"radius\": 6}, \"joint\": {\"law\": \"constant\", \"value\": 0.15}, "                           \
    "\"laguerre\": {\"shrink\": \"offset\"}"

static void test_mesh_band_graded_to_its_thickness(void)
{
    char json[1024];
    for (int seed = 1; seed <= 1; seed++) { /* (a constant law packs alike from any seed) */
        double graded, graded_grain, plain, plain_grain, fixed, fixed_grain, unused;
        gp_mesh_stats strips, s;
        /* the band's thickness, measured on its straight strips by the geometry */
        snprintf(json, sizeof json, "{" GRADED_LAW ", \"seed\": %d, \"mesh\": {\"element_size\": 1.5, "
                 "\"band_layers\": 1}}", seed);
        if (phase_edges(json, &unused, &unused, &strips))
            continue;
        CHECK(strips.band_strips > 0 && strips.band_thickness_mean > 0.2);
        double t = strips.band_thickness_mean;
        snprintf(json, sizeof json, "{" GRADED_LAW ", \"seed\": %d, \"mesh\": {\"element_size\": 1.5}}", seed);
        CHECK(phase_edges(json, &graded, &graded_grain, &s) == 0);
        CHECK(s.below_min_angle == 0 && s.min_angle >= GP_MESH_MAX_MIN_ANGLE - 1e-9);
        snprintf(json, sizeof json, "{" GRADED_LAW ", \"seed\": %d, \"mesh\": {\"element_size\": 1.5, "
                 "\"grading\": false}}", seed);
        CHECK(phase_edges(json, &plain, &plain_grain, &s) == 0);
        snprintf(json, sizeof json, "{" GRADED_LAW ", \"seed\": %d, \"mesh\": {\"element_size\": 1.5, "
                 "\"band_size\": 0.1}}", seed);
        CHECK(phase_edges(json, &fixed, &fixed_grain, &s) == 0);
        CHECK(s.below_min_angle == 0);
        /* the band's edges track its thickness; without grading they are longer */
        CHECK_MSG(graded > 0.5 * t && graded < 1.5 * t, "band edges %g, thickness %g", graded, t);
        CHECK_MSG(plain > 1.25 * graded, "ungraded band edges %g, graded %g", plain, graded);
        CHECK_MSG(fixed > 0.05 && fixed < 0.1, "band_size 0.1: band edges %g", fixed);
        /* the grains' interiors stay coarse: their edges (away from the outlines, where the
         * mesh grades from the band's size) about as long as without grading */
        CHECK_MSG(graded_grain > 0.5 * 1.5 && graded_grain < 1.5 && graded_grain > 0.75 * plain_grain,
                  "grain interior edges %g (without grading %g)", graded_grain, plain_grain);
        (void)fixed_grain;
    }
}

static void cancel_in_mesh(void *ctx, const char *stage, double fraction)
{
    gp_cancel_flag *flag = ctx;
    if (strcmp(stage, "mesh") == 0 && fraction > 0.1)
        atomic_store(flag, 1);
}

/* The refinement looks at the cancel flag while it works: raised once the stage reports
 * progress, the run stops with GP_ECANCELED and nothing half made. */
static void test_mesh_cancel(void)
{
    gp_spec spec;
    if (load("{\"domain\": {\"width\": 60, \"height\": 60}, \"distribution\": {\"kind\": \"constant\", "
             "\"radius\": 1}, \"laguerre\": {\"shrink\": \"none\"}, \"mesh\": {\"element_size\": 0.05}}",
             &spec))
        return;
    gp_cancel_flag flag;
    atomic_init(&flag, 0);
    gp_progress progress = {cancel_in_mesh, &flag, &flag};
    gp_result res;
    gp_error err;
    int rc = gp_pipeline_run(&spec, 0, &progress, &res, &err);
    CHECK_MSG(rc == GP_ECANCELED, "rc %d: %s", rc, err.message);
    CHECK(atomic_load(&flag) == 1);
    gp_spec_free(&spec);
}

/* The same spec gives the same mesh, node for node. */
static void test_mesh_deterministic(void)
{
    const char *json = "{\"domain\": {\"width\": 20, \"height\": 20}, \"distribution\": {\"kind\": "
                       "\"uniform\", \"min\": 0.5, \"max\": 1.5}, \"joint\": {\"law\": \"constant\", "
                       "\"value\": 0.1}, \"laguerre\": {\"shrink\": \"offset\"}, \"mesh\": "
                       "{\"band_layers\": 2, \"order\": 2}}";
    gp_spec spec;
    gp_result a, b;
    if (load(json, &spec) || run(&spec, &a))
        return;
    if (run(&spec, &b) == 0) {
        CHECK(a.mesh.nnodes == b.mesh.nnodes && a.mesh.ntri == b.mesh.ntri && a.mesh.nquad == b.mesh.nquad);
        if (a.mesh.nnodes == b.mesh.nnodes && a.mesh.ntri == b.mesh.ntri) {
            CHECK(memcmp(a.mesh.xy, b.mesh.xy, 2 * a.mesh.nnodes * sizeof(double)) == 0);
            CHECK(memcmp(a.mesh.tri, b.mesh.tri, 6 * a.mesh.ntri * sizeof(int32_t)) == 0);
        }
        gp_result_free(&b);
    }
    gp_result_free(&a);
    gp_spec_free(&spec);
}

/* The runtime cap: a mesh growing past it fails with GP_ETOOBIG. */
static void test_mesh_runtime_cap(void)
{
    gp_spec spec;
    if (load("{\"domain\": {\"width\": 20, \"height\": 20}, \"distribution\": {\"kind\": \"constant\", "
             "\"radius\": 1}, \"mesh\": {\"element_size\": 0.05}}", &spec))
        return;
    spec.max_elements = 1000;
    gp_result res;
    gp_error err;
    int rc = gp_pipeline_run(&spec, 0, NULL, &res, &err);
    CHECK_MSG(rc == GP_ETOOBIG, "rc %d: %s", rc, err.message);
    gp_spec_free(&spec);
}

int main(void)
{
    RUN(test_mesh_grains_and_band_offset);
    RUN(test_mesh_grains_and_band_flush);
    RUN(test_mesh_grains_and_band_homothetic);
    RUN(test_mesh_cells_conform_across_cells);
    RUN(test_mesh_disks_in_matrix);
    RUN(test_mesh_band_layers);
    RUN(test_mesh_periodic_cells);
    RUN(test_mesh_periodic_disks_in_matrix);
    RUN(test_mesh_band_graded_to_its_thickness);
    RUN(test_mesh_reference_examples);
    RUN(test_mesh_cancel);
    RUN(test_mesh_deterministic);
    RUN(test_mesh_runtime_cap);
    fprintf(stderr, "%zu triangles, %zu below the angle bound asked (each near a sharp input "
                    "corner or a strip end)\n", all_triangles, all_excused);
    return check_status();
}
