/* power_cell3d.c - the power cell of one sphere clipped to the box (power_cell3d.h), in
 * coordinates relative to its centre. */
#include "power_cell3d.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "grow.h"

/* poly_tidy's judge: a face is kept when its area is at least GP_LAGUERRE_EDGE_RTOL^2
 * times the square of the two grains' mean packing radius (the cell's own for a wall). */
static int keep_face(void *ctx, int32_t label, double area)
{
    const power_cell3d *pc = ctx;
    double R = label >= 0 ? 0.5 * (pc->p->R + pc->spheres[pc->ring[label]].R) : pc->p->R;
    double t = GP_LAGUERRE_EDGE_RTOL * R;
    return area >= t * t;
}

void power_cell3d_wall(const gp_box *box, const gp_sphere *p, int k, double inset, plane3 *h)
{
    double centre[3] = {p->x, p->y, p->z}, side[3] = {box->width, box->height, box->depth};
    int axis = k / 2;
    h->n[0] = h->n[1] = h->n[2] = 0.0;
    h->len = 1.0;
    if (k % 2 == 0) {
        h->n[axis] = -1.0;
        h->c = centre[axis] - inset;
    } else {
        h->n[axis] = 1.0;
        h->c = side[axis] - centre[axis] - inset;
    }
}

int power_cell3d_box(power_cell3d *pc)
{
    static const int32_t walls[6] = {GP_WALL3D(0), GP_WALL3D(1), GP_WALL3D(2),
                                     GP_WALL3D(3), GP_WALL3D(4), GP_WALL3D(5)};
    const gp_sphere *p = pc->p;
    const double *g = pc->grow;
    double lo[3] = {-g[0] - p->x, -g[1] - p->y, -g[2] - p->z};
    double hi[3] = {pc->box->width + g[0] - p->x, pc->box->height + g[1] - p->y, pc->box->depth + g[2] - p->z};
    return poly_box(&pc->a, lo, hi, walls);
}

int power_cell3d_tidy(power_cell3d *pc)
{
    return poly_tidy(&pc->a, POWER_CELL3D_MERGE_RTOL * pc->p->R, keep_face, pc, &pc->b, &pc->sc);
}

/* The largest |u|^2 over the vertices of q. */
static double reach2(const poly *q)
{
    double m = 0.0;
    for (size_t v = 0; v < q->nv; v++) {
        const double *u = q->u + 3 * v;
        double d = u[0] * u[0] + u[1] * u[1] + u[2] * u[2];
        m = d > m ? d : m;
    }
    return m;
}

int power_cell3d_build(power_cell3d *pc, int32_t i, const int32_t *ring, size_t degree,
                       int *holds_centre)
{
    const gp_sphere *p = &pc->spheres[i];
    pc->p = p;
    pc->ring = ring;
    plane3 *pl = grow(pc->pl, &pc->pl_cap, degree ? degree : 1, sizeof *pl);
    if (!pl)
        return GP_ENOMEM;
    pc->pl = pl;
    uint32_t *order = grow(pc->order, &pc->order_cap, degree ? degree : 1, sizeof *order);
    if (!order)
        return GP_ENOMEM;
    pc->order = order;
    const gp_box *box = pc->box;
    const double *g = pc->grow;
    *holds_centre = p->x > -g[0] && p->x < box->width + g[0] && p->y > -g[1] && p->y < box->height + g[1] &&
                    p->z > -g[2] && p->z < box->depth + g[2];
    /* the radical plane of p against q: |u|^2 - R_p^2 <= |u - n|^2 - R_q^2, n = q - p; for
     * spheres apart c = (d^2 + R_p^2 - R_q^2) / 2 >= R_p (R_p + R_q) > 0 */
    for (size_t k = 0; k < degree; k++) {
        const gp_sphere *q = &pc->spheres[ring[k]];
        plane3 *h = &pl[k];
        h->n[0] = q->x - p->x;
        h->n[1] = q->y - p->y;
        h->n[2] = q->z - p->z;
        double n2 = h->n[0] * h->n[0] + h->n[1] * h->n[1] + h->n[2] * h->n[2];
        h->len = sqrt(n2);
        h->c = 0.5 * (n2 + p->R * p->R - q->R * q->R);
        *holds_centre &= h->c > 0.0;
        /* nearest plane first (insertion sort of a ring): the far ones then miss the cell */
        size_t m = k;
        while (m > 0 && pl[order[m - 1]].c * h->len > h->c * pl[order[m - 1]].len) {
            order[m] = order[m - 1];
            m--;
        }
        order[m] = (uint32_t)k;
    }
    if (!*holds_centre)
        return 0;
    int rc = power_cell3d_box(pc);
    double r2 = reach2(&pc->a);
    for (size_t m = 0; m < degree && rc == 0 && pc->a.nf > 0; m++) {
        const plane3 *h = &pl[order[m]];
        /* a plane beyond the farthest vertex cuts nothing, nor do the ones after it */
        if (h->c * h->c > r2 * h->len * h->len)
            break;
        rc = poly_cut(&pc->a, h->n, h->c, (int32_t)order[m], &pc->b, &pc->sc);
        if (rc == 0)
            r2 = reach2(&pc->a);
    }
    return rc ? rc : power_cell3d_tidy(pc);
}

void power_cell3d_free(power_cell3d *pc)
{
    poly_free(&pc->a);
    poly_free(&pc->b);
    poly_scratch_free(&pc->sc);
    free(pc->pl);
    free(pc->order);
    memset(pc, 0, sizeof *pc);
}
