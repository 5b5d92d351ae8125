/* mesh_periodic.c - what a mesh of a periodic domain needs beyond a walled one: outlines
 * cut into their pieces inside the domain (docs/method.md §6.6), the points on opposite
 * periodic sides made translates of each other before meshing, and the node pairs of
 * the finished mesh that the writers list. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mesh_internal.h"

/* The crossing of edge p-q with the line where coordinate `axis` is c: computed from the
 * endpoint of lower coordinate, so that the two boxes on either side of the line (the
 * same edge seen from both) get the same point, bit for bit. */
static void crossing(const double *p, const double *q, int axis, double c, double *out)
{
    const double *a = p[axis] <= q[axis] ? p : q, *b = a == p ? q : p;
    double t = (c - a[axis]) / (b[axis] - a[axis]);
    out[axis] = c;
    out[1 - axis] = a[1 - axis] + t * (b[1 - axis] - a[1 - axis]);
}

/* Sutherland-Hodgman: the part of polygon in[0 .. n-1] where coordinate `axis` is >= c
 * (keep_above) or <= c. out has room for n + 1 vertices. Returns the count. */
static size_t clip_line(const double *in, size_t n, int axis, double c, int keep_above, double *out)
{
    size_t m = 0;
    for (size_t k = 0; k < n; k++) {
        const double *p = in + 2 * k, *q = in + 2 * ((k + 1) % n);
        int pin = keep_above ? p[axis] >= c : p[axis] <= c;
        int qin = keep_above ? q[axis] >= c : q[axis] <= c;
        if (pin) {
            out[2 * m] = p[0];
            out[2 * m + 1] = p[1];
            m++;
        }
        if (pin != qin && p[axis] != c && q[axis] != c)
            crossing(p, q, axis, c, out + 2 * m++);
    }
    return m;
}

size_t gp_mesh_clip_box(const double *xy, size_t n, const double box[4], double *out, double *work)
{
    /* left, right, bottom, top: each pass adds at most one vertex */
    size_t m = clip_line(xy, n, 0, box[0], 1, work);
    m = m ? clip_line(work, m, 0, box[1], 0, out) : 0;
    m = m ? clip_line(out, m, 1, box[2], 1, work) : 0;
    m = m ? clip_line(work, m, 1, box[3], 0, out) : 0;
    return m;
}


static int by_along(const void *a, const void *b)
{
    double x = ((const gp_side_point *)a)->along, y = ((const gp_side_point *)b)->along;
    return (x > y) - (x < y);
}

/* The points on the line where coordinate `axis` is c, sorted along it; *n gets how
 * many. NULL when out of memory. */
static gp_side_point *on_line(const gp_pslg *g, int axis, double c, size_t *n)
{
    gp_side_point *list = malloc((g->npoints ? g->npoints : 1) * sizeof *list);
    *n = 0;
    if (!list)
        return NULL;
    for (size_t k = 0; k < g->npoints; k++)
        if (g->xy[2 * k + axis] == c)
            list[(*n)++] = (gp_side_point){g->xy[2 * k + 1 - axis], (int32_t)k};
    qsort(list, *n, sizeof *list, by_along);
    return list;
}

/* Makes the points on the sides across `axis` (at 0 and at `period`) translates of each
 * other: a pair closer than tol along the side gets the low side's coordinate on both,
 * a point with no partner gets one made on the other side. */
static int match_axis(gp_pslg *g, int axis, double period, double tol)
{
    size_t nlo, nhi;
    gp_side_point *lo = on_line(g, axis, 0.0, &nlo), *hi = on_line(g, axis, period, &nhi);
    int rc = lo && hi ? 0 : GP_ENOMEM;
    size_t i = 0, j = 0;
    while (rc == 0 && (i < nlo || j < nhi)) {
        double a = i < nlo ? lo[i].along : INFINITY, b = j < nhi ? hi[j].along : INFINITY;
        double xy[2];
        if (fabs(a - b) <= tol) {
            g->xy[2 * hi[j].point + 1 - axis] = a;
            i++, j++;
            continue;
        }
        /* the lower one lacks a partner */
        xy[axis] = a < b ? period : 0.0;
        xy[1 - axis] = a < b ? a : b;
        if (gp_pslg_point(g, xy[0], xy[1]) < 0)
            rc = GP_ENOMEM;
        if (a < b)
            i++;
        else
            j++;
    }
    free(lo);
    free(hi);
    return rc;
}

