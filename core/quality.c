/* quality.c - the quality criterion F of docs/method.md §4.2: the spread of the gaps between
 * a centre and its triangulation neighbours, over its packing radius. */
#include "quality.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"

/* Whether the power cell of p, whose ring is closed (p not on the hull), lies in the
 * domain: every power vertex (the weighted circumcentre of a triangle around p) inside.
 * Near a wall the regular triangulation has long thin triangles across the empty space
 * beyond the wall, whose power vertices lie outside the domain; a centre with such a
 * triangle has neighbours only through the outside, not through the free space around
 * it, and F would measure that instead. */
int quality_cell_inside(const gp_domain *domain, const gp_disk *disks, int32_t i,
                        const int32_t *ring, size_t degree)
{
    const gp_disk *p = &disks[i];
    for (size_t k = 0; k < degree; k++) {
        const gp_disk *a = &disks[ring[k]], *b = &disks[ring[(k + 1) % degree]];
        /* the power vertex o = p + u solves u.(a - p) = ca and u.(b - p) = cb, where
         * c = (|q - p|^2 + R_p^2 - R_q^2) / 2 (equal power distance to p and q) */
        double ax = a->x - p->x, ay = a->y - p->y, bx = b->x - p->x, by = b->y - p->y;
        double ca = 0.5 * (ax * ax + ay * ay + p->R * p->R - a->R * a->R);
        double cb = 0.5 * (bx * bx + by * by + p->R * p->R - b->R * b->R);
        double det = ax * by - ay * bx;
        if (!(det > 0.0))
            return 0;
        double ox = p->x + (ca * by - cb * ay) / det, oy = p->y + (ax * cb - bx * ca) / det;
        if (!(ox >= 0.0 && oy >= 0.0 && ox <= domain->width && oy <= domain->height))
            return 0;
    }
    return 1;
}

double quality_of_centre(const gp_domain *domain, const gp_disk *disks, int32_t i,
                         const int32_t *ring, size_t degree, int on_hull)
{
    if (on_hull || degree < 3 || !quality_cell_inside(domain, disks, i, ring, degree))
        return NAN;
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

int gp_quality(const gp_domain *domain, const gp_rt *rt, const gp_disk *disks, size_t n, double *F,
               gp_quality_stats *stats, const gp_cancel_flag *cancel, gp_error *err)
{
    memset(stats, 0, sizeof *stats);
    size_t cap = 64;
    int32_t *ring = malloc(cap * sizeof *ring);
    double *values = F ? F : malloc((n ? n : 1) * sizeof *values);
    int rc = 0;
    if (!ring || !values) {
        rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory measuring F on %zu disks", n);
        goto done;
    }
    for (size_t i = 0; i < n; i++) {
        if (i % GP_QUALITY_CENTRES_PER_CHECK == GP_QUALITY_CENTRES_PER_CHECK - 1 && gp_canceled(cancel)) {
            rc = gp_error_set(err, GP_ECANCELED, NULL, "measuring F canceled");
            goto done;
        }
        int hull;
        size_t degree;
        while ((degree = gp_rt_ring(rt, (int32_t)i, ring, cap, &hull)) > cap) {
            int32_t *grown = grow(ring, &cap, degree, sizeof *grown);
            if (!grown) {
                rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory for a ring");
                goto done;
            }
            ring = grown;
        }
        values[i] = quality_of_centre(domain, disks, (int32_t)i, ring, degree, hull);
    }
    quality_summarise(values, n, 1, stats);
done:
    free(ring);
    if (values != F)
        free(values);
    return rc;
}
