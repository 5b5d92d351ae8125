/* polyhedron.c - a convex polyhedron cut by half-spaces (polyhedron.h): each face is cut as
 * laguerre.c cuts a polygon (Sutherland-Hodgman), with the vertices shared between faces
 * (indices), so that the faces agree on where every edge is cut; the new face is chained
 * from the edges the cut faces leave on the plane. */
#include "polyhedron.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grow.h"

/* Room in p for nv vertices, nf faces and nfv face entries. */
static int poly_reserve(poly *p, size_t nv, size_t nf, size_t nfv)
{
    if (nv > p->vcap) {
        size_t cap = grow_capacity(p->vcap, nv);
        double *u = cap && cap <= SIZE_MAX / 3 ? grow_realloc(p->u, 3 * cap, sizeof *u) : NULL;
        if (!u)
            return GP_ENOMEM;
        p->u = u;
        p->vcap = cap;
    }
    if (nf + 1 > p->fcap) {
        size_t cap = grow_capacity(p->fcap, nf + 1);
        size_t *fs = cap ? grow_realloc(p->fs, cap, sizeof *fs) : NULL;
        if (!fs)
            return GP_ENOMEM;
        p->fs = fs;
        int32_t *label = grow_realloc(p->label, cap, sizeof *label);
        if (!label)
            return GP_ENOMEM;
        p->label = label;
        p->fcap = cap;
    }
    uint32_t *fv = grow(p->fv, &p->fvcap, nfv ? nfv : 1, sizeof *fv);
    if (!fv)
        return GP_ENOMEM;
    p->fv = fv;
    return 0;
}

static int scratch_reserve(poly_scratch *s, size_t nv)
{
    if (nv <= s->cap)
        return 0;
    size_t cap = grow_capacity(s->cap, nv);
    double *d = cap ? grow_realloc(s->d, cap, sizeof *d) : NULL;
    if (!d)
        return GP_ENOMEM;
    s->d = d;
    uint32_t *map = cap <= SIZE_MAX / 2 ? grow_realloc(s->map, 2 * cap, sizeof *map) : NULL;
    if (!map)
        return GP_ENOMEM;
    s->map = map;
    s->cap = cap;
    return 0;
}

static void swap_poly(poly *a, poly *b)
{
    poly t = *a;
    *a = *b;
    *b = t;
}

