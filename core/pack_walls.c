/* pack_walls.c - the initial front of docs/method.md §3.2: disks laid along the walls,
 * counter-clockwise, from the corner that starts a longest wall. A front that starts
 * from something else than the walls (a seed cluster) would replace this file's one
 * entry point, pack_walls, and hand its own loop to front_add_loop. */
#include <math.h>
#include <stdlib.h>

#include "packer.h"

enum { N = GP_DOMAIN_CORNERS };

/* The boundary as the packer walks it: corner v[i], unit vector e[i] along the wall from
 * corner i to corner i + 1, and the inward normal n[i] of that wall. */
typedef struct walls {
    double vx[N], vy[N], ex[N], ey[N], nx[N], ny[N];
} walls;

static void walls_init(const gp_domain *dom, walls *w)
{
    for (int i = 0; i < N; i++)
        gp_domain_corner(dom, i, &w->vx[i], &w->vy[i]);
    for (int i = 0; i < N; i++) {
        double dx = w->vx[(i + 1) % N] - w->vx[i], dy = w->vy[(i + 1) % N] - w->vy[i];
        double len = sqrt(dx * dx + dy * dy);
        w->ex[i] = dx / len;
        w->ey[i] = dy / len;
        w->nx[i] = -w->ey[i]; /* inward: the domain is counter-clockwise */
        w->ny[i] = w->ex[i];
    }
}

/* The corner the walk starts from: the first that starts a longest wall. A rectangle
 * turned by 90 degrees has its longest walls turned too, so its packing starts from the
 * turned corner and is the turned packing: a tall strip fills as the wide one does
 * (docs/method.md §3.2). A square starts at corner 0 whichever way it is turned. */
static int start_corner(const walls *w)
{
    int best = 0;
    double best_len = -1.0;
    for (int i = 0; i < N; i++) {
        double dx = w->vx[(i + 1) % N] - w->vx[i], dy = w->vy[(i + 1) % N] - w->vy[i];
        double len = dx * dx + dy * dy;
        if (len > best_len * (1.0 + 1e-12)) {
            best = i;
            best_len = len;
        }
    }
    return best;
}

/* Distance of disk d along wall i from its corner. */
static double along(const walls *w, int i, const gp_disk *d)
{
    return (d->x - w->vx[i]) * w->ex[i] + (d->y - w->vy[i]) * w->ey[i];
}

/* Places the pending radius in corner i, tangent to both walls, if it fits there. The
 * centre at distance R from both walls is v + R (n_prev + n) / (1 + n_prev . n).
 * *id gets the disk, or -1 if it does not fit. Returns 0 or a GP_E code. */
static int corner_disk(packer *pk, const walls *w, int i, int32_t *id)
{
    int p = (i + N - 1) % N;
    double scale = pk->pending_R / (1.0 + w->nx[p] * w->nx[i] + w->ny[p] * w->ny[i]);
    double cx = w->vx[i] + scale * (w->nx[p] + w->nx[i]);
    double cy = w->vy[i] + scale * (w->ny[p] + w->ny[i]);
    *id = -1;
    if (!pack_fits(pk, cx, cy, pk->pending_R, -1, -1, FRONT_NONE, NULL))
        return 0;
    int32_t c = pack_add_disk(pk, cx, cy, 0);
    if (c < 0)
        return c;
    *id = c;
    return 0;
}

/* The disk ids of the initial loop, grown as the walk goes. */
typedef struct id_list {
    int32_t *ids;
    size_t n, cap;
} id_list;

static int list_append(packer *pk, id_list *l, int32_t id)
{
    if (l->n == l->cap) {
        size_t cap = l->cap ? 2 * l->cap : 256;
        int32_t *grown = realloc(l->ids, cap * sizeof *grown);
        if (!grown)
            return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for the initial front");
        l->ids = grown;
        l->cap = cap;
    }
    l->ids[l->n++] = id;
    return 0;
}

/* Walks wall i from its corner to the next, appending to `loop` each disk laid: the
 * corner's own disk when it fitted (`corner`, else -1), then disks that each touch the
 * wall and the disks before them, as near the corner as those allow, until one would
 * leave the domain past the next corner. When the corner disk did not fit (a wall
 * shorter than two disks), the walk starts anyway, pushed along by the disks already
 * there: skipping the wall would leave a narrow domain's long wall empty. */
