/* front.h - the advancing front (internal to core/).
 *
 * The front is a set of closed loops of disk centres, counter-clockwise around the part
 * of the domain still empty: each loop is a circular doubly linked list of nodes, and the
 * segment u -> u.next of node u has the filled region on its right. A disk can sit on
 * several loops (where a loop was pinched in two), once per node.
 *
 * Segments waiting to be worked sit in one bucket per level (docs/method.md §3.3): the untried ones
 * in a list, newest first, and the ones that failed in lists by the radius they failed
 * for, quantised into FRONT_FAIL_CLASSES classes over the law's range with a bit mask of
 * the classes in use. "The next segment of a level that has not failed for a radius <= R"
 * is then found, and every update made, in O(1).
 *
 * A segment whose disks do not touch spans a void. Such a "barrier" is registered in the
 * bucket grid so that no later disk is placed across it into the filled side; with it,
 * the loops stay simple and every closing cuts a triangle off the empty region.
 *
 * On a periodic domain (docs/method.md §3.8) segments join nearest images, and a loop may
 * wind around the torus: its winding (the sum of its segments, in periods) is kept per
 * loop, because two winding loops can bound the same empty region, and closing one on
 * the other merges them. */
#ifndef GRAINPACK_CORE_FRONT_H
#define GRAINPACK_CORE_FRONT_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/disk.h"
#include "grid.h"

#define FRONT_NONE (-1)

/* A node's hot part: what the packer's loop reads for every segment it tries (its
 * geometry, its failure record, its links), in one 64-byte cache line (nodes are
 * allocated on a line boundary). The parts a try does not read are in front_cold: at
 * 10^7 disks the front's nodes are far larger than the cache, so a try should touch one
 * line, not two (cachegrind: 13 % fewer first-level misses at 10^6; no CPU time gain
 * measured out of the noise, bench/RESULTS.md). */
typedef struct front_node {
    double ux, uy, length;  /* the segment disk -> next's disk: unit vector a -> b and
                               distance of the centres */
    double fail_R;          /* the segment takes no radius from fail_R up; +inf if untried */
    int32_t disk;
    int32_t prev, next;     /* neighbours on the loop; next is the free list when unused */
    int32_t list_prev, list_next; /* neighbours in its list (untried, or failed of a class) */
    int32_t blocker;        /* SEG_FAILED: the disk last in the way, tested first next time */
    uint32_t level;         /* level(a) + level(b) (report eq. 5) */
    uint8_t state;          /* SEG_UNTRIED, SEG_FAILED or SEG_FROZEN */
    uint8_t fail_class;     /* SEG_FAILED: class of fail_R, the list it is in */
} front_node;

/* A node's cold part (same index as its front_node): read when loops are labelled,
 * closed or searched, and for barriers. */
typedef struct front_cold {
    int32_t next_of_disk;   /* another node of the same disk */
    uint32_t loop;          /* loop label: equal labels, same loop */
    int32_t barrier_cell;   /* FRONT_NONE unless the segment is a registered barrier */
    double gap[4];          /* the uncovered part of a barrier: px, py, qx, qy */
} front_cold;

enum { SEG_UNTRIED = 0, SEG_FAILED, SEG_FROZEN };

/* Classes of failure radii: 128 over the law's packing-radius range, so a class spans
 * under 1% of it, which is how finely "failed for a radius <= R" is told. */
#define FRONT_FAIL_CLASSES 128

/* One registration of a barrier in one grid cell. */
typedef struct front_link {
    int32_t node; /* whose segment is the barrier */
    int32_t next; /* next registration in the same cell; next free one when unused */
} front_link;

/* The segments of one level still to work: the untried ones in a list, newest first (the
 * front sweeps on from the last placement, as the report's in-place list does), and the
 * failed ones in one list per class of the radius they failed for. */
typedef struct front_bucket {
    int32_t untried;        /* newest untried segment, FRONT_NONE if none */
    int32_t failed[FRONT_FAIL_CLASSES]; /* newest failed segment of each class */
    uint64_t failed_mask[FRONT_FAIL_CLASSES / 64]; /* bit c set: class c not empty */
} front_bucket;

/* The front borrows the disks, levels and grid of its packer (they must outlive it) and
 * owns everything else. */
