/* front.c - the advancing front: loops of nodes, per-level lists of segments, barriers. */
#include "front.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grow.h"

/* Two disks whose gap is below this fraction of their radii touch: the segment between
 * them is covered by the disks themselves and needs no barrier. Same reasoning as
 * GP_CONTACT_RTOL, with room for the rounding of a placement. */
#define TOUCH_RTOL 1e-7

/* The vector from disk a to disk b: to b's image nearest a on a periodic domain. */
static void disk_vector(const front *f, const gp_disk *da, const gp_disk *db, double *dx,
                        double *dy)
{
    *dx = db->x - da->x;
    *dy = db->y - da->y;
    gp_domain_min_image(f->grid->domain, dx, dy);
}

int front_init(front *f, const gp_disk *const *disks, const uint32_t *const *levels,
               const gp_grid *grid, size_t disk_capacity, double R_lo, double R_hi)
{
    memset(f, 0, sizeof *f);
    f->class_lo = R_lo;
    f->class_scale = R_hi > R_lo ? FRONT_FAIL_CLASSES / (R_hi - R_lo) : 0.0;
    f->disks = disks;
    f->levels = levels;
    f->grid = grid;
    f->free_node = FRONT_NONE;
    size_t ncells = grid->ncells;
    f->barrier_head = malloc(ncells * sizeof *f->barrier_head);
    if (!f->barrier_head)
        return GP_ENOMEM;
    memset(f->barrier_head, 0xff, ncells * sizeof *f->barrier_head); /* FRONT_NONE */
    f->free_link = FRONT_NONE;
    return front_reserve_disks(f, disk_capacity);
}

void front_free(front *f)
{
    free(f->buckets);
    free(f->nodes);
    free(f->cold);
    free(f->first_node);
    free(f->barrier_head);
    free(f->links);
    free(f->winding);
    memset(f, 0, sizeof *f);
}

int front_reserve_disks(front *f, size_t capacity)
{
    if (capacity <= f->disk_capacity)
        return 0;
    int32_t *first = grow_realloc(f->first_node, capacity, sizeof *first);
    if (!first)
        return GP_ENOMEM;
    f->first_node = first;
    f->disk_capacity = capacity;
    return 0;
}

void front_disk_added(front *f, int32_t disk)
{
    f->first_node[disk] = FRONT_NONE;
}

/* ---- per-level buckets ---- */

static int grow_buckets(front *f, uint32_t level)
{
    if (level < f->nbuckets)
        return 0;
    size_t n = grow_capacity(f->nbuckets, (size_t)level + 1);
    front_bucket *grown = n <= UINT32_MAX ? grow_realloc(f->buckets, n, sizeof *grown) : NULL;
    if (!grown)
        return GP_ENOMEM;
    for (size_t i = f->nbuckets; i < n; i++) {
        front_bucket *b = &grown[i];
        b->untried = FRONT_NONE;
        for (int c = 0; c < FRONT_FAIL_CLASSES; c++)
            b->failed[c] = FRONT_NONE;
        memset(b->failed_mask, 0, sizeof b->failed_mask);
    }
    f->buckets = grown;
    f->nbuckets = (uint32_t)n;
    return 0;
}

static int fail_class(const front *f, double R)
{
    double c = (R - f->class_lo) * f->class_scale;
    if (!(c > 0.0))
        return 0;
    return c >= FRONT_FAIL_CLASSES - 1 ? FRONT_FAIL_CLASSES - 1 : (int)c;
}

/* The list node u belongs to (untried, or the failed list of its class). */
static int32_t *list_of(front *f, int32_t u)
{
    front_node *n = &f->nodes[u];
    front_bucket *b = &f->buckets[n->level];
    return n->state == SEG_UNTRIED ? &b->untried : &b->failed[n->fail_class];
}

static void list_push(front *f, int32_t *head, int32_t u)
{
    front_node *n = &f->nodes[u];
    n->list_prev = FRONT_NONE;
    n->list_next = *head;
    if (*head != FRONT_NONE)
        f->nodes[*head].list_prev = u;
    *head = u;
}

