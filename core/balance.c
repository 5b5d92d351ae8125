/* balance.c - the quality criterion F and the two balancing methods of docs/method.md §4: sweeps
 * that move each interior centre a step toward a target (the barycentre of its neighbours,
 * or of the positions tangent to its ball's boundary edges), refused when the step would
 * overlap a disk or leave the domain. */
#include "grainpack/balance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/grid.h"

/* Steps tried toward the target, as fractions w of the way: from the largest allowed
 * (gp_balance_params.max_step) down by 0.05 to 0.05, as report Algorithm 3 does from
 * 0.30; the first conflict-free one is taken. */
#define STEP_DECREMENT 0.05

/* Centres between two progress reports and cancel checks: a few milliseconds of work. */
#define CENTRES_PER_REPORT GP_QUALITY_CENTRES_PER_CHECK

const char *gp_balance_method_name(gp_balance_method method)
{
    switch (method) {
    case GP_BALANCE_NONE: return "none";
    case GP_BALANCE_LAPLACIAN: return "laplacian";
    case GP_BALANCE_RELOCATION: return "relocation";
    }
    return "?";
}

/* A growable buffer for rings. */
typedef struct ring_buffer {
    int32_t *ids;
    size_t cap;
} ring_buffer;

/* The ring of `id` in buf; returns its degree, or (size_t)-1 when out of memory. */
static size_t ring_of(const gp_rt *rt, int32_t id, ring_buffer *buf, int *on_hull)
{
    for (;;) {
        size_t degree = gp_rt_ring(rt, id, buf->ids, buf->cap, on_hull);
        if (degree <= buf->cap)
            return degree;
        int32_t *grown = realloc(buf->ids, 2 * degree * sizeof *grown);
        if (!grown)
            return (size_t)-1;
        buf->ids = grown;
        buf->cap = 2 * degree;
    }
}

/* F(p) of docs/method.md §4.2 for the disk p with the given ring. */
static double quality_of(const gp_disk *disks, const gp_disk *p, const int32_t *ring,
                         size_t degree)
{
    double h_min = INFINITY, h_max = -INFINITY;
    for (size_t k = 0; k < degree; k++) {
        const gp_disk *q = &disks[ring[k]];
        double h = hypot(q->x - p->x, q->y - p->y) - p->R - q->R;
        h_min = h < h_min ? h : h_min;
        h_max = h > h_max ? h : h_max;
    }
    return (h_max - h_min) / p->R;
}

/* Whether the power cell of p, whose ring is closed (p not on the hull), lies in the
 * domain: every power vertex (the weighted circumcentre of a triangle around p) inside.
 * Near a wall the regular triangulation has long thin triangles across the empty space
 * beyond the wall, whose power vertices lie outside the domain; a centre with such a
 * triangle has neighbours only through the outside, not through the free space around
 * it, and F would measure that instead. */
