/* mesh_stats.c - what a mesh is like: its counts, angles, element quality, and the area
 * of each phase against the polygons it meshes. */
#include <math.h>
#include <string.h>

#include "mesh_internal.h"

/* An angle this much below the bound (degrees) is below it: rounding of atan2. */
#define ANGLE_SLACK 1e-9

/* A sum with Neumaier's compensation: a mesh's 10^6 element areas added to a running
 * total lose up to 10^6 half-ulps of it (2e-7 of a domain of area 10^4) without it. */
typedef struct exact_sum {
    double sum, carry;
} exact_sum;

static void add(exact_sum *s, double x)
{
    double t = s->sum + x;
    s->carry += fabs(s->sum) >= fabs(x) ? (s->sum - t) + x : (x - t) + s->sum;
    s->sum = t;
}

static double total(const exact_sum *s)
{
    return s->sum + s->carry;
}

/* The corner angles (degrees) of element `index`, into angle[]; returns how many. */
static int corner_angles(const gp_mesh *mesh, int quad, size_t index, double *angle)
{
    int corners = quad ? 4 : 3;
    const int32_t *c = quad ? mesh->quad + (size_t)gp_mesh_quad_nodes(mesh->order) * index
                            : mesh->tri + (size_t)gp_mesh_tri_nodes(mesh->order) * index;
    for (int k = 0; k < corners; k++) {
        int32_t o = c[k], a = c[(k + 1) % corners], b = c[(k + corners - 1) % corners];
        double ax = mesh->xy[2 * a] - mesh->xy[2 * o], ay = mesh->xy[2 * a + 1] - mesh->xy[2 * o + 1];
        double bx = mesh->xy[2 * b] - mesh->xy[2 * o], by = mesh->xy[2 * b + 1] - mesh->xy[2 * o + 1];
        angle[k] = atan2(ax * by - ay * bx, ax * bx + ay * by) * 180.0 / M_PI;
    }
    return corners;
}

/* What the statistics need of one triangle, from one pass over its corners: twice its
 * area (as gp_mesh_element_area computes it), the sum of its squared edge lengths, and
 * the dot products of the two edges at its sharpest and at its widest corner. All three
 * corners share the cross product `twice_area`, so with twice_area > 0 the smallest angle
 * is the one with the largest dot product (its cotangent dot / twice_area is largest):
 * no atan2 per corner (which was 13% of the stage, callgrind on iron). */
typedef struct triangle_measure {
    double twice_area, edges2, dot_sharp, dot_wide;
} triangle_measure;

static triangle_measure measure_triangle(const gp_mesh *mesh, size_t index)
{
    const int32_t *c = mesh->tri + (size_t)gp_mesh_tri_nodes(mesh->order) * index;
    double x0 = mesh->xy[2 * c[0]], y0 = mesh->xy[2 * c[0] + 1];
    double ax = mesh->xy[2 * c[1]] - x0, ay = mesh->xy[2 * c[1] + 1] - y0;
    double bx = mesh->xy[2 * c[2]] - x0, by = mesh->xy[2 * c[2] + 1] - y0;
    double ex = bx - ax, ey = by - ay; /* from corner 1 to corner 2 */
    double d0 = ax * bx + ay * by, d1 = -(ax * ex + ay * ey), d2 = ex * bx + ey * by;
    triangle_measure m = {ax * by - ay * bx, ax * ax + ay * ay + bx * bx + by * by + ex * ex + ey * ey,
                          fmax(d0, fmax(d1, d2)), fmin(d0, fmin(d1, d2))};
    return m;
}

/* The extreme angles seen so far, as the (cross, dot) pair of their corner: converted to
 * degrees once, at the end. */
typedef struct angle_range {
    double lo_cot, hi_cot;           /* the sharpest and the widest corners' cotangents */
    double lo_y, lo_x, hi_y, hi_x;   /* their atan2 arguments */
    double lo_deg, hi_deg;           /* angles of elements measured with atan2 (quads) */
} angle_range;

static double degrees(double y, double x)
{
    return atan2(y, x) * 180.0 / M_PI;
}

