/* balance.c - the two balancing methods of docs/method.md §4: sweeps that move each interior
 * centre a step toward a target (the barycentre of its neighbours, or of the positions
 * tangent to its ball's boundary edges), refused when the step would overlap a disk or
 * leave the domain, until the structure stops improving (§4.5). Between sweeps only what
 * the moves changed is redone: the rings the triangulation's update changed, F where a
 * centre or a neighbour moved, the steps of centres whose last step read something that
 * moved (settled.h); the results are those of redoing everything, to the bit. */
#include "grow.h"
#include "grainpack/balance.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "balance_watch.h"
#include "nearby.h"
#include "periodic.h"
#include "quality.h"
#include "rings.h"
#include "settled.h"

/* Steps tried toward the target, as fractions w of the way: from the largest allowed
 * (gp_balance_params.max_step) down by 0.05 to 0.05, as report Algorithm 3 does from
 * 0.30; the first conflict-free one is taken. */
#define STEP_DECREMENT 0.05

/* Centres between two progress reports and cancel checks: a few milliseconds of work. */
#define CENTRES_PER_REPORT GP_QUALITY_CENTRES_PER_CHECK

/* The box of the positions a centre tries is widened by this fraction of its radius, so
 * that the positions on the way to its target, which rounding can put a few ulps outside
 * the box of the tangent positions they are averaged from, still fall inside; a position
 * outside is tested against the grid cells around it instead (the same answer, slower). */
#define BOX_MARGIN_RTOL 1e-6

/* On a periodic domain with GP_RT_UPDATE_FLIPS the ghosts follow their disks and the
 * layer is made again, centres wrapped, before a sweep once some disk has moved this
 * share of the margin away from where the layer was made: the images present are then
 * still those within 3/4 of the margin, 4.5 largest radii at the first margin, well past
 * the power circles of a dense packing's cells and the reach of a centre's moves. */
#define LAYER_DRIFT_SHARE 0.25

/* measure's answer when a cell on a periodic domain may miss a neighbour beyond the
 * ghosts: the layer must be made again with a wider margin. */
#define LAYER_TOO_THIN 1

const char *gp_balance_method_name(gp_balance_method method)
{
    switch (method) {
    case GP_BALANCE_NONE: return "none";
    case GP_BALANCE_LAPLACIAN: return "laplacian";
    case GP_BALANCE_RELOCATION: return "relocation";
    }
    return "?";
}

/* Everything one balancing run works with. */
typedef struct balancer {
    const gp_domain *domain;
    gp_disk *disks;     /* the caller's disks, or on a periodic domain layer.all */
    size_t n;           /* the disks balanced: the caller's */
    size_t m;           /* the triangulation's vertices: n, or n and the ghosts */
    gp_rt *rt;          /* the caller's triangulation, or the layer's */
    quality_frame frame;
    gp_balance_method method;
    double max_step;
    rings rings;        /* the rings of the structure the sweep starts from */
    nearby near;        /* the disks near the positions a centre tries */
    int box_inside;     /* whether every position in near's box keeps the disk gathered for
                           in the domain (walled domains; see gather) */
    settled settled;    /* the centres whose last step still holds (walled domains) */
    int remember;       /* whether `settled` is kept: walled domains only */
    double *F;          /* F of the structure the sweep starts from (NAN: not interior);
                           the result's array, which holds F of the best one at the end */
    uint8_t *changed;   /* rings the last update changed (gp_rt_mark_changes) */
    uint8_t *stale;     /* F to measure again after the sweep */
    uint8_t *moved_in;  /* the sweep each centre last moved in, modulo 256 (0: never) */
    uint8_t sweep;      /* the sweep under way, from 1, modulo 256 */
    double *tangent;    /* x, y of one centre's tangent positions (x NAN: none) */
    size_t tangent_cap; /* positions allocated in tangent */
    int32_t *moved;     /* ids moved in the current sweep, or restored at the end */
    size_t nmoved;
    double *best;       /* x, y of every centre in the best structure seen */
    /* periodic domains (docs/method.md §4.7): the sweeps work on the disks and their
     * ghosts, each ghost moved with its disk */
    gp_disk *user;      /* the caller's disks, written back wrapped at each new layer */
    periodic_layer layer;
    gp_domain grid_domain; /* nearby's grid: the walled rectangle, ghosts in its edge cells */
    double *anchor;     /* x, y of each disk when the layer was made */
    double drift;       /* the farthest a disk has moved since */
    double margin;      /* the margin of the next layer */
    double R_max;
} balancer;

