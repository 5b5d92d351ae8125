/* pack3d_internal.h - the parts of the 3D packer (internal to core/, docs/3d.md):
 * pack3d_grid.c the bucket grid, pack3d_solve.c the tangency solve, pack3d_front.c the
 * front of triangles, pack3d.c the loop, pack3d_periodic.c periodic boxes. */
#ifndef GRAINPACK_CORE_PACK3D_INTERNAL_H
#define GRAINPACK_CORE_PACK3D_INTERNAL_H

#include <stddef.h>
#include <stdint.h>

#include "grainpack/pack3d.h"

/* No sphere / no triangle. */
#define P3_NONE (-1)

/* A member of a front triangle is a sphere id (>= 0) or one of the six walls, coded
 * P3_WALL(w) for w in 0..5: w / 2 is the axis (x, y, z), w % 2 the side (0 at 0, 1 at the
 * box's far side). */
#define P3_WALLS 6
#define P3_WALL(w) (-2 - (int32_t)(w))
#define P3_IS_WALL(m) ((m) <= -2)
#define P3_WALL_INDEX(m) (-2 - (m))

/* ---- the bucket grid (pack3d_grid.c) ---- */

/* Cells of side >= the `cell_min` given to p3_grid_init, each the head of a list of the
 * spheres whose centres lie in it (linked through next[]). */
typedef struct p3_grid {
    double cell[3];      /* side of a cell along each axis (box side / cells) */
    double inv[3];       /* 1 / cell */
    int32_t n[3];        /* cells along each axis */
    int32_t *head;       /* owned; n[0] n[1] n[2] entries, P3_NONE for an empty cell */
    int32_t *next;       /* owned; per sphere */
} p3_grid;

/* Cells along an axis at most (so that indices and products stay in int32 and size_t
 * without overflow, and the head array within a few GB). */
#define P3_GRID_MAX_CELLS 400000000.0

/* Sets up the grid of `box` with cells of side >= cell_min and room for `capacity`
 * spheres. Returns 0, GP_ETOOBIG (more than P3_GRID_MAX_CELLS cells) or GP_ENOMEM; the grid
 * owns its arrays (p3_grid_free). */
int p3_grid_init(p3_grid *grid, const gp_box *box, double cell_min, size_t capacity);
/* Room for `capacity` spheres: 0 or GP_ENOMEM (the grid is then unchanged). */
int p3_grid_reserve(p3_grid *grid, size_t capacity);
void p3_grid_insert(p3_grid *grid, int32_t id, double x, double y, double z);
/* The head of cell (i, j, k)'s list. */
static inline int32_t p3_grid_cell(const p3_grid *grid, int32_t i, int32_t j, int32_t k)
{
    return grid->head[((size_t)k * (size_t)grid->n[1] + (size_t)j) * (size_t)grid->n[0] + (size_t)i];
}
/* The heads of the cells (0..n[0]-1, j, k). */
static inline const int32_t *p3_grid_row(const p3_grid *grid, int32_t j, int32_t k)
{
    return grid->head + ((size_t)k * (size_t)grid->n[1] + (size_t)j) * (size_t)grid->n[0];
}
void p3_grid_free(p3_grid *grid);
/* The index range of the cells a ball of radius `reach` around (x, y, z) meets. */
void p3_grid_range(const p3_grid *grid, double x, double y, double z, double reach, int32_t lo[3],
                   int32_t hi[3]);
/* The first sphere (in grid order) whose packing sphere overlaps the ball (x, y, z, R)
 * beyond GP_CONTACT_RTOL, or P3_NONE; R_max is the largest packing radius. */
int32_t p3_grid_first_overlap(const p3_grid *grid, const gp_sphere *spheres, double x, double y,
                              double z, double R, double R_max);

/* Whether packing spheres a and b overlap beyond GP_CONTACT_RTOL (disk.h's rule). */
int p3_overlap(double ax, double ay, double az, double aR, const gp_sphere *b);

