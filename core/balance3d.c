/* balance3d.c - F and the balancing of a sphere packing (geometry3d.h, docs/3d.md §8): the
 * 2D methods of balance.c in 3D, each interior centre moved a step toward its target (the
 * barycentre of its neighbours, or of the positions tangent to the three spheres of each
 * face of its star), refused when the step would overlap a sphere or leave the box; the
 * triangulation is built again after each sweep, and the rules of balance_watch.h say
 * when to stop and which structure to return. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "balance_watch.h"
#include "grainpack/geometry3d.h"
#include "grow.h"
#include "pack3d_internal.h"
#include "power_cell3d.h"
#include "quality.h"
#include "triangulation3d.h"

/* Steps tried toward the target, as fractions of the way: from the largest allowed down by
 * this to it, as in 2D (balance.c). */
#define STEP_DECREMENT 0.05

/* Centres between two progress reports and cancel checks: a few milliseconds of work. */
#define CENTRES_PER_CHECK 2048

/* Everything one run works with. */
typedef struct balancer3 {
    const gp_box *box;
    gp_sphere *s;
    size_t n;
    gp_rt3 *rt;
    gp_balance_method method;
    double max_step;
    size_t *start;        /* the rings (gp_rt3_rings) */
    int32_t *ids;
    uint8_t *hull;
    int32_t *tets;        /* the finite tetrahedra, and each vertex's: tet_of[tstart[i]..] */
    size_t ntets, *tstart;
    int32_t *tet_of;
    power_cell3d pc;
    p3_grid grid;
    double R_max;
    double *F;
    double *best;         /* x y z of every centre in the best structure seen */
} balancer3;

/* Reads the rings of b->rt (and, for relocation, the tetrahedra around each vertex). */
static int read_triangulation(balancer3 *b, const gp_cancel_flag *cancel, gp_error *err)
{
    free(b->ids);
    b->ids = NULL;
    gp_progress quiet = {NULL, NULL, cancel};
    int rc = gp_rt3_rings(b->rt, b->start, b->hull, &b->ids, &quiet);
    if (rc)
        return gp_error_set(err, rc, NULL, rc == GP_ECANCELED ? "balancing canceled" : "out of memory for the rings");
    if (b->method != GP_BALANCE_RELOCATION)
        return 0;
    free(b->tets);
    free(b->tet_of);
    b->tet_of = NULL;
    if (gp_rt3_tetrahedra(b->rt, &b->tets, &b->ntets))
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the tetrahedra");
    memset(b->tstart, 0, (b->n + 1) * sizeof *b->tstart);
    for (size_t t = 0; t < 4 * b->ntets; t++)
        b->tstart[b->tets[t] + 1]++;
    for (size_t i = 0; i < b->n; i++)
        b->tstart[i + 1] += b->tstart[i];
    b->tet_of = malloc((b->ntets ? 4 * b->ntets : 1) * sizeof *b->tet_of);
    size_t *fill = malloc((b->n ? b->n : 1) * sizeof *fill);
    if (!b->tet_of || !fill) {
        free(fill);
        return gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the tetrahedra");
    }
    memcpy(fill, b->tstart, b->n * sizeof *fill);
    for (size_t t = 0; t < 4 * b->ntets; t++)
        b->tet_of[fill[b->tets[t]]++] = (int32_t)(t / 4);
    free(fill);
    return 0;
}

/* F of centre i (NAN when not interior: on the hull, fewer than four neighbours, or its
 * power cell reaching a wall of the box). */
static int quality_of(balancer3 *b, int32_t i, double *F)
{
    const int32_t *ring = b->ids + b->start[i];
    size_t degree = b->start[i + 1] - b->start[i];
    *F = NAN;
    if (b->hull[i] || degree < 4)
        return 0;
    int holds;
    int rc = power_cell3d_build(&b->pc, i, ring, degree, &holds);
    if (rc || !holds)
        return rc;
    for (size_t f = 0; f < b->pc.a.nf; f++)
        if (GP_IS_WALL3D(b->pc.a.label[f]))
            return 0;
    const gp_sphere *p = &b->s[i];
    double lo = INFINITY, hi = -INFINITY;
    for (size_t k = 0; k < degree; k++) {
        const gp_sphere *q = &b->s[ring[k]];
        double dx = q->x - p->x, dy = q->y - p->y, dz = q->z - p->z;
        double h = sqrt(dx * dx + dy * dy + dz * dz) - p->R - q->R;
        lo = h < lo ? h : lo;
        hi = h > hi ? h : hi;
    }
    *F = (hi - lo) / p->R;
    return 0;
}

