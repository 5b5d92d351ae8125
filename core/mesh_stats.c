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

void gp_mesh_compute_stats(gp_mesh *mesh, double min_angle, const gp_domain *domain,
                           double min_input_angle)
{
    gp_mesh_stats *s = &mesh->stats;
    memset(s, 0, sizeof *s);
    s->nodes = mesh->nnodes;
    s->triangles = mesh->ntri;
    s->quads = mesh->nquad;
    s->boundary_edges = mesh->nbedges;
    s->min_angle = 180.0;
    s->max_angle = 0.0;
    s->quality_min = 1.0;
    s->min_input_angle = min_input_angle;
    s->domain_area = gp_domain_area(domain);
    double quality_sum = 0.0;
    exact_sum all = {0, 0}, grains = {0, 0}, phase = {0, 0}, polygons = {0, 0};
    for (int quad = 0; quad < 2; quad++) {
        size_t count = quad ? mesh->nquad : mesh->ntri;
        const int32_t *region = quad ? mesh->quad_region : mesh->tri_region;
        for (size_t e = 0; e < count; e++) {
            double angle[4], lo = 180.0;
            int n = corner_angles(mesh, quad, e, angle);
            for (int k = 0; k < n; k++) {
                lo = fmin(lo, angle[k]);
                s->max_angle = fmax(s->max_angle, angle[k]);
            }
            s->min_angle = fmin(s->min_angle, lo);
            if (!quad && lo < min_angle - ANGLE_SLACK)
                s->below_min_angle++;
            double q = gp_mesh_element_quality(mesh, quad, e);
            quality_sum += q;
            s->quality_min = fmin(s->quality_min, q);
            int bin = (int)(q * GP_MESH_QUALITY_BINS);
            bin = bin < 0 ? 0 : bin >= GP_MESH_QUALITY_BINS ? GP_MESH_QUALITY_BINS - 1 : bin;
            s->quality_histogram[bin]++;
            double a = gp_mesh_element_area(mesh, quad, e);
            add(&all, a);
            add(gp_mesh_region_phase(mesh, region[e]) == GP_PHASE_GRAIN ? &grains : &phase, a);
        }
    }
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