int poly_box(poly *p, const double lo[3], const double hi[3], const int32_t wall_label[6])
{
    /* vertex v has x = hi when bit 0 is set, y bit 1, z bit 2; each face counter-clockwise
     * seen from outside */
    static const uint32_t faces[6][4] = {
        {0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    if (poly_reserve(p, 8, 6, 24))
        return GP_ENOMEM;
    for (uint32_t v = 0; v < 8; v++)
        for (int a = 0; a < 3; a++)
            p->u[3 * v + a] = (v >> a) & 1 ? hi[a] : lo[a];
    p->nv = 8;
    p->nf = 6;
    for (size_t f = 0; f < 6; f++) {
        p->fs[f] = 4 * f;
        p->label[f] = wall_label[f];
        memcpy(p->fv + 4 * f, faces[f], sizeof faces[f]);
    }
    p->fs[6] = 24;
    return 0;
}

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/* The new vertex where edge (a, b) crosses the plane, made once per edge: from the inner
 * end, so that both faces of the edge get the same point. */
static uint32_t crossing(const poly *p, poly *out, poly_scratch *s, uint32_t a, uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    for (size_t k = 0; k < s->ncross; k++)
        if (s->cross[3 * k] == lo && s->cross[3 * k + 1] == hi)
            return s->cross[3 * k + 2];
    uint32_t in = s->d[a] <= 0.0 ? a : b, outv = in == a ? b : a;
    double t = s->d[in] / (s->d[in] - s->d[outv]);
    uint32_t v = (uint32_t)out->nv++;
    for (int i = 0; i < 3; i++)
        out->u[3 * v + i] = p->u[3 * in + i] + t * (p->u[3 * outv + i] - p->u[3 * in + i]);
    s->cross[3 * s->ncross] = lo;
    s->cross[3 * s->ncross + 1] = hi;
    s->cross[3 * s->ncross + 2] = v;
    s->ncross++;
    return v;
}

/* The new face's vertices in order, chained from the cap edges (from, to): each vertex
 * must start exactly one edge and the chain close after all of them. Returns how many it
 * wrote to `face`, or 0 when the edges do not make one cycle (rounding at a degenerate
 * cut). */
static size_t chain_cap(const poly_scratch *s, uint32_t *face)
{
    size_t m = s->ncap;
    uint32_t start = s->cap_edge[0], cur = start;
    for (size_t steps = 0; steps < m; steps++) {
        face[steps] = cur;
        size_t k = 0;
        while (k < m && s->cap_edge[2 * k] != cur)
            k++;
        if (k == m)
            return 0;
        cur = s->cap_edge[2 * k + 1];
        if (cur == start)
            return steps + 1 == m ? m : 0;
    }
    return 0;
}

/* The fallback: the distinct vertices of the cap edges sorted by angle about their
 * centroid, counter-clockwise about n. Returns how many it wrote, or GP_ENOMEM as -1. */
static long sort_cap(const poly *out, poly_scratch *s, const double n[3], uint32_t *face)
{
    size_t m = 0;
    for (size_t k = 0; k < 2 * s->ncap; k++) {
        uint32_t v = s->cap_edge[k];
        size_t j = 0;
        while (j < m && face[j] != v)
            j++;
        if (j == m)
            face[m++] = v;
    }
    double *angle = grow(s->angle, &s->angle_cap, m ? m : 1, sizeof *angle);
    if (!angle)
        return -1;
    s->angle = angle;
    double g[3] = {0.0, 0.0, 0.0};
    for (size_t j = 0; j < m; j++)
        for (int i = 0; i < 3; i++)
            g[i] += out->u[3 * face[j] + i] / (double)m;
    /* e1 across n from the axis least along it, e2 = n x e1 / |n| */
    int a = fabs(n[0]) <= fabs(n[1]) && fabs(n[0]) <= fabs(n[2]) ? 0 : fabs(n[1]) <= fabs(n[2]) ? 1 : 2;
    double ax[3] = {0.0, 0.0, 0.0};
    ax[a] = 1.0;
    double e1[3] = {n[1] * ax[2] - n[2] * ax[1], n[2] * ax[0] - n[0] * ax[2], n[0] * ax[1] - n[1] * ax[0]};
    double e2[3] = {n[1] * e1[2] - n[2] * e1[1], n[2] * e1[0] - n[0] * e1[2], n[0] * e1[1] - n[1] * e1[0]};
    for (size_t j = 0; j < m; j++) {
        const double *u = out->u + 3 * face[j];
        double w[3] = {u[0] - g[0], u[1] - g[1], u[2] - g[2]};
        angle[j] = atan2(dot3(w, e2), dot3(w, e1));
    }
    for (size_t j = 1; j < m; j++) /* insertion sort: a handful of vertices */
        for (size_t k = j; k > 0 && angle[k - 1] > angle[k]; k--) {
            double ta = angle[k];
            angle[k] = angle[k - 1];
            angle[k - 1] = ta;
            uint32_t tv = face[k];
            face[k] = face[k - 1];
            face[k - 1] = tv;
        }
    return (long)m;
}

int poly_cut(poly *p, const double n[3], double c, int32_t label, poly *out, poly_scratch *s)
{
    if (scratch_reserve(s, p->nv))
        return GP_ENOMEM;
    int any_out = 0, all_out = 1;
    for (size_t v = 0; v < p->nv; v++) {
        s->d[v] = dot3(p->u + 3 * v, n) - c;
        any_out |= s->d[v] > 0.0;
        all_out &= s->d[v] > 0.0;
    }
    if (!any_out)
        return 0;
    if (all_out) {
        p->nv = p->nf = 0;
        return 0;
    }
    size_t nfv = p->fs[p->nf];
    /* a cut adds at most one vertex per edge (nfv / 2 edges), one per face, one face */
    size_t max_v = p->nv + nfv / 2 + 1;
    if (poly_reserve(out, max_v, p->nf + 1, nfv + p->nf + max_v + 1))
        return GP_ENOMEM;
    uint32_t *cross = grow(s->cross, &s->cross_cap, 3 * (nfv / 2 + 1), sizeof *cross);
    if (!cross)
        return GP_ENOMEM;
    s->cross = cross;
    uint32_t *cap_edge = grow(s->cap_edge, &s->cap_edge_cap, 2 * (nfv + 1), sizeof *cap_edge);
    if (!cap_edge)
        return GP_ENOMEM;
    s->cap_edge = cap_edge;
    s->ncross = s->ncap = 0;
    out->nv = 0;
    uint32_t *old = s->map + s->cap; /* kept vertex -> its index in p */
    for (size_t v = 0; v < p->nv; v++)
        if (s->d[v] <= 0.0) {
            s->map[v] = (uint32_t)out->nv;
            old[out->nv] = (uint32_t)v;
            memcpy(out->u + 3 * out->nv++, p->u + 3 * v, 3 * sizeof *out->u);
        }
    /* on the plane: the crossings (indices from kept_v on) and the kept vertices at
     * distance 0 */
    size_t kept_v = out->nv, w = 0, nf = 0;
    for (size_t f = 0; f < p->nf; f++) {
        size_t b0 = p->fs[f], m = p->fs[f + 1] - b0, begin = w;
        for (size_t k = 0; k < m; k++) {
            uint32_t a = p->fv[b0 + k], b = p->fv[b0 + (k + 1 < m ? k + 1 : 0)];
            int a_in = s->d[a] <= 0.0, b_in = s->d[b] <= 0.0;
            if (a_in)
                out->fv[w++] = s->map[a];
            if (a_in == b_in)
                continue;
            /* leaving, the new edge starts at the crossing; entering, the face resumes
             * there; a vertex exactly on the plane is the crossing itself */
            if (a_in ? s->d[a] < 0.0 : s->d[b] < 0.0)
                out->fv[w++] = crossing(p, out, s, a, b);
        }
        if (w - begin < 3) {
            w = begin;
            continue;
        }
        /* the face's edges on the plane are the new face's, run the other way */
        size_t fm = w - begin;
        for (size_t k = 0; k < fm; k++) {
            uint32_t x = out->fv[begin + k], y = out->fv[begin + (k + 1 < fm ? k + 1 : 0)];
            if (!(x >= kept_v || s->d[old[x]] == 0.0) || !(y >= kept_v || s->d[old[y]] == 0.0))
                continue;
            s->cap_edge[2 * s->ncap] = y;
            s->cap_edge[2 * s->ncap + 1] = x;
            s->ncap++;
        }
        out->fs[nf] = begin;
        out->label[nf++] = p->label[f];
    }
    out->fs[nf] = w;
    out->nf = nf;
    if (s->ncap >= 3) {
        size_t m = chain_cap(s, out->fv + w);
        if (m == 0) {
            long sorted = sort_cap(out, s, n, out->fv + w);
            if (sorted < 0)
                return GP_ENOMEM;
            m = (size_t)sorted;
        }
        if (m >= 3) {
            out->fs[nf + 1] = w + m;
            out->label[nf] = label;
            out->nf = nf + 1;
        }
    }
    swap_poly(p, out);
    return 0;
}

/* Twice the vector area of the polygon of vertex indices f[0..m-1] of u. */
static void vector_area2(const double *u, const uint32_t *f, size_t m, double a[3])
{
    a[0] = a[1] = a[2] = 0.0;
    const double *o = u + 3 * f[0];
    for (size_t k = 1; k + 1 < m; k++) {
        const double *p = u + 3 * f[k], *q = u + 3 * f[k + 1];
        double x[3] = {p[0] - o[0], p[1] - o[1], p[2] - o[2]};
        double y[3] = {q[0] - o[0], q[1] - o[1], q[2] - o[2]};
        a[0] += x[1] * y[2] - x[2] * y[1];
        a[1] += x[2] * y[0] - x[0] * y[2];
        a[2] += x[0] * y[1] - x[1] * y[0];
    }
}

static double face_area(const double *u, const uint32_t *f, size_t m)
{
    double a[3];
    vector_area2(u, f, m, a);
    return 0.5 * sqrt(dot3(a, a));
}

double poly_face_area(const poly *p, size_t f)
{
    return face_area(p->u, p->fv + p->fs[f], p->fs[f + 1] - p->fs[f]);
}

double poly_volume(const poly *p)
{
    double v = 0.0;
    for (size_t f = 0; f < p->nf; f++) {
        const uint32_t *fv = p->fv + p->fs[f];
        size_t m = p->fs[f + 1] - p->fs[f];
        const double *o = p->u + 3 * fv[0];
        for (size_t k = 1; k + 1 < m; k++) {
            const double *a = p->u + 3 * fv[k], *b = p->u + 3 * fv[k + 1];
            v += o[0] * (a[1] * b[2] - a[2] * b[1]) + o[1] * (a[2] * b[0] - a[0] * b[2]) +
                 o[2] * (a[0] * b[1] - a[1] * b[0]);
        }
    }
    return v / 6.0;
}

int poly_tidy(poly *p, double merge, int (*keep)(void *ctx, int32_t label, double area), void *ctx,
              poly *out, poly_scratch *s)
{
    size_t nfv = p->fs[p->nf];
    if (scratch_reserve(s, p->nv) || poly_reserve(out, p->nv, p->nf, nfv))
        return GP_ENOMEM;
    uint32_t *rep = s->map, *renum = s->map + s->cap;
    double m2 = merge * merge;
    /* each vertex to the first earlier representative within `merge` (a handful of
     * vertices a cell: the quadratic search is the cheap one) */
    for (size_t v = 0; v < p->nv; v++) {
        rep[v] = (uint32_t)v;
        renum[v] = UINT32_MAX;
        const double *a = p->u + 3 * v;
        for (size_t w = 0; w < v; w++) {
            if (rep[w] != w)
                continue;
            const double *b = p->u + 3 * w;
            double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
            if (dx * dx + dy * dy + dz * dz <= m2) {
                rep[v] = (uint32_t)w;
                break;
            }
        }
    }
    size_t w = 0, nf = 0;
    out->nv = 0;
    for (size_t f = 0; f < p->nf; f++) {
        size_t b0 = p->fs[f], m = p->fs[f + 1] - b0, begin = w;
        for (size_t k = 0; k < m; k++) {
            uint32_t v = rep[p->fv[b0 + k]];
            if (w > begin && out->fv[w - 1] == v)
                continue;
            out->fv[w++] = v;
        }
        while (w - begin > 1 && out->fv[w - 1] == out->fv[begin])
            w--;
        if (w - begin < 3 || (keep && !keep(ctx, p->label[f], face_area(p->u, out->fv + begin, w - begin)))) {
            w = begin;
            continue;
        }
        for (size_t k = begin; k < w; k++) {
            uint32_t v = out->fv[k];
            if (renum[v] == UINT32_MAX) {
                renum[v] = (uint32_t)out->nv;
                memcpy(out->u + 3 * out->nv++, p->u + 3 * v, 3 * sizeof *out->u);
            }
            out->fv[k] = renum[v];
        }
        out->fs[nf] = begin;
        out->label[nf++] = p->label[f];
    }
    out->fs[nf] = w;
    out->nf = nf;
    swap_poly(p, out);
    return 0;
}

void poly_free(poly *p)
{
    free(p->u);
    free(p->fv);
    free(p->fs);
    free(p->label);
    memset(p, 0, sizeof *p);
}

void poly_scratch_free(poly_scratch *s)
{
    free(s->d);
    free(s->map);
    free(s->cross);
    free(s->cap_edge);
    free(s->angle);
    memset(s, 0, sizeof *s);
}