/* Gathers the disks that may overlap the packing disk of `id` placed anywhere in the box
 * (widened by BOX_MARGIN_RTOL); 0 or GP_ENOMEM. */
static int gather(balancer *b, int32_t id, double x0, double y0, double x1, double y1)
{
    double R = b->disks[id].R;
    int rc = nearby_gather(&b->near, b->disks, id, R, x0, y0, x1, y1, BOX_MARGIN_RTOL * R);
    /* the walls' test of gp_domain_contains_disk is monotone along each axis (x - R >=
     * -slack grows with x, x + R <= W + slack holds for every x below one where it holds):
     * when the box's two corners pass it, so does every position between them, and
     * position_is_free need not ask again (a sixth of its time) */
    const nearby *nb = &b->near;
    b->box_inside = !b->domain->periodic &&
                    gp_domain_contains_disk(b->domain, nb->x0, nb->y0, R, R * GP_CONTACT_RTOL) &&
                    gp_domain_contains_disk(b->domain, nb->x1, nb->y1, R, R * GP_CONTACT_RTOL);
    return rc;
}

/* Whether every disk that could overlap a disk of radius R at (x, y) has its images in
 * the layer (periodic domains): the disks within R + R_max, along the periodic axes,
 * inside the box of the ghosts less the drift (quality_frame). */
static int within_layer(const balancer *b, double x, double y, double R)
{
    double reach = R + b->R_max, box = b->frame.box;
    return (!(b->domain->periodic & GP_PERIODIC_X) ||
            (x - reach > -box && x + reach < b->domain->width + box)) &&
           (!(b->domain->periodic & GP_PERIODIC_Y) ||
            (y - reach > -box && y + reach < b->domain->height + box));
}

/* Whether the packing disk of `id` may sit at (x, y): inside the domain and clear of
 * every other disk (on a periodic domain, every image), with the packer's contact
 * tolerance. */
static int position_is_free(balancer *b, int32_t id, double x, double y)
{
    double R = b->disks[id].R;
    if (b->box_inside && nearby_in_box(&b->near, x, y, R))
        return nearby_is_clear_in_box(&b->near, x, y);
    return gp_domain_contains_disk(b->domain, x, y, R, R * GP_CONTACT_RTOL) &&
           (!b->domain->periodic || within_layer(b, x, y, R)) &&
           nearby_is_clear(&b->near, b->disks, id, R, x, y);
}

/* The target of an interior centre: for relocation, the barycentre of the conflict-free
 * positions tangent to the boundary edges of its ball (docs/method.md §4.4); for Laplacian
 * smoothing, the barycentre of its neighbours. Gathers the disks near every position the
 * centre will try. Returns 1, 0 when there is no target, or GP_ENOMEM. */
