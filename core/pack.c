/* pack.c - the advancing-front disk packer of docs/method.md §3 (report §III, Algorithm 1).
 *
 * Disks are laid along the boundary (the initial front), then placed one at a time
 * tangent to the two disks of a front segment, lowest level first, with the radius drawn
 * from the law kept until it is placed. When no segment of the front's level band takes
 * the radius, the front is closed at its first segment by the distance criterion.
 * The loops of segments themselves are kept by front.c. */
#include "grainpack/pack.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"
#include "packer.h"

/* Fraction of the domain a packing is expected to fill: used for the capacity guess and
 * to turn the filled area into a progress fraction. */
#define FILL_GUESS 0.86
/* Closings a disk may start (as p1) before the segments it starts are frozen instead.
 * A disk of radius R_max ringed by disks of radius R_min has about pi (R_max + R_min) /
 * R_min neighbours, each of which may cost one closing: 64 covers a ratio of 20. With
 * simple loops the cap is never reached (it was not, over 160 runs of the reference
 * cases); it is there so that the loop stays finite whatever rounding does. */
#define CLOSINGS_PER_DISK 64

/* ---- radii ---- */

static void draw_radius(packer *pk)
{
    pk->pending_r = gp_distribution_sample(pk->params->dist, &pk->rng);
    pk->pending_R = gp_joint_packing_radius(pk->params->joint, pk->pending_r);
}

/* ---- disks ---- */

static int grow_disks(packer *pk)
{
    size_t cap = pk->capacity + pk->capacity / 2 + 64;
    gp_disk *disks = grow_aligned(pk->disks, pk->count, cap, sizeof *disks);
    if (!disks)
        return GP_ENOMEM;
    pk->disks = disks;
    uint32_t *level = grow_realloc(pk->level, cap, sizeof *level);
    if (!level)
        return GP_ENOMEM;
    pk->level = level;
    uint8_t *closings = grow_realloc(pk->closings, cap, sizeof *closings);
    if (!closings)
        return GP_ENOMEM;
    pk->closings = closings;
    if (gp_grid_reserve(&pk->grid, cap) || front_reserve_disks(&pk->fr, cap))
        return GP_ENOMEM;
    pk->capacity = cap;
    return 0;
}

int32_t pack_add_disk(packer *pk, double x, double y, uint32_t level)
{
    if (pk->params->max_disks && pk->count >= pk->params->max_disks)
        return gp_error_set(pk->err, GP_ETOOBIG, NULL,
                            "the packing exceeded the cap of %zu disks", pk->params->max_disks);
    if (pk->count == pk->capacity && grow_disks(pk))
        return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory after %zu disks", pk->count);
    int32_t id = (int32_t)pk->count++;
    gp_domain_wrap(pk->params->domain, &x, &y); /* a disk across a periodic side: its image inside */
    pk->disks[id] = (gp_disk){x, y, pk->pending_r, pk->pending_R};
    pk->level[id] = level;
    pk->closings[id] = 0;
    gp_grid_insert(&pk->grid, id, x, y);
    front_disk_added(&pk->fr, id);
    pk->out->fill_area += M_PI * pk->pending_R * pk->pending_R;
    if (level > pk->out->max_level)
        pk->out->max_level = level;
    draw_radius(pk);
    return id;
}

int pack_fits(const packer *pk, double x, double y, double R, int32_t skip_a, int32_t skip_b,
                int32_t skip_segment, int32_t *blocker)
{
    int32_t q = GP_GRID_NONE;
    int ok = gp_domain_contains_disk(pk->params->domain, x, y, R, R * GP_CONTACT_RTOL) &&
             (q = gp_grid_first_overlap(&pk->grid, pk->disks, x, y, R, skip_a, skip_b)) == GP_GRID_NONE &&
             front_barrier_crossed(&pk->fr, x, y, R, skip_segment) == FRONT_NONE;
    if (blocker)
        *blocker = q;
    return ok;
}

/* Whether the disk (x, y, R) overlaps disk `id` (cheap test run before the grid's). */
static int overlaps_disk(const packer *pk, double x, double y, double R, int32_t id)
{
    gp_disk candidate = {x, y, R, R}, image;
    return gp_disks_overlap(&candidate, pack_image(pk, &pk->disks[id], x, y, &image));
}

static int front_oom(packer *pk)
{
    return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for the front");
}

/* ---- the loop (docs/method.md §3.5) ---- */