static void list_unlink(front *f, int32_t *head, int32_t u)
{
    front_node *n = &f->nodes[u];
    if (n->list_prev != FRONT_NONE)
        f->nodes[n->list_prev].list_next = n->list_next;
    else
        *head = n->list_next;
    if (n->list_next != FRONT_NONE)
        f->nodes[n->list_next].list_prev = n->list_prev;
}

static void set_class_bit(front_bucket *b, int c)
{
    if (b->failed[c] != FRONT_NONE)
        b->failed_mask[c / 64] |= (uint64_t)1 << (c % 64);
    else
        b->failed_mask[c / 64] &= ~((uint64_t)1 << (c % 64));
}

/* The highest non-empty failure class of a bucket at or below `below`, or -1. */
static int highest_class(const front_bucket *b, int below)
{
    for (int w = below / 64; w >= 0; w--) {
        uint64_t bits = b->failed_mask[w];
        if (w == below / 64 && below % 64 != 63)
            bits &= ((uint64_t)1 << (below % 64 + 1)) - 1;
        if (bits)
            return w * 64 + 63 - __builtin_clzll(bits);
    }
    return -1;
}

/* The lowest non-empty failure class of a bucket strictly above `above`, or -1. */
static int lowest_class_above(const front_bucket *b, int above)
{
    for (int w = (above + 1) / 64; w < FRONT_FAIL_CLASSES / 64; w++) {
        uint64_t bits = b->failed_mask[w];
        if (w == (above + 1) / 64)
            bits &= ~(((uint64_t)1 << ((above + 1) % 64)) - 1);
        if (bits)
            return w * 64 + __builtin_ctzll(bits);
    }
    return -1;
}

/* Puts node u's fresh segment at the head of its level's untried list. */
static int bucket_push(front *f, int32_t u)
{
    front_node *n = &f->nodes[u];
    if (grow_buckets(f, n->level))
        return GP_ENOMEM;
    n->state = SEG_UNTRIED;
    n->fail_R = INFINITY;
    n->blocker = FRONT_NONE;
    list_push(f, &f->buckets[n->level].untried, u);
    if (n->level < f->low)
        f->low = n->level;
    return 0;
}

static void bucket_remove(front *f, int32_t u)
{
    list_unlink(f, list_of(f, u), u);
    if (f->nodes[u].state == SEG_FAILED)
        set_class_bit(&f->buckets[f->nodes[u].level], f->nodes[u].fail_class);
}

uint32_t front_low_level(front *f)
{
    while (f->low < f->nbuckets && f->buckets[f->low].untried == FRONT_NONE &&
           highest_class(&f->buckets[f->low], FRONT_FAIL_CLASSES - 1) < 0)
        f->low++;
    return f->low;
}

int32_t front_top(const front *f, uint32_t level)
{
    if (level >= f->nbuckets)
        return FRONT_NONE;
    const front_bucket *b = &f->buckets[level];
    if (b->untried != FRONT_NONE)
        return b->untried;
    /* the tightest pocket: the one the front closes at if nothing takes the radius, which
     * then costs the least empty space (docs/method.md §3.5) */
    int c = lowest_class_above(b, -1);
    return c < 0 ? FRONT_NONE : b->failed[c];
}

int32_t front_next_eligible(const front *f, uint32_t level, double R)
{
    if (level >= f->nbuckets)
        return FRONT_NONE;
    const front_bucket *b = &f->buckets[level];
    if (b->untried != FRONT_NONE)
        return b->untried;
    /* Only classes above R's count as not having failed for R: members of R's own class
     * failed for radii within 1/FRONT_FAIL_CLASSES of the law's range of R, and are taken
     * as failing for R too. Walking that class to tell them apart made the search linear
     * in the front when many segments had failed for similar radii. Of the classes above,
     * the lowest: the segment whose limit is the least above R, the tightest pocket that
     * may take it (best fit, docs/method.md §3.5), which leaves the roomier pockets to the
     * larger radii still to come. */
    int c = lowest_class_above(b, fail_class(f, R));
    return c < 0 ? FRONT_NONE : b->failed[c];
}