static int target_of(balancer *b, int32_t id, const int32_t *ring, size_t degree, double *tx,
                     double *ty)
{
    const gp_disk *p = &b->disks[id];
    double x0 = p->x, y0 = p->y, x1 = p->x, y1 = p->y, sx = 0.0, sy = 0.0;
    size_t used = 0;
    if (b->method == GP_BALANCE_LAPLACIAN) {
        for (size_t k = 0; k < degree; k++) {
            sx += b->disks[ring[k]].x;
            sy += b->disks[ring[k]].y;
        }
        *tx = sx / (double)degree;
        *ty = sy / (double)degree;
        return gather(b, id, *tx < x0 ? *tx : x0, *ty < y0 ? *ty : y0, *tx > x1 ? *tx : x1,
                      *ty > y1 ? *ty : y1) ? GP_ENOMEM : 1;
    }
    /* a position is two doubles */
    double *grown = grow(b->tangent, &b->tangent_cap, degree, 2 * sizeof *grown);
    if (!grown)
        return GP_ENOMEM;
    b->tangent = grown;
    double *t = b->tangent;
    for (size_t k = 0; k < degree; k++) {
        /* the link edge (q1, q2) has p on its left: the tangent position on p's side */
        const gp_disk *q1 = &b->disks[ring[k]], *q2 = &b->disks[ring[k + 1 < degree ? k + 1 : 0]];
        if (!gp_place_tangent(q1, q2, p->R, &t[2 * k], &t[2 * k + 1])) {
            t[2 * k] = NAN;
            continue;
        }
        /* not fmin/fmax: those are calls to libm, they must honour NAN */
        x0 = t[2 * k] < x0 ? t[2 * k] : x0;
        x1 = t[2 * k] > x1 ? t[2 * k] : x1;
        y0 = t[2 * k + 1] < y0 ? t[2 * k + 1] : y0;
        y1 = t[2 * k + 1] > y1 ? t[2 * k + 1] : y1;
    }
    if (gather(b, id, x0, y0, x1, y1))
        return GP_ENOMEM;
    for (size_t k = 0; k < degree; k++) {
        if (isnan(t[2 * k]) || !position_is_free(b, id, t[2 * k], t[2 * k + 1]))
            continue;
        sx += t[2 * k];
        sy += t[2 * k + 1];
        used++;
    }
    if (!used)
        return 0;
    *tx = sx / (double)used;
    *ty = sy / (double)used;
    return 1;
}

/* Moves centre `id` the largest conflict-free step toward its target; returns 1 if it
 * moved, 0 if it is settled or blocked (counted in *refused), or GP_ENOMEM. */
static int step_centre(balancer *b, int32_t id, const int32_t *ring, size_t degree,
                       uint64_t *refused)
{
    gp_disk *p = &b->disks[id];
    double tx, ty;
    int rc = target_of(b, id, ring, degree, &tx, &ty);
    if (rc <= 0)
        return rc;
    double dx = tx - p->x, dy = ty - p->y, way = hypot(dx, dy);
    for (double w = b->max_step; w > 0.5 * STEP_DECREMENT; w -= STEP_DECREMENT) {
        if (w * way < GP_BALANCE_MIN_STEP_RTOL * p->R)
            return 0; /* settled: what is left of the way is too short to matter */
        double x = p->x + w * dx, y = p->y + w * dy;
        if (!position_is_free(b, id, x, y))
            continue;
        double old_x = p->x, old_y = p->y;
        p->x = x;
        p->y = y;
        nearby_move(&b->near, b->disks, id, old_x, old_y);
        return b->remember && settled_moved(&b->settled, id, old_x, old_y, x, y) ? GP_ENOMEM : 1;
    }
    (*refused)++;
    return 0;
}

/* Whether the power cell of interior-looking centre i (not on the hull, three
 * neighbours or more) lies in the domain now: what its F says, unless a neighbour
 * moved earlier in this sweep. (A neighbour that moved 256 sweeps ago looks as if it
 * moved in this one: the cell is then tested again, with the same answer.) */
static int inside_now(const balancer *b, int32_t i, const int32_t *ring, size_t degree)
{
    for (size_t k = 0; k < degree; k++)
        if (b->moved_in[ring[k]] == b->sweep)
            return quality_cell_inside(&b->frame, b->disks, i, ring, degree) == 1;
    return !isnan(b->F[i]);
}

/* Puts the ghosts of disk i, which moved, at its new images, and counts how far it is
 * from where the layer was made. */
static void move_ghosts(balancer *b, int32_t i)
{
    const periodic_layer *L = &b->layer;
    for (size_t k = L->ghost_start[i]; k < L->ghost_start[i + 1]; k++) {
        int32_t g = L->ghost_ids[k];
        double old_x = b->disks[g].x, old_y = b->disks[g].y;
        periodic_ghost_place(L, b->domain, g);
        nearby_move(&b->near, b->disks, g, old_x, old_y);
        b->moved[b->nmoved++] = g;
        b->moved_in[g] = b->sweep;
    }
    double d = hypot(b->disks[i].x - b->anchor[2 * i], b->disks[i].y - b->anchor[2 * i + 1]);
    if (d > b->drift) {
        b->drift = d;
        b->frame.box = b->layer.margin - d;
    }
}

/* Steps centre `id` (interior, with the given ring) unless its last step still holds
 * (settled.h): 1 if it moved, 0 if not, or GP_ENOMEM. */