/* ---- the tangency solve (pack3d_solve.c) ---- */

/* The centres of the spheres of radius R tangent to the three members of a triangle
 * (spheres from `spheres`, walls of `box`): writes up to two into out[] and returns how
 * many (0 when there is none: spheres too far apart, collinear centres, two opposite walls).
 * On a periodic box the sphere members are taken at their images nearest the first one,
 * and the centres returned may lie outside [0, side) along a periodic axis (p3_wrap). */
int p3_tangent(const gp_sphere *spheres, const gp_box *box, const int32_t m[3], double R,
               double out[2][3]);

/* ---- the front of triangles (pack3d_front.c) ---- */

/* Radius classes of the failed triangles kept for smaller radii (docs/3d.md §4): a
 * triangle that failed for a radius of class k is tried again only for radii of a class
 * below k, so it is tried at most P3_CLASSES + 1 times in all. Eight classes, geometric
 * between R_min and R_max, split a ratio of 7 in steps of 28%: finer gains nothing
 * measurable, coarser wastes pockets (docs/3d.md). */
#define P3_CLASSES 8

typedef struct p3_tri {
    int32_t m[3];     /* members: sphere ids or P3_WALL(w) */
    int32_t behind;   /* a sphere on the filled side (its mirror position is not tried), or P3_NONE */
    int32_t next;     /* in its bucket's or class's list, or the free list */
    uint32_t key;     /* its bucket (the order's key) */
} p3_tri;

typedef struct p3_front {
    p3_tri *tris;      /* owned pool */
    size_t count, capacity;
    int32_t free_list;
    int32_t *head, *tail; /* owned; per key: the FIFO of waiting triangles */
    size_t nkeys;      /* keys with room in head/tail */
    uint32_t low;      /* no waiting triangle has a key below this */
    size_t waiting;    /* triangles in the key buckets */
    int32_t retry[P3_CLASSES]; /* per class: the triangles that failed for it (a stack) */
    uint32_t retrying;   /* bit k set when retry[k] is not empty */
    uint64_t made;     /* triangles pushed in all */
} p3_front;

void p3_front_init(p3_front *fr);
void p3_front_free(p3_front *fr);
/* Queues a new triangle under `key`: 0 or GP_ENOMEM. */
int p3_front_push(p3_front *fr, const int32_t m[3], int32_t behind, uint32_t key);
/* Queues triangle t again under its key (the same triangle, its other side to try). */
void p3_front_requeue(p3_front *fr, int32_t t);
/* The waiting triangle of lowest key (first pushed first), taken off; or P3_NONE. */
int32_t p3_front_pop(p3_front *fr);
/* Keeps triangle t for radii of a class below `cls` (cls >= 1). */
void p3_front_retry(p3_front *fr, int32_t t, int cls);
/* A triangle kept for a class above `cls`, taken off; or P3_NONE. */
int32_t p3_front_pop_retry(p3_front *fr, int cls);
/* Returns triangle t to the pool. */
void p3_front_release(p3_front *fr, int32_t t);

/* ---- the packer's state (pack3d.c, pack3d_links.c) ---- */

/* Spheres a new sphere links with at most (docs/3d.md §3): the nearest by gap. A sphere
 * makes at most P3_LINKS (P3_LINKS + 5) / 2 triangles (pairs of links and walls), which
 * bounds the work per sphere; 12 is the kissing number, the most a sphere can touch
 * among equal ones; 24 moved the densities by 0.002 at most (docs/3d.md §6). */
#ifndef P3_LINKS
#define P3_LINKS 12
#endif
/* Two spheres (or a sphere and a wall) are linked when the gap between their packing
 * spheres is below P3_LINK_GAP R_min: a smallest sphere fits between them; a wider gap
 * is left to the triangles of the spheres around it (docs/3d.md §3 measures the choice). */