/* F of every centre into b->F and its statistics. */
static int measure(balancer3 *b, int histogram, gp_quality_stats *stats, const gp_cancel_flag *cancel,
                   gp_error *err)
{
    for (size_t i = 0; i < b->n; i++) {
        if (i % CENTRES_PER_CHECK == CENTRES_PER_CHECK - 1 && gp_canceled(cancel))
            return gp_error_set(err, GP_ECANCELED, NULL, "measuring F canceled");
        if (quality_of(b, (int32_t)i, &b->F[i]))
            return gp_error_set(err, GP_ENOMEM, NULL, "out of memory measuring F");
    }
    quality_summarise(b->F, b->n, histogram, stats);
    return 0;
}

/* Whether sphere id (out of the grid) may sit at u: inside the box and clear of every
 * other sphere, with the packer's contact tolerance. */
static int position_is_free(const balancer3 *b, int32_t id, const double u[3])
{
    double R = b->s[id].R, slack = R * (1.0 - GP_CONTACT_RTOL);
    return u[0] >= slack && u[0] <= b->box->width - slack && u[1] >= slack &&
           u[1] <= b->box->height - slack && u[2] >= slack && u[2] <= b->box->depth - slack &&
           p3_grid_first_overlap(&b->grid, b->s, u[0], u[1], u[2], R, b->R_max) == P3_NONE;
}

/* Takes sphere id out of the grid (its list is that of the cell of its centre). */
static void grid_remove(balancer3 *b, int32_t id)
{
    int32_t lo[3], hi[3];
    p3_grid_range(&b->grid, b->s[id].x, b->s[id].y, b->s[id].z, 0.0, lo, hi);
    int32_t *link = &b->grid.head[((size_t)lo[2] * (size_t)b->grid.n[1] + (size_t)lo[1]) * (size_t)b->grid.n[0] +
                                  (size_t)lo[0]];
    while (*link != id)
        link = &b->grid.next[*link];
    *link = b->grid.next[id];
}

/* The relocation target (docs/3d.md §8): the barycentre of the conflict-free positions
 * tangent to the three spheres of each face of the star of i (the face of each tetrahedron
 * around i opposite i), each on i's side of the face, where the gaps to those three are
 * zero. The 2D rule with an edge of the ball's boundary replaced by a triangle. */