static int visit(balancer *b, int32_t id, const int32_t *ring, size_t degree, uint64_t *refused)
{
    if (!b->remember)
        return step_centre(b, id, ring, degree, refused);
    int held = settled_holds(&b->settled, b->disks, id, b->disks[id].R);
    if (held != SETTLED_UNKNOWN) {
        *refused += held == SETTLED_REFUSED;
        return 0;
    }
    uint64_t refused_before = *refused;
    int rc = step_centre(b, id, ring, degree, refused);
    if (rc == 0)
        settled_record(&b->settled, id, *refused != refused_before ? SETTLED_REFUSED : SETTLED_STILL,
                       b->near.x0, b->near.y0, b->near.x1, b->near.y1);
    if (rc == 1) {
        /* its own step and its ring's read its position */
        settled_forget(&b->settled, id);
        for (size_t k = 0; k < degree; k++)
            settled_forget(&b->settled, ring[k]);
    }
    return rc;
}

/* How far ahead of the centre being stepped its successors' data is asked for, in
 * three stages (see nearby_prefetch_cells): the disk and its ring's ids, then the ring's
 * disks and the cells around the disk, then the disks sorted in those cells. Why these
 * distances: a centre takes about a microsecond, a read from memory a tenth of that, and
 * each stage waits on the one before. */
#define AHEAD_DISK 12
#define AHEAD_CELLS 6
#define AHEAD_ENTRIES 3

/* Asks the memory for what visiting centre i will read (a hint: nothing changes). */
static void prefetch_visit(const balancer *b, size_t i)
{
    if (i + AHEAD_DISK < b->n) {
        __builtin_prefetch(&b->disks[i + AHEAD_DISK]);
        __builtin_prefetch(&b->rings.ids[b->rings.start[i + AHEAD_DISK]]);
    }
    if (i + AHEAD_CELLS < b->n) {
        size_t j = i + AHEAD_CELLS, degree;
        const int32_t *ring = rings_of(&b->rings, (int32_t)j, &degree);
        for (size_t k = 0; k < degree; k++)
            __builtin_prefetch(&b->disks[ring[k]]);
        size_t cell = nearby_prefetch_cells(&b->near, b->disks[j].x, b->disks[j].y);
        if (b->remember)
            settled_prefetch(&b->settled, cell);
    }
    if (i + AHEAD_ENTRIES < b->n)
        nearby_prefetch_entries(&b->near, b->disks[i + AHEAD_ENTRIES].x, b->disks[i + AHEAD_ENTRIES].y);
}

/* One sweep over the interior centres, in id order, each seeing the moves before it;
 * the ids moved go to b->moved. */
static int sweep(balancer *b, const gp_progress *progress, double done, double share,
                 gp_balance_result *out, gp_error *err)
{
    b->nmoved = 0;
    if (b->remember)
        settled_sweep(&b->settled);
    for (size_t i = 0; i < b->n; i++) {
        if (i % CENTRES_PER_REPORT == CENTRES_PER_REPORT - 1) {
            int rc = balance_report(progress, done + share * (double)i / (double)b->n, err);
            if (rc)
                return rc;
        }
        prefetch_visit(b, i);
        size_t degree;
        const int32_t *ring = rings_of(&b->rings, (int32_t)i, &degree);
        if (b->rings.hull[i] || degree < 3 || !inside_now(b, (int32_t)i, ring, degree)) {
            if (b->remember)
                settled_forget(&b->settled, (int32_t)i);
            continue;
        }
        int rc = visit(b, (int32_t)i, ring, degree, &out->refused);
        if (rc < 0)
            return gp_error_set(err, rc, NULL, "out of memory balancing disk %zu", i);
        if (rc) {
            b->moved[b->nmoved++] = (int32_t)i;
            b->moved_in[i] = b->sweep;
            if (b->domain->periodic)
                move_ghosts(b, (int32_t)i);
        }
    }
    out->moves += b->nmoved;
    return 0;
}

/* Measures F again where it is stale or where the last update changed the ring, then
 * the whole structure into *stats (ghosts have no F: their marks are only cleared).
 * Reads *cancel (may be NULL) as gp_quality does, every GP_QUALITY_CENTRES_PER_CHECK
 * centres: before the sweeps every centre is measured. Returns 0, LAYER_TOO_THIN (a
 * periodic cell may miss a neighbour beyond the ghosts) or GP_ECANCELED with err. */
