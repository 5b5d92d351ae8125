/* pack3d.c - the advancing-front sphere packer of docs/3d.md: spheres laid against the
 * walls first, then each new sphere tangent to the three members of a front triangle,
 * with the radius drawn from the law kept until it is placed. The front's queues are
 * pack3d_front.c's, the triangles a sphere adds pack3d_links.c's, the tangency solve
 * pack3d_solve.c's. */
#include "grainpack/pack3d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grainpack/disk.h"
#include "grainpack/pack.h"
#include "grow.h"
#include "pack3d_internal.h"

/* Fraction of the box a packing is expected to fill (random close packing): the
 * capacity guess and the progress fraction. */
#define FILL_GUESS 0.64
/* Triangle tries between two cancel checks: a try is two grid queries of at most
 * ~60 000 tests (GP_PACK3D_MAX_RADIUS_RATIO), so 256 of them stay near a millisecond at
 * worst, and a few microseconds with ordinary laws. */
#define TRIES_PER_CHECK 256

/* ---- radii ---- */

/* The class of radius R: 0 for the smallest radii up to P3_CLASSES - 1 (docs/3d.md §4). */
static int radius_class(const p3_packer *pk, double R)
{
    double c = floor(log(R / pk->R_min) * pk->class_scale);
    if (!(c >= 0.0))
        return 0;
    return c >= P3_CLASSES - 1 ? P3_CLASSES - 1 : (int)c;
}

static void draw_radius(p3_packer *pk)
{
    pk->pending_r = gp_distribution_sample(pk->params->dist, &pk->rng);
    pk->pending_R = gp_joint_packing_radius(pk->params->joint, pk->pending_r);
    pk->pending_class = radius_class(pk, pk->pending_R);
}

/* ---- the order (gp_pack3d_order) ---- */

uint32_t p3_key(const p3_packer *pk, const int32_t m[3])
{
    if (pk->params->order == GP_PACK3D_LOWEST) {
        double z = INFINITY;
        for (int i = 0; i < 3; i++)
            if (!P3_IS_WALL(m[i]) && pk->spheres[m[i]].z < z)
                z = pk->spheres[m[i]].z;
        return z == INFINITY ? 0 : (uint32_t)(z / pk->R_min);
    }
    uint32_t key = UINT32_MAX;
    for (int i = 0; i < 3; i++) {
        if (P3_IS_WALL(m[i]))
            return 0; /* the walls first */
        if (pk->level[m[i]] < key)
            key = pk->level[m[i]];
    }
    return key;
}

/* The smaller of two numbers, neither NaN (libm's fmin is a call). */
static inline double min2(double a, double b)
{
    return b < a ? b : a;
}

/* Of two positions that both fit, the one taken (docs/3d.md §3): under the level rule the
 * one nearer a wall, so that the front fills behind itself before it moves inward; in a
 * deposition the lower. Returns 1 when b is preferred to a. */
static int prefer(const p3_packer *pk, const double a[3], const double b[3])
{
    if (pk->params->order == GP_PACK3D_LOWEST)
        return b[2] < a[2];
    if (pk->box->periodic == (GP_PERIODIC_X | GP_PERIODIC_Y | GP_PERIODIC_Z))
        return p3_periodic_prefer(pk, a, b);
    const double side[3] = {pk->box->width, pk->box->height, pk->box->depth};
    double da = INFINITY, db = INFINITY;
    for (int k = 0; k < 3; k++) {
        if (p3_periodic_axis(pk->box, k))
            continue; /* no wall across it */
        da = min2(da, min2(a[k], side[k] - a[k]));
        db = min2(db, min2(b[k], side[k] - b[k]));
    }
    return db < da;
}

/* ---- spheres ---- */

static int grow_spheres(p3_packer *pk)
{
    size_t cap = pk->capacity + pk->capacity / 2 + 64;
    gp_sphere *spheres = grow_realloc(pk->spheres, cap, sizeof *spheres);
    if (!spheres)
        return GP_ENOMEM;
    pk->spheres = spheres;
    uint32_t *level = grow_realloc(pk->level, cap, sizeof *level);
    if (!level)
        return GP_ENOMEM;
    pk->level = level;
    if (p3_grid_reserve(&pk->grid, cap))
        return GP_ENOMEM;
    pk->capacity = cap;
    return 0;
}

/* Appends the pending radius as a sphere at p and draws the next radius. Returns its id
 * or a negative GP_E code with err set. */