static int relocation_target(const balancer3 *b, int32_t i, double t[3])
{
    const gp_sphere *p = &b->s[i];
    double sum[3] = {0.0, 0.0, 0.0};
    size_t used = 0;
    for (size_t k = b->tstart[i]; k < b->tstart[i + 1]; k++) {
        const int32_t *tet = b->tets + 4 * b->tet_of[k];
        int32_t m[3];
        int c = 0;
        for (int v = 0; v < 4; v++)
            if (tet[v] != i)
                m[c++] = tet[v];
        double out[2][3];
        int found = p3_tangent(b->s, b->box, m, p->R, out);
        /* the solution on i's side of the plane of the three centres */
        const gp_sphere *a = &b->s[m[0]], *q1 = &b->s[m[1]], *q2 = &b->s[m[2]];
        double e1[3] = {q1->x - a->x, q1->y - a->y, q1->z - a->z};
        double e2[3] = {q2->x - a->x, q2->y - a->y, q2->z - a->z};
        double nrm[3] = {e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
        double side = nrm[0] * (p->x - a->x) + nrm[1] * (p->y - a->y) + nrm[2] * (p->z - a->z);
        for (int s = 0; s < found; s++) {
            const double *u = out[s];
            double su = nrm[0] * (u[0] - a->x) + nrm[1] * (u[1] - a->y) + nrm[2] * (u[2] - a->z);
            if ((su > 0.0) != (side > 0.0) || !position_is_free(b, i, u))
                continue;
            for (int x = 0; x < 3; x++)
                sum[x] += u[x];
            used++;
            break;
        }
    }
    if (!used)
        return 0;
    for (int x = 0; x < 3; x++)
        t[x] = sum[x] / (double)used;
    return 1;
}

/* Moves centre i the largest conflict-free step toward its target: 1 moved, 0 not
 * (settled, no target, or blocked: counted in *refused). */
static int step_centre(balancer3 *b, int32_t i, uint64_t *refused)
{
    gp_sphere *p = &b->s[i];
    grid_remove(b, i);
    double t[3];
    int has_target = 1;
    if (b->method == GP_BALANCE_LAPLACIAN) {
        size_t degree = b->start[i + 1] - b->start[i];
        t[0] = t[1] = t[2] = 0.0;
        for (size_t k = b->start[i]; k < b->start[i + 1]; k++) {
            t[0] += b->s[b->ids[k]].x;
            t[1] += b->s[b->ids[k]].y;
            t[2] += b->s[b->ids[k]].z;
        }
        for (int x = 0; x < 3; x++)
            t[x] /= (double)degree;
    } else {
        has_target = relocation_target(b, i, t);
    }
    int moved = 0, blocked = has_target;
    if (has_target) {
        double d[3] = {t[0] - p->x, t[1] - p->y, t[2] - p->z};
        double way = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (double w = b->max_step; w > 0.5 * STEP_DECREMENT; w -= STEP_DECREMENT) {
            if (w * way < GP_BALANCE_MIN_STEP_RTOL * p->R) {
                blocked = 0; /* settled: what is left of the way is too short to matter */
                break;
            }
            double u[3] = {p->x + w * d[0], p->y + w * d[1], p->z + w * d[2]};
            if (!position_is_free(b, i, u))
                continue;
            p->x = u[0];
            p->y = u[1];
            p->z = u[2];
            moved = 1;
            blocked = 0;
            break;
        }
    }
    *refused += blocked;
    p3_grid_insert(&b->grid, i, p->x, p->y, p->z);
    return moved;
}

/* One sweep over the interior centres (F not NAN), in id order; returns the moves or a
 * negative GP_ code. */
static long sweep(balancer3 *b, const gp_progress *progress, double done, double share,
                  gp_balance_result *out, gp_error *err)
{
    long moved = 0;
    for (size_t i = 0; i < b->n; i++) {
        if (i % CENTRES_PER_CHECK == CENTRES_PER_CHECK - 1) {
            int rc = balance_report(progress, done + share * (double)i / (double)b->n, err);
            if (rc)
                return rc;
        }
        if (!isnan(b->F[i]))
            moved += step_centre(b, (int32_t)i, &out->refused);
    }
    out->moves += (uint64_t)moved;
    return moved;
}

/* Builds the triangulation again from the moved centres and measures F. */
static int follow(balancer3 *b, int histogram, const gp_progress *progress, gp_quality_stats *stats,
                  gp_balance_result *out, gp_error *err)
{
    const gp_cancel_flag *cancel = gp_progress_cancel(progress);
    gp_progress quiet = {NULL, NULL, cancel};
    int rc = gp_rt3_rebuild(b->rt, b->s, b->n, &quiet, err);
    if (rc)
        return rc;
    out->triangulation.rebuilds++;
    if ((rc = read_triangulation(b, cancel, err)))
        return rc;
    return measure(b, histogram, stats, cancel, err);
}

static void save_best(balancer3 *b)
{
    for (size_t i = 0; i < b->n; i++) {
        b->best[3 * i] = b->s[i].x;
        b->best[3 * i + 1] = b->s[i].y;
        b->best[3 * i + 2] = b->s[i].z;
    }
}

/* Puts the centres back where they were in the best structure: whether any moved. */
static int restore_best(balancer3 *b)
{
    int moved = 0;
    for (size_t i = 0; i < b->n; i++) {
        gp_sphere *p = &b->s[i];
        moved |= p->x != b->best[3 * i] || p->y != b->best[3 * i + 1] || p->z != b->best[3 * i + 2];
        p->x = b->best[3 * i];
        p->y = b->best[3 * i + 1];
        p->z = b->best[3 * i + 2];
    }
    return moved;
}

static int run_sweeps(balancer3 *b, const gp_balance_params *params, const gp_progress *progress,
                      gp_balance_result *out, gp_error *err)
{
    uint32_t cap = params->max_iterations ? params->max_iterations : GP_BALANCE_DEFAULT_MAX_ITERATIONS;
    const gp_cancel_flag *cancel = gp_progress_cancel(progress);
    int rc = read_triangulation(b, cancel, err);
    if (rc || (rc = measure(b, 1, &out->before, cancel, err)))
        return rc;
    for (size_t i = 0; i < b->n; i++)
        b->R_max = b->s[i].R > b->R_max ? b->s[i].R : b->R_max;
    if ((rc = p3_grid_init(&b->grid, b->box, 2.0 * b->R_max, b->n)))
        return gp_error_set(err, rc, NULL, rc == GP_ETOOBIG ? "the bucket grid would be too large"
                                                           : "out of memory for the bucket grid");
    for (size_t i = 0; i < b->n; i++)
        p3_grid_insert(&b->grid, (int32_t)i, b->s[i].x, b->s[i].y, b->s[i].z);
    balance_watch watch;
    balance_watch_start(&watch, &out->before);
    gp_quality_stats now;
    save_best(b);
    out->stop = GP_BALANCE_STOP_CAP;
    while (out->sweeps < cap) {
        double share = 1.0 / cap;
        long moved = sweep(b, progress, share * out->sweeps, share, out, err);
        if (moved < 0)
            return (int)moved;
        out->sweeps++;
        if (moved == 0) {
            out->stop = GP_BALANCE_STOP_CONVERGED;
            break;
        }
        if ((rc = follow(b, 0, progress, &now, out, err)) ||
            (rc = balance_report(progress, share * out->sweeps, err)))
            return rc;
        int better, stop = balance_watch_record(&watch, b->method, out, &now, &better);
        if (better)
            save_best(b);
        if (stop)
            break;
    }
    /* the best is the last structure measured (the triangulation's), or is built again */
    if (restore_best(b))
        return follow(b, 1, progress, &out->after, out, err);
    return measure(b, 1, &out->after, cancel, err);
}

/* Sets up a balancer over the spheres (its arrays, the rings' room); 0 or GP_ENOMEM. */
static int balancer_init(balancer3 *b, const gp_box *box, gp_sphere *s, size_t n, gp_rt3 *rt, double *F)
{
    memset(b, 0, sizeof *b);
    b->box = box;
    b->s = s;
    b->n = n;
    b->rt = rt;
    b->F = F;
    b->pc.box = box;
    b->pc.spheres = s;
    b->start = malloc((n + 1) * sizeof *b->start);
    b->tstart = malloc((n + 1) * sizeof *b->tstart);
    b->hull = malloc(n ? n : 1);
    return b->start && b->tstart && b->hull ? 0 : GP_ENOMEM;
}

static void balancer_free(balancer3 *b)
{
    free(b->start);
    free(b->ids);
    free(b->hull);
    free(b->tets);
    free(b->tstart);
    free(b->tet_of);
    free(b->best);
    power_cell3d_free(&b->pc);
    p3_grid_free(&b->grid);
}

int gp_quality3d(const gp_box *box, const gp_rt3 *rt, const gp_sphere *spheres, size_t n, double *F,
                 gp_quality_stats *stats, const gp_cancel_flag *cancel, gp_error *err)
{
    double *own = F ? NULL : malloc((n ? n : 1) * sizeof *own);
    balancer3 b;
    /* read only: the balancer's sphere array is not written by the measure */
    int rc = balancer_init(&b, box, (gp_sphere *)spheres, n, (gp_rt3 *)rt, F ? F : own);
    gp_quality_stats local;
    if (rc || (!F && !own))
        rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory measuring F of %zu spheres", n);
    else if ((rc = read_triangulation(&b, cancel, err)) == 0)
        rc = measure(&b, 1, stats ? stats : &local, cancel, err);
    balancer_free(&b);
    free(own);
    return rc;
}

int gp_balance3d(const gp_box *box, gp_sphere *spheres, size_t n, gp_rt3 *rt,
                 const gp_balance_params *params, const gp_progress *progress,
                 gp_balance_result *out, gp_error *err)
{
    memset(out, 0, sizeof *out);
    out->method = params->method;
    out->max_step = params->max_step > 0.0 ? params->max_step : GP_BALANCE_DEFAULT_MAX_STEP;
    out->count = n;
    out->stop = GP_BALANCE_STOP_CONVERGED;
    out->F = malloc((n ? n : 1) * sizeof *out->F);
    balancer3 b;
    int rc = balancer_init(&b, box, spheres, n, rt, out->F);
    b.method = params->method;
    b.max_step = out->max_step;
    if (rc || !out->F || !(b.best = malloc((n ? 3 * n : 1) * sizeof *b.best))) {
        rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory balancing %zu spheres", n);
    } else if (params->method == GP_BALANCE_NONE || n == 0) {
        const gp_cancel_flag *cancel = gp_progress_cancel(progress);
        if ((rc = read_triangulation(&b, cancel, err)) == 0 &&
            (rc = measure(&b, 1, &out->before, cancel, err)) == 0)
            out->after = out->before;
    } else {
        rc = run_sweeps(&b, params, progress, out, err);
    }
    if (rc == 0 && progress && progress->report)
        progress->report(progress->ctx, "balance", 1.0);
    balancer_free(&b);
    if (rc)
        gp_balance_result_free(out);
    return rc;
}
