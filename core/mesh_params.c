/* mesh_params.c - the mesh stage's defaults, its element-count estimate (the cap a spec
 * is checked against before any work), and the names and measures the writers share. */
#include <math.h>

#include "grainpack/mesh.h"
#include "mesh_cdt.h"

/* Calibration of the estimate (bench/MESH.md, "The element-count estimate"): CGAL's
 * refinement gives a triangle about 0.2 h^2 for a size bound h; a thin strip of
 * thickness t gets about 1.5 triangles per t^2 of its area; an outline needs about two
 * triangles per polygon edge; where the band is graded to a size g finer than h, the
 * grains' triangles grow from g at their outline to h inside: about 8 triangles per unit
 * of outline length times (1/g - 1/h) (fitted on fixed, 166,334 more than ungraded, and
 * iron, 30,817 more). */
#define AREA_PER_TRIANGLE_H2 0.2
#define BAND_TRIANGLES_PER_T2 1.5
#define TRIANGLES_PER_OUTLINE_EDGE 2.0
#define GRADED_TRANSITION_TRIANGLES 8.0
/* Radii at which a law's graded size is sampled per bin (or over a uniform law). */
#define GRADED_SAMPLES 16
/* The edges of a Laguerre cell, on average (a hexagon). */
#define CELL_EDGES 6.0
/* The packing density the structure reaches, for the share of grains in the matrix. */
#define PACKING_FILL 0.86

static const char *const phase_names[] = {"grain", "grain_boundary", "matrix"};
static const char *const side_names[] = {"left", "right", "bottom", "top"};

const char *gp_mesh_phase_name(gp_mesh_phase phase)
{
    return phase_names[phase];
}

const char *gp_mesh_side_name(gp_mesh_side side)
{
    return side_names[side];
}

gp_mesh_phase gp_mesh_region_phase(const gp_mesh *mesh, int32_t region)
{
    if ((size_t)region < mesh->ngrains)
        return GP_PHASE_GRAIN;
    return mesh->kind == GP_MESH_DISKS_IN_MATRIX ? GP_PHASE_MATRIX : GP_PHASE_BAND;
}

double gp_mesh_mean_radius(const gp_distribution *dist)
{
    switch (dist->kind) {
    case GP_DIST_CONSTANT: return dist->radius;
    case GP_DIST_UNIFORM: return 0.5 * (dist->min + dist->max);
    case GP_DIST_HISTOGRAM: {
        double sum = 0.0, p = 0.0;
        for (size_t i = 0; i < dist->nbins; i++) {
            sum += dist->bins[i].p * 0.5 * (dist->bins[i].min + dist->bins[i].max);
            p += dist->bins[i].p;
        }
        return p > 0.0 ? sum / p : 0.0;
    }
    }
    return 0.0;
}

void gp_mesh_params_default(const gp_distribution *dist, gp_mesh_params *params)
{
    params->element_size = GP_MESH_DEFAULT_SIZE_RATIO * gp_mesh_mean_radius(dist);
    params->min_angle = GP_MESH_MAX_MIN_ANGLE;
    params->order = 1;
    params->band_layers = 0;
    params->band_size = 0.0;
    params->grading = 1;
    params->disk_tolerance = GP_MESH_DEFAULT_DISK_TOLERANCE;
    params->plane = GP_MESH_PLANE_STRESS;
    params->reduced = 0;
}

/* The mean over the grains' outline length (a grain of radius r has outline about
 * proportional to r) of max(0, 1/g - 1/h), g the graded size of the band around a grain
 * of radius r: band_size when set, else GP_CDT_GRADED_SIZE_PER_THICKNESS times the
 * band's thickness there (twice the joint: each neighbour is shrunk by about as much). */
static double graded_excess(const gp_distribution *dist, const gp_joint *joint,
                            const gp_mesh_params *params)
{
    double num = 0.0, den = 0.0, h = params->element_size;
    size_t nbins = dist->kind == GP_DIST_HISTOGRAM ? dist->nbins : 1;
    for (size_t b = 0; b < nbins; b++) {
        double lo, hi, p;
        switch (dist->kind) {
        case GP_DIST_CONSTANT: lo = hi = dist->radius, p = 1.0; break;
        case GP_DIST_UNIFORM: lo = dist->min, hi = dist->max, p = 1.0; break;
        default: lo = dist->bins[b].min, hi = dist->bins[b].max, p = dist->bins[b].p; break;
        }
        for (int i = 0; i < GRADED_SAMPLES; i++) {
            double r = lo + (hi - lo) * (i + 0.5) / GRADED_SAMPLES;
            double t = 2.0 * (joint ? gp_joint_thickness(joint, r) : 0.0);
            double g = params->band_size > 0.0 ? params->band_size : GP_CDT_GRADED_SIZE_PER_THICKNESS * t;
            num += p * r * (g > 0.0 ? fmax(0.0, 1.0 / g - 1.0 / h) : 0.0);
            den += p * r;
        }
    }
    return den > 0.0 ? num / den : 0.0;
}