void front_mark_failed(front *f, int32_t u, double R)
{
    front_node *n = &f->nodes[u];
    if (n->state == SEG_FAILED && !(R < n->fail_R))
        return;
    bucket_remove(f, u);
    n->state = SEG_FAILED;
    n->fail_R = R;
    n->fail_class = (uint8_t)fail_class(f, R);
    front_bucket *b = &f->buckets[n->level];
    list_push(f, &b->failed[n->fail_class], u);
    set_class_bit(b, n->fail_class);
}

/* ---- barriers: the part of a segment that its two disks do not cover ---- */

static int uncovered_part(const front *f, int32_t u, double *px, double *py, double *qx,
                          double *qy)
{
    const gp_disk *da = &(*f->disks)[f->nodes[u].disk];
    const gp_disk *db = &(*f->disks)[f->nodes[f->nodes[u].next].disk];
    double ux, uy;
    disk_vector(f, da, db, &ux, &uy);
    double d = sqrt(ux * ux + uy * uy);
    if (!(d - da->R - db->R > TOUCH_RTOL * (da->R + db->R)))
        return 0;
    ux /= d;
    uy /= d;
    *px = da->x + da->R * ux;
    *py = da->y + da->R * uy;
    /* b itself, or on a periodic domain its image nearest a */
    double bx = f->grid->domain->periodic ? da->x + d * ux : db->x;
    double by = f->grid->domain->periodic ? da->y + d * uy : db->y;
    *qx = bx - db->R * ux;
    *qy = by - db->R * uy;
    return 1;
}

/* The cells a barrier is registered in: every cell a centre can lie in and still bring a
 * disk of radius <= R_max (half a cell) onto the uncovered part, i.e. the cells meeting
 * the part's bounding box grown by R_max. The part is shorter than a cell side (a closing
 * joins disks that both met one candidate disk, and the initial front stops where the
 * next disk would not fit), so that is at most 3x3 cells and usually 2x2; a query then
 * reads its own cell's list only. Along a periodic axis the range is in unwrapped cell
 * numbers (it may run past either side), read through gp_grid_index_wrapped, and holds
 * at most one period of cells so that none is registered twice. */
static void barrier_cells(const front *f, const double *part, int32_t range[4])
{
    const gp_grid *g = f->grid;
    double reach = 0.5 * g->cell;
    double lo_x = fmin(part[0], part[2]) - reach, hi_x = fmax(part[0], part[2]) + reach;
    double lo_y = fmin(part[1], part[3]) - reach, hi_y = fmax(part[1], part[3]) + reach;
    unsigned periodic = g->domain->periodic;
    if (!periodic) {
        gp_grid_coords(g, lo_x, lo_y, &range[0], &range[1]);
        gp_grid_coords(g, hi_x, hi_y, &range[2], &range[3]);
        return;
    }
    /* the part starts within R_max of a centre inside the domain and is under 4 R_max
     * long: its box reaches under three cells past the domain, within one period */
    double lo[2] = {lo_x, lo_y}, hi[2] = {hi_x, hi_y}, inv[2] = {g->inv_cell_x, g->inv_cell_y};
    int32_t n[2] = {g->nx, g->ny};
    for (int a = 0; a < 2; a++) {
        int32_t first = (int32_t)floor(lo[a] * inv[a]), last = (int32_t)floor(hi[a] * inv[a]);
        if (!(periodic & (a ? GP_PERIODIC_Y : GP_PERIODIC_X))) {
            first = first < 0 ? 0 : (first >= n[a] ? n[a] - 1 : first);
            last = last < 0 ? 0 : (last >= n[a] ? n[a] - 1 : last);
        } else if (last - first >= n[a]) {
            last = first + n[a] - 1;
        }
        range[a] = first;
        range[a + 2] = last;
    }
}

