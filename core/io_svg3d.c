/* io_svg3d.c - the section picture of a 3D result: the plane of "picture": {"section"}
 * cuts the spheres (circles of the grain radius) and, with cells, the shrunk polyhedra
 * (convex polygons), drawn in the box's section. Coordinates are the model's own, exact
 * (shortest decimals) in a viewBox: a section holds one layer of grains, few enough
 * that exact numbers cost little, and a reader can check the geometry on them. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/io3d.h"

/* Width of the picture in pixels for the section's longer side. */
#define PICTURE_PX 1000.0
#define BACKGROUND "#f4f1ea" /* the voids */
#define BAND "#3b3b3b"       /* the boundary band between cells */
#define OUTLINE "#1d1d1d"
/* Two crossings closer than this fraction of the section's size are one point: the same
 * crossing computed from the two ends of an edge differs by a few ulps. */
#define SAME_POINT_RTOL 1e-12
/* Grain colours: a blend from small (blue) to large (gold) grains. */
static const int SMALL[3] = {44, 62, 140}, LARGE[3] = {233, 196, 106};

/* The section's axes: the two others than `axis`, in order (x: y z; y: x z; z: x y). */
static void plane_axes(int axis, int *u, int *v)
{
    *u = axis == 0 ? 1 : 0;
    *v = axis == 2 ? 1 : 2;
}

static void colour(gp_out *o, double r, double r_min, double r_max)
{
    double t = r_max > r_min ? (r - r_min) / (r_max - r_min) : 0.5;
    t = fmin(1.0, fmax(0.0, t));
    gp_out_printf(o, "#%02x%02x%02x", (int)lround(SMALL[0] + t * (LARGE[0] - SMALL[0])),
                  (int)lround(SMALL[1] + t * (LARGE[1] - SMALL[1])),
                  (int)lround(SMALL[2] + t * (LARGE[2] - SMALL[2])));
}

typedef struct point2 {
    double u, v, angle;
} point2;

static int by_angle(const void *a, const void *b)
{
    double x = ((const point2 *)a)->angle, y = ((const point2 *)b)->angle;
    return (x > y) - (x < y);
}

/* The cut of cell i by the plane x_axis = at: the points where its faces' edges cross
 * it, around their centroid (a convex polyhedron cuts into a convex polygon). Returns
 * the number of points in pts (at most `cap`). */
static size_t cut_cell(const gp_cells3d *c, size_t i, int axis, double at, double eps, point2 *pts,
                       size_t cap)
{
    int u, v;
    plane_axes(axis, &u, &v);
    size_t n = 0;
    const double *xyz = &c->xyz[3 * c->vstart[i]];
    for (size_t f = c->fstart[i]; f < c->fstart[i + 1]; f++) {
        size_t a = c->fvstart[f], m = c->fvstart[f + 1] - a;
        for (size_t k = 0; k < m && n < cap; k++) {
            const double *p = &xyz[3 * (size_t)c->fverts[a + k]];
            const double *q = &xyz[3 * (size_t)c->fverts[a + (k + 1) % m]];
            double sp = p[axis] - at, sq = q[axis] - at;
            if (sp == 0.0) {
                pts[n++] = (point2){p[u], p[v], 0.0};
            } else if ((sp < 0.0 && sq > 0.0) || (sp > 0.0 && sq < 0.0)) {
                double t = sp / (sp - sq);
                pts[n++] = (point2){p[u] + t * (q[u] - p[u]), p[v] + t * (q[v] - p[v]), 0.0};
            }
        }
    }
    if (n < 3)
        return 0;
    double cu = 0.0, cv = 0.0;
    for (size_t k = 0; k < n; k++) {
        cu += pts[k].u / (double)n;
        cv += pts[k].v / (double)n;
    }
    for (size_t k = 0; k < n; k++)
        pts[k].angle = atan2(pts[k].v - cv, pts[k].u - cu);
    qsort(pts, n, sizeof *pts, by_angle);
    /* each crossing is met from both faces of its edge (computed from either end): keep one */
    size_t kept = 0;
    for (size_t k = 0; k < n; k++)
        if (!kept || fabs(pts[k].u - pts[kept - 1].u) + fabs(pts[k].v - pts[kept - 1].v) > eps)
            pts[kept++] = pts[k];
    while (kept > 1 && fabs(pts[kept - 1].u - pts[0].u) + fabs(pts[kept - 1].v - pts[0].v) <= eps)
        kept--;
    return kept >= 3 ? kept : 0;
}