void gp_mesh_compute_stats(gp_mesh *mesh, double min_angle, const gp_domain *domain,
                           double min_input_angle)
{
    gp_mesh_stats *s = &mesh->stats;
    memset(s, 0, sizeof *s);
    s->nodes = mesh->nnodes;
    s->triangles = mesh->ntri;
    s->quads = mesh->nquad;
    s->boundary_edges = mesh->nbedges;
    s->quality_min = 1.0;
    s->min_input_angle = min_input_angle;
    s->domain_area = gp_domain_area(domain);
    double quality_sum = 0.0;
    exact_sum all = {0, 0}, grains = {0, 0}, phase = {0, 0}, polygons = {0, 0};
    /* a triangle is below the bound when its sharpest corner's cotangent is above this */
    double bound = min_angle - ANGLE_SLACK;
    double below_cot = bound > 0.0 ? 1.0 / tan(bound * M_PI / 180.0) : INFINITY;
    angle_range range = {-INFINITY, INFINITY, 0, 0, 0, 0, 180.0, 0.0};
    for (int quad = 0; quad < 2; quad++) {
        size_t count = quad ? mesh->nquad : mesh->ntri;
        const int32_t *region = quad ? mesh->quad_region : mesh->tri_region;
        for (size_t e = 0; e < count; e++) {
            double q, a;
            triangle_measure t;
            if (!quad && (t = measure_triangle(mesh, e)).twice_area > 0.0) {
                double lo_cot = t.dot_sharp / t.twice_area, hi_cot = t.dot_wide / t.twice_area;
                if (lo_cot > range.lo_cot) {
                    range.lo_cot = lo_cot;
                    range.lo_y = t.twice_area;
                    range.lo_x = t.dot_sharp;
                }
                if (hi_cot < range.hi_cot) {
                    range.hi_cot = hi_cot;
                    range.hi_y = t.twice_area;
                    range.hi_x = t.dot_wide;
                }
                s->below_min_angle += lo_cot > below_cot;
                q = 2.0 * sqrt(3.0) * t.twice_area / t.edges2;
                a = 0.5 * t.twice_area;
            } else { /* a quadrilateral, or a flat or inverted triangle */
                double angle[4], lo = 180.0;
                int n = corner_angles(mesh, quad, e, angle);
                for (int k = 0; k < n; k++) {
                    lo = fmin(lo, angle[k]);
                    range.hi_deg = fmax(range.hi_deg, angle[k]);
                }
                range.lo_deg = fmin(range.lo_deg, lo);
                if (!quad && lo < min_angle - ANGLE_SLACK)
                    s->below_min_angle++;
                q = gp_mesh_element_quality(mesh, quad, e);
                a = gp_mesh_element_area(mesh, quad, e);
            }
            quality_sum += q;
            s->quality_min = fmin(s->quality_min, q);
            int bin = (int)(q * GP_MESH_QUALITY_BINS);
            bin = bin < 0 ? 0 : bin >= GP_MESH_QUALITY_BINS ? GP_MESH_QUALITY_BINS - 1 : bin;
            s->quality_histogram[bin]++;
            add(&all, a);
            add(gp_mesh_region_phase(mesh, region[e]) == GP_PHASE_GRAIN ? &grains : &phase, a);
        }
    }
    s->min_angle = range.lo_cot > -INFINITY ? fmin(range.lo_deg, degrees(range.lo_y, range.lo_x)) : range.lo_deg;
    s->max_angle = range.hi_cot < INFINITY ? fmax(range.hi_deg, degrees(range.hi_y, range.hi_x)) : range.hi_deg;
    size_t elements = mesh->ntri + mesh->nquad;
    s->quality_mean = elements ? quality_sum / (double)elements : 0.0;
    if (!elements)
        s->min_angle = s->quality_min = 0.0;
    s->element_area = total(&all);
    s->grain_area = total(&grains);
    s->phase_area = total(&phase);
    for (size_t g = 0; g < mesh->ngrains; g++)
        add(&polygons, mesh->region_area[g]);
    s->grain_polygon_area = total(&polygons);
    s->phase_polygon_area = mesh->region_area[mesh->ngrains];
}
