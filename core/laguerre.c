/* laguerre.c - power cells clipped to the domain and shrunk (docs/method.md §5). A cell is built by
 * cutting the domain rectangle with the radical half-plane of each triangulation neighbour
 * (Sutherland-Hodgman on a convex polygon), in coordinates relative to the centre so that
 * every vertex is accurate to a few ulps of the grain's size wherever the grain lies. */
#include "grainpack/laguerre.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "periodic.h"

/* Cells between two progress reports and cancel checks: a few milliseconds of work. */
#define CELLS_PER_REPORT 16384
/* build_cell's answer when a periodic cell may miss a neighbour beyond the ghosts. */
#define CELL_INCOMPLETE 1

/* Edge labels of a polygon under construction: the neighbour's index in the ring (>= 0)
 * or a wall. */
#define WALL_BOTTOM (-1)
#define WALL_RIGHT (-2)
#define WALL_TOP (-3)
#define WALL_LEFT (-4)

const char *gp_shrink_name(gp_shrink shrink)
{
    switch (shrink) {
    case GP_SHRINK_NONE: return "none";
    case GP_SHRINK_HOMOTHETIC: return "homothetic";
    case GP_SHRINK_OFFSET: return "offset";
    }
    return "?";
}

double gp_polygon_area(const double *xy, size_t n)
{
    if (n < 3)
        return 0.0;
    /* relative to the first vertex: no cancellation between large coordinates */
    double sum = 0.0;
    for (size_t k = 1; k + 1 < n; k++) {
        double ax = xy[2 * k] - xy[0], ay = xy[2 * k + 1] - xy[1];
        double bx = xy[2 * k + 2] - xy[0], by = xy[2 * k + 3] - xy[1];
        sum += ax * by - ay * bx;
    }
    return 0.5 * sum;
}

/* A convex polygon relative to the centre, with the label of the edge that starts at
 * each vertex. Two of them are swapped by each cut. */
typedef struct polygon {
    double *u; /* x, y interleaved */
    int32_t *label;
    size_t n, cap;
} polygon;

static int polygon_reserve(polygon *p, size_t cap)
{
    if (cap <= p->cap)
        return 0;
    double *u = cap <= SIZE_MAX / 2 ? grow_realloc(p->u, 2 * cap, sizeof *u) : NULL;
    if (!u)
        return GP_ENOMEM;
    p->u = u;
    int32_t *label = grow_realloc(p->label, cap, sizeof *label);
    if (!label)
        return GP_ENOMEM;
    p->label = label;
    p->cap = cap;
    return 0;
}

static void polygon_push(polygon *p, double x, double y, int32_t label)
{
    p->u[2 * p->n] = x;
    p->u[2 * p->n + 1] = y;
    p->label[p->n++] = label;
}

/* out = in cut by the half-plane u.(nx, ny) <= c, the new edge labelled `label`.
 * out must have room for in->n + 1 vertices (a convex polygon gains at most one). */
static void cut(const polygon *in, double nx, double ny, double c, int32_t label, polygon *out)
{
    out->n = 0;
    for (size_t k = 0; k < in->n; k++) {
        size_t l = k + 1 < in->n ? k + 1 : 0;
        double ax = in->u[2 * k], ay = in->u[2 * k + 1], bx = in->u[2 * l], by = in->u[2 * l + 1];
        double da = ax * nx + ay * ny - c, db = bx * nx + by * ny - c;
        int a_in = da <= 0.0, b_in = db <= 0.0;
        if (a_in)
            polygon_push(out, ax, ay, in->label[k]);
        if (a_in == b_in)
            continue;
        /* leaving, the new edge starts at the crossing; entering, the cut edge resumes
         * there. A vertex exactly on the line is the crossing itself: no duplicate. */
        double t = da / (da - db);
        if (a_in && da == 0.0)
            out->label[out->n - 1] = label;
        else if (a_in)
            polygon_push(out, ax + t * (bx - ax), ay + t * (by - ay), label);
        else if (db < 0.0)
            polygon_push(out, ax + t * (bx - ax), ay + t * (by - ay), in->label[k]);
    }
}