int gp_mesh_match_sides(gp_pslg *g, unsigned periodic, double W, double H, double tol)
{
    int rc = 0;
    if (periodic & GP_PERIODIC_X)
        rc = match_axis(g, 0, W, tol);
    if (rc == 0 && (periodic & GP_PERIODIC_Y))
        rc = match_axis(g, 1, H, tol);
    return rc;
}

void gp_side_nodes_init(gp_side_nodes *s, const gp_domain *d, int axis)
{
    memset(s, 0, sizeof *s);
    s->axis = axis;
    s->period = axis == 0 ? d->width : d->height;
}

static int add_side_point(gp_side_point **list, size_t *n, size_t *cap, double along, size_t k)
{
    if (gp_mesh_reserve((void **)list, cap, *n + 1, sizeof **list))
        return GP_ENOMEM;
    (*list)[(*n)++] = (gp_side_point){along, (int32_t)k};
    return 0;
}

int gp_side_nodes_add(gp_side_nodes *s, const double *xy, size_t first, size_t n)
{
    for (size_t j = 0; j < n; j++) {
        double c = xy[2 * j + s->axis], along = xy[2 * j + 1 - s->axis];
        int rc = 0;
        if (c == 0.0)
            rc = add_side_point(&s->lo, &s->nlo, &s->cap_lo, along, first + j);
        else if (c == s->period)
            rc = add_side_point(&s->hi, &s->nhi, &s->cap_hi, along, first + j);
        if (rc)
            return rc;
    }
    return 0;
}

int gp_side_nodes_pairs(gp_side_nodes *s, int32_t **pairs, size_t *n)
{
    *pairs = NULL;
    *n = 0;
    gp_side_point *lo = s->lo, *hi = s->hi;
    size_t nlo = s->nlo, nhi = s->nhi;
    qsort(lo, nlo, sizeof *lo, by_along);
    qsort(hi, nhi, sizeof *hi, by_along);
    int rc = nlo == nhi ? 0 : GP_EGEOM;
    for (size_t k = 0; k < nlo && rc == 0; k++)
        if (lo[k].along != hi[k].along || (k > 0 && lo[k].along == lo[k - 1].along))
            rc = GP_EGEOM;
    if (rc == 0 && (*pairs = malloc(2 * (nlo ? nlo : 1) * sizeof **pairs)) == NULL)
        rc = GP_ENOMEM;
    for (size_t k = 0; k < nlo && rc == 0; k++) {
        (*pairs)[2 * k] = lo[k].point;
        (*pairs)[2 * k + 1] = hi[k].point;
    }
    if (rc == 0)
        *n = nlo;
    gp_side_nodes_free(s);
    return rc;
}

void gp_side_nodes_free(gp_side_nodes *s)
{
    free(s->lo);
    free(s->hi);
    s->lo = s->hi = NULL;
    s->nlo = s->nhi = s->cap_lo = s->cap_hi = 0;
}

int gp_mesh_periodic_pairs(const gp_mesh *m, const gp_domain *d, int axis, int32_t **pairs,
                           size_t *n)
{
    *pairs = NULL;
    *n = 0;
    unsigned bit = axis == 0 ? GP_PERIODIC_X : GP_PERIODIC_Y;
    if (!(d->periodic & bit))
        return 0;
    gp_side_nodes s;
    gp_side_nodes_init(&s, d, axis);
    int rc = gp_side_nodes_add(&s, m->xy, 0, m->nnodes);
    if (rc) {
        gp_side_nodes_free(&s);
        return rc;
    }
    return gp_side_nodes_pairs(&s, pairs, n);
}
