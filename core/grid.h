/* grid.h - the bucket grid of docs/method.md §3.4 (internal to core/): square cells of
 * side 2 R_max over the domain, each holding the disks whose centre it contains, so that
 * every disk a candidate can touch lies in the 3x3 cells around the candidate's centre.
 * Along a periodic axis (docs/method.md §3.8) the cells divide the period evenly (side
 * >= 2 R_max, at least 3 of them) and the 3x3 scan wraps, with minimum-image distances. */
#ifndef GRAINPACK_CORE_GRID_H
#define GRAINPACK_CORE_GRID_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/disk.h"
#include "grainpack/domain.h"

#ifdef __cplusplus
extern "C" {
#endif

#define GP_GRID_NONE (-1)

/* Cells along a periodic axis at the least: with three, the 3x3 scan meets no cell twice,
 * so no image of a disk is counted twice. */
#define GP_GRID_MIN_PERIOD_CELLS 3

/* Cells are singly linked lists threaded through `next`, indexed by disk. A border of
 * always-empty cells surrounds the nx x ny cells over the domain, so that a 3x3 scan
 * never tests bounds: cell (ix, iy), 0 <= ix < nx, has index (iy + 1) * stride + ix + 1.
 * The grid does not own the disks; it owns `head` and `next`. */
typedef struct gp_grid {
    double cell;       /* side of a cell, >= 2 R_max (along a walled axis: exactly) */
    double inv_cell;
    double inv_cell_x, inv_cell_y; /* 1 / side along each axis: inv_cell but where periodic */
    int32_t nx, ny;    /* cells over the domain along x and y */
    int32_t stride;    /* nx + 2 */
    size_t ncells;     /* (nx + 2) * (ny + 2), border included */
    int32_t around[9]; /* index offsets of a cell and its neighbours, in the report's order */
    int32_t *head;     /* ncells first disks, GP_GRID_NONE when empty */
    int32_t *next;     /* per disk: the next disk of its cell */
    size_t capacity;   /* entries allocated in next */
    const gp_domain *domain; /* borrowed: the domain the candidates must stay in */
} gp_grid;

/* Sets up an empty grid for disks of packing radius at most R_max in `domain` (borrowed,
 * must outlive the grid), with room for `capacity` disks (grown on demand by insert).
 * Returns 0, GP_ENOMEM, GP_ETOOBIG when the grid would exceed max_cells cells, or GP_EINVAL
 * when a periodic side is shorter than GP_GRID_MIN_PERIOD_CELLS cells of 2 R_max. */
int gp_grid_init(gp_grid *grid, const gp_domain *domain, double R_max, size_t capacity,
                 size_t max_cells);

void gp_grid_free(gp_grid *grid);

/* Makes room for disks with ids below `capacity`; returns 0 or GP_ENOMEM. */
int gp_grid_reserve(gp_grid *grid, size_t capacity);

/* Inserts disk `id` centred at (x, y) (room must have been reserved). */
void gp_grid_insert(gp_grid *grid, int32_t id, double x, double y);

/* Removes disk `id`, which was inserted with centre (x, y). */
void gp_grid_remove(gp_grid *grid, int32_t id, double x, double y);

/* The first disk of `disks` overlapping the candidate packing disk (x, y, R), skipping
 * ids skip_a and skip_b, searched in the report's order (own cell, the four edge
 * neighbours, the four corners); GP_GRID_NONE if there is none. Does not test the domain. */
int32_t gp_grid_first_overlap(const gp_grid *grid, const gp_disk *disks, double x, double y,
                              double R, int32_t skip_a, int32_t skip_b);

/* All disks overlapping the candidate, as above; writes at most `cap` ids to `out` and
 * returns how many overlap. */
size_t gp_grid_overlaps(const gp_grid *grid, const gp_disk *disks, double x, double y,
                        double R, int32_t skip_a, int32_t skip_b, int32_t *out, size_t cap);

/* The cell (ix, iy) holding point (x, y), 0 <= ix < nx, 0 <= iy < ny; points outside the
 * domain go to the nearest cell along a walled axis, to their image's cell along a periodic
 * one. Inline, as the next two: every grid query starts here. */
static inline void gp_grid_coords(const gp_grid *grid, double x, double y, int32_t *ix,
                                  int32_t *iy)
{
    if (grid->domain->periodic)
        gp_domain_wrap(grid->domain, &x, &y);
    double cx = x * grid->inv_cell_x, cy = y * grid->inv_cell_y;
    *ix = !(cx >= 0.0) ? 0 : (cx >= (double)grid->nx ? grid->nx - 1 : (int32_t)cx);
    *iy = !(cy >= 0.0) ? 0 : (cy >= (double)grid->ny ? grid->ny - 1 : (int32_t)cy);
}

/* The index in `head` of cell (ix, iy) (0 <= ix < nx, 0 <= iy < ny). */
static inline size_t gp_grid_index(const gp_grid *grid, int32_t ix, int32_t iy)
{
    return (size_t)(iy + 1) * (size_t)grid->stride + (size_t)(ix + 1);
}

/* The index in `head` of cell (ix, iy) for any ix, iy within one period of the domain's
 * cells: wrapped along a periodic axis, the empty border cell along a walled one when
 * just outside (the barriers' cell ranges and the periodic scan use it). */
static inline size_t gp_grid_index_wrapped(const gp_grid *grid, int32_t ix, int32_t iy)
{
    if (grid->domain->periodic & GP_PERIODIC_X)
        ix = ix < 0 ? ix + grid->nx : (ix >= grid->nx ? ix - grid->nx : ix);
    if (grid->domain->periodic & GP_PERIODIC_Y)
        iy = iy < 0 ? iy + grid->ny : (iy >= grid->ny ? iy - grid->ny : iy);
    return gp_grid_index(grid, ix, iy);
}

/* The index in `head` of the cell holding point (x, y) (see gp_grid_coords). */
static inline size_t gp_grid_cell(const gp_grid *grid, double x, double y)
{
    int32_t ix, iy;
    gp_grid_coords(grid, x, y, &ix, &iy);
    return gp_grid_index(grid, ix, iy);
}

#ifdef __cplusplus
}
#endif
#endif