/* The disks of node u's segment. */
static int32_t seg_from(const packer *pk, int32_t u)
{
    return pk->fr.nodes[u].disk;
}

static int32_t seg_to(const packer *pk, int32_t u)
{
    return pk->fr.nodes[pk->fr.nodes[u].next].disk;
}

/* Where a disk of radius R goes against node u's segment (a, b): tangent to both on the
 * empty side (docs/method.md §3.1, as gp_place_tangent); or, when the two are further apart than the
 * disk can bridge and `bridge_gap` is set, touching a with its centre on the segment, so
 * that the gap is filled from one end rather than given up. Returns 1 with the centre when the position
 * exists and fits. The disk that was in the way last time, then the disks next to a and b
 * on the loop, are the likeliest to be in the way, so they are tested before the grid;
 * a disk found in the way is remembered in the node. */
static int find_position(packer *pk, int32_t u, double R, int bridge_gap, double *x, double *y,
                         int *touches_b)
{
    front_node *nodes = pk->fr.nodes;
    const front_node *n = &nodes[u];
    int32_t a = n->disk, b = nodes[n->next].disk;
    pk->blocked = -1;
    const gp_disk *da = &pk->disks[a], *db = &pk->disks[b];
    /* docs/method.md §3.1 with the segment's direction and length computed once per segment */
    double ra = da->R + R, rb = db->R + R, d = n->length;
    *touches_b = !(d > ra + rb);
    if (!*touches_b) {
        if (!bridge_gap)
            return 0;
        *x = da->x + ra * n->ux;
        *y = da->y + ra * n->uy;
    } else {
        if (!(d > 0.0) || d < fabs(ra - rb))
            return 0;
        double along = (ra * ra - rb * rb + d * d) / (2.0 * d);
        double h2 = ra * ra - along * along;
        double h = h2 > 0.0 ? sqrt(h2) : 0.0;
        *x = da->x + along * n->ux - h * n->uy;
        *y = da->y + along * n->uy + h * n->ux;
    }
    int32_t likely[3] = {nodes[u].blocker, nodes[nodes[u].prev].disk,
                         nodes[nodes[nodes[u].next].next].disk};
    for (int i = 0; i < 3; i++)
        if (likely[i] >= 0 && likely[i] != a && likely[i] != b &&
            overlaps_disk(pk, *x, *y, R, likely[i])) {
            nodes[u].blocker = pk->blocked = likely[i];
            return 0;
        }
    int32_t q;
    int ok = pack_fits(pk, *x, *y, R, a, b, u, &q);
    pk->blocked = q;
    if (q != GP_GRID_NONE)
        nodes[u].blocker = q;
    return ok;
}

/* Records that node u's segment did not take radius R (find_position just said so): a
 * disk in the way gives the limit from which no radius fits there, which spares the
 * front trying the segment again for each radius above it; without one (a wall, a
 * barrier), R itself is the limit. */
static void mark_failed(packer *pk, int32_t u, double R)
{
    double limit = R;
    const front_node *n = &pk->fr.nodes[u];
    /* the limit is never below the smaller of R and R_min: a segment that already failed
     * at or below that keeps its record whatever the limit, so it is not computed (the
     * first segment of the front's level is tried on every pass, dead pocket or not) */
    if (n->state == SEG_FAILED && !(fmin(R, pk->R_min) < n->fail_R))
        return;
    if (pk->blocked >= 0) {
        const gp_disk *a = &pk->disks[n->disk];
        gp_disk b_image, q_image;
        limit = pack_fit_limit(a, pack_image(pk, &pk->disks[pk->fr.nodes[n->next].disk], a->x, a->y, &b_image),
                               n->length, n->ux, n->uy,
                               pack_image(pk, &pk->disks[pk->blocked], a->x, a->y, &q_image), pk->R_min, R);
    }
    front_mark_failed(&pk->fr, u, limit);
}

/* Whether node u's segment is wider than a disk of radius R can bridge. */
static int too_wide(const packer *pk, int32_t u, double R)
{
    const gp_disk *da = &pk->disks[seg_from(pk, u)], *db = &pk->disks[seg_to(pk, u)];
    return pk->fr.nodes[u].length > da->R + db->R + 2.0 * R;
}

/* Places the pending radius against node u's segment (see find_position) if it fits
 * there. Returns 1 if placed, 0 if not, or a GP_E code. */