/* Whether a disk of radius R (the smallest the law draws) can reach the segment between
 * disks a and b without overlapping them. The deepest it can go is tangent to both, its
 * centre at height h over the line a-b; it reaches the line when h < R, or when the gap
 * is wider than 2 R. h - R grows with R, so no larger disk can reach a gap the smallest
 * cannot: such narrow gaps, the common case after a closing, need no barrier. */
static int gap_crossable(const gp_disk *a, const gp_disk *b, double d, double R)
{
    double ra = a->R + R, rb = b->R + R;
    if (d >= ra + rb)
        return 1;
    double along = (ra * ra - rb * rb + d * d) / (2.0 * d);
    double h2 = ra * ra - along * along;
    return h2 < R * R;
}

static int register_barrier(front *f, int32_t u)
{
    double part[4];
    front_node *n = &f->nodes[u];
    front_cold *c = &f->cold[u];
    c->barrier_cell = FRONT_NONE;
    if (!uncovered_part(f, u, &part[0], &part[1], &part[2], &part[3]) ||
        !gap_crossable(&(*f->disks)[n->disk], &(*f->disks)[f->nodes[n->next].disk], n->length,
                       f->class_lo))
        return 0;
    memcpy(c->gap, part, sizeof part);
    int32_t range[4];
    barrier_cells(f, part, range);
    for (int32_t cy = range[1]; cy <= range[3]; cy++) {
        for (int32_t cx = range[0]; cx <= range[2]; cx++) {
            int32_t link = f->free_link;
            if (link == FRONT_NONE) {
                front_link *grown = grow(f->links, &f->link_capacity, f->nlinks + 1, sizeof *grown);
                if (!grown)
                    return GP_ENOMEM;
                f->links = grown;
                link = (int32_t)f->nlinks++;
            } else {
                f->free_link = f->links[link].next;
            }
            size_t cell = gp_grid_index_wrapped(f->grid, cx, cy);
            f->links[link] = (front_link){u, f->barrier_head[cell]};
            f->barrier_head[cell] = link;
        }
    }
    c->barrier_cell = 1;
    return 0;
}

static void unregister_barrier(front *f, int32_t u)
{
    front_cold *c = &f->cold[u];
    if (c->barrier_cell == FRONT_NONE)
        return;
    int32_t range[4];
    barrier_cells(f, c->gap, range);
    for (int32_t cy = range[1]; cy <= range[3]; cy++) {
        for (int32_t cx = range[0]; cx <= range[2]; cx++) {
            int32_t *link = &f->barrier_head[gp_grid_index_wrapped(f->grid, cx, cy)];
            while (f->links[*link].node != u)
                link = &f->links[*link].next;
            int32_t gone = *link;
            *link = f->links[gone].next;
            f->links[gone].next = f->free_link;
            f->free_link = gone;
        }
    }
    c->barrier_cell = FRONT_NONE;
}

/* Squared distance from (x, y) to the segment [p, q]. */
static double dist2_to_segment(double x, double y, double px, double py, double qx, double qy)
{
    double vx = qx - px, vy = qy - py, wx = x - px, wy = y - py;
    double len2 = vx * vx + vy * vy;
    double t = len2 > 0.0 ? (wx * vx + wy * vy) / len2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    double dx = wx - t * vx, dy = wy - t * vy;
    return dx * dx + dy * dy;
}

int32_t front_barrier_crossed(const front *f, double x, double y, double R, int32_t skip)
{
    double reach = R * (1.0 - GP_CONTACT_RTOL);
    for (int32_t link = f->barrier_head[gp_grid_cell(f->grid, x, y)]; link != FRONT_NONE;
         link = f->links[link].next) {
        int32_t u = f->links[link].node;
        const double *part = f->cold[u].gap;
        double px = x, py = y;
        if (f->grid->domain->periodic) {
            /* the candidate's image nearest the part's start */
            double dx = x - part[0], dy = y - part[1];
            gp_domain_min_image(f->grid->domain, &dx, &dy);
            px = part[0] + dx;
            py = part[1] + dy;
        }
        if (u != skip && dist2_to_segment(px, py, part[0], part[1], part[2], part[3]) < reach * reach)
            return u;
    }
    return FRONT_NONE;
}