/* The radical half-plane of p against neighbour q, relative to p: the points u with
 * |u|^2 - R_p^2 <= |u - n|^2 - R_q^2, i.e. u.n <= (|n|^2 + R_p^2 - R_q^2) / 2 with
 * n = q - p; *len gets |n|. */
static double radical(const gp_disk *p, const gp_disk *q, double *nx, double *ny, double *len)
{
    *nx = q->x - p->x;
    *ny = q->y - p->y;
    double n2 = *nx * *nx + *ny * *ny;
    *len = sqrt(n2);
    return 0.5 * (n2 + p->R * p->R - q->R * q->R);
}

/* The wall labelled `wall` as a half-plane relative to p, moved inward by `inset`. */
static void wall_half_plane(const gp_domain *dom, const gp_disk *p, int32_t wall, double inset,
                            double *nx, double *ny, double *c)
{
    switch (wall) {
    case WALL_BOTTOM: *nx = 0.0; *ny = -1.0; *c = p->y - inset; break;
    case WALL_RIGHT: *nx = 1.0; *ny = 0.0; *c = dom->width - p->x - inset; break;
    case WALL_TOP: *nx = 0.0; *ny = 1.0; *c = dom->height - p->y - inset; break;
    default: *nx = -1.0; *ny = 0.0; *c = p->x - inset; break;
    }
}

/* A half-plane u.(nx, ny) <= c relative to the centre; len = |(nx, ny)|. */
typedef struct half_plane {
    double nx, ny, c, len;
} half_plane;

/* Everything one run works with. */
typedef struct builder {
    const gp_domain *domain;
    const gp_disk *disks;
    const gp_laguerre_params *params;
    const gp_rt *rt;
    polygon a, b;    /* the cell, and the scratch the cuts swap with it */
    int32_t *labels; /* the edge labels of the unshrunk cell, while it is shrunk */
    size_t labels_cap;
    int32_t *doubtful; /* pairs (i, j) whose shared edge is near the tolerance */
    size_t ndoubtful, doubtful_cap;
    size_t *ring_start; /* every ring, from gp_rt_rings */
    int32_t *rings;
    const int32_t *ring; /* the ring of the cell being built */
    half_plane *hp;  /* the radical half-plane of each ring neighbour */
    size_t hp_cap;
    gp_cells *out;
    size_t nxy, xy_cap, nnb, nb_cap; /* used and allocated entries of out->xy / neighbours */
    /* periodic domains: disks[n..] are ghosts, copies of disks[origin[k - n]]; cells are
     * cut from the domain grown by `margin` along the periodic axes */
    const int32_t *origin;
    size_t n;
    double margin, R_max;
} builder;

/* The power cell of disk i clipped to the domain, into bd->a; its ring in bd->ring.
 * *holds_centre is cleared when the centre is not strictly inside every half-plane: a
 * packing disk lies in its own power cell unless it overlaps another disk (for disks
 * apart, c = (d^2 + R_p^2 - R_q^2) / 2 >= R_p (R_p + R_q) > 0) or leaves the domain. */
