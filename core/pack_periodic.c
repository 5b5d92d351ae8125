/* pack_periodic.c - the initial front on a periodic domain (docs/method.md §3.8): with no
 * wall to start from, a torus starts from a seed cluster of three mutually tangent disks
 * and a strip periodic along one axis from a chain of disks along each of its two walls,
 * each chain closing on itself across the periodic sides. */
#include <math.h>
#include <stdlib.h>

#include "packer.h"

/* The torus: three mutually tangent disks in the middle of the domain, drawn from the law
 * like every other, all of level 0. The loop runs A -> C -> B, clockwise around the
 * cluster, so that the empty region (everything else) is on the left of its segments as
 * the front wants; placements then grow the cluster outward until it meets itself across
 * the sides. */
static int seed_cluster(packer *pk)
{
    const gp_domain *dom = pk->params->domain;
    double x = 0.5 * dom->width, y = 0.5 * dom->height;
    int32_t a = pack_add_disk(pk, x, y, 0);
    if (a < 0)
        return a;
    double R_b = pk->pending_R;
    int32_t b = pack_add_disk(pk, x + pk->disks[a].R + R_b, y, 0);
    if (b < 0)
        return b;
    double cx, cy;
    if (!gp_place_tangent(&pk->disks[a], &pk->disks[b], pk->pending_R, &cx, &cy))
        return gp_error_set(pk->err, GP_EINVAL, NULL, "no disk tangent to the seed pair");
    int32_t c = pack_add_disk(pk, cx, cy, 0);
    if (c < 0)
        return c;
    int32_t loop[3] = {a, c, b};
    pk->out->initial_front = pk->count;
    if (front_add_loop(&pk->fr, loop, 3))
        return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for the front");
    return 0;
}

/* One wall of a strip: its points are o + t e (0 <= t < period), the domain is on the
 * side of the inward normal n. */
typedef struct chain_wall {
    double ox, oy, ex, ey, nx, ny, period;
} chain_wall;

/* Where disk k is along the wall: its image nearest the point at t_ref, projected. */
static double along(const packer *pk, const chain_wall *w, int32_t k, double t_ref)
{
    double dx = pk->disks[k].x - (w->ox + t_ref * w->ex), dy = pk->disks[k].y - (w->oy + t_ref * w->ey);
    gp_domain_min_image(pk->params->domain, &dx, &dy);
    return t_ref + dx * w->ex + dy * w->ey;
}

/* Lays disks touching the wall, each touching the ones before (centres 2 sqrt(R R') on
 * along the wall, as pack_walls does), from t = 0 on until the next would meet one of the
 * chain's own disks across the periodic side, and makes them a loop in the order laid,
 * which has the domain on the left as the front wants. A disk of the other wall in the way
 * (a strip under four radii high) pushes the next one on, just past it, as in pack_walls.
 * The chain's disks are the consecutive ids first..last. Returns 0 or a GP_E code. */
static int lay_chain(packer *pk, const chain_wall *w)
{
    int32_t first = (int32_t)pk->count, last = first - 1;
    double t_last = 0.0;
    for (;;) {
        double R = pk->pending_R, t = 0.0;
        /* only the disks within two cells back can hold the new one back (the nearest is
         * not always the last: a tiny disk between two large) */
        for (int32_t k = last; k >= first; k--) {
            double tk = along(pk, w, k, t_last);
            if (tk < t_last - 2.0 * pk->grid.cell)
                break;
            double reach = tk + 2.0 * sqrt(R * pk->disks[k].R);
            if (reach > t)
                t = reach;
        }
        double cx, cy;
        for (;;) {
            if (!(t < w->period))
                goto done;
            cx = w->ox + t * w->ex + R * w->nx;
            cy = w->oy + t * w->ey + R * w->ny;
            int rc = pack_work(pk, pk->query_units);
            if (rc)
                return rc;
            int32_t q = gp_grid_first_overlap(&pk->grid, pk->disks, cx, cy, R, -1, -1);
            if (q == GP_GRID_NONE)
                break;
            if (q >= first)
                goto done; /* the chain met itself across the periodic side */
            gp_disk image;
            const gp_disk *dq = pack_image(pk, &pk->disks[q], cx, cy, &image);
            double hq = (dq->x - w->ox) * w->nx + (dq->y - w->oy) * w->ny;
            double tq = t + (dq->x - cx) * w->ex + (dq->y - cy) * w->ey;
            double t_past = tq + sqrt((R + dq->R) * (R + dq->R) - (R - hq) * (R - hq));
            if (!(t_past > t))
                goto done; /* rounding: the wall ends here rather than spin */
            t = t_past;
        }
        int32_t id = pack_add_disk(pk, cx, cy, 0);
        if (id < 0)
            return id;
        last = id;
        t_last = t;
    }
done:;
    size_t n = (size_t)(last - first + 1);
    if (n < 3)
        return 0; /* fewer than three disks enclose nothing */
    int32_t *ids = malloc(n * sizeof *ids);
    if (!ids)
        return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for the initial front");
    for (size_t i = 0; i < n; i++)
        ids[i] = first + (int32_t)i;
    int rc = front_add_loop(&pk->fr, ids, n);
    free(ids);
    return rc ? gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for the front") : 0;
}

int pack_periodic_start(packer *pk)
{
    const gp_domain *dom = pk->params->domain;
    if ((dom->periodic & GP_PERIODIC_X) && (dom->periodic & GP_PERIODIC_Y))
        return seed_cluster(pk);
    double W = dom->width, H = dom->height;
    chain_wall walls[2];
    if (dom->periodic & GP_PERIODIC_X) {
        walls[0] = (chain_wall){0.0, 0.0, 1.0, 0.0, 0.0, 1.0, W};   /* bottom, towards +x */
        walls[1] = (chain_wall){W, H, -1.0, 0.0, 0.0, -1.0, W};     /* top, towards -x */
    } else {
        walls[0] = (chain_wall){W, 0.0, 0.0, 1.0, -1.0, 0.0, H};    /* right, towards +y */
        walls[1] = (chain_wall){0.0, H, 0.0, -1.0, 1.0, 0.0, H};    /* left, towards -y */
    }
    int rc = lay_chain(pk, &walls[0]);
    if (rc == 0)
        rc = lay_chain(pk, &walls[1]);
    pk->out->initial_front = pk->count;
    return rc;
}
