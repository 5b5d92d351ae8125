/* front.c - the advancing front: loops of nodes, per-level heaps of segments, barriers. */
#include "front.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"

/* Two disks whose gap is below this fraction of their radii touch: the segment between
 * them is covered by the disks themselves and needs no barrier. Same reasoning as
 * GP_CONTACT_RTOL, with room for the rounding of a placement. */
#define TOUCH_RTOL 1e-7

int front_init(front *f, const gp_disk *const *disks, const uint32_t *const *levels,
               const gp_grid *grid, size_t disk_capacity)
{
    memset(f, 0, sizeof *f);
    f->disks = disks;
    f->levels = levels;
    f->grid = grid;
    f->free_node = FRONT_NONE;
    size_t ncells = (size_t)grid->nx * (size_t)grid->ny;
    f->barrier_head = malloc(ncells * sizeof *f->barrier_head);
    if (!f->barrier_head)
        return GP_ENOMEM;
    memset(f->barrier_head, 0xff, ncells * sizeof *f->barrier_head); /* FRONT_NONE */
    return front_reserve_disks(f, disk_capacity);
}

void front_free(front *f)
{
    for (uint32_t i = 0; i < f->nbuckets; i++)
        free(f->buckets[i].failed);
    free(f->buckets);
    free(f->nodes);
    free(f->first_node);
    free(f->barrier_head);
    memset(f, 0, sizeof *f);
}

int front_reserve_disks(front *f, size_t capacity)
{
    if (capacity <= f->disk_capacity)
        return 0;
    int32_t *first = realloc(f->first_node, capacity * sizeof *first);
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
    uint32_t n = f->nbuckets ? f->nbuckets : 16;
    while (n <= level)
        n *= 2;
    front_bucket *grown = realloc(f->buckets, n * sizeof *grown);
    if (!grown)
        return GP_ENOMEM;
    for (uint32_t i = f->nbuckets; i < n; i++)
        grown[i] = (front_bucket){FRONT_NONE, NULL, 0, 0};
    f->buckets = grown;
    f->nbuckets = n;
    return 0;
}

/* The heap of failed segments is 4-ary: half the depth of a binary one, and the four
 * children of an entry share a cache line or two. */
#define HEAP_ARITY 4

static void heap_place(front *f, front_bucket *b, uint32_t pos, front_failed entry)
{
    b->failed[pos] = entry;
    f->nodes[entry.node].heap_pos = pos;
}

static void sift_up(front *f, front_bucket *b, uint32_t pos)
{
    front_failed entry = b->failed[pos];
    while (pos > 0) {
        uint32_t parent = (pos - 1) / HEAP_ARITY;
        if (!(entry.fail_R > b->failed[parent].fail_R))
            break;
        heap_place(f, b, pos, b->failed[parent]);
        pos = parent;
    }
    heap_place(f, b, pos, entry);
}

static void sift_down(front *f, front_bucket *b, uint32_t pos)
{
    front_failed entry = b->failed[pos];
    for (;;) {
        uint32_t first = HEAP_ARITY * pos + 1;
        if (first >= b->nfailed)
            break;
        uint32_t end = first + HEAP_ARITY < b->nfailed ? first + HEAP_ARITY : b->nfailed;
        uint32_t best = first;
        for (uint32_t c = first + 1; c < end; c++)
            if (b->failed[c].fail_R > b->failed[best].fail_R)
                best = c;
        if (!(b->failed[best].fail_R > entry.fail_R))
            break;
        heap_place(f, b, pos, b->failed[best]);
        pos = best;
    }
    heap_place(f, b, pos, entry);
}

static void untried_unlink(front *f, front_bucket *b, int32_t u)
{
    front_node *n = &f->nodes[u];
    if (n->list_prev != FRONT_NONE)
        f->nodes[n->list_prev].list_next = n->list_next;
    else
        b->untried = n->list_next;
    if (n->list_next != FRONT_NONE)
        f->nodes[n->list_next].list_prev = n->list_prev;
}

static void failed_remove(front *f, front_bucket *b, int32_t u)
{
    uint32_t pos = f->nodes[u].heap_pos;
    front_failed last = b->failed[--b->nfailed];
    if (last.node == u)
        return;
    heap_place(f, b, pos, last);
    sift_up(f, b, pos);
    sift_down(f, b, f->nodes[last.node].heap_pos);
}