static int measure(balancer *b, int histogram, gp_quality_stats *stats, const gp_cancel_flag *cancel,
                   gp_error *err)
{
    int incomplete = 0;
    for (size_t i = 0; i < b->m; i++) {
        if (i % GP_QUALITY_CENTRES_PER_CHECK == GP_QUALITY_CENTRES_PER_CHECK - 1 && gp_canceled(cancel))
            return gp_error_set(err, GP_ECANCELED, NULL, "measuring F canceled");
        if (i + AHEAD_CELLS < b->n) {
            size_t degree;
            const int32_t *ring = rings_of(&b->rings, (int32_t)(i + AHEAD_CELLS), &degree);
            for (size_t k = 0; k < degree; k++)
                __builtin_prefetch(&b->disks[ring[k]]);
        }
        if (!b->stale[i] && !b->changed[i])
            continue;
        if (i < b->n) {
            if (b->changed[i] && b->remember)
                settled_forget(&b->settled, (int32_t)i); /* a step reads its ring */
            size_t degree;
            const int32_t *ring = rings_of(&b->rings, (int32_t)i, &degree);
            b->F[i] = quality_of_centre(&b->frame, b->disks, (int32_t)i, ring, degree, b->rings.hull[i],
                                        &incomplete);
        }
        b->stale[i] = b->changed[i] = 0;
    }
    if (incomplete)
        return LAYER_TOO_THIN;
    quality_summarise(b->F, b->n, histogram, stats);
    return 0;
}

/* The error of a rings_init or rings_refresh that returned rc. */
static int rings_failed(int rc, size_t n, gp_error *err)
{
    return rc == GP_ECANCELED ? gp_error_set(err, rc, NULL, "balancing canceled")
                              : gp_error_set(err, rc, NULL, "out of memory for the rings of %zu disks", n);
}

/* Brings the triangulation, the rings and F up to date after the centres in b->moved
 * moved, and measures the structure into *stats. F is measured again only where it may
 * have changed: at the centres that moved, at their neighbours (their gaps changed),
 * and at every centre whose ring the update changed. */
