/* quality.c - the quality criterion F of docs/method.md §4.2: the spread of the gaps between
 * a centre and its triangulation neighbours, over its packing radius. */
#include "quality.h"

#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "periodic.h"

/* Whether the power vertex o (relative to p: u) keeps along the axis of length L the
 * rule of quality_cell_inside: 1, 0 or QUALITY_INCOMPLETE. */
static int axis_inside(int periodic, double o, double L, double box, double reach)
{
    if (!periodic)
        return o >= 0.0 && o <= L;
    return o - reach > -box && o + reach < L + box ? 1 : QUALITY_INCOMPLETE;
}

/* Whether the power cell of p, whose ring is closed (p not on the hull), lies in the
 * domain: every power vertex (the weighted circumcentre of a triangle around p) inside.
 * Near a wall the regular triangulation has long thin triangles across the empty space
 * beyond the wall, whose power vertices lie outside the domain; a centre with such a
 * triangle has neighbours only through the outside, not through the free space around
 * it, and F would measure that instead. Along a periodic axis, the vertex's power circle
 * grown by R_max must lie in the box of the ghosts: a site left out cuts the cell only
 * if it is nearer in power than p to one of its vertices (laguerre.c, cell_complete). */
/* c = (|q - p|^2 + R_p^2 - R_q^2) / 2 for q - p = (qx, qy): the power vertices u
 * relative to p of the triangles around p with q solve u.(q - p) = c (equal power
 * distance to p and q). */
static double power_offset(const gp_disk *p, double qx, double qy, double qR)
{
    return 0.5 * (qx * qx + qy * qy + p->R * p->R - qR * qR);
}

int quality_cell_inside(const quality_frame *frame, const gp_disk *disks, int32_t i,
                        const int32_t *ring, size_t degree)
{
    const gp_domain *domain = frame->domain;
    const gp_disk *p = &disks[i];
    /* walled domains: half the distance from p to the nearer wall along each axis. A
     * vertex whose offset from p is within it is inside without the two divisions: from
     * |n| <= det * m, |n / det| rounded and added to p's coordinate stay far from the
     * walls (a few ulps against half the distance), so the test below gives the answer
     * the divisions would; a vertex nearer the walls is divided for. */
    double wx = domain->width - p->x, wy = domain->height - p->y;
    double mx = 0.5 * (p->x < wx ? p->x : wx), my = 0.5 * (p->y < wy ? p->y : wy);
    int answer = 1;
    /* each ring entry's offset is read twice, as the end of one edge and the start of
     * the next: computed once, the same value either way */
    const gp_disk *a = &disks[ring[0]];
    double ax = a->x - p->x, ay = a->y - p->y, ca = power_offset(p, ax, ay, a->R);
    for (size_t k = 0; k < degree; k++) {
        /* the next ring entry without `%`: an integer division, slow, on every edge */
        const gp_disk *b = &disks[ring[k + 1 < degree ? k + 1 : 0]];
        /* the power vertex o = p + u solves u.(a - p) = ca and u.(b - p) = cb */
        double bx = b->x - p->x, by = b->y - p->y, cb = power_offset(p, bx, by, b->R);
        double det = ax * by - ay * bx;
        if (!(det > 0.0))
            return 0;
        double nx = ca * by - cb * ay, ny = ax * cb - bx * ca;
        if (!domain->periodic && det < DBL_MAX && fabs(nx) <= det * mx && fabs(ny) <= det * my) {
            ax = bx;
            ay = by;
            ca = cb;
            continue;
        }
        double ux = nx / det, uy = ny / det;
        double ox = p->x + ux, oy = p->y + uy;
        ax = bx;
        ay = by;
        ca = cb;
        if (!domain->periodic) {
            if (!(ox >= 0.0 && oy >= 0.0 && ox <= domain->width && oy <= domain->height))
                return 0;
            continue;
        }
        double pow_o = ux * ux + uy * uy - p->R * p->R;
        double reach = sqrt((pow_o > 0.0 ? pow_o : 0.0) + frame->R_max * frame->R_max);
        int in_x = axis_inside(domain->periodic & GP_PERIODIC_X, ox, domain->width, frame->box, reach);
        int in_y = axis_inside(domain->periodic & GP_PERIODIC_Y, oy, domain->height, frame->box, reach);
        if (!in_x || !in_y)
            return 0;
        if (in_x < 0 || in_y < 0)
            answer = QUALITY_INCOMPLETE;
    }
    return answer;
}

