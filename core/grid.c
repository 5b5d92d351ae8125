/* grid.c - bucket grid for neighbour queries (docs/method.md §3.4). */
#include "grid.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/error.h"
#include "grow.h"

/* The report's search order around cell (i, j): itself, (i+1,j), (i,j+1), (i-1,j),
 * (i,j-1), then the corners (i+1,j+1), (i-1,j+1), (i-1,j-1), (i+1,j-1). */
static const int8_t order[9][2] = {{0, 0}, {1, 0},  {0, 1},   {-1, 0}, {0, -1},
                                   {1, 1}, {-1, 1}, {-1, -1}, {1, -1}};

int gp_grid_init(gp_grid *grid, const gp_domain *domain, double R_max, size_t capacity,
                 size_t max_cells)
{
    memset(grid, 0, sizeof *grid);
    grid->domain = domain;
    grid->cell = 2.0 * R_max;
    grid->inv_cell = 1.0 / grid->cell;
    /* m = E(W / 2R_max) + 1, n = E(H / 2R_max) + 1 (report eqs. 3-4); along a periodic
     * axis E(W / 2R_max) cells of equal side W / m >= 2 R_max fill the period exactly */
    int px = (domain->periodic & GP_PERIODIC_X) != 0, py = (domain->periodic & GP_PERIODIC_Y) != 0;
    double nx = floor(domain->width * grid->inv_cell) + (px ? 0.0 : 1.0);
    double ny = floor(domain->height * grid->inv_cell) + (py ? 0.0 : 1.0);
    if ((px && nx < GP_GRID_MIN_PERIOD_CELLS) || (py && ny < GP_GRID_MIN_PERIOD_CELLS))
        return GP_EINVAL;
    if (!(nx * ny <= (double)max_cells) || nx > INT32_MAX || ny > INT32_MAX)
        return GP_ETOOBIG;
    grid->nx = (int32_t)nx;
    grid->ny = (int32_t)ny;
    grid->inv_cell_x = px ? nx / domain->width : grid->inv_cell;
    grid->inv_cell_y = py ? ny / domain->height : grid->inv_cell;
    grid->stride = grid->nx + 2;
    grid->ncells = (size_t)grid->stride * (size_t)(grid->ny + 2);
    for (int k = 0; k < 9; k++)
        grid->around[k] = order[k][0] + order[k][1] * grid->stride;
    grid->head = malloc(grid->ncells * sizeof *grid->head);
    if (!grid->head)
        return GP_ENOMEM;
    memset(grid->head, 0xff, grid->ncells * sizeof *grid->head); /* all GP_GRID_NONE */
    int rc = gp_grid_reserve(grid, capacity);
    if (rc)
        gp_grid_free(grid);
    return rc;
}

void gp_grid_free(gp_grid *grid)
{
    free(grid->head);
    free(grid->next);
    memset(grid, 0, sizeof *grid);
}

int gp_grid_reserve(gp_grid *grid, size_t capacity)
{
    if (capacity <= grid->capacity)
        return 0;
    int32_t *next = grow_realloc(grid->next, capacity, sizeof *next);
    if (!next)
        return GP_ENOMEM;
    grid->next = next;
    grid->capacity = capacity;
    return 0;
}

void gp_grid_insert(gp_grid *grid, int32_t id, double x, double y)
{
    size_t c = gp_grid_cell(grid, x, y);
    grid->next[id] = grid->head[c];
    grid->head[c] = id;
}

void gp_grid_remove(gp_grid *grid, int32_t id, double x, double y)
{
    int32_t *link = &grid->head[gp_grid_cell(grid, x, y)];
    while (*link != GP_GRID_NONE && *link != id)
        link = &grid->next[*link];
    if (*link == id)
        *link = grid->next[id];
}

/* Tests the disks of one cell's list from `id` on against the candidate (x, y, R), with
 * minimum-image distances when `periodic`: stores each overlapping one other than the
 * skipped two in out (if room) and counts it in *found. Returns 1 to stop (the first one
 * found when `first_only`). Inline, with `periodic` a constant at each call. */
static inline int scan_list(const gp_grid *grid, const gp_disk *disks, int32_t id, double x,
                            double y, double R, int32_t skip_a, int32_t skip_b, int first_only,
                            int periodic, int32_t *out, size_t cap, size_t *found)
{
    double shrink = 1.0 - GP_CONTACT_RTOL;
    for (; id != GP_GRID_NONE; id = grid->next[id]) {
        const gp_disk *d = &disks[id];
        double dx = d->x - x, dy = d->y - y;
        if (periodic)
            gp_domain_min_image(grid->domain, &dx, &dy);
        double reach = (d->R + R) * shrink;
        if (dx * dx + dy * dy >= reach * reach || id == skip_a || id == skip_b)
            continue;
        if (*found < cap)
            out[*found] = id;
        (*found)++;
        if (first_only)
            return 1;
    }
    return 0;
}

/* Visits the 3x3 cells around (x, y) in the report's order (own cell, the four edge
 * neighbours, the four corners); for each disk overlapping (x, y, R) other than the
 * skipped two, stores it (if room) and stops after the first when `first_only`. On a
 * periodic domain the cells wrap across the periodic sides and distances are between
 * nearest images. */
static size_t scan_overlaps(const gp_grid *grid, const gp_disk *disks, double x, double y,
                            double R, int32_t skip_a, int32_t skip_b, int first_only,
                            int32_t *out, size_t cap)
{
    size_t found = 0;
    if (!grid->domain->periodic) {
        const int32_t *center = grid->head + gp_grid_cell(grid, x, y);
        for (int k = 0; k < 9; k++)
            if (scan_list(grid, disks, center[grid->around[k]], x, y, R, skip_a, skip_b, first_only,
                          0, out, cap, &found))
                break;
        return found;
    }
    int32_t ix, iy;
    gp_grid_coords(grid, x, y, &ix, &iy);
    for (int k = 0; k < 9; k++) {
        size_t c = gp_grid_index_wrapped(grid, ix + order[k][0], iy + order[k][1]);
        if (scan_list(grid, disks, grid->head[c], x, y, R, skip_a, skip_b, first_only, 1, out,
                      cap, &found))
            break;
    }
    return found;
}

int32_t gp_grid_first_overlap(const gp_grid *grid, const gp_disk *disks, double x, double y,
                              double R, int32_t skip_a, int32_t skip_b)
{
    int32_t id = GP_GRID_NONE;
    scan_overlaps(grid, disks, x, y, R, skip_a, skip_b, 1, &id, 1);
    return id;
}

size_t gp_grid_overlaps(const gp_grid *grid, const gp_disk *disks, double x, double y,
                        double R, int32_t skip_a, int32_t skip_b, int32_t *out, size_t cap)
{
    return scan_overlaps(grid, disks, x, y, R, skip_a, skip_b, 0, out, cap);
}