static int try_segment(packer *pk, int32_t u, int bridge_gap)
{
    int32_t a = seg_from(pk, u), b = seg_to(pk, u);
    double x, y;
    int touches_b;
    pk->out->attempts++;
    int rc = pack_work(pk, pk->query_units);
    if (rc)
        return rc;
    if (!find_position(pk, u, pk->pending_R, bridge_gap, &x, &y, &touches_b))
        return 0;
    uint32_t la = pk->level[a], lb = pk->level[b];
    /* our definition of report eq. 6: one more than the lower of the two */
    int32_t c = pack_add_disk(pk, x, y, (la < lb ? la : lb) + 1);
    if (c < 0)
        return c;
    return front_place(&pk->fr, u, c, touches_b) ? front_oom(pk) : 1;
}

/* The criterion of our eq. 7: the free space between pi and the two disks of s. */
static double closing_gap(const gp_disk *d1, const gp_disk *d2, const gp_disk *di)
{
    double x1 = di->x - d1->x, y1 = di->y - d1->y, x2 = di->x - d2->x, y2 = di->y - d2->y;
    return sqrt(x1 * x1 + y1 * y1) - d1->R - di->R + sqrt(x2 * x2 + y2 * y2) - d2->R - di->R;
}

/* Collects in pk->conflicts the disks the pending radius meets at (x, y) when placed
 * against node u's segment: the disks it overlaps, and the two ends of a barrier it would
 * cross. Returns how many, or GP_ENOMEM. */
static long gather_conflicts(packer *pk, double x, double y, int32_t u)
{
    size_t n;
    for (;;) {
        n = gp_grid_overlaps(&pk->grid, pk->disks, x, y, pk->pending_R, seg_from(pk, u),
                             seg_to(pk, u), pk->conflicts, pk->conflict_capacity);
        if (n + 2 <= pk->conflict_capacity)
            break;
        int32_t *grown = grow(pk->conflicts, &pk->conflict_capacity, n + 2, sizeof *grown);
        if (!grown)
            return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory closing the front");
        pk->conflicts = grown;
    }
    int32_t barrier = front_barrier_crossed(&pk->fr, x, y, pk->pending_R, u);
    if (barrier != FRONT_NONE) {
        pk->conflicts[n++] = seg_from(pk, barrier);
        pk->conflicts[n++] = seg_to(pk, barrier);
    }
    return (long)n;
}

/* Among the n disks in pk->conflicts, the node the front closes on at node u's segment
 * (p1, p2), or FRONT_NONE: a disk of the same loop, strictly on the empty side of p1 -> p2,
 * with the least closing_gap. A disk off the loop is buried or beyond another loop, and
 * one behind the segment is on the filled side: joining either would wind the front back
 * over filled ground, whereas a disk on the empty side makes the closing cut a triangle
 * off the empty region, which is what lets the front shrink to nothing. */
static int32_t closing_node(const packer *pk, size_t n, int32_t u)
{
    int32_t p1 = seg_from(pk, u), p2 = seg_to(pk, u);
    const gp_disk *d1 = &pk->disks[p1];
    gp_disk d2_image, di_image;
    const gp_disk *d2 = pack_image(pk, &pk->disks[p2], d1->x, d1->y, &d2_image);
    double best_gap = INFINITY;
    int32_t best = FRONT_NONE;
    for (size_t i = 0; i < n; i++) {
        int32_t id = pk->conflicts[i];
        const gp_disk *di = pack_image(pk, &pk->disks[id], d1->x, d1->y, &di_image);
        if (id == p1 || id == p2 || gp_orient2d(d1->x, d1->y, d2->x, d2->y, di->x, di->y) <= 0.0)
            continue;
        int32_t w = front_node_on_loop(&pk->fr, id, u);
        if (w == FRONT_NONE)
            w = front_node_on_winding_loop(&pk->fr, id, u); /* periodic: loops that meet */
        if (w == FRONT_NONE)
            continue;
        double gap = closing_gap(d1, d2, di);
        if (gap < best_gap) {
            best_gap = gap;
            best = w;
        }
    }
    return best;
}

/* Nothing in the front's level band takes the pending radius: close the front at node u's
 * segment (p1, p2) (docs/method.md §3.5, our eq. 7), on the node chosen by closing_node among the
 * disks the radius met when placed against it. When it met none of the loop (only the
 * wall, or disks the front has passed) or the two disks are too far apart for it, the
 * segment is frozen and the pocket behind it stays a void. */
