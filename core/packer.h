/* packer.h - the packer's state and the helpers its parts share (internal to core/):
 * pack.c runs the advancing front, pack_walls.c lays the initial front along the walls,
 * pack_periodic.c starts it on a periodic domain. */
#ifndef GRAINPACK_CORE_PACKER_H
#define GRAINPACK_CORE_PACKER_H

#include <stddef.h>
#include <stdint.h>

#include "front.h"
#include "grid.h"
#include "grainpack/pack.h"
#include "grainpack/rng.h"

/* Units of work between two cancel checks. A unit is one step of a loop that places
 * nothing, or PACK_TESTS_PER_UNIT of the disks a grid query may have to test at worst
 * (packer.query_units): 4096 units are under a millisecond whatever the law
 * (docs/method.md §3.7). */
#define PACK_WORK_PER_CHECK 4096
#define PACK_TESTS_PER_UNIT 64
/* Cancel checks per progress report: reports stay at a few hundred a second at most. */
#define PACK_CHECKS_PER_REPORT 16

typedef struct packer {
    const gp_pack_params *params;
    const gp_progress *progress;
    gp_rng rng;
    double pending_r, pending_R; /* the drawn radius, kept until it is placed */

    gp_disk *disks;
    uint32_t *level;    /* per disk (report eq. 6) */
    uint8_t *closings;  /* per disk: closings it started as p1 */
    size_t count, capacity;
    gp_grid grid;
    front fr;

    int32_t *conflicts; /* scratch for the closing step, room for two at least */
    size_t conflict_capacity;

    gp_packing *out;
    gp_error *err;
    uint64_t work;      /* units of work since the last check */
    uint64_t query_units; /* units a grid query counts for (see PACK_TESTS_PER_UNIT) */
    uint32_t checks;    /* cancel checks since the last progress report */

    /* the front's rule (gp_front_rule): the level band, and for the waiting rule the
     * levels a held radius may climb and the radius a waiting pocket must take */
    uint32_t band, wait;
    double R_min, R_alive;
    int32_t blocked;    /* the disk in the way of the last position tested, or -1 */
} packer;

/* Reads the cancel flag and now and then reports progress: 0, or GP_ECANCELED with err
 * set. */
int pack_check(packer *pk);

/* Counts `units` of work and checks for cancellation every PACK_WORK_PER_CHECK of them:
 * every loop of the packer that can run without placing a disk calls it, with
 * pk->query_units for each grid query. */
static inline int pack_work(packer *pk, uint64_t units)
{
    pk->work += units;
    return pk->work >= PACK_WORK_PER_CHECK ? pack_check(pk) : 0;
}

/* Appends the pending radius as a disk at (x, y) with the given level and draws the next
 * radius. Returns its id, or a negative GP_E code with err set. */
int32_t pack_add_disk(packer *pk, double x, double y, uint32_t level);

/* Whether the pending-size disk of radius R centred at (x, y) fits: inside the domain,
 * overlapping no disk but skip_a and skip_b, crossing no barrier but skip_segment's.
 * *blocker (when not NULL) gets the disk in the way, or GP_GRID_NONE. */
int pack_fits(const packer *pk, double x, double y, double R, int32_t skip_a, int32_t skip_b,
              int32_t skip_segment, int32_t *blocker);

/* The packing radius from which on the disk tangent to a and b (d apart, unit vector
 * (ux, uy) from a to b; the disk on the left) overlaps q, given that it does at R_hi: a
 * value in [R_lo, R_hi], R_lo when q is in the way of every radius from R_lo, R_hi when
 * the limit is not known (docs/method.md §3.5). */
double pack_fit_limit(const gp_disk *a, const gp_disk *b, double d, double ux, double uy,
                      const gp_disk *q, double R_lo, double R_hi);

/* Lays the initial front along the walls (docs/method.md §3.2) and hands its loop to the
 * front. Returns 0 or a GP_E code with err set. */
int pack_walls(packer *pk);

/* The initial front of a periodic domain (docs/method.md §3.8): a seed cluster of three
 * mutually tangent disks on a torus, or a chain of disks along each wall of a strip
 * periodic along the other axis. Returns 0 or a GP_E code with err set. */
int pack_periodic_start(packer *pk);

/* Disk d as seen from (x, y): d itself on a walled domain; on a periodic one a copy of d
 * at its image nearest (x, y), written to *image (the caller's). */
static inline const gp_disk *pack_image(const packer *pk, const gp_disk *d, double x, double y,
                                        gp_disk *image)
{
    const gp_domain *dom = pk->params->domain;
    if (!dom->periodic)
        return d;
    double dx = d->x - x, dy = d->y - y;
    gp_domain_min_image(dom, &dx, &dy);
    *image = *d;
    image->x = x + dx;
    image->y = y + dy;
    return image;
}

#endif