/* ---- segments: what a node's link to its successor carries ---- */

/* Starts node u's segment afresh (its successor changed): geometry, level, untried, in
 * its bucket, and registered as a barrier if its disks may not touch (`touching` says
 * they do, as after a placement, which saves the test). */
static int attach_segment(front *f, int32_t u, int touching)
{
    front_node *n = &f->nodes[u];
    const gp_disk *da = &(*f->disks)[n->disk], *db = &(*f->disks)[f->nodes[n->next].disk];
    double dx, dy;
    disk_vector(f, da, db, &dx, &dy);
    /* touching disks are R_a + R_b apart up to rounding; no need for the square root */
    n->length = touching ? da->R + db->R : sqrt(dx * dx + dy * dy);
    n->ux = n->length > 0.0 ? dx / n->length : 0.0;
    n->uy = n->length > 0.0 ? dy / n->length : 0.0;
    n->level = (*f->levels)[n->disk] + (*f->levels)[f->nodes[n->next].disk];
    if (bucket_push(f, u))
        return GP_ENOMEM;
    f->active++;
    f->cold[u].barrier_cell = FRONT_NONE;
    return touching ? 0 : register_barrier(f, u);
}

static void detach_segment(front *f, int32_t u)
{
    front_node *n = &f->nodes[u];
    if (n->state == SEG_FROZEN) {
        f->frozen--;
    } else {
        bucket_remove(f, u);
        f->active--;
    }
    unregister_barrier(f, u);
}

void front_freeze(front *f, int32_t u)
{
    bucket_remove(f, u);
    f->nodes[u].state = SEG_FROZEN;
    f->active--;
    f->frozen++;
}

/* ---- nodes ---- */

/* Doubles the room for nodes (grow_capacity): the hot parts in a fresh block on a cache
 * line (grow_aligned), the cold ones reallocated. Returns 0 or GP_ENOMEM (the front then
 * untouched). */
static int grow_nodes(front *f)
{
    _Static_assert(sizeof(front_node) == GROW_CACHE_LINE, "a node's hot part is one cache line");
    size_t cap = grow_capacity(f->node_capacity, f->nnodes + 1);
    if (!cap || cap > INT32_MAX)
        return GP_ENOMEM;
    front_cold *cold = grow_realloc(f->cold, cap, sizeof *cold);
    if (!cold)
        return GP_ENOMEM;
    f->cold = cold;
    front_node *nodes = grow_aligned(f->nodes, f->nnodes, cap, sizeof *nodes);
    if (!nodes)
        return GP_ENOMEM; /* the cold parts' extra room is harmless */
    f->nodes = nodes;
    f->node_capacity = cap;
    return 0;
}

static int32_t new_node(front *f, int32_t disk, uint32_t loop)
{
    int32_t u;
    if (f->free_node != FRONT_NONE) {
        u = f->free_node;
        f->free_node = f->nodes[u].next;
    } else {
        if (f->nnodes == f->node_capacity && grow_nodes(f))
            return GP_ENOMEM;
        u = (int32_t)f->nnodes++;
    }
    front_node *n = &f->nodes[u];
    memset(n, 0, sizeof *n);
    n->disk = disk;
    front_cold *c = &f->cold[u];
    memset(c, 0, sizeof *c);
    c->loop = loop;
    c->barrier_cell = FRONT_NONE;
    c->next_of_disk = f->first_node[disk];
    f->first_node[disk] = u;
    return u;
}