int gp_write_section_svg(gp_out *o, const gp_spec3d *spec, const gp_result3d *result)
{
    const double side[3] = {spec->box.width, spec->box.height, spec->box.depth};
    int axis = spec->section.axis, u, v;
    plane_axes(axis, &u, &v);
    double at = spec->section.at * side[axis], W = side[u], H = side[v];
    double px = PICTURE_PX / fmax(W, H);
    double r_min, r_max;
    gp_distribution_support(&spec->dist, &r_min, &r_max);
    static const char *const names[] = {"x", "y", "z"};
    gp_out_printf(o, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
                     "width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 ", W * px, H * px);
    gp_out_double(o, W);
    gp_out_char(o, ' ');
    gp_out_double(o, H);
    gp_out_printf(o, "\" data-axis=\"%s\" data-at=\"", names[axis]);
    gp_out_double(o, at);
    gp_out_printf(o, "\" data-u=\"%s\" data-v=\"%s\">\n<title>grainpack pack3d: section %s = ", names[u],
                  names[v], names[axis]);
    gp_out_double(o, at);
    gp_out_printf(o, " (%s to the right, %s up)</title>\n", names[u], names[v]);
    /* the model's v axis upwards */
    GP_OUT_LITERAL(o, "<g transform=\"matrix(1 0 0 -1 0 ");
    gp_out_double(o, H);
    GP_OUT_LITERAL(o, ")\">\n<rect id=\"box\" x=\"0\" y=\"0\" width=\"");
    gp_out_double(o, W);
    GP_OUT_LITERAL(o, "\" height=\"");
    gp_out_double(o, H);
    gp_out_puts(o, result->has_cells ? "\" fill=\"" BAND "\"/>\n" : "\" fill=\"" BACKGROUND "\"/>\n");
    const gp_sphere *s = result->packing.spheres;
    if (result->has_cells) {
        const gp_cells3d *c = &result->cells;
        size_t cap = 0;
        for (size_t i = 0; i < c->count; i++)
            if (c->fvstart[c->fstart[i + 1]] - c->fvstart[c->fstart[i]] > cap)
                cap = c->fvstart[c->fstart[i + 1]] - c->fvstart[c->fstart[i]];
        point2 *pts = malloc((cap + 1) * sizeof *pts);
        if (!pts)
            return GP_ENOMEM;
        GP_OUT_LITERAL(o, "<g id=\"cells\" stroke=\"none\">\n");
        for (size_t i = 0; i < c->count; i++) {
            size_t n = cut_cell(c, i, axis, at, SAME_POINT_RTOL * (W + H), pts, cap);
            if (!n)
                continue;
            GP_OUT_LITERAL(o, "<polygon data-grain=\"");
            gp_out_uint(o, i);
            GP_OUT_LITERAL(o, "\" fill=\"");
            colour(o, s[i].r, r_min, r_max);
            GP_OUT_LITERAL(o, "\" points=\"");
            for (size_t k = 0; k < n; k++) {
                if (k)
                    gp_out_char(o, ' ');
                gp_out_double(o, pts[k].u);
                gp_out_char(o, ',');
                gp_out_double(o, pts[k].v);
            }
            GP_OUT_LITERAL(o, "\"/>\n");
        }
        GP_OUT_LITERAL(o, "</g>\n");
        free(pts);
    }
    GP_OUT_LITERAL(o, "<g id=\"spheres\"");
    gp_out_puts(o, result->has_cells ? " fill=\"none\" stroke=\"" OUTLINE "\"" : " stroke=\"none\"");
    GP_OUT_LITERAL(o, ">\n");
    const double *cc[3];
    for (size_t i = 0; i < result->packing.count; i++) {
        cc[0] = &s[i].x;
        cc[1] = &s[i].y;
        cc[2] = &s[i].z;
        double d = *cc[axis] - at;
        if (!(fabs(d) < s[i].r))
            continue;
        GP_OUT_LITERAL(o, "<circle data-grain=\"");
        gp_out_uint(o, i);
        GP_OUT_LITERAL(o, "\" cx=\"");
        gp_out_double(o, *cc[u]);
        GP_OUT_LITERAL(o, "\" cy=\"");
        gp_out_double(o, *cc[v]);
        GP_OUT_LITERAL(o, "\" r=\"");
        gp_out_double(o, sqrt(s[i].r * s[i].r - d * d));
        if (result->has_cells) {
            GP_OUT_LITERAL(o, "\" stroke-width=\"");
            gp_out_double(o, 1.0 / px);
        } else {
            GP_OUT_LITERAL(o, "\" fill=\"");
            colour(o, s[i].r, r_min, r_max);
        }
        GP_OUT_LITERAL(o, "\"/>\n");
    }
    GP_OUT_LITERAL(o, "</g>\n</g>\n</svg>\n");
    return gp_out_flush(o);
}
