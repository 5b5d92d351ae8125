/* io_svg3d.c - the section picture of a 3D result: the plane of "picture": {"section"}
 * cuts the spheres (circles of the grain radius) and, with cells, the shrunk polyhedra
 * (convex polygons), drawn in the box's section. Coordinates are the model's own, exact
 * (shortest decimals) in a viewBox: a section holds one layer of grains, few enough
 * that exact numbers cost little, and a reader can check the geometry on them. Written
 * window by window (writer3d.h): a cell's cut needs only its own vertices, and nothing
 * global but the spec. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "writer3d.h"

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

typedef struct svg3d_state {
    gp_state3d base;
    int axis, u, v;
    double at, W, H, px, r_min, r_max;
    point2 *pts;  /* a cell's crossings */
    size_t cap;   /* the crossings pts has room for, but one */
} svg3d_state;

static void drop(void *state)
{
    free(((svg3d_state *)state)->pts);
}

static void head(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    svg3d_state *st = w->state;
    const gp_spec3d *spec = st->base.spec;
    const double side[3] = {spec->box.width, spec->box.height, spec->box.depth};
    st->axis = spec->section.axis;
    plane_axes(st->axis, &st->u, &st->v);
    st->at = spec->section.at * side[st->axis];
    st->W = side[st->u];
    st->H = side[st->v];
    st->px = PICTURE_PX / fmax(st->W, st->H);
    gp_distribution_support(&spec->dist, &st->r_min, &st->r_max);
    static const char *const names[] = {"x", "y", "z"};
    double W = st->W, H = st->H, at = st->at;
    gp_out_printf(o, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\" "
                     "width=\"%.0f\" height=\"%.0f\" viewBox=\"0 0 ", W * st->px, H * st->px);
    gp_out_double(o, W);
    gp_out_char(o, ' ');
    gp_out_double(o, H);
    gp_out_printf(o, "\" data-axis=\"%s\" data-at=\"", names[st->axis]);
    gp_out_double(o, at);
    gp_out_printf(o, "\" data-u=\"%s\" data-v=\"%s\">\n<title>grainpack pack3d: section %s = ", names[st->u],
                  names[st->v], names[st->axis]);
    gp_out_double(o, at);
    gp_out_printf(o, " (%s to the right, %s up)</title>\n", names[st->u], names[st->v]);
    /* the model's v axis upwards */
    GP_OUT_LITERAL(o, "<g transform=\"matrix(1 0 0 -1 0 ");
    gp_out_double(o, H);
    GP_OUT_LITERAL(o, ")\">\n<rect id=\"box\" x=\"0\" y=\"0\" width=\"");
    gp_out_double(o, W);
    GP_OUT_LITERAL(o, "\" height=\"");
    gp_out_double(o, H);
    int cells = st->base.result->has_cells;
    gp_out_puts(o, cells ? "\" fill=\"" BAND "\"/>\n" : "\" fill=\"" BACKGROUND "\"/>\n");
    if (cells)
        GP_OUT_LITERAL(o, "<g id=\"cells\" stroke=\"none\">\n");
}

