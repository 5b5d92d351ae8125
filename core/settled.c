/* settled.c - the centres a balancing sweep may skip: their last step's record, and the log
 * of the moves since, by cell (see settled.h). */
#include "settled.h"

#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grow.h"
#include "nearby.h"

int settled_init(settled *s, const gp_grid *grid, double R_max, size_t n)
{
    memset(s, 0, sizeof *s);
    s->grid = grid;
    s->R_max = R_max;
    s->n = n;
    size_t m = n ? n : 1;
    s->state = calloc(m, sizeof *s->state);
    s->since = malloc(m * sizeof *s->since);
    s->box = malloc(4 * m * sizeof *s->box);
    for (int k = 0; k < 2; k++)
        s->log[k].head = malloc(grid->ncells * sizeof *s->log[k].head);
    if (!s->state || !s->since || !s->box || !s->log[0].head || !s->log[1].head) {
        settled_free(s);
        return GP_ENOMEM;
    }
    for (int k = 0; k < 2; k++)
        memset(s->log[k].head, 0xff, grid->ncells * sizeof *s->log[k].head); /* all GP_GRID_NONE */
    return 0;
}

void settled_sweep(settled *s)
{
    s->current ^= 1;
    settled_log *log = &s->log[s->current];
    /* only the cells the dropped moves chained into need emptying */
    for (size_t k = 0; k < log->count; k++)
        log->head[gp_grid_cell(s->grid, log->moves[k].x, log->moves[k].y)] = GP_GRID_NONE;
    log->count = 0;
}

/* Chains one position of a moved disk in this sweep's log; 0 or GP_ENOMEM. */
static int log_position(settled *s, int32_t id, double x, double y)
{
    settled_log *log = &s->log[s->current];
    settled_move *grown = grow(log->moves, &log->cap, log->count + 1, sizeof *grown);
    if (!grown)
        return GP_ENOMEM;
    log->moves = grown;
    int32_t *head = &log->head[gp_grid_cell(s->grid, x, y)];
    log->moves[log->count] = (settled_move){s->now, x, y, id, *head};
    *head = (int32_t)log->count++;
    return 0;
}

int settled_moved(settled *s, int32_t id, double old_x, double old_y, double x, double y)
{
    s->now++;
    return log_position(s, id, old_x, old_y) || log_position(s, id, x, y) ? GP_ENOMEM : 0;
}

void settled_prefetch(const settled *s, size_t c)
{
    for (int k = 0; k < 2; k++)
        for (int row = -1; row <= 1; row++)
            __builtin_prefetch(&s->log[k].head[c + (size_t)((ptrdiff_t)row * s->grid->stride) - 1]);
}

void settled_record(settled *s, int32_t id, int state, double x0, double y0, double x1, double y1)
{
    s->state[id] = (uint8_t)state;
    s->since[id] = s->now;
    double *box = &s->box[4 * (size_t)id];
    box[0] = x0;
    box[1] = y0;
    box[2] = x1;
    box[3] = y1;
}

/* Whether a move logged in `log` after `since` reaches the box of a disk of radius R:
 * the moves in each cell are chained newest first, so each chain is read down to the
 * first older one. */
static int moved_near(const settled *s, const settled_log *log, const gp_disk *disks, uint64_t since,
                      const double *box, double R, int32_t ix0, int32_t iy0, int32_t ix1, int32_t iy1)
{
    for (int32_t iy = iy0; iy <= iy1; iy++)
        for (size_t c = gp_grid_index(s->grid, ix0, iy), last = gp_grid_index(s->grid, ix1, iy); c <= last; c++)
            for (int32_t k = log->head[c]; k != GP_GRID_NONE && log->moves[k].time > since; k = log->moves[k].next) {
                const settled_move *m = &log->moves[k];
                if (nearby_box_reaches(box[0], box[1], box[2], box[3], m->x, m->y, disks[m->id].R, R))
                    return 1;
            }
    return 0;
}

int settled_holds(settled *s, const gp_disk *disks, int32_t id, double R)
{
    int state = s->state[id];
    if (state == SETTLED_UNKNOWN)
        return state;
    /* the cells nearby_gather read for this box: a disk that reaches it lies in them */
    const double *box = &s->box[4 * (size_t)id];
    double reach = R + s->R_max;
    int32_t ix0, iy0, ix1, iy1;
    gp_grid_coords(s->grid, box[0] - reach, box[1] - reach, &ix0, &iy0);
    gp_grid_coords(s->grid, box[2] + reach, box[3] + reach, &ix1, &iy1);
    /* the record is from the last sweep or this one (settled_sweep): both logs cover it */
    if (moved_near(s, &s->log[s->current], disks, s->since[id], box, R, ix0, iy0, ix1, iy1) ||
        moved_near(s, &s->log[s->current ^ 1], disks, s->since[id], box, R, ix0, iy0, ix1, iy1)) {
        s->state[id] = SETTLED_UNKNOWN;
        return SETTLED_UNKNOWN;
    }
    s->since[id] = s->now; /* nothing it read changed up to now */
    return state;
}

void settled_free(settled *s)
{
    free(s->state);
    free(s->since);
    free(s->box);
    for (int k = 0; k < 2; k++) {
        free(s->log[k].head);
        free(s->log[k].moves);
    }
    memset(s, 0, sizeof *s);
}