/* Frees node u, whose segment must already be detached. */
static void free_node(front *f, int32_t u)
{
    int32_t *link = &f->first_node[f->nodes[u].disk];
    while (*link != u)
        link = &f->cold[*link].next_of_disk;
    *link = f->cold[u].next_of_disk;
    f->nodes[u].next = f->free_node;
    f->free_node = u;
}

/* Removes the loop through u if it has fewer than three nodes: it encloses nothing. */
static void drop_if_degenerate(front *f, int32_t u)
{
    int32_t v = f->nodes[u].next;
    if (v != u && f->nodes[v].next != u)
        return;
    detach_segment(f, u);
    free_node(f, u);
    if (v != u) {
        detach_segment(f, v);
        free_node(f, v);
    }
}

/* ---- loop labels, and on a periodic domain their windings ---- */

static int periodic(const front *f)
{
    return f->grid->domain->periodic != 0;
}

/* A fresh loop label in *label (with room for its winding on a periodic domain): 0 or
 * GP_ENOMEM. */
static int new_label(front *f, uint32_t *label)
{
    uint32_t l = f->next_loop;
    if (periodic(f)) {
        int32_t *grown = grow(f->winding, &f->winding_capacity, (size_t)l + 1, 2 * sizeof *grown);
        if (!grown)
            return GP_ENOMEM;
        f->winding = grown;
        f->winding[2 * l] = f->winding[2 * l + 1] = 0;
    }
    f->next_loop++;
    *label = l;
    return 0;
}

/* Gives every node of the loop through `start` the label `loop` and, on a periodic
 * domain, sets that label's winding from the loop's segments: the sum of the vectors
 * between nearest images is a whole number of periods along each axis (0 for a loop
 * that does not wind around the torus). */
static void label_loop(front *f, int32_t start, uint32_t loop)
{
    double sx = 0.0, sy = 0.0;
    int32_t u = start;
    do {
        f->cold[u].loop = loop;
        if (periodic(f)) {
            double dx, dy;
            disk_vector(f, &(*f->disks)[f->nodes[u].disk],
                        &(*f->disks)[f->nodes[f->nodes[u].next].disk], &dx, &dy);
            sx += dx;
            sy += dy;
        }
        u = f->nodes[u].next;
    } while (u != start);
    if (periodic(f)) {
        f->winding[2 * loop] = (int32_t)lround(sx / f->grid->domain->width);
        f->winding[2 * loop + 1] = (int32_t)lround(sy / f->grid->domain->height);
    }
}

static int winds(const front *f, uint32_t loop)
{
    return f->winding[2 * loop] != 0 || f->winding[2 * loop + 1] != 0;
}

int front_add_loop(front *f, const int32_t *disks, size_t n)
{
    uint32_t loop;
    if (new_label(f, &loop))
        return GP_ENOMEM;
    int32_t first = FRONT_NONE, prev = FRONT_NONE;
    for (size_t i = 0; i < n; i++) {
        int32_t u = new_node(f, disks[i], loop);
        if (u < 0)
            return u;
        if (prev == FRONT_NONE)
            first = u;
        else
            f->nodes[prev].next = u;
        f->nodes[u].prev = prev;
        prev = u;
    }
    f->nodes[prev].next = first;
    f->nodes[first].prev = prev;
    label_loop(f, first, loop);
    for (int32_t u = first;;) {
        if (attach_segment(f, u, 0))
            return GP_ENOMEM;
        u = f->nodes[u].next;
        if (u == first)
            break;
    }
    drop_if_degenerate(f, first);
    return 0;
}

int front_place(front *f, int32_t u, int32_t c, int c_touches_b)
{
    int32_t v = f->nodes[u].next;
    int32_t w = new_node(f, c, f->cold[u].loop);
    if (w < 0)
        return w;
    detach_segment(f, u);
    f->nodes[w].prev = u;
    f->nodes[w].next = v;
    f->nodes[u].next = w;
    f->nodes[v].prev = w;
    if (attach_segment(f, u, 1) || attach_segment(f, w, c_touches_b))
        return GP_ENOMEM;
    return 0;
}