static int32_t add_sphere(p3_packer *pk, const double p[3], uint32_t level)
{
    if (pk->params->max_spheres && pk->count >= pk->params->max_spheres)
        return gp_error_set(pk->err, GP_ETOOBIG, NULL, "the packing exceeded the cap of %zu spheres",
                            pk->params->max_spheres);
    if (pk->count == pk->capacity && grow_spheres(pk))
        return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory after %zu spheres", pk->count);
    int32_t id = (int32_t)pk->count++;
    pk->spheres[id] = (gp_sphere){p[0], p[1], p[2], pk->pending_r, pk->pending_R};
    pk->level[id] = level;
    p3_grid_insert(&pk->grid, id, p[0], p[1], p[2]);
    pk->out->fill_volume += 4.0 / 3.0 * M_PI * pk->pending_R * pk->pending_R * pk->pending_R;
    if (level == 0)
        pk->out->wall_spheres++;
    if (level > pk->out->max_level)
        pk->out->max_level = level;
    draw_radius(pk);
    return id;
}

int32_t p3_add_sphere(p3_packer *pk, const double p[3], uint32_t level)
{
    return add_sphere(pk, p, level);
}

/* Whether a sphere of packing radius R centred at p is inside the box (to GP_CONTACT_RTOL
 * of R: a sphere against a wall is at exactly R from it, up to rounding) and overlaps no
 * sphere. */
static int fits(p3_packer *pk, const double p[3], double R)
{
    if (pk->box->periodic)
        return p3_periodic_fits(pk, p, R);
    const double side[3] = {pk->box->width, pk->box->height, pk->box->depth};
    double slack = R * GP_CONTACT_RTOL;
    for (int a = 0; a < 3; a++)
        if (!(p[a] - R >= -slack) || !(p[a] + R <= side[a] + slack))
            return 0;
    if (pk->blocker != P3_NONE && p3_overlap(p[0], p[1], p[2], R, &pk->spheres[pk->blocker]))
        return 0; /* the sphere in the way of the last position tried, often in the way again */
    int32_t q = p3_grid_first_overlap(&pk->grid, pk->spheres, p[0], p[1], p[2], R, pk->R_max);
    if (q == P3_NONE)
        return 1;
    pk->blocker = q;
    return 0;
}

/* ---- the loop (docs/3d.md §4) ---- */

static int check_cancel(p3_packer *pk)
{
    pk->tries = 0;
    const gp_progress *pr = pk->progress;
    if (!pr)
        return 0;
    if (gp_canceled(pr->cancel))
        return gp_error_set(pk->err, GP_ECANCELED, NULL, "packing canceled after %zu spheres", pk->count);
    if (pr->report) {
        const gp_box *b = pk->box;
        double f = pk->out->fill_volume / (FILL_GUESS * b->width * b->height * b->depth);
        pr->report(pr->ctx, "pack3d", f < 0.99 ? f : 0.99);
    }
    return 0;
}

/* The level of a sphere placed on a triangle of these members (our eq. 6 in 3D): 0 against
 * a wall, else one more than the lowest of its three spheres. */
static uint32_t new_level(const p3_packer *pk, const int32_t m[3])
{
    uint32_t level = UINT32_MAX;
    for (int i = 0; i < 3; i++) {
        if (P3_IS_WALL(m[i]))
            return 0;
        if (pk->level[m[i]] < level)
            level = pk->level[m[i]];
    }
    return level + 1;
}

/* Tries the pending radius on triangle t: its two positions (or the one away from the
 * sphere behind it), the preferred first. Returns 1 and places the sphere when one fits,
 * 0 when none does, or a GP_E code. */
static int try_triangle(p3_packer *pk, int32_t t)
{
    pk->out->attempts++;
    if (++pk->tries >= TRIES_PER_CHECK) {
        int rc = check_cancel(pk);
        if (rc)
            return rc;
    }
    p3_tri tri = pk->fr.tris[t];
    double R = pk->pending_R, pos[2][3];
    int n = p3_tangent(pk->spheres, pk->box, tri.m, R, pos);
    for (int s = 0; pk->box->periodic && s < n; s++)
        p3_wrap(pk->box, pos[s]); /* a sphere across a periodic side: its image inside */
    if (n == 2 && tri.behind != P3_NONE) {
        /* the two positions mirror each other: the one nearer the sphere behind is filled */
        const gp_sphere *b = &pk->spheres[tri.behind];
        double d[2];
        for (int s = 0; s < 2; s++) {
            double v[3] = {pos[s][0] - b->x, pos[s][1] - b->y, pos[s][2] - b->z};
            if (pk->box->periodic)
                p3_min_image(pk->box, v);
            d[s] = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        }
        if (d[0] < d[1])
            memcpy(pos[0], pos[1], sizeof pos[0]);
        n = 1;
    }
    int first = n == 2 && prefer(pk, pos[0], pos[1]) ? 1 : 0;
    for (int k = 0; k < n; k++) {
        const double *p = pos[k ? 1 - first : first];
        if (!fits(pk, p, R))
            continue;
        int32_t c = add_sphere(pk, p, new_level(pk, tri.m));
        if (c < 0)
            return c;
        if (p3_link(pk, c, t))
            return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for the front");
        /* the other side stays to be tried, with the new sphere behind it */
        pk->fr.tris[t].behind = c;
        p3_front_requeue(&pk->fr, t);
        return 1;
    }
    return 0;
}

