/* settled.h - the centres a balancing sweep may skip (internal to core/): a centre whose last
 * step went nowhere (settled, blocked, or without a target) goes nowhere again as long as
 * nothing that step read has changed: its position, its ring and the positions of its ring,
 * and the disks near the positions it tried. Skipping it gives the same sweep, to the bit;
 * at 10^5 grains of the variable law a third of the visits are skipped (bench/GEOM_RESULTS.md). */
#ifndef GRAINPACK_CORE_SETTLED_H
#define GRAINPACK_CORE_SETTLED_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/disk.h"
#include "grid.h"

/* What a centre's last step found, while it holds. */
enum { SETTLED_UNKNOWN = 0, SETTLED_STILL, SETTLED_REFUSED };

/* One position of a moved disk (where it was, or where it went), chained by cell. */
typedef struct settled_move {
    uint64_t time;
    double x, y;
    int32_t id;
    int32_t next;
} settled_move;

/* The moves of one sweep, chained newest first in each cell of the grid. */
typedef struct settled_log {
    int32_t *head; /* per cell: the newest move there, or GP_GRID_NONE */
    settled_move *moves;
    size_t count, cap;
} settled_log;

typedef struct settled {
    const gp_grid *grid; /* borrowed: the cells of the gathering (nearby.h) */
    double R_max;        /* the largest radius */
    size_t n;
    uint64_t now;        /* counts the moves */
    uint8_t *state;      /* per centre: SETTLED_* */
    uint64_t *since;     /* per centre: `now` when its step was last found to hold */
    double *box;         /* per centre: the box its last step gathered for (x0, y0, x1, y1) */
    settled_log log[2];  /* this sweep's moves and the last sweep's (see settled_sweep) */
    int current;         /* which of the two logs is this sweep's */
} settled;

/* Sets up s for n centres of radius at most R_max on `grid` (borrowed, as long as s
 * lives); 0 or GP_ENOMEM (s is then empty and only settled_free may follow). */
int settled_init(settled *s, const gp_grid *grid, double R_max, size_t n);

/* A sweep begins: the moves of the sweep before the last are dropped. Every centre whose
 * state is known must have been visited in the last sweep (settled_forget the others). */
void settled_sweep(settled *s);

/* Disk `id` moved from (old_x, old_y) to (x, y): the centres whose steps read
 * either position find out in settled_holds. Returns 0 or GP_ENOMEM. */
int settled_moved(settled *s, int32_t id, double old_x, double old_y, double x, double y);

/* What the last step of centre `id` found no longer holds (it moved, its ring changed, a
 * neighbour of its ring moved, or a sweep passed it by). */
static inline void settled_forget(settled *s, int32_t id)
{
    s->state[id] = SETTLED_UNKNOWN;
}

/* The step of centre `id` went nowhere (`state` SETTLED_STILL or SETTLED_REFUSED) after
 * gathering for the box x0, y0, x1, y1 (nearby_gather's, margin included). */
void settled_record(settled *s, int32_t id, int state, double x0, double y0, double x1, double y1);

/* The state of centre `id` (radius R) if its last step still holds: no disk moved from or
 * to a position whose disk could reach the box it gathered for since (nearby_box_reaches:
 * the test that picks the gathered disks); else SETTLED_UNKNOWN, and its state is forgotten. */
int settled_holds(settled *s, const gp_disk *disks, int32_t id, double R);

/* Asks the memory for the cells' chains settled_holds will read for a centre in cell c
 * of the grid (the one nearby_prefetch_cells returns): only a hint. */
void settled_prefetch(const settled *s, size_t c);

void settled_free(settled *s);

#endif