static int close_front(packer *pk, int32_t u)
{
    int32_t p1 = seg_from(pk, u), p2 = seg_to(pk, u);
    double x, y;
    int32_t w = FRONT_NONE;
    pk->out->closures++;
    int rc = pack_work(pk, pk->query_units);
    if (rc)
        return rc;
    if (pk->closings[p1] >= CLOSINGS_PER_DISK) {
        front_freeze(&pk->fr, u);
        pk->out->capped++;
        return 0;
    }
    pk->closings[p1]++;
    gp_disk p2_image;
    const gp_disk *d1 = &pk->disks[p1];
    if (gp_place_tangent(d1, pack_image(pk, &pk->disks[p2], d1->x, d1->y, &p2_image),
                         pk->pending_R, &x, &y)) {
        long n = gather_conflicts(pk, x, y, u);
        if (n < 0)
            return (int)n;
        w = closing_node(pk, (size_t)n, u);
    }
    if (w == FRONT_NONE) {
        front_freeze(&pk->fr, u);
        pk->out->frozen++;
        return 0;
    }
    return front_close(&pk->fr, u, w) ? front_oom(pk) : 0;
}

int pack_check(packer *pk)
{
    pk->work = 0;
    const gp_progress *pr = pk->progress;
    if (!pr)
        return 0;
    if (pr->cancel && atomic_load_explicit(pr->cancel, memory_order_relaxed))
        return gp_error_set(pk->err, GP_ECANCELED, NULL, "packing canceled after %zu disks", pk->count);
    if (++pk->checks < PACK_CHECKS_PER_REPORT)
        return 0;
    pk->checks = 0;
    if (pr->report) {
        double expected = FILL_GUESS * gp_domain_area(pk->params->domain);
        double f = pk->out->fill_area / expected;
        pr->report(pr->ctx, "pack", f < 0.99 ? f : 0.99);
    }
    return 0;
}

/* Tries the pending radius on the segments of levels from..to that have not failed for
 * it, best fit first in each level (front_next_eligible), until one takes it. Returns 1
 * if placed, 0 if not, or a GP_E code. */
static int try_levels(packer *pk, uint32_t from, uint32_t to)
{
    for (uint32_t level = from; level <= to; level++) {
        int32_t s;
        while ((s = front_next_eligible(&pk->fr, level, pk->pending_R)) != FRONT_NONE) {
            int placed = try_segment(pk, s, 0);
            if (placed)
                return placed;
            mark_failed(pk, s, pk->pending_R);
        }
    }
    return 0;
}

/* Whether the pocket at node u's segment, which just failed the pending radius, would
 * take a disk of radius R_alive: then it is worth waiting for one. 1, 0 or a GP_E code. */
static int pocket_alive(packer *pk, int32_t u)
{
    if (!(pk->fr.nodes[u].fail_R > pk->R_alive))
        return 0; /* its limit is already below */
    int rc = pack_work(pk, pk->query_units);
    if (rc)
        return rc;
    double x, y;
    int touches_b;
    if (find_position(pk, u, pk->R_alive, 0, &x, &y, &touches_b))
        return 1;
    mark_failed(pk, u, pk->R_alive);
    return 0;
}

/* The loop of docs/method.md §3.5. The first segment of the front's level is tried first,
 * whatever it failed for before; then every segment of the level band that has not
 * failed for a radius <= R, lowest level first; under the waiting rule, when the first
 * segment's pocket would take a radius of the law's alive quantile, the radius climbs up
 * to pk->wait levels more; only then is the front closed at the first segment.
 *
 * Work per placed disk (docs/method.md §3.7): every pass of this loop tests the first
 * segment, then places a disk, or closes or freezes the first segment. A closing is
 * counted against its p1 (at most CLOSINGS_PER_DISK each) and a freeze takes a segment
 * off for good, and each placement or closing makes at most two segments: so passes,
 * segments and closings are all O(disks). Every other test either places the disk or
 * lowers a segment's failure class (FRONT_FAIL_CLASSES of them), or tests the alive
 * radius once per pass; each test is one grid query of at most (6 rho + 2)^2 / pi disks,
 * rho = R_max / R_min <= GP_PACK_MAX_RADIUS_RATIO. */