int32_t front_node_on_loop(const front *f, int32_t disk, int32_t u)
{
    for (int32_t w = f->first_node[disk]; w != FRONT_NONE; w = f->cold[w].next_of_disk)
        if (f->cold[w].loop == f->cold[u].loop)
            return w;
    return FRONT_NONE;
}

int32_t front_node_on_winding_loop(const front *f, int32_t disk, int32_t u)
{
    uint32_t loop = f->cold[u].loop;
    if (!periodic(f) || !winds(f, loop))
        return FRONT_NONE;
    for (int32_t w = f->first_node[disk]; w != FRONT_NONE; w = f->cold[w].next_of_disk)
        if (f->cold[w].loop != loop && winds(f, f->cold[w].loop))
            return w;
    return FRONT_NONE;
}

/* After a split, gives the shorter of the loops through a and b a new label, walking both
 * at the same pace so that the cost is that of the shorter one; the longer keeps the old
 * label, and its winding is what the shorter's leaves of the old loop's. */
static int relabel_shorter(front *f, int32_t a, int32_t b)
{
    uint32_t old = f->cold[a].loop;
    int32_t x = f->nodes[a].next, y = f->nodes[b].next;
    while (x != a && y != b) {
        x = f->nodes[x].next;
        y = f->nodes[y].next;
    }
    int32_t start = x == a ? a : b;
    uint32_t loop;
    if (new_label(f, &loop))
        return GP_ENOMEM;
    label_loop(f, start, loop);
    if (periodic(f)) {
        f->winding[2 * old] -= f->winding[2 * loop];
        f->winding[2 * old + 1] -= f->winding[2 * loop + 1];
    }
    return 0;
}

/* Takes node `middle` off its loop: `before` (its predecessor) links to what followed
 * it, as when the segments before -> middle -> after are closed by before -> after. */
static int cut_ear(front *f, int32_t before, int32_t middle)
{
    int32_t after = f->nodes[middle].next;
    detach_segment(f, before);
    detach_segment(f, middle);
    free_node(f, middle);
    f->nodes[before].next = after;
    f->nodes[after].prev = before;
    if (attach_segment(f, before, 0))
        return GP_ENOMEM;
    drop_if_degenerate(f, before);
    return 0;
}

int front_close(front *f, int32_t u, int32_t w)
{
    int32_t v = f->nodes[u].next;
    int merge = f->cold[w].loop != f->cold[u].loop;
    if (w == f->nodes[v].next)
        return cut_ear(f, u, v); /* pk follows p2: p2 leaves the loop */
    if (w == f->nodes[u].prev)
        return cut_ear(f, w, u); /* pk precedes p1: p1 leaves the loop */
    /* pk elsewhere on the loop: p1 -> pk -> (on to p1) and pk' -> p2 -> (on to pk') */
    int32_t w2 = new_node(f, f->nodes[w].disk, f->cold[u].loop);
    if (w2 < 0)
        return w2;
    int32_t before_w = f->nodes[w].prev;
    detach_segment(f, u);
    f->nodes[before_w].next = w2; /* same disk as w: its segment is unchanged */
    f->nodes[w2].prev = before_w;
    f->nodes[w2].next = v;
    f->nodes[v].prev = w2;
    f->nodes[u].next = w;
    f->nodes[w].prev = u;
    if (attach_segment(f, u, 0) || attach_segment(f, w2, 0))
        return GP_ENOMEM;
    if (merge) {
        /* two winding loops made one: it gets a label of its own (a walk of the whole loop,
         * once per pair of winding loops, so a few times per packing) */
        uint32_t loop;
        if (new_label(f, &loop))
            return GP_ENOMEM;
        label_loop(f, u, loop);
        return 0;
    }
    if (relabel_shorter(f, u, w2))
        return GP_ENOMEM;
    drop_if_degenerate(f, u);
    drop_if_degenerate(f, w2);
    return 0;
}