/* Puts node u's fresh segment at the head of its level's untried list. */
static int bucket_push(front *f, int32_t u)
{
    front_node *n = &f->nodes[u];
    if (grow_buckets(f, n->level))
        return GP_ENOMEM;
    front_bucket *b = &f->buckets[n->level];
    n->state = SEG_UNTRIED;
    n->fail_R = INFINITY;
    n->blocker = FRONT_NONE;
    n->list_prev = FRONT_NONE;
    n->list_next = b->untried;
    if (b->untried != FRONT_NONE)
        f->nodes[b->untried].list_prev = u;
    b->untried = u;
    if (n->level < f->low)
        f->low = n->level;
    return 0;
}

static void bucket_remove(front *f, int32_t u)
{
    front_bucket *b = &f->buckets[f->nodes[u].level];
    if (f->nodes[u].state == SEG_UNTRIED)
        untried_unlink(f, b, u);
    else
        failed_remove(f, b, u);
}

uint32_t front_low_level(front *f)
{
    while (f->low < f->nbuckets && f->buckets[f->low].untried == FRONT_NONE &&
           f->buckets[f->low].nfailed == 0)
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
    return b->nfailed ? b->failed[0].node : FRONT_NONE;
}

void front_mark_failed(front *f, int32_t u, double R)
{
    front_node *n = &f->nodes[u];
    front_bucket *b = &f->buckets[n->level];
    if (n->state == SEG_FAILED) {
        if (R < n->fail_R) {
            n->fail_R = R;
            b->failed[n->heap_pos].fail_R = R;
            sift_down(f, b, n->heap_pos);
        }
        return;
    }
    if (b->nfailed == b->capacity) {
        uint32_t cap = b->capacity ? 2 * b->capacity : 16;
        front_failed *heap = realloc(b->failed, cap * sizeof *heap);
        if (!heap)
            return; /* stays untried: it will merely be tried again */
        b->failed = heap;
        b->capacity = cap;
    }
    untried_unlink(f, b, u);
    n->state = SEG_FAILED;
    n->fail_R = R;
    b->failed[b->nfailed] = (front_failed){R, u};
    sift_up(f, b, b->nfailed++);
}

/* ---- barriers: the part of a segment that its two disks do not cover ---- */

static int uncovered_part(const front *f, int32_t u, double *px, double *py, double *qx,
                          double *qy)
{
    const gp_disk *da = &(*f->disks)[f->nodes[u].disk];
    const gp_disk *db = &(*f->disks)[f->nodes[f->nodes[u].next].disk];
    double ux = db->x - da->x, uy = db->y - da->y;
    double d = sqrt(ux * ux + uy * uy);
    if (!(d - da->R - db->R > TOUCH_RTOL * (da->R + db->R)))
        return 0;
    ux /= d;
    uy /= d;
    *px = da->x + da->R * ux;
    *py = da->y + da->R * uy;
    *qx = db->x - db->R * ux;
    *qy = db->y - db->R * uy;
    return 1;
}

static void register_barrier(front *f, int32_t u)
{
    double px, py, qx, qy;
    front_node *n = &f->nodes[u];
    n->barrier_cell = FRONT_NONE;
    if (!uncovered_part(f, u, &px, &py, &qx, &qy))
        return;
    /* The uncovered part is shorter than a cell side (2 R_max): a closing joins disks that
     * both met one candidate disk, and the initial front stops where the next disk would
     * not fit. So a disk of radius <= R_max crossing it has its centre within the 3x3
     * cells around the cell of the part's midpoint. */
    size_t cell = gp_grid_cell(f->grid, 0.5 * (px + qx), 0.5 * (py + qy));
    n->barrier_cell = (int32_t)cell;
    n->gap[0] = px;
    n->gap[1] = py;
    n->gap[2] = qx;
    n->gap[3] = qy;
    n->next_barrier = f->barrier_head[cell];
    f->barrier_head[cell] = u;
}