static int follow_moves(balancer *b, gp_rt_update update, gp_rt_update_stats *counts,
                        int histogram, const gp_progress *progress, gp_quality_stats *stats,
                        gp_error *err)
{
    const gp_cancel_flag *cancel = gp_progress_cancel(progress);
    for (size_t m = 0; m < b->nmoved; m++) {
        size_t degree;
        const int32_t *ring = rings_of(&b->rings, b->moved[m], &degree);
        b->stale[b->moved[m]] = 1;
        for (size_t k = 0; k < degree; k++)
            b->stale[ring[k]] = 1;
    }
    int rc = gp_rt_update_moved(b->rt, b->disks, b->m, b->moved, b->nmoved, update, counts, progress, err);
    if (rc)
        return rc;
    if ((rc = rings_refresh(&b->rings, b->rt, b->changed, cancel)))
        return rings_failed(rc, b->m, err);
    return measure(b, histogram, stats, cancel, err);
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

/* (Re)allocates the per-vertex marks for m vertices, cleared; 0 or GP_ENOMEM. */
static int marks_for(balancer *b, size_t m)
{
    free(b->changed);
    free(b->stale);
    free(b->moved_in);
    free(b->moved);
    size_t c = m ? m : 1;
    b->changed = calloc(c, 1);
    b->stale = calloc(c, 1);
    b->moved_in = calloc(c, sizeof *b->moved_in);
    b->moved = malloc(c * sizeof *b->moved);
    b->m = m;
    return b->changed && b->stale && b->moved_in && b->moved ? 0 : GP_ENOMEM;
}

/* Sets up what the sweeps work with from the triangulation b->rt of b->disks[0..m-1] and
 * measures F into *stats; reads the cancel flag of `progress` (may be NULL) while it
 * walks the rings and measures F. Returns as measure does. */
static int start_sweeps(balancer *b, int histogram, const gp_progress *progress,
                        gp_quality_stats *stats, gp_error *err)
{
    const gp_domain *grid_domain = b->domain->periodic ? &b->grid_domain : b->domain;
    int rc = nearby_init(&b->near, grid_domain, b->disks, b->m, b->R_max);
    if (rc)
        return gp_error_set(err, rc, NULL, rc == GP_ETOOBIG ? "the bucket grid would be too large"
                                                           : "out of memory for the bucket grid");
    /* walled domains only: on a periodic one the grid is made again with each layer and
     * a move carries ghosts, which the record's log does not follow */
    if (b->remember && !b->settled.state &&
        (rc = settled_init(&b->settled, &b->near.grid, b->near.R_max, b->n)))
        return gp_error_set(err, rc, NULL, "out of memory for the record of %zu centres", b->n);
    if ((rc = rings_init(&b->rings, b->rt, b->m, progress)))
        return rings_failed(rc, b->m, err);
    gp_rt_mark_changes(b->rt, b->changed);
    memset(b->stale, 1, b->m);
    return measure(b, histogram, stats, gp_progress_cancel(progress), err);
}

/* Periodic domains: writes the disks back to the caller's array wrapped into the domain,
 * makes the ghost layer and its triangulation again from them (b->margin, doubled
 * while some cell may miss a neighbour), and starts the sweeps on it, F measured into
 * *stats. Returns 0 or a GP_E code with err. */
static int new_layer(balancer *b, int histogram, const gp_progress *progress,
                     gp_quality_stats *stats, gp_error *err)
{
    for (;;) {
        for (size_t i = 0; i < b->n; i++) {
            b->user[i] = b->disks[i];
            gp_domain_wrap(b->domain, &b->user[i].x, &b->user[i].y);
        }
        periodic_layer_free(&b->layer);
        nearby_free(&b->near);
        rings_free(&b->rings);
        b->disks = b->user;
        b->rt = NULL;
        /* the cancel flag only: the job's progress stays in the stage "balance" */
        gp_progress quiet = {NULL, NULL, gp_progress_cancel(progress)};
        int rc = periodic_layer_build(&b->layer, b->domain, b->user, b->n, b->margin, &quiet, err);
        if (rc)
            return rc;
        b->disks = b->layer.all;
        b->rt = b->layer.rt;
        if (marks_for(b, b->layer.m))
            return gp_error_set(err, GP_ENOMEM, NULL, "out of memory balancing %zu disks", b->n);
        for (size_t i = 0; i < b->n; i++) {
            b->anchor[2 * i] = b->disks[i].x;
            b->anchor[2 * i + 1] = b->disks[i].y;
        }
        b->drift = 0.0;
        b->frame = (quality_frame){b->domain, b->margin, b->R_max};
        rc = start_sweeps(b, histogram, progress, stats, err);
        if (rc != LAYER_TOO_THIN)
            return rc;
        double last = periodic_last_margin(b->domain);
        if (b->margin >= last)
            return periodic_too_small(err);
        b->margin = 2.0 * b->margin < last ? 2.0 * b->margin : last;
    }
}

/* After a sweep: brings the triangulation, the rings and F up to date (follow_moves) or,
 * on a periodic domain with GP_RT_UPDATE_REBUILD, makes the layer again; a layer that
 * turns out too thin is made again wider. */
static int follow(balancer *b, gp_rt_update update, gp_rt_update_stats *counts, int histogram,
                  const gp_progress *progress, gp_quality_stats *stats, gp_error *err)
{
    if (b->domain->periodic && update == GP_RT_UPDATE_REBUILD) {
        counts->rebuilds++;
        return new_layer(b, histogram, progress, stats, err);
    }
    int rc = follow_moves(b, update, counts, histogram, progress, stats, err);
    if (rc != LAYER_TOO_THIN)
        return rc;
    b->margin *= 2.0;
    return new_layer(b, histogram, progress, stats, err);
}

/* Sweeps until one moves nothing, the structure is steady, the best structure has not
 * improved for GP_BALANCE_STALL_SWEEPS sweeps, or the cap (docs/method.md §4.5); then
 * returns to the best structure and measures it into out->after and out->F. */
static int run_sweeps(balancer *b, const gp_balance_params *params, const gp_progress *progress,
                      gp_balance_result *out, gp_error *err)
{
    uint32_t cap = params->max_iterations ? params->max_iterations : GP_BALANCE_DEFAULT_MAX_ITERATIONS;
    int rc = b->domain->periodic ? new_layer(b, 1, progress, &out->before, err)
                                 : start_sweeps(b, 1, progress, &out->before, err);
    if (rc)
        return rc;
    balance_watch watch;
    balance_watch_start(&watch, &out->before);
    gp_quality_stats now;
    save_best(b);
    out->stop = GP_BALANCE_STOP_CAP;
    while (out->sweeps < cap) {
        double share = 1.0 / cap;
        if (b->domain->periodic && b->drift > LAYER_DRIFT_SHARE * b->layer.margin) {
            /* the same structure, wrapped: F as it was, to rounding */
            out->triangulation.rebuilds++;
            if ((rc = new_layer(b, 0, progress, &now, err)))
                return rc;
        }
        b->sweep = (uint8_t)(out->sweeps + 1);
        if ((rc = sweep(b, progress, share * out->sweeps, share, out, err)))
            return rc;
        out->sweeps++;
        if (b->nmoved == 0) {
            out->stop = GP_BALANCE_STOP_CONVERGED;
            break;
        }
        if ((rc = follow(b, params->update, &out->triangulation, 0, progress, &now, err)) ||
            (rc = balance_report(progress, share * out->sweeps, err)))
            return rc;
        nearby_sort(&b->near, b->disks);
        int better, stop = balance_watch_record(&watch, b->method, out, &now, &better);
        if (better)
            save_best(b);
        if (stop)
            break;
    }
    restore_best(b);
    if (b->domain->periodic) {
        /* the returned structure measured as gp_quality measures it: wrapped, from a layer
         * of the first margin */
        b->margin = periodic_first_margin(b->domain, b->R_max);
        return new_layer(b, 1, progress, &out->after, err);
    }
    return follow_moves(b, params->update, &out->triangulation, 1, progress, &out->after, err);
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
    b.remember = !domain->periodic;
    b.method = params->method;
    b.max_step = params->max_step > 0.0 ? params->max_step : GP_BALANCE_DEFAULT_MAX_STEP;
    out->method = params->method;
    out->max_step = b.max_step;
    out->count = n;
    out->stop = GP_BALANCE_STOP_CONVERGED;
    size_t m = n ? n : 1;
    int rc = 0;
    out->F = malloc(m * sizeof *out->F);
    if (!out->F) {
        rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory balancing %zu disks", n);
        goto done;
    }
    if (params->method == GP_BALANCE_NONE || n == 0) {
        if ((rc = gp_quality(domain, rt, disks, n, out->F, &out->before, gp_progress_cancel(progress), err)))
            goto done;
        out->after = out->before;
    } else {
        b.F = out->F;
        b.rt = rt;
        b.R_max = largest_radius(disks, n);
        b.best = malloc(2 * m * sizeof *b.best);
        if (domain->periodic) {
            b.user = disks;
            b.grid_domain = (gp_domain){domain->width, domain->height, 0};
            b.margin = periodic_first_margin(domain, b.R_max);
            b.anchor = malloc(2 * m * sizeof *b.anchor);
        } else {
            b.frame = (quality_frame){domain, 0.0, 0.0};
        }
        if (!b.best || (domain->periodic && !b.anchor) || (!domain->periodic && marks_for(&b, n))) {
            rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory balancing %zu disks", n);
            goto done;
        }
        if ((rc = run_sweeps(&b, params, progress, out, err)))
            goto done;
    }
    if (progress && progress->report)
        progress->report(progress->ctx, "balance", 1.0);
done:
    if (b.rt && !domain->periodic)
        gp_rt_mark_changes(b.rt, NULL);
    periodic_layer_free(&b.layer);
    nearby_free(&b.near);
    settled_free(&b.settled);
    rings_free(&b.rings);
    free(b.changed);
    free(b.stale);
    free(b.moved_in);
    free(b.tangent);
    free(b.moved);
    free(b.best);
    free(b.anchor);
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
    case GP_BALANCE_STOP_STEADY: return "steady";
    case GP_BALANCE_STOP_CAP: return "max_iterations";
    }
    return "?";
}