/* Cell i's cut by the plane, a polygon when it has one. */
static void cell(gp_writer *w, gp_out *o, size_t i, int param)
{
    (void)param;
    svg3d_state *st = w->state;
    const gp_window3d *win =
        gp_state3d_window(w, o, GP_W3_SPHERES | GP_W3_CELLS | GP_W3_FACES | GP_W3_XYZ, i);
    if (!win)
        return;
    const gp_cells3d *c = win->cells;
    size_t j = i - win->first;
    /* room for every crossing of the cell's face edges, one a face vertex at most */
    size_t cap = c->fvstart[c->fstart[j + 1]] - c->fvstart[c->fstart[j]];
    if (cap > st->cap || !st->pts) {
        point2 *grown = realloc(st->pts, (cap + 1) * sizeof *grown);
        if (!grown) {
            if (!o->err)
                o->err = GP_ENOMEM;
            return;
        }
        st->pts = grown;
        st->cap = cap;
    }
    size_t n = cut_cell(c, j, st->axis, st->at, SAME_POINT_RTOL * (st->W + st->H), st->pts, cap);
    if (!n)
        return;
    GP_OUT_LITERAL(o, "<polygon data-grain=\"");
    gp_out_uint(o, i);
    GP_OUT_LITERAL(o, "\" fill=\"");
    colour(o, win->spheres[j].r, st->r_min, st->r_max);
    GP_OUT_LITERAL(o, "\" points=\"");
    for (size_t k = 0; k < n; k++) {
        if (k)
            gp_out_char(o, ' ');
        gp_out_double(o, st->pts[k].u);
        gp_out_char(o, ',');
        gp_out_double(o, st->pts[k].v);
    }
    GP_OUT_LITERAL(o, "\"/>\n");
}

/* Closes the cells' group (with cells) and opens the spheres'. */
static void spheres_open(gp_writer *w, gp_out *o, int param)
{
    (void)param;
    svg3d_state *st = w->state;
    int cells = st->base.result->has_cells;
    if (cells)
        GP_OUT_LITERAL(o, "</g>\n");
    GP_OUT_LITERAL(o, "<g id=\"spheres\"");
    gp_out_puts(o, cells ? " fill=\"none\" stroke=\"" OUTLINE "\"" : " stroke=\"none\"");
    GP_OUT_LITERAL(o, ">\n");
}

/* Sphere i's cut by the plane, a circle when it has one. */
static void sphere(gp_writer *w, gp_out *o, size_t i, int param)
{
    (void)param;
    svg3d_state *st = w->state;
    const gp_window3d *win = gp_state3d_window(w, o, GP_W3_SPHERES, i);
    if (!win)
        return;
    const gp_sphere *s = &win->spheres[i - win->first];
    const double cc[3] = {s->x, s->y, s->z};
    double d = cc[st->axis] - st->at;
    if (!(fabs(d) < s->r))
        return;
    GP_OUT_LITERAL(o, "<circle data-grain=\"");
    gp_out_uint(o, i);
    GP_OUT_LITERAL(o, "\" cx=\"");
    gp_out_double(o, cc[st->u]);
    GP_OUT_LITERAL(o, "\" cy=\"");
    gp_out_double(o, cc[st->v]);
    GP_OUT_LITERAL(o, "\" r=\"");
    gp_out_double(o, sqrt(s->r * s->r - d * d));
    if (st->base.result->has_cells) {
        GP_OUT_LITERAL(o, "\" stroke-width=\"");
        gp_out_double(o, 1.0 / st->px);
    } else {
        GP_OUT_LITERAL(o, "\" fill=\"");
        colour(o, s->r, st->r_min, st->r_max);
    }
    GP_OUT_LITERAL(o, "\"/>\n");
}

static void tail(gp_writer *w, gp_out *o, int param)
{
    (void)w;
    (void)param;
    GP_OUT_LITERAL(o, "</g>\n</g>\n</svg>\n");
}

int gp_plan_svg3d(gp_writer *w, const gp_plan3d_args *a)
{
    int rc = gp_plan3d_state(w, a, sizeof(svg3d_state));
    if (rc)
        return rc;
    w->drop = drop;
    size_t n = a->result->packing.count;
    gp_writer_text(w, head, 0);
    if (a->result->has_cells)
        gp_writer_items(w, cell, n, 0);
    gp_writer_text(w, spheres_open, 0);
    gp_writer_items(w, sphere, n, 0);
    gp_writer_text(w, tail, 0);
    return 0;
}

int gp_write_section_svg(gp_out *o, const gp_spec3d *spec, const gp_result3d *result)
{
    return gp_write3d_memory(o, GP_FORMAT3D_SVG, spec, result);
}