double quality_of_centre(const quality_frame *frame, const gp_disk *disks, int32_t i,
                         const int32_t *ring, size_t degree, int on_hull, int *incomplete)
{
    if (on_hull || degree < 3)
        return NAN;
    int inside = quality_cell_inside(frame, disks, i, ring, degree);
    if (inside != 1) {
        *incomplete |= inside == QUALITY_INCOMPLETE;
        return NAN;
    }
    const gp_disk *p = &disks[i];
    double h_min = INFINITY, h_max = -INFINITY;
    for (size_t k = 0; k < degree; k++) {
        const gp_disk *q = &disks[ring[k]];
        double h = hypot(q->x - p->x, q->y - p->y) - p->R - q->R;
        h_min = h < h_min ? h : h_min;
        h_max = h > h_max ? h : h_max;
    }
    return (h_max - h_min) / p->R;
}

void quality_summarise(const double *F, size_t n, int histogram, gp_quality_stats *stats)
{
    memset(stats, 0, sizeof *stats);
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (isnan(F[i]))
            continue;
        if (stats->interior == 0 || F[i] < stats->min)
            stats->min = F[i];
        if (stats->interior == 0 || F[i] > stats->max)
            stats->max = F[i];
        sum += F[i];
        stats->interior++;
    }
    if (!stats->interior)
        return;
    stats->mean = sum / (double)stats->interior;
    if (!histogram)
        return;
    double span = stats->max - stats->min;
    for (size_t i = 0; i < n; i++) {
        if (isnan(F[i]))
            continue;
        int bin = span > 0.0 ? (int)((F[i] - stats->min) / span * GP_QUALITY_BINS) : 0;
        stats->histogram[bin < GP_QUALITY_BINS ? bin : GP_QUALITY_BINS - 1]++;
    }
}

/* F into values[0..n-1] for the first n vertices of rt, triangulated from `disks`; sets
 * *incomplete as quality_of_centre does. Returns 0, GP_ENOMEM or GP_ECANCELED with err. */
static int measure_all(const quality_frame *frame, const gp_rt *rt, const gp_disk *disks, size_t n,
                       double *values, int *incomplete, const gp_cancel_flag *cancel, gp_error *err)
{
    size_t cap = 64;
    int32_t *ring = malloc(cap * sizeof *ring);
    int rc = 0;
    if (!ring)
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for a ring");
    for (size_t i = 0; i < n; i++) {
        if (i % GP_QUALITY_CENTRES_PER_CHECK == GP_QUALITY_CENTRES_PER_CHECK - 1 && gp_canceled(cancel)) {
            rc = gp_error_set(err, GP_ECANCELED, NULL, "measuring F canceled");
            break;
        }
        int hull;
        size_t degree;
        while ((degree = gp_rt_ring(rt, (int32_t)i, ring, cap, &hull)) > cap) {
            int32_t *grown = grow(ring, &cap, degree, sizeof *grown);
            if (!grown) {
                free(ring);
                return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for a ring");
            }
            ring = grown;
        }
        values[i] = quality_of_centre(frame, disks, (int32_t)i, ring, degree, hull, incomplete);
    }
    free(ring);
    return rc;
}

/* F on a periodic domain: from a ghost layer whose margin doubles until every cell is
 * complete (docs/method.md §4.2, §5.1). */
static int measure_periodic(const gp_domain *domain, const gp_disk *disks, size_t n, double *values,
                            const gp_cancel_flag *cancel, gp_error *err)
{
    double R_max = 0.0;
    for (size_t i = 0; i < n; i++)
        R_max = disks[i].R > R_max ? disks[i].R : R_max;
    gp_progress progress = {NULL, NULL, cancel};
    for (double margin = periodic_first_margin(domain, R_max);; margin *= 2.0) {
        double last = periodic_last_margin(domain);
        margin = margin < last ? margin : last;
        periodic_layer L;
        int rc = periodic_layer_build(&L, domain, disks, n, margin, &progress, err);
        if (rc)
            return rc;
        quality_frame frame = {domain, margin, R_max};
        int incomplete = 0;
        rc = measure_all(&frame, L.rt, L.all, n, values, &incomplete, cancel, err);
        periodic_layer_free(&L);
        if (rc || !incomplete)
            return rc;
        if (margin >= last)
            return periodic_too_small(err);
    }
}

int gp_quality(const gp_domain *domain, const gp_rt *rt, const gp_disk *disks, size_t n, double *F,
               gp_quality_stats *stats, const gp_cancel_flag *cancel, gp_error *err)
{
    memset(stats, 0, sizeof *stats);
    double *values = F ? F : malloc((n ? n : 1) * sizeof *values);
    if (!values)
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory measuring F on %zu disks", n);
    quality_frame frame = {domain, 0.0, 0.0};
    int incomplete = 0;
    int rc = domain->periodic ? measure_periodic(domain, disks, n, values, cancel, err)
                              : measure_all(&frame, rt, disks, n, values, &incomplete, cancel, err);
    if (rc == 0)
        quality_summarise(values, n, 1, stats);
    if (values != F)
        free(values);
    return rc;
}