/* The loop: triangles kept for a larger radius class first (they failed for a larger
 * radius and may take the pending one), then the front's, lowest key first; a triangle
 * that does not take the pending radius is kept for the radius classes below it, or
 * dropped from the smallest. The radius is kept until a triangle takes it. Ends when no
 * triangle may take it.
 *
 * Work (docs/3d.md §5): a sphere adds at most P3_LINKS (P3_LINKS + 5) / 2 triangles and
 * requeues one; a triangle is tried at most once per class on the way down (P3_CLASSES)
 * plus once per requeue; a try is two grid queries, each bounded by the radius ratio. So
 * the work is O(spheres placed), and spheres are bounded by the box's volume over the
 * smallest sphere's. */
static int run(p3_packer *pk)
{
    for (;;) {
        int cls = pk->pending_class;
        int32_t t = p3_front_pop_retry(&pk->fr, cls);
        if (t == P3_NONE)
            t = p3_front_pop(&pk->fr);
        if (t == P3_NONE)
            return 0;
        int placed = try_triangle(pk, t);
        if (placed < 0)
            return placed;
        if (placed)
            continue;
        if (cls > 0)
            p3_front_retry(&pk->fr, t, cls);
        else
            p3_front_release(&pk->fr, t);
    }
}

int gp_pack3d_check(const gp_box *b, const gp_distribution *dist, const gp_joint *joint, gp_error *err)
{
    double r_min, r_max, R_min, R_max;
    gp_distribution_support(dist, &r_min, &r_max);
    gp_joint_packing_range(joint, r_min, r_max, &R_min, &R_max);
    const double side[3] = {b->width, b->height, b->depth};
    static const char *const names[3] = {"/domain/width", "/domain/height", "/domain/depth"};
    for (int a = 0; a < 3; a++)
        if (!isfinite(side[a]) || !(side[a] > 0.0))
            return gp_error_set(err, GP_EINVAL, names[a], "a box side must be a positive number, got %g",
                                side[a]);
    if (!(R_min > 0.0) || !isfinite(R_max))
        return gp_error_set(err, GP_EINVAL, "/distribution",
                            "packing radii must be positive and finite, got %g to %g", R_min, R_max);
    if (b->periodic & ~(GP_PERIODIC_X | GP_PERIODIC_Y | GP_PERIODIC_Z))
        return gp_error_set(err, GP_EINVAL, "/domain/periodic", "unknown periodic axes 0x%x", b->periodic);
    for (int a = 0; a < 3; a++)
        if ((b->periodic & (1u << a)) && !(side[a] >= GP_PACK_MIN_PERIOD_RADII * R_max))
            return gp_error_set(err, GP_EINVAL, "/domain/periodic",
                                "a periodic side must be at least %g largest packing radii long (%g "
                                "for R_max = %g), so that only the nearest image of a sphere can "
                                "touch another; the box's %s is %g (docs/3d.md §11)",
                                GP_PACK_MIN_PERIOD_RADII, GP_PACK_MIN_PERIOD_RADII * R_max, R_max,
                                names[a] + 8, side[a]);
    for (int a = 0; a < 3; a++)
        if (!(side[a] >= 2.0 * R_max))
            return gp_error_set(err, GP_EINVAL, names[a],
                                "the largest packing sphere (diameter %g) must fit in the box, whose "
                                "side is %g",
                                2.0 * R_max, side[a]);
    if (!(R_max <= GP_PACK3D_MAX_RADIUS_RATIO * R_min))
        return gp_error_set(err, GP_EINVAL, "/distribution",
                            "packing radii from %g to %g span a ratio of %.3g, more than the 3D "
                            "packer's limit of %g: the work to test a position grows with the cube "
                            "of that ratio (docs/3d.md §5)",
                            R_min, R_max, R_max / R_min, GP_PACK3D_MAX_RADIUS_RATIO);
    for (int a = 0; a < 3; a++)
        if (!(side[a] <= GP_PACK_MAX_SIDE_RADII * R_min))
            return gp_error_set(err, GP_EINVAL, names[a],
                                "a box side of %g is %.3g smallest packing radii, above the limit of "
                                "%g: spheres placed in doubles that far from the origin would overlap "
                                "by more than the contact tolerance (docs/method.md §3.7)",
                                side[a], side[a] / R_min, GP_PACK_MAX_SIDE_RADII);
    return 0;
}