static int power_cell(builder *bd, int32_t i, size_t *degree, int *holds_centre)
{
    const gp_disk *p = &bd->disks[i];
    bd->ring = bd->rings + bd->ring_start[i];
    *degree = bd->ring_start[i + 1] - bd->ring_start[i];
    /* the cell has at most the four walls and one edge per neighbour (m <= degree + 4);
     * while it is shrunk, at most its m edges and their m moved copies */
    size_t m = *degree + 4;
    int32_t *labels = grow(bd->labels, &bd->labels_cap, m, sizeof *labels);
    if (!labels)
        return GP_ENOMEM;
    bd->labels = labels;
    half_plane *hp = grow(bd->hp, &bd->hp_cap, *degree ? *degree : 1, sizeof *hp);
    if (!hp)
        return GP_ENOMEM;
    bd->hp = hp;
    if (polygon_reserve(&bd->a, 2 * m + 1) || polygon_reserve(&bd->b, 2 * m + 1))
        return GP_ENOMEM;
    /* all the neighbours first: their loads, far apart in memory, then overlap */
    for (size_t k = 0; k < *degree; k++)
        hp[k].c = radical(p, &bd->disks[bd->ring[k]], &hp[k].nx, &hp[k].ny, &hp[k].len);
    double W = bd->domain->width, H = bd->domain->height;
    bd->a.n = 0;
    if (bd->origin) {
        /* the ghosts' box along the periodic axes: a cell that reaches it is incomplete */
        double gx = (bd->domain->periodic & GP_PERIODIC_X) ? bd->margin : 0.0;
        double gy = (bd->domain->periodic & GP_PERIODIC_Y) ? bd->margin : 0.0;
        polygon_push(&bd->a, -gx - p->x, -gy - p->y, WALL_BOTTOM);
        polygon_push(&bd->a, W + gx - p->x, -gy - p->y, WALL_RIGHT);
        polygon_push(&bd->a, W + gx - p->x, H + gy - p->y, WALL_TOP);
        polygon_push(&bd->a, -gx - p->x, H + gy - p->y, WALL_LEFT);
    } else {
        polygon_push(&bd->a, -p->x, -p->y, WALL_BOTTOM);
        polygon_push(&bd->a, W - p->x, -p->y, WALL_RIGHT);
        polygon_push(&bd->a, W - p->x, H - p->y, WALL_TOP);
        polygon_push(&bd->a, -p->x, H - p->y, WALL_LEFT);
    }
    /* inside the domain along its walled axes (a centre on a periodic side is inside) */
    unsigned per = bd->origin ? bd->domain->periodic : 0;
    *holds_centre = ((per & GP_PERIODIC_X) || (p->x > 0.0 && p->x < W)) &&
                    ((per & GP_PERIODIC_Y) || (p->y > 0.0 && p->y < H));
    for (size_t k = 0; k < *degree && bd->a.n > 0; k++) {
        *holds_centre &= hp[k].c > 0.0;
        cut(&bd->a, hp[k].nx, hp[k].ny, hp[k].c, (int32_t)k, &bd->b);
        polygon swap = bd->a;
        bd->a = bd->b;
        bd->b = swap;
    }
    return 0;
}

/* Whether the power cell of disk p in bd->a (periodic domain) is its cell among all the
 * periodic images: the cell from a subset of the sites contains the true one, and a site
 * left out cuts it only if it is nearer in power than p to one of its vertices v, i.e.
 * within sqrt(pow_p(v) + R_max^2) of v. When that disk around every vertex lies inside
 * the ghosts' box along the periodic axes, no site left out can cut the cell (and no
 * edge is the box's). */
static int cell_complete(const builder *bd, const gp_disk *p)
{
    const gp_domain *dom = bd->domain;
    for (size_t k = 0; k < bd->a.n; k++) {
        double ux = bd->a.u[2 * k], uy = bd->a.u[2 * k + 1];
        double pow_v = ux * ux + uy * uy - p->R * p->R;
        double reach = sqrt((pow_v > 0.0 ? pow_v : 0.0) + bd->R_max * bd->R_max);
        double x = p->x + ux, y = p->y + uy, m = bd->margin;
        if ((dom->periodic & GP_PERIODIC_X) && !(x - reach > -m && x + reach < dom->width + m))
            return 0;
        if ((dom->periodic & GP_PERIODIC_Y) && !(y - reach > -m && y + reach < dom->height + m))
            return 0;
    }
    return 1;
}