double gp_mesh_expected_elements(const gp_domain *domain, const gp_distribution *dist,
                                 const gp_joint *joint, double expected_disks, int has_cells,
                                 gp_shrink shrink, const gp_mesh_params *params)
{
    double area = gp_domain_area(domain), h = params->element_size, n = expected_disks;
    double r = gp_mesh_mean_radius(dist), j = joint ? gp_joint_thickness(joint, r) : 0.0;
    double outline_edges = has_cells ? CELL_EDGES : 2.0 * M_PI / (2.0 * acos(1.0 - params->disk_tolerance));
    double elements = n * outline_edges * TRIANGLES_PER_OUTLINE_EDGE;
    /* the second phase: a band of thickness about 2j around every cell's perimeter, or
     * the matrix between the disks, whose gaps are about the joint's */
    double second = 0.0, t = 2.0 * j;
    double perimeter = 2.0 * sqrt(2.0 * sqrt(3.0) * area / (n > 1.0 ? n : 1.0)); /* hexagons */
    int band = has_cells && shrink != GP_SHRINK_NONE && t > 0.0;
    if (band) {
        second = 0.5 * n * perimeter * t;
    } else if (!has_cells) {
        second = area * (1.0 - PACKING_FILL * (r * r) / ((r + j) * (r + j)));
        t = fmax(t, 0.25 * r);
    }
    double grains = area - second;
    elements += grains / (AREA_PER_TRIANGLE_H2 * h * h);
    if (second > 0.0) {
        double s = fmin(t, h);
        if (params->band_layers > 0) {
            double along = params->band_size > 0.0 ? params->band_size : t;
            elements += second / (t * along) * params->band_layers;
        } else {
            elements += BAND_TRIANGLES_PER_T2 * second / (s * s);
        }
    }
    if (band && params->grading)
        elements += GRADED_TRANSITION_TRIANGLES * n * perimeter * graded_excess(dist, joint, params);
    return elements;
}

double gp_mesh_element_area(const gp_mesh *mesh, int quad, size_t index)
{
    int corners = quad ? 4 : 3;
    const int32_t *c = quad ? mesh->quad + (size_t)gp_mesh_quad_nodes(mesh->order) * index
                            : mesh->tri + (size_t)gp_mesh_tri_nodes(mesh->order) * index;
    /* relative to the first corner: no cancellation between large coordinates */
    double x0 = mesh->xy[2 * c[0]], y0 = mesh->xy[2 * c[0] + 1], s = 0.0;
    for (int k = 1; k + 1 < corners; k++) {
        double ax = mesh->xy[2 * c[k]] - x0, ay = mesh->xy[2 * c[k] + 1] - y0;
        double bx = mesh->xy[2 * c[k + 1]] - x0, by = mesh->xy[2 * c[k + 1] + 1] - y0;
        s += ax * by - ay * bx;
    }
    return 0.5 * s;
}

double gp_mesh_element_quality(const gp_mesh *mesh, int quad, size_t index)
{
    int corners = quad ? 4 : 3;
    const int32_t *c = quad ? mesh->quad + (size_t)gp_mesh_quad_nodes(mesh->order) * index
                            : mesh->tri + (size_t)gp_mesh_tri_nodes(mesh->order) * index;
    if (!quad) {
        double l2 = 0.0;
        for (int k = 0; k < 3; k++) {
            double dx = mesh->xy[2 * c[(k + 1) % 3]] - mesh->xy[2 * c[k]];
            double dy = mesh->xy[2 * c[(k + 1) % 3] + 1] - mesh->xy[2 * c[k] + 1];
            l2 += dx * dx + dy * dy;
        }
        return l2 > 0.0 ? 4.0 * sqrt(3.0) * gp_mesh_element_area(mesh, 0, index) / l2 : 0.0;
    }
    double q = 1.0;
    for (int k = 0; k < corners; k++) {
        int32_t o = c[k], a = c[(k + 1) % 4], b = c[(k + 3) % 4];
        double ax = mesh->xy[2 * a] - mesh->xy[2 * o], ay = mesh->xy[2 * a + 1] - mesh->xy[2 * o + 1];
        double bx = mesh->xy[2 * b] - mesh->xy[2 * o], by = mesh->xy[2 * b + 1] - mesh->xy[2 * o + 1];
        double den = ax * ax + ay * ay + bx * bx + by * by;
        double corner = den > 0.0 ? 2.0 * (ax * by - ay * bx) / den : 0.0;
        q = corner < q ? corner : q;
    }
    return q;
}