typedef struct front {
    const gp_disk *const *disks;  /* the packer's disk array (it moves when it grows) */
    const uint32_t *const *levels;
    const gp_grid *grid;

    front_node *nodes;            /* on a cache line (grow_aligned) */
    front_cold *cold;             /* per node, as nodes */
    size_t nnodes, node_capacity;
    int32_t free_node;
    uint32_t next_loop;
    front_bucket *buckets;
    uint32_t nbuckets, low;       /* no bucket below `low` holds a segment */
    double class_lo, class_scale; /* fail class = (fail_R - class_lo) * class_scale */
    size_t active;                /* segments in the buckets, still to be worked */
    size_t frozen;                /* segments given up on */

    int32_t *first_node;          /* per disk: one of its nodes, FRONT_NONE if off the front */
    size_t disk_capacity;
    int32_t *barrier_head;        /* per grid cell: first registration (front_link) */
    front_link *links;
    size_t nlinks, link_capacity;
    int32_t free_link;
    int32_t *winding;             /* periodic domains: per loop label, periods along x, y */
    size_t winding_capacity;      /* labels with room in winding */
} front;

/* Sets up an empty front over `grid`, with per-disk room for `disk_capacity` disks, for
 * packing radii in [R_lo, R_hi]. Returns 0 or GP_ENOMEM (front_free is safe either way). */
int front_init(front *f, const gp_disk *const *disks, const uint32_t *const *levels,
               const gp_grid *grid, size_t disk_capacity, double R_lo, double R_hi);
void front_free(front *f);

/* Makes per-disk room for `capacity` disks; returns 0 or GP_ENOMEM. */
int front_reserve_disks(front *f, size_t capacity);

/* Registers a new disk (off the front). */
void front_disk_added(front *f, int32_t disk);

/* Makes a loop of the n >= 3 disks given counter-clockwise; returns 0 or GP_ENOMEM. */
int front_add_loop(front *f, const int32_t *disks, size_t n);

/* The lowest level holding a segment to work (meaningful while f->active > 0). */
uint32_t front_low_level(front *f);

/* The node whose segment to try first at `level` (the newest untried one, else one of the
 * lowest failure class, the tightest pocket), or FRONT_NONE when the level is empty. */
int32_t front_top(const front *f, uint32_t level);

/* A node of `level` whose segment has not failed for a radius <= R: the newest untried
 * one, else the failed one of the lowest class above R's (best fit), or FRONT_NONE. A
 * failure radius in the same class as R counts as <= R (see front.c). */
int32_t front_next_eligible(const front *f, uint32_t level, double R);

/* Records that node u's segment takes no packing radius from R up (it keeps the smallest
 * such R): the radius that failed there, or the limit pack_fit_limit found below it. */
void front_mark_failed(front *f, int32_t u, double R);

/* Disk c was placed against node u's segment (a, b), touching a (and b too when
 * `c_touches_b`): the segment becomes a -> c -> b. Returns 0 or GP_ENOMEM. */
int front_place(front *f, int32_t u, int32_t c, int c_touches_b);

/* The node of `disk` on the same loop as node u, or FRONT_NONE. */
int32_t front_node_on_loop(const front *f, int32_t disk, int32_t u);

/* On a periodic domain, when node u's loop winds around the domain: a node of `disk` on
 * another loop that winds too (the two then bound the same empty band, see front.c), or
 * FRONT_NONE. */
int32_t front_node_on_winding_loop(const front *f, int32_t disk, int32_t u);

/* Closes the front at node u's segment (p1, p2) on node w of the same loop (docs/method.md §3.5):
 * the segment is replaced by p1 -> pk -> p2, which cuts an ear off the loop when pk is
 * next to p1 or p2, and splits the loop in two otherwise. Loops left with fewer than
 * three nodes enclose nothing and go. On a periodic domain w may be on another winding
 * loop (front_node_on_winding_loop): the same replacement then merges the two loops into
 * one. Returns 0 or GP_ENOMEM. */
int front_close(front *f, int32_t u, int32_t w);

/* Takes node u's segment out of the work; it still bounds its loop. */
void front_freeze(front *f, int32_t u);

/* A barrier (other than node `skip`'s segment) that the disk (x, y, R) would cross, as
 * the node whose segment it is, or FRONT_NONE. */
int32_t front_barrier_crossed(const front *f, double x, double y, double R, int32_t skip);

#endif