/* The grain a ring neighbour is: itself, or the disk a ghost copies. */
static int32_t grain_of(const builder *bd, int32_t j)
{
    return bd->origin && (size_t)j >= bd->n ? bd->origin[(size_t)j - bd->n] : j;
}

/* Appends the neighbours across the edges of bd->a longer than the tolerance, which is
 * the same for both grains of an edge; an edge whose length is within a factor 2 of it
 * goes to the doubtful list, for gp_laguerre to check that both cells agree on it. */
static int record_neighbours(builder *bd, int32_t i)
{
    const polygon *a = &bd->a;
    int32_t *nb = grow(bd->out->neighbours, &bd->nb_cap, bd->nnb + a->n, sizeof *nb);
    if (!nb)
        return GP_ENOMEM;
    bd->out->neighbours = nb;
    for (size_t k = 0; k < a->n; k++) {
        if (a->label[k] < 0)
            continue;
        int32_t j = bd->ring[a->label[k]];
        size_t l = k + 1 < a->n ? k + 1 : 0;
        double ex = a->u[2 * l] - a->u[2 * k], ey = a->u[2 * l + 1] - a->u[2 * k + 1];
        double len2 = ex * ex + ey * ey;
        double t = 0.5 * GP_LAGUERRE_EDGE_RTOL * (bd->disks[i].R + bd->disks[j].R), t2 = t * t;
        j = grain_of(bd, j);
        if (len2 > t2)
            nb[bd->nnb++] = j;
        if (len2 >= 0.25 * t2 && len2 <= 4.0 * t2) {
            int32_t *pairs = grow(bd->doubtful, &bd->doubtful_cap, bd->ndoubtful + 2, sizeof *pairs);
            if (!pairs)
                return GP_ENOMEM;
            bd->doubtful = pairs;
            pairs[bd->ndoubtful++] = i;
            pairs[bd->ndoubtful++] = j;
        }
    }
    return 0;
}

/* Shrinks the cell in bd->a (docs/method.md §5). */
static void shrink(builder *bd, const gp_disk *p)
{
    polygon *a = &bd->a;
    if (bd->params->shrink == GP_SHRINK_HOMOTHETIC) {
        double s = p->r / p->R;
        for (size_t k = 0; k < 2 * a->n; k++)
            a->u[k] *= s;
        return;
    }
    if (bd->params->shrink != GP_SHRINK_OFFSET)
        return;
    /* the erosion of a convex polygon by j is the intersection of its edges' half-planes
     * moved inward by j; the cuts use the edges of the unshrunk cell */
    double j = p->R - p->r;
    if (!(j > 0.0))
        return; /* no joint: cutting the cell by its own edges again only adds rounding */
    size_t m = a->n;
    int32_t *labels = bd->labels;
    memcpy(labels, a->label, m * sizeof *labels);
    for (size_t k = 0; k < m && a->n > 0; k++) {
        double nx, ny, c;
        if (labels[k] >= 0) {
            const half_plane *h = &bd->hp[labels[k]];
            nx = h->nx;
            ny = h->ny;
            c = h->c - j * h->len;
        } else {
            wall_half_plane(bd->domain, p, labels[k], bd->params->flush_boundary ? 0.0 : j, &nx, &ny, &c);
        }
        cut(a, nx, ny, c, labels[k], &bd->b);
        polygon swap = *a;
        *a = bd->b;
        bd->b = swap;
    }
}