static int cell_inside_domain(const gp_domain *domain, const gp_disk *disks, const gp_disk *p,
                              const int32_t *ring, size_t degree)
{
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

int gp_quality(const gp_domain *domain, const gp_rt *rt, const gp_disk *disks, size_t n, double *F,
               gp_quality_stats *stats, const gp_cancel_flag *cancel, gp_error *err)
{
    memset(stats, 0, sizeof *stats);
    ring_buffer buf = {malloc(64 * sizeof(int32_t)), 64};
    double *values = malloc((n ? n : 1) * sizeof *values);
    int rc = 0;
    if (!buf.ids || !values) {
        rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory measuring F on %zu disks", n);
        goto done;
    }
    double sum = 0.0;
    for (size_t i = 0; i < n; i++) {
        if (i % GP_QUALITY_CENTRES_PER_CHECK == GP_QUALITY_CENTRES_PER_CHECK - 1 && gp_canceled(cancel)) {
            rc = gp_error_set(err, GP_ECANCELED, NULL, "measuring F canceled");
            goto done;
        }
        int hull;
        size_t degree = ring_of(rt, (int32_t)i, &buf, &hull);
        if (degree == (size_t)-1) {
            rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory for a ring");
            goto done;
        }
        values[i] = !hull && degree >= 3 && cell_inside_domain(domain, disks, &disks[i], buf.ids, degree)
                        ? quality_of(disks, &disks[i], buf.ids, degree)
                        : NAN;
        if (isnan(values[i]))
            continue;
        if (stats->interior == 0 || values[i] < stats->min)
            stats->min = values[i];
        if (stats->interior == 0 || values[i] > stats->max)
            stats->max = values[i];
        sum += values[i];
        stats->interior++;
    }
    if (stats->interior) {
        stats->mean = sum / (double)stats->interior;
        double span = stats->max - stats->min;
        for (size_t i = 0; i < n; i++) {
            if (isnan(values[i]))
                continue;
            int bin = span > 0.0 ? (int)((values[i] - stats->min) / span * GP_QUALITY_BINS) : 0;
            stats->histogram[bin < GP_QUALITY_BINS ? bin : GP_QUALITY_BINS - 1]++;
        }
    }
    if (F)
        memcpy(F, values, n * sizeof *F);
done:
    free(buf.ids);
    free(values);
    return rc;
}

/* Everything one balancing run works with. */
typedef struct balancer {
    const gp_domain *domain;
    gp_disk *disks;
    size_t n;
    const gp_rt *rt;
    gp_balance_method method;
    double max_step;
    gp_grid grid;
    ring_buffer ring;
    int32_t *moved; /* ids moved in the current sweep, or restored at the end */
    size_t nmoved;
    double *best;   /* x, y of every centre in the best structure seen */
} balancer;

/* Whether the packing disk of `id` may sit at (x, y): inside the domain and clear of
 * every other disk, with the packer's contact tolerance. */
static int position_is_free(const balancer *b, int32_t id, double x, double y)
{
    double R = b->disks[id].R;
    return gp_domain_contains_disk(b->domain, x, y, R, R * GP_CONTACT_RTOL) &&
           gp_grid_first_overlap(&b->grid, b->disks, x, y, R, id, id) == GP_GRID_NONE;
}

/* The target of an interior centre: for relocation, the barycentre of the conflict-free
 * positions tangent to the boundary edges of its ball (docs/method.md §4.4); for Laplacian
 * smoothing, the barycentre of its neighbours. Returns 0 when there is none. */
static int target_of(const balancer *b, int32_t id, const int32_t *ring, size_t degree,
                     double *tx, double *ty)
{
    double sx = 0.0, sy = 0.0;
    size_t used = 0;
    const gp_disk *p = &b->disks[id];
    for (size_t k = 0; k < degree; k++) {
        const gp_disk *q1 = &b->disks[ring[k]];
        if (b->method == GP_BALANCE_LAPLACIAN) {
            sx += q1->x;
            sy += q1->y;
            used++;
            continue;
        }
        /* the link edge (q1, q2) has p on its left: the tangent position on p's side */
        const gp_disk *q2 = &b->disks[ring[(k + 1) % degree]];
        double x, y;
        if (gp_place_tangent(q1, q2, p->R, &x, &y) && position_is_free(b, id, x, y)) {
            sx += x;
            sy += y;
            used++;
        }
    }
    if (!used)
        return 0;
    *tx = sx / (double)used;
    *ty = sy / (double)used;
    return 1;
}

/* Moves centre `id` the largest conflict-free step toward its target; returns 1 if it
 * moved, 0 if it is settled or blocked (counted in *refused). */
static int step_centre(balancer *b, int32_t id, const int32_t *ring, size_t degree,
                       uint64_t *refused)
{
    gp_disk *p = &b->disks[id];
    double tx, ty;
    if (!target_of(b, id, ring, degree, &tx, &ty))
        return 0;
    double dx = tx - p->x, dy = ty - p->y, way = hypot(dx, dy);
    for (double w = b->max_step; w > 0.5 * STEP_DECREMENT; w -= STEP_DECREMENT) {
        if (w * way < GP_BALANCE_MIN_STEP_RTOL * p->R)
            return 0; /* settled: what is left of the way is too short to matter */
        double x = p->x + w * dx, y = p->y + w * dy;
        if (!position_is_free(b, id, x, y))
            continue;
        gp_grid_remove(&b->grid, id, p->x, p->y);
        p->x = x;
        p->y = y;
        gp_grid_insert(&b->grid, id, x, y);
        return 1;
    }
    (*refused)++;
    return 0;
}

static int report(const gp_progress *progress, double fraction, gp_error *err)
{
    if (!progress)
        return 0;
    if (gp_canceled(progress->cancel))
        return gp_error_set(err, GP_ECANCELED, NULL, "balancing canceled");
    if (progress->report)
        progress->report(progress->ctx, "balance", fraction);
    return 0;
}

/* One sweep over the interior centres, in id order, each seeing the moves before it;
 * the ids moved go to b->moved. */
static int sweep(balancer *b, const gp_progress *progress, double done, double share,
                 gp_balance_result *out, gp_error *err)
{
    b->nmoved = 0;
    for (size_t i = 0; i < b->n; i++) {
        if (i % CENTRES_PER_REPORT == CENTRES_PER_REPORT - 1) {
            int rc = report(progress, done + share * (double)i / (double)b->n, err);
            if (rc)
                return rc;
        }
        int hull;
        size_t degree = ring_of(b->rt, (int32_t)i, &b->ring, &hull);
        if (degree == (size_t)-1)
            return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for a ring");
        if (hull || degree < 3 ||
            !cell_inside_domain(b->domain, b->disks, &b->disks[i], b->ring.ids, degree))
            continue;
        if (step_centre(b, (int32_t)i, b->ring.ids, degree, &out->refused))
            b->moved[b->nmoved++] = (int32_t)i;
    }
    out->moves += b->nmoved;
    return 0;
}

/* Whether structure `a` is better than `best`: a lower F_max (the report's figure),
 * else as low an F_max and a lower mean. Differences below GP_BALANCE_QUALITY_TOL do not
 * count, so that a structure that only wanders does not look like progress. */
static int improves(const gp_quality_stats *a, const gp_quality_stats *best)
{
    if (a->max < best->max - GP_BALANCE_QUALITY_TOL)
        return 1;
    return a->max <= best->max && a->mean < best->mean - GP_BALANCE_QUALITY_TOL;
}

static void save_best(balancer *b)
{
    for (size_t i = 0; i < b->n; i++) {
        b->best[2 * i] = b->disks[i].x;
        b->best[2 * i + 1] = b->disks[i].y;
    }
}

/* Puts the centres back where they were in the best structure; the ids that move go to
 * b->moved. */
static void restore_best(balancer *b)
{
    b->nmoved = 0;
    for (size_t i = 0; i < b->n; i++) {
        if (b->disks[i].x == b->best[2 * i] && b->disks[i].y == b->best[2 * i + 1])
            continue;
        b->disks[i].x = b->best[2 * i];
        b->disks[i].y = b->best[2 * i + 1];
        b->moved[b->nmoved++] = (int32_t)i;
    }
}

static double largest_radius(const gp_disk *disks, size_t n)
{
    double R_max = 0.0;
    for (size_t i = 0; i < n; i++)
        R_max = disks[i].R > R_max ? disks[i].R : R_max;
    return R_max;
}

/* Sweeps until one moves nothing, the best structure has not improved for
 * GP_BALANCE_STALL_SWEEPS sweeps, or the cap; then returns to the best structure. */
static int run_sweeps(balancer *b, gp_rt *rt, const gp_balance_params *params,
                      const gp_progress *progress, gp_balance_result *out, gp_error *err)
{
    uint32_t cap = params->max_iterations ? params->max_iterations : GP_BALANCE_DEFAULT_MAX_ITERATIONS;
    const gp_cancel_flag *cancel = gp_progress_cancel(progress);
    /* the grid is as fine as the packer's: about one cell per disk or fewer */
    int rc = gp_grid_init(&b->grid, b->domain, largest_radius(b->disks, b->n), b->n, 8 * b->n + 1024);
    if (rc)
        return gp_error_set(err, rc, NULL, rc == GP_ETOOBIG ? "the bucket grid would be too large"
                                                           : "out of memory for the bucket grid");
    for (size_t i = 0; i < b->n; i++)
        gp_grid_insert(&b->grid, (int32_t)i, b->disks[i].x, b->disks[i].y);
    /* `best` is the structure returned; the lowest F_max and the lowest mean seen, even
     * in two different structures, tell whether the sweeps still make progress */
    gp_quality_stats best = out->before, now;
    double lowest_max = best.max, lowest_mean = best.mean;
    save_best(b);
    out->stop = GP_BALANCE_STOP_CAP;
    for (uint32_t stall = 0; out->sweeps < cap;) {
        double share = 1.0 / cap;
        if ((rc = sweep(b, progress, share * out->sweeps, share, out, err)))
            return rc;
        out->sweeps++;
        if (b->nmoved == 0) {
            out->stop = GP_BALANCE_STOP_CONVERGED;
            break;
        }
        if ((rc = gp_rt_update_moved(rt, b->disks, b->n, b->moved, b->nmoved, params->update,
                                     &out->triangulation, progress, err)) ||
            (rc = gp_quality(b->domain, rt, b->disks, b->n, NULL, &now, cancel, err)) ||
            (rc = report(progress, share * out->sweeps, err)))
            return rc;
        if (improves(&now, &best)) {
            best = now;
            out->best_sweep = out->sweeps;
            save_best(b);
        }
        if (now.max < lowest_max - GP_BALANCE_QUALITY_TOL || now.mean < lowest_mean - GP_BALANCE_QUALITY_TOL)
            stall = 0;
        else if (++stall >= GP_BALANCE_STALL_SWEEPS) {
            out->stop = GP_BALANCE_STOP_STALLED;
            break;
        }
        lowest_max = now.max < lowest_max ? now.max : lowest_max;
        lowest_mean = now.mean < lowest_mean ? now.mean : lowest_mean;
    }
    restore_best(b);
    return gp_rt_update_moved(rt, b->disks, b->n, b->moved, b->nmoved, params->update,
                              &out->triangulation, progress, err);
}

int gp_balance(const gp_domain *domain, gp_disk *disks, size_t n, gp_rt *rt,
               const gp_balance_params *params, const gp_progress *progress,
               gp_balance_result *out, gp_error *err)
{
    memset(out, 0, sizeof *out);
    balancer b;
    memset(&b, 0, sizeof b);
    b.domain = domain;
    b.disks = disks;
    b.n = n;
    b.rt = rt;
    b.method = params->method;
    b.max_step = params->max_step > 0.0 ? params->max_step : GP_BALANCE_DEFAULT_MAX_STEP;
    out->method = params->method;
    out->max_step = b.max_step;
    out->count = n;
    out->F = malloc((n ? n : 1) * sizeof *out->F);
    b.ring.cap = 64;
    b.ring.ids = malloc(b.ring.cap * sizeof *b.ring.ids);
    b.moved = malloc((n ? n : 1) * sizeof *b.moved);
    b.best = malloc((n ? 2 * n : 1) * sizeof *b.best);
    int rc = 0;
    if (!out->F || !b.ring.ids || !b.moved || !b.best) {
        rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory balancing %zu disks", n);
        goto done;
    }
    if ((rc = gp_quality(domain, rt, disks, n, NULL, &out->before, gp_progress_cancel(progress), err)))
        goto done;
    out->stop = GP_BALANCE_STOP_CONVERGED;
    if (params->method != GP_BALANCE_NONE && n > 0 &&
        (rc = run_sweeps(&b, rt, params, progress, out, err)))
        goto done;
    rc = gp_quality(domain, rt, disks, n, out->F, &out->after, gp_progress_cancel(progress), err);
    if (rc == 0 && progress && progress->report)
        progress->report(progress->ctx, "balance", 1.0);
done:
    gp_grid_free(&b.grid);
    free(b.ring.ids);
    free(b.moved);
    free(b.best);
    if (rc)
        gp_balance_result_free(out);
    return rc;
}

void gp_balance_result_free(gp_balance_result *result)
{
    free(result->F);
    memset(result, 0, sizeof *result);
}

const char *gp_balance_stop_name(gp_balance_stop stop)
{
    switch (stop) {
    case GP_BALANCE_STOP_CONVERGED: return "converged";
    case GP_BALANCE_STOP_STALLED: return "stalled";
    case GP_BALANCE_STOP_CAP: return "max_iterations";
    }
    return "?";
}