/* Sets up the packer's arrays for the expected number of spheres: 0 or a GP_E code with
 * err set. */
static int setup(p3_packer *pk)
{
    const gp_pack3d_params *params = pk->params;
    const gp_box *b = pk->box;
    double volume = b->width * b->height * b->depth;
    double expected = FILL_GUESS * volume /
                      (4.0 / 3.0 * M_PI * gp_distribution_packing_moment(params->dist, params->joint, 3));
    double guess = expected * 1.04 + 256.0;
    if (params->max_spheres && guess > (double)params->max_spheres + 1.0)
        guess = (double)params->max_spheres + 1.0;
    if (guess > (double)INT32_MAX)
        guess = (double)INT32_MAX; /* ids are int32: gp_pack3d refuses more (max_spheres) */
    size_t capacity = (size_t)guess;
    int rc = p3_grid_init(&pk->grid, b, 2.0 * pk->R_max, capacity);
    if (rc == GP_ETOOBIG)
        return gp_error_set(pk->err, rc, NULL, "the bucket grid would be too large for this box");
    if (rc)
        return gp_error_set(pk->err, rc, NULL, "out of memory for the bucket grid");
    pk->spheres = malloc(capacity * sizeof *pk->spheres);
    pk->level = malloc(capacity * sizeof *pk->level);
    pk->capacity = capacity;
    if (!pk->spheres || !pk->level)
        return gp_error_set(pk->err, GP_ENOMEM, NULL, "out of memory for %zu spheres", capacity);
    return 0;
}

int gp_pack3d(const gp_pack3d_params *params, const gp_progress *progress, gp_packing3d *out,
              gp_error *err)
{
    memset(out, 0, sizeof *out);
    int rc = gp_pack3d_check(params->box, params->dist, params->joint, err);
    if (rc)
        return rc;
    if (params->order != GP_PACK3D_LEVEL && params->order != GP_PACK3D_LOWEST)
        return gp_error_set(err, GP_EINVAL, NULL, "unknown 3D packing order %d", (int)params->order);
    double r_min, r_max, R_min, R_max;
    gp_distribution_support(params->dist, &r_min, &r_max);
    gp_joint_packing_range(params->joint, r_min, r_max, &R_min, &R_max);
    /* sphere ids are int32 */
    gp_pack3d_params capped = *params;
    if (!capped.max_spheres || capped.max_spheres > (size_t)INT32_MAX - 1)
        capped.max_spheres = (size_t)INT32_MAX - 1;

    p3_packer pk;
    memset(&pk, 0, sizeof pk);
    pk.params = &capped;
    pk.box = params->box;
    pk.progress = progress;
    pk.out = out;
    pk.err = err;
    pk.R_min = R_min;
    pk.R_max = R_max;
    pk.gap = P3_LINK_GAP;
    pk.blocker = P3_NONE;
    pk.class_scale = R_max > R_min ? P3_CLASSES / log(R_max / R_min) : 0.0;
    gp_rng_seed(&pk.rng, params->seed);
    p3_front_init(&pk.fr);

    rc = setup(&pk);
    if (rc == 0) {
        draw_radius(&pk);
        /* the first triangle: the corner of the three walls at the origin; on a periodic
         * box, those of a seed cluster (pack3d_periodic.c) */
        const int32_t corner[3] = {P3_WALL(0), P3_WALL(2), P3_WALL(4)};
        if (params->box->periodic)
            rc = p3_periodic_start(&pk);
        else if (p3_front_push(&pk.fr, corner, P3_NONE, 0))
            rc = gp_error_set(err, GP_ENOMEM, NULL, "out of memory for the front");
    }
    if (rc == 0)
        rc = run(&pk);
    out->triangles = pk.fr.made;

    free(pk.level);
    p3_front_free(&pk.fr);
    p3_grid_free(&pk.grid);
    if (rc) {
        free(pk.spheres);
        memset(out, 0, sizeof *out);
        return rc;
    }
    gp_sphere *trimmed = pk.count ? realloc(pk.spheres, pk.count * sizeof *trimmed) : NULL;
    if (!pk.count)
        free(pk.spheres);
    out->spheres = trimmed ? trimmed : (pk.count ? pk.spheres : NULL);
    out->count = pk.count;
    if (progress && progress->report)
        progress->report(progress->ctx, "pack3d", 1.0);
    return 0;
}

void gp_packing3d_free(gp_packing3d *packing)
{
    free(packing->spheres);
    memset(packing, 0, sizeof *packing);
}
