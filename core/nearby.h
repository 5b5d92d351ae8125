/* nearby.h - the disks near the positions a balancing sweep tries (internal to core/): the
 * disks sorted by bucket-grid cell, with x, y and R side by side so that the cells of a
 * row are read in one run instead of one linked disk at a time; sorted again after each
 * sweep, while the disks moved since the sort wait in the grid's lists. At 10^6 grains
 * gathering a centre's neighbourhood through the lists was a fifth of a sweep. */
#ifndef GRAINPACK_CORE_NEARBY_H
#define GRAINPACK_CORE_NEARBY_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/disk.h"
#include "grainpack/domain.h"
#include "grid.h"

/* A disk as sorted: everything a gathering reads of it in one half cache line. */
typedef struct nearby_entry {
    double x, y, R;
    int64_t id;
} nearby_entry;

typedef struct nearby {
    gp_grid grid;       /* the cells; its lists hold the disks moved since the sort */
    double R_max;       /* the largest radius */
    size_t n;
    uint32_t *start;    /* grid.ncells + 1: cell c sorted into entries start[c] .. start[c+1]-1 */
    nearby_entry *sorted; /* n entries in cell order; x is INFINITY once its disk has moved */
    uint32_t *entry;    /* per disk: its entry */
    /* the disks gathered for one centre of radius gR, and the box of positions they
     * answer for; gr2: the square of the distance under which each overlaps that centre */
    double *gx, *gy, *gr2, gR;
    size_t gn, gcap;
    size_t blocker;     /* the gathered disk that blocked the last position tested, if any */
    double x0, y0, x1, y1;
} nearby;

/* Whether a disk of radius Rq at (x, y) is closer than R + Rq to the box [x0, x1] x
 * [y0, y1]: the test that picks the disks nearby_gather gathers. */
static inline int nearby_box_reaches(double x0, double y0, double x1, double y1, double x, double y,
                                     double Rq, double R)
{
    double cx = x < x0 ? x0 : (x > x1 ? x1 : x), cy = y < y0 ? y0 : (y > y1 ? y1 : y);
    double dx = x - cx, dy = y - cy, r = R + Rq;
    return dx * dx + dy * dy < r * r;
}

/* Sets up nb for disks[0..n-1] (at most 2^31 - 1) of packing radius at most R_max in
 * `domain` (borrowed) and sorts them. Returns 0, GP_ENOMEM or GP_ETOOBIG (the grid
 * would be too large); on failure nb is empty and only nearby_free may follow. */
int nearby_init(nearby *nb, const gp_domain *domain, const gp_disk *disks, size_t n, double R_max);

/* Sorts all the disks again from their positions and empties the lists. */
void nearby_sort(nearby *nb, const gp_disk *disks);

/* Asks the memory for what a gathering around (x, y) will read: first the cells' starts
 * and lists (the 3 x 3 cells around it), then, once those have come, the disks sorted in
 * them. Only a hint: the answers do not change. (The sweeps visit the centres in id
 * order, which on the packer's ids jumps across the structure: at 10^6 grains the median
 * distance between consecutive ids is 500 radii, and every gathering waited on memory.) */
size_t nearby_prefetch_cells(const nearby *nb, double x, double y); /* returns the cell of (x, y) */
void nearby_prefetch_entries(const nearby *nb, double x, double y);

/* Disk `id`, which was at (old_x, old_y), is now at disks[id]. */
void nearby_move(nearby *nb, const gp_disk *disks, int32_t id, double old_x, double old_y);

/* Gathers the disks other than `id` that may overlap a disk of radius R anywhere in the
 * box [x0, x1] x [y0, y1] widened by `margin`: those closer to it than R + their own R.
 * Returns 0 or GP_ENOMEM. */
int nearby_gather(nearby *nb, const gp_disk *disks, int32_t id, double R, double x0, double y0,
                  double x1, double y1, double margin);

/* Whether a disk of radius R at (x, y) overlaps no disk but `id` (GP_CONTACT_RTOL, the
 * predicate of gp_grid_first_overlap): tested against the gathered disks when (x, y)
 * lies in their box and R is the radius they were gathered for, else against the cells
 * around it. Remembers which gathered disk blocked it, to test that one first next time. */
int nearby_is_clear(nearby *nb, const gp_disk *disks, int32_t id, double R, double x, double y);

/* Whether a disk of radius R at (x, y) is one the gathered disks answer for: (x, y) in
 * their box and R the radius they were gathered for. */
static inline int nearby_in_box(const nearby *nb, double x, double y, double R)
{
    return x >= nb->x0 && x <= nb->x1 && y >= nb->y0 && y <= nb->y1 && R == nb->gR;
}

/* nearby_is_clear for a position nearby_in_box accepts: tested against the gathered disks
 * alone. */
int nearby_is_clear_in_box(nearby *nb, double x, double y);

void nearby_free(nearby *nb);

#endif