static void unregister_barrier(front *f, int32_t u)
{
    int32_t cell = f->nodes[u].barrier_cell;
    if (cell == FRONT_NONE)
        return;
    int32_t *link = &f->barrier_head[cell];
    while (*link != u)
        link = &f->nodes[*link].next_barrier;
    *link = f->nodes[u].next_barrier;
    f->nodes[u].barrier_cell = FRONT_NONE;
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
    const gp_grid *g = f->grid;
    size_t cell = gp_grid_cell(g, x, y);
    int32_t ix = (int32_t)(cell % (size_t)g->nx), iy = (int32_t)(cell / (size_t)g->nx);
    double reach = R * (1.0 - GP_CONTACT_RTOL);
    for (int k = 0; k < 9; k++) {
        int32_t cx = ix + gp_grid_search_order[k][0], cy = iy + gp_grid_search_order[k][1];
        if (cx < 0 || cy < 0 || cx >= g->nx || cy >= g->ny)
            continue;
        for (int32_t u = f->barrier_head[(size_t)cy * (size_t)g->nx + (size_t)cx]; u != FRONT_NONE;
             u = f->nodes[u].next_barrier) {
            const double *part = f->nodes[u].gap;
            if (u != skip && dist2_to_segment(x, y, part[0], part[1], part[2], part[3]) < reach * reach)
                return u;
        }
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
    double dx = db->x - da->x, dy = db->y - da->y;
    n->length = sqrt(dx * dx + dy * dy);
    n->ux = n->length > 0.0 ? dx / n->length : 0.0;
    n->uy = n->length > 0.0 ? dy / n->length : 0.0;
    n->level = (*f->levels)[n->disk] + (*f->levels)[f->nodes[n->next].disk];
    if (bucket_push(f, u))
        return GP_ENOMEM;
    f->active++;
    n->barrier_cell = FRONT_NONE;
    if (!touching)
        register_barrier(f, u);
    return 0;
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

static int32_t new_node(front *f, int32_t disk, uint32_t loop)
{
    int32_t u;
    if (f->free_node != FRONT_NONE) {
        u = f->free_node;
        f->free_node = f->nodes[u].next;
    } else {
        if (f->nnodes == f->node_capacity) {
            size_t cap = f->node_capacity * 2 + 64;
            front_node *nodes = realloc(f->nodes, cap * sizeof *nodes);
            if (!nodes)
                return GP_ENOMEM;
            f->nodes = nodes;
            f->node_capacity = cap;
        }
        u = (int32_t)f->nnodes++;
    }
    front_node *n = &f->nodes[u];
    memset(n, 0, sizeof *n);
    n->disk = disk;
    n->loop = loop;
    n->barrier_cell = FRONT_NONE;
    n->next_of_disk = f->first_node[disk];
    f->first_node[disk] = u;
    return u;
}

/* Frees node u, whose segment must already be detached. */
static void free_node(front *f, int32_t u)
{
    int32_t *link = &f->first_node[f->nodes[u].disk];
    while (*link != u)
        link = &f->nodes[*link].next_of_disk;
    *link = f->nodes[u].next_of_disk;
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

int front_add_loop(front *f, const int32_t *disks, size_t n)
{
    uint32_t loop = f->next_loop++;
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

int front_place(front *f, int32_t u, int32_t c)
{
    int32_t v = f->nodes[u].next;
    int32_t w = new_node(f, c, f->nodes[u].loop);
    if (w < 0)
        return w;
    detach_segment(f, u);
    f->nodes[w].prev = u;
    f->nodes[w].next = v;
    f->nodes[u].next = w;
    f->nodes[v].prev = w;
    if (attach_segment(f, u, 1) || attach_segment(f, w, 1))
        return GP_ENOMEM;
    return 0;
}

int32_t front_node_on_loop(const front *f, int32_t disk, int32_t u)
{
    for (int32_t w = f->first_node[disk]; w != FRONT_NONE; w = f->nodes[w].next_of_disk)
        if (f->nodes[w].loop == f->nodes[u].loop)
            return w;
    return FRONT_NONE;
}

/* After a split, gives the shorter of the loops through a and b a new label, walking both
 * at the same pace so that the cost is that of the shorter one. */
static void relabel_shorter(front *f, int32_t a, int32_t b)
{
    int32_t x = f->nodes[a].next, y = f->nodes[b].next;
    while (x != a && y != b) {
        x = f->nodes[x].next;
        y = f->nodes[y].next;
    }
    int32_t start = x == a ? a : b;
    uint32_t loop = f->next_loop++;
    int32_t u = start;
    do {
        f->nodes[u].loop = loop;
        u = f->nodes[u].next;
    } while (u != start);
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
    if (w == f->nodes[v].next)
        return cut_ear(f, u, v); /* pk follows p2: p2 leaves the loop */
    if (w == f->nodes[u].prev)
        return cut_ear(f, w, u); /* pk precedes p1: p1 leaves the loop */
    /* pk elsewhere on the loop: p1 -> pk -> (on to p1) and pk' -> p2 -> (on to pk') */
    int32_t w2 = new_node(f, f->nodes[w].disk, f->nodes[u].loop);
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
    relabel_shorter(f, u, w2);
    drop_if_degenerate(f, u);
    drop_if_degenerate(f, w2);
    return 0;
}
