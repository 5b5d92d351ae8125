/* io_csv3d.c - the 3D packing as CSV: one line per sphere, x,y,z,r,R (r the grain radius,
 * R = r + j(r)), as the 2D CSV's x,y,r,R; written window by window (writer3d.h). */
#include "grainpack/pack3d.h"
#include "writer3d.h"

static void head(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    (void)param;
    gp_out_puts(out, "x,y,z,r,R\n");
}

static void sphere(gp_writer *w, gp_out *out, size_t i, int param)
{
    (void)param;
    const gp_window3d *win = gp_state3d_window(w, out, GP_W3_SPHERES, i);
    if (!win)
        return;
    const gp_sphere *s = &win->spheres[i - win->first];
    const double v[5] = {s->x, s->y, s->z, s->r, s->R};
    for (int k = 0; k < 5; k++) {
        if (k)
            gp_out_char(out, ',');
        gp_out_double(out, v[k]);
    }
    gp_out_char(out, '\n');
}

int gp_plan_csv3d(gp_writer *w, const gp_plan3d_args *a)
{
    int rc = gp_plan3d_state(w, a, sizeof(gp_state3d));
    if (rc)
        return rc;
    gp_writer_text(w, head, 0);
    gp_writer_items(w, sphere, a->result->packing.count, 0);
    return 0;
}

int gp_write_spheres_csv(gp_out *out, const gp_packing3d *packing)
{
    gp_result3d result = {.packing = *packing};
    return gp_write3d_memory(out, GP_FORMAT3D_CSV, NULL, &result);
}