static int walk_wall(packer *pk, const walls *w, int i, int32_t corner, id_list *loop)
{
    const gp_domain *dom = pk->params->domain;
    size_t wall_start = loop->n;
    int p = (i + N - 1) % N;
    /* a disk larger than the corner's must clear the previous wall too: at the least it
     * sits where the corner disk would for its own radius */
    double clear = (w->nx[p] * w->ex[i] + w->ny[p] * w->ey[i]) /
                   (1.0 + w->nx[p] * w->nx[i] + w->ny[p] * w->ny[i]);
    double t_last = -INFINITY; /* where the last disk laid on this wall is along it */
    if (corner >= 0) {
        int rc = list_append(pk, loop, corner);
        if (rc)
            return rc;
        t_last = along(w, i, &pk->disks[corner]);
    }
    for (;;) {
        double R = pk->pending_R, t = clear * R;
        /* two disks of radii R and R' on a wall touch when their centres are 2 sqrt(R R')
         * apart along it; only the disks within 2 R_max of the last one can hold the new
         * one back (the nearest is not always the last: a tiny disk between two large) */
        for (size_t k = loop->n; k-- > wall_start;) {
            const gp_disk *dk = &pk->disks[loop->ids[k]];
            double tk = along(w, i, dk);
            if (tk < t_last - 2.0 * pk->grid.cell)
                break;
            double reach = tk + 2.0 * sqrt(R * dk->R);
            if (reach > t)
                t = reach;
        }
        /* any other disk in the way (the last ones of the previous wall, near the corner,
         * or across a narrow domain) pushes the disk on along the wall, just past it.
         * Termination: t only grows, and past the disk q that pushed it the candidate
         * only moves away from q, so each disk pushes at most once per wall; if rounding
         * ever failed to move t forward, the wall ends there rather than spin. */
        double cx, cy;
        for (;;) {
            cx = w->vx[i] + t * w->ex[i] + R * w->nx[i];
            cy = w->vy[i] + t * w->ey[i] + R * w->ny[i];
            if (!gp_domain_contains_disk(dom, cx, cy, R, R * GP_CONTACT_RTOL))
                return 0;
            int rc = pack_work(pk, pk->query_units);
            if (rc)
                return rc;
            int32_t q = gp_grid_first_overlap(&pk->grid, pk->disks, cx, cy, R, -1, -1);
            if (q == GP_GRID_NONE)
                break;
            const gp_disk *dq = &pk->disks[q];
            double hq = (dq->x - w->vx[i]) * w->nx[i] + (dq->y - w->vy[i]) * w->ny[i];
            double t_past = along(w, i, dq) + sqrt((R + dq->R) * (R + dq->R) - (R - hq) * (R - hq));
            if (!(t_past > t))
                return 0;
            t = t_past;
        }
        int32_t id = pack_add_disk(pk, cx, cy, 0);
        if (id < 0)
            return id;
        int rc = list_append(pk, loop, id);
        if (rc)
            return rc;
        t_last = t;
    }
}

int pack_walls(packer *pk)
{
    walls w;
    walls_init(pk->params->domain, &w);
    int start = start_corner(&w);

    /* one disk in each corner first, so that every wall knows where it must stop */
    int32_t corner[N];
    for (int k = 0; k < N; k++) {
        int rc = corner_disk(pk, &w, (start + k) % N, &corner[(start + k) % N]);
        if (rc)
            return rc;
    }

    id_list loop = {NULL, 0, 0};
    int rc = 0;
    for (int k = 0; k < N && rc == 0; k++)
        rc = walk_wall(pk, &w, (start + k) % N, corner[(start + k) % N], &loop);
    pk->out->initial_front = pk->count;
    /* fewer than three disks enclose nothing: the domain holds no more */
    if (rc == 0 && loop.n >= 3 && front_add_loop(&pk->fr, loop.ids, loop.n))
        rc = gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for the front");
    free(loop.ids);
    return rc;
}