static int run_front(packer *pk)
{
    while (pk->fr.active > 0) {
        uint32_t low = front_low_level(&pk->fr);
        int32_t first = front_top(&pk->fr, low);
        int placed = try_segment(pk, first, 0);
        if (placed < 0)
            return placed;
        if (!placed) {
            mark_failed(pk, first, pk->pending_R);
            placed = try_levels(pk, low, low + pk->band);
        }
        if (!placed && pk->wait) {
            placed = pocket_alive(pk, first);
            if (placed > 0)
                placed = try_levels(pk, low + pk->band + 1, low + pk->band + pk->wait);
        }
        if (placed < 0)
            return placed;
        if (!placed && too_wide(pk, first, pk->pending_R)) {
            /* a gap wider than the radius is filled from one end before it is given up */
            placed = try_segment(pk, first, 1);
            if (placed < 0)
                return placed;
        }
        if (!placed) {
            int rc = close_front(pk, first);
            if (rc)
                return rc;
        }
    }
    return 0;
}

gp_pack_law_limit gp_pack_check_law(const gp_domain *domain, const gp_distribution *dist,
                                    const gp_joint *joint, gp_error *err)
{
    double r_min, r_max, R_min, R_max;
    gp_distribution_support(dist, &r_min, &r_max);
    gp_joint_packing_range(joint, r_min, r_max, &R_min, &R_max);
    if (!(R_max <= GP_PACK_MAX_RADIUS_RATIO * R_min)) {
        gp_error_set(err, GP_EINVAL, NULL,
                     "packing radii from %g to %g span a ratio of %.3g, more than the packer's "
                     "limit of %g: the work to test a position grows with the square of that "
                     "ratio, so such a law could take unbounded time (docs/method.md §3.7)",
                     R_min, R_max, R_max / R_min, GP_PACK_MAX_RADIUS_RATIO);
        return GP_PACK_LAW_RATIO;
    }
    double side = domain->width > domain->height ? domain->width : domain->height;
    if (!(side <= GP_PACK_MAX_SIDE_RADII * R_min)) {
        gp_error_set(err, GP_EINVAL, NULL,
                     "the smallest packing radius %g is too small for a domain side of %g "
                     "(%.3g radii, the limit is %g): disks placed in double precision that far "
                     "from the origin would overlap by more than the contact tolerance "
                     "(docs/method.md §3.7)",
                     R_min, side, side / R_min, GP_PACK_MAX_SIDE_RADII);
        return GP_PACK_LAW_PRECISION;
    }
    double period = GP_PACK_MIN_PERIOD_RADII * R_max;
    if (((domain->periodic & GP_PERIODIC_X) && !(domain->width >= period)) ||
        ((domain->periodic & GP_PERIODIC_Y) && !(domain->height >= period))) {
        gp_error_set(err, GP_EINVAL, NULL,
                     "a periodic side must be at least %g largest packing radii long (%g for "
                     "R_max = %g), so that only the nearest image of a disk can touch another "
                     "(docs/method.md §3.8)",
                     GP_PACK_MIN_PERIOD_RADII, period, R_max);
        return GP_PACK_LAW_PERIOD;
    }
    return GP_PACK_LAW_OK;
}

/* Sets the packer's rule from params (running the pilots for the default) and records it
 * in the output. Returns 0 or a GP_E code with err set. */
static int set_rule(packer *pk, double R_min)
{
    const gp_pack_params *params = pk->params;
    gp_packing *out = pk->out;
    out->rule = params->rule == GP_FRONT_LEVEL_BAND ? GP_FRONT_LEVEL_BAND : GP_FRONT_WAIT;
    pk->R_min = R_min;
    if (params->rule == GP_FRONT_LEVEL_BAND) {
        pk->band = params->level_band;
        return 0;
    }
    out->wait_levels = params->wait_levels;
    out->alive_quantile = params->alive_quantile;
    if (params->rule == GP_FRONT_DEFAULT) {
        int rc = gp_pack_default_rule(params->dist, params->joint, pk->progress, &out->wait_levels,
                                      &out->alive_quantile, pk->err);
        if (rc)
            return rc;
    } else if (params->rule != GP_FRONT_WAIT || out->wait_levels < 1 ||
               out->wait_levels > GP_PACK_MAX_WAIT_LEVELS || !(out->alive_quantile >= 0.0) ||
               !(out->alive_quantile < 1.0)) {
        return gp_error_set(pk->err, GP_EINVAL, NULL,
                            "the waiting rule needs 1 to %d levels and a quantile in [0, 1), got "
                            "%u and %g",
                            GP_PACK_MAX_WAIT_LEVELS, out->wait_levels, out->alive_quantile);
    }
    pk->wait = out->wait_levels;
    /* the smallest radius for quantile 0, whatever the joint does to the law's ends */
    double r = gp_distribution_quantile(params->dist, out->alive_quantile);
    double R = gp_joint_packing_radius(params->joint, r);
    pk->R_alive = out->alive_quantile > 0.0 && R > R_min ? R : R_min;
    return 0;
}