static int build_cell(builder *bd, int32_t i, gp_error *err)
{
    const gp_disk *p = &bd->disks[i];
    size_t degree;
    int holds_centre;
    if (power_cell(bd, i, &degree, &holds_centre))
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the cell of disk %d", i);
    if (!holds_centre || bd->a.n < 3)
        return gp_error_set(err, GP_EGEOM, NULL,
                            "disk %d at (%.17g, %.17g) is outside its own power cell: it overlaps "
                            "another disk or lies outside the domain",
                            i, p->x, p->y);
    if (bd->origin && !cell_complete(bd, p))
        return CELL_INCOMPLETE;
    bd->out->power_area_sum += gp_polygon_area(bd->a.u, bd->a.n);
    if (record_neighbours(bd, i))
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for neighbours");
    bd->out->nstart[i + 1] = bd->nnb;
    shrink(bd, p);
    gp_cells *out = bd->out;
    double *xy = grow(out->xy, &bd->xy_cap, 2 * (bd->nxy + bd->a.n), sizeof *xy);
    if (!xy)
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for cell vertices");
    out->xy = xy;
    for (size_t k = 0; k < bd->a.n; k++) {
        out->xy[2 * bd->nxy] = p->x + bd->a.u[2 * k];
        out->xy[2 * bd->nxy + 1] = p->y + bd->a.u[2 * k + 1];
        bd->nxy++;
    }
    out->start[i + 1] = bd->nxy;
    out->area[i] = gp_polygon_area(bd->a.u, bd->a.n);
    return 0;
}

static int lists(const gp_cells *c, int32_t i, int32_t j)
{
    for (size_t m = c->nstart[i]; m < c->nstart[i + 1]; m++)
        if (c->neighbours[m] == j)
            return 1;
    return 0;
}

/* Keeps j among the neighbours of i only if i is among those of j. The two cells compute
 * their shared edge separately; only an edge whose length is within rounding of the
 * tolerance (the doubtful pairs) can count on one side only. */
static void symmetrize_neighbours(gp_cells *c, const int32_t *doubtful, size_t ndoubtful)
{
    int dropped = 0;
    for (size_t d = 0; d + 1 < ndoubtful; d += 2) {
        int32_t i = doubtful[d], j = doubtful[d + 1];
        if (lists(c, j, i))
            continue;
        for (size_t m = c->nstart[i]; m < c->nstart[i + 1]; m++)
            if (c->neighbours[m] == j) {
                c->neighbours[m] = -1;
                dropped = 1;
            }
    }
    if (!dropped)
        return;
    size_t w = 0;
    for (size_t i = 0; i < c->count; i++) {
        size_t begin = c->nstart[i], end = c->nstart[i + 1];
        c->nstart[i] = w;
        for (size_t k = begin; k < end; k++)
            if (c->neighbours[k] >= 0)
                c->neighbours[w++] = c->neighbours[k];
    }
    c->nstart[c->count] = w;
}

/* The cells of disks[0..n-1] from rt, the triangulation of disks[0..nrt-1]: the disks
 * themselves on a walled domain; on a periodic one the disks and their ghosts, copies of
 * disks[origin[k - n]], within `margin` of the sides. Returns 0, CELL_INCOMPLETE (out
 * zeroed) when the margin is too small for some cell, or a GP_E code with err set. */