#ifndef P3_LINK_GAP
#define P3_LINK_GAP 1.0
#endif

typedef struct p3_packer {
    const gp_pack3d_params *params;
    const gp_box *box;
    const gp_progress *progress;
    gp_rng rng;
    double pending_r, pending_R; /* the drawn radius, kept until it is placed */
    int pending_class;           /* its radius class (P3_CLASSES) */
    int32_t blocker;             /* the sphere in the way of the last position tested, or P3_NONE */
    gp_sphere *spheres;
    uint32_t *level;             /* per sphere: 0 on a wall, else 1 + the lowest of its three */
    size_t count, capacity;
    p3_grid grid;
    p3_front fr;
    double R_min, R_max, gap;    /* gap: the link gap P3_LINK_GAP R_min */
    double class_scale;          /* P3_CLASSES / log(R_max / R_min), 0 for one radius */
    gp_packing3d *out;
    gp_error *err;
    uint32_t tries;              /* since the last cancel check */
} p3_packer;

/* The key a triangle of these members is queued under (the order's, gp_pack3d_order). */
uint32_t p3_key(const p3_packer *pk, const int32_t m[3]);

/* Makes the triangles of new sphere c with its links (pack3d_links.c): pairs of the
 * spheres and walls within the link gap of c and of each other. `parent` (P3_NONE for
 * none) is the triangle c was placed on: a new triangle of two of its members has the
 * third behind it. Returns 0 or GP_ENOMEM. */
int p3_link(p3_packer *pk, int32_t c, int32_t parent);

/* Appends the pending radius as a sphere at p (inside the box, wrapped) with this level,
 * draws the next radius (pack3d.c). Returns its id or a negative GP_E code with err set. */
int32_t p3_add_sphere(p3_packer *pk, const double p[3], uint32_t level);

/* ---- periodic boxes (pack3d_periodic.c, docs/3d.md §11) ---- */

/* Whether axis a of the box is periodic. */
static inline int p3_periodic_axis(const gp_box *box, int a)
{
    return (box->periodic >> a) & 1u;
}

/* Turns the vector d between two points into the shortest between their images along the
 * box's periodic axes (the minimum image; unchanged along walled axes). Both points must
 * lie in [0, side) along those axes (stored centres and wrapped positions do). */
void p3_min_image(const gp_box *box, double d[3]);
/* Brings p into [0, side) along the box's periodic axes. */
void p3_wrap(const gp_box *box, double p[3]);
/* The cells a ball of radius `reach` around p meets: along each axis `count[a]` cells from
 * lo[a] on, to be taken modulo n[a] (p3_wrap_cell) on a periodic axis, where a range as
 * wide as the grid is every cell once. */
void p3_grid_span(const p3_grid *grid, unsigned periodic, const double p[3], double reach, int32_t lo[3],
                  int32_t count[3]);
/* Cell index i (0 <= i < 2 n) of a span, modulo n. */
static inline int32_t p3_wrap_cell(int32_t i, int32_t n)
{
    return i >= n ? i - n : i;
}
/* fits() on a periodic box: the sphere (p, R) inside along the walled axes (to
 * GP_CONTACT_RTOL of R) and overlapping no sphere's nearest image; sets pk->blocker to the
 * sphere in the way. */
int p3_periodic_fits(p3_packer *pk, const double p[3], double R);
/* Of two positions that both fit in a box with no wall, whether b is preferred to a: the
 * one nearer the seed cluster (the first sphere's centre, minimum image), so that the
 * front fills behind itself before it moves outward as it does from the walls. */
int p3_periodic_prefer(const p3_packer *pk, const double a[3], const double b[3]);
/* The initial front of a box with a periodic axis: a seed cluster of spheres against the
 * walls left (three mutually tangent ones when there is none), linked. 0 or a GP_E code
 * with err set. */
int p3_periodic_start(p3_packer *pk);

#endif