int gp_pack(const gp_pack_params *params, const gp_progress *progress, gp_packing *out,
            gp_error *err)
{
    memset(out, 0, sizeof *out);
    packer pk;
    memset(&pk, 0, sizeof pk);
    pk.params = params;
    pk.progress = progress;
    pk.out = out;
    pk.err = err;
    gp_rng_seed(&pk.rng, params->seed);

    double r_min, r_max, R_min, R_max;
    gp_distribution_support(params->dist, &r_min, &r_max);
    gp_joint_packing_range(params->joint, r_min, r_max, &R_min, &R_max);
    if (!(R_max > 0.0) || !(params->domain->width >= 2 * R_max) ||
        !(params->domain->height >= 2 * R_max))
        return gp_error_set(err, GP_EINVAL, NULL,
                            "the largest packing disk (R = %g) does not fit in the domain", R_max);
    if (gp_pack_check_law(params->domain, params->dist, params->joint, err))
        return GP_EINVAL;
    int rc = set_rule(&pk, R_min);
    if (rc) {
        memset(out, 0, sizeof *out);
        return rc;
    }

    /* The disks a grid query may test: those with centres in the 3 x 3 cells of side
     * 2 R_max around the candidate, disjoint and of radius R_min at least, so within the
     * block grown by R_min: (6 R_max + 2 R_min)^2 / (pi R_min^2) of them at most. */
    double ratio = R_max / R_min;
    pk.query_units = 1 + (uint64_t)((6.0 * ratio + 2.0) * (6.0 * ratio + 2.0) / M_PI / PACK_TESTS_PER_UNIT);

    /* room for the expected number of disks, so that large runs never copy the arrays */
    double expected = FILL_GUESS * gp_domain_area(params->domain) /
                      (M_PI * gp_distribution_mean_packing_r2(params->dist, params->joint));
    size_t capacity = (size_t)(expected * 1.04) + 256;
    if (params->max_disks && capacity > params->max_disks + 1)
        capacity = params->max_disks + 1;

    /* the grid has about one cell per expected disk or fewer (cells are 2 R_max wide) */
    rc = gp_grid_init(&pk.grid, params->domain, R_max, capacity, (size_t)(4.0 * expected) + 1024);
    if (rc == GP_ETOOBIG)
        gp_error_set(err, rc, NULL, "the bucket grid would be too large for this domain");
    else if (rc)
        gp_error_set(err, rc, NULL, "out of memory for the bucket grid");
    if (rc == 0) {
        /* on a cache line: a disk (32 bytes) then never straddles two */
        pk.disks = grow_aligned(NULL, 0, capacity, sizeof *pk.disks);
        pk.level = malloc(capacity * sizeof *pk.level);
        pk.closings = malloc(capacity * sizeof *pk.closings);
        pk.capacity = capacity;
        pk.conflict_capacity = 64;
        pk.conflicts = malloc(pk.conflict_capacity * sizeof *pk.conflicts);
        if (!pk.conflicts || !pk.disks || !pk.level || !pk.closings ||
            front_init(&pk.fr, (const gp_disk *const *)&pk.disks, (const uint32_t *const *)&pk.level,
                       &pk.grid, capacity, R_min, R_max))
            rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory for %zu disks", capacity);
    }
    if (rc == 0) {
        draw_radius(&pk);
        rc = params->domain->periodic ? pack_periodic_start(&pk) : pack_walls(&pk);
    }
    if (rc == 0)
        rc = run_front(&pk);

    free(pk.level);
    free(pk.closings);
    free(pk.conflicts);
    front_free(&pk.fr);
    gp_grid_free(&pk.grid);
    if (rc) {
        free(pk.disks);
        memset(out, 0, sizeof *out);
        return rc;
    }
    /* hand back exactly what is used */
    gp_disk *trimmed = pk.count ? realloc(pk.disks, pk.count * sizeof *trimmed) : NULL;
    if (!pk.count)
        free(pk.disks);
    out->disks = trimmed ? trimmed : (pk.count ? pk.disks : NULL);
    out->count = pk.count;
    if (progress && progress->report)
        progress->report(progress->ctx, "pack", 1.0);
    return 0;
}

void gp_packing_free(gp_packing *packing)
{
    free(packing->disks);
    memset(packing, 0, sizeof *packing);
}