static int build_cells(const gp_domain *domain, const gp_disk *disks, size_t n, const gp_rt *rt,
                       const int32_t *origin, double margin, double R_max,
                       const gp_laguerre_params *params, const gp_progress *progress,
                       gp_cells *out, gp_error *err)
{
    memset(out, 0, sizeof *out);
    builder bd;
    memset(&bd, 0, sizeof bd);
    bd.domain = domain;
    bd.disks = disks;
    bd.params = params;
    bd.rt = rt;
    bd.out = out;
    bd.origin = origin;
    bd.n = n;
    bd.margin = margin;
    bd.R_max = R_max;
    out->count = n;
    out->shrink = params->shrink;
    out->start = calloc(n + 1, sizeof *out->start);
    out->nstart = calloc(n + 1, sizeof *out->nstart);
    out->area = malloc((n ? n : 1) * sizeof *out->area);
    /* room for the usual: six neighbours and seven vertices a cell; grown if needed */
    bd.xy_cap = 16 * n + 16;
    out->xy = malloc(bd.xy_cap * sizeof *out->xy);
    bd.nb_cap = 7 * n + 16;
    out->neighbours = malloc(bd.nb_cap * sizeof *out->neighbours);
    bd.ring_start = malloc((gp_rt_count(rt) + 1) * sizeof *bd.ring_start);
    int rc = 0;
    if (!out->start || !out->nstart || !out->area || !out->xy || !out->neighbours || !bd.ring_start ||
        (rc = gp_rt_rings(rt, bd.ring_start, NULL, &bd.rings, progress))) {
        rc = rc == GP_ECANCELED ? gp_error_set(err, GP_ECANCELED, NULL, "laguerre cells canceled")
                                : gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the cells of %zu disks", n);
        goto done;
    }
    for (size_t i = 0; i < n; i++) {
        if (progress && i % CELLS_PER_REPORT == CELLS_PER_REPORT - 1) {
            if (gp_canceled(progress->cancel)) {
                rc = gp_error_set(err, GP_ECANCELED, NULL, "laguerre cells canceled");
                goto done;
            }
            if (progress->report)
                progress->report(progress->ctx, "laguerre", (double)i / (double)n);
        }
        if ((rc = build_cell(&bd, (int32_t)i, err)))
            goto done;
    }
    symmetrize_neighbours(out, bd.doubtful, bd.ndoubtful);
    if (progress && progress->report)
        progress->report(progress->ctx, "laguerre", 1.0);
done:
    free(bd.a.u);
    free(bd.a.label);
    free(bd.b.u);
    free(bd.b.label);
    free(bd.ring_start);
    free(bd.rings);
    free(bd.hp);
    free(bd.labels);
    free(bd.doubtful);
    if (rc)
        gp_cells_free(out);
    return rc;
}

/* The cells on a periodic domain (docs/method.md §5.1): the ghost layer, its own regular
 * triangulation, and the cells of the real disks, with the margin doubled until every
 * cell is complete. */
static int periodic_cells(const gp_domain *domain, const gp_disk *disks, size_t n,
                          const gp_laguerre_params *params, const gp_progress *progress,
                          gp_cells *out, gp_error *err)
{
    double R_max = 0.0;
    for (size_t i = 0; i < n; i++)
        R_max = disks[i].R > R_max ? disks[i].R : R_max;
    /* the first margin (periodic.h) is found too small cell by cell (cell_complete) and
     * doubled, up to a period */
    double period = periodic_last_margin(domain);
    memset(out, 0, sizeof *out);
    for (double margin = PERIODIC_MARGIN_RADII * R_max;; margin *= 2.0) {
        if (margin > period)
            margin = period;
        gp_disk *all;
        int32_t *origin;
        size_t m;
        if (periodic_images(domain, disks, n, margin, &all, &origin, &m))
            return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the periodic images");
        gp_rt *rt;
        int rc = gp_rt_build(all, m, progress, &rt, err);
        if (rc == 0) {
            rc = build_cells(domain, all, n, rt, origin, margin, R_max, params, progress, out, err);
            gp_rt_free(rt);
        }
        free(all);
        free(origin);
        if (rc != CELL_INCOMPLETE)
            return rc;
        if (margin >= period)
            return periodic_too_small(err);
    }
}

int gp_laguerre(const gp_domain *domain, const gp_disk *disks, size_t n, const gp_rt *rt,
                const gp_laguerre_params *params, const gp_progress *progress,
                gp_cells *out, gp_error *err)
{
    if (domain->periodic)
        return periodic_cells(domain, disks, n, params, progress, out, err);
    return build_cells(domain, disks, n, rt, NULL, 0.0, 0.0, params, progress, out, err);
}

void gp_cells_free(gp_cells *cells)
{
    free(cells->start);
    free(cells->xy);
    free(cells->nstart);
    free(cells->neighbours);
    free(cells->area);
    memset(cells, 0, sizeof *cells);
}
