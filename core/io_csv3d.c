/* io_csv3d.c - the 3D packing as CSV: one line per sphere, x,y,z,r,R (r the grain radius,
 * R = r + j(r)), as the 2D CSV's x,y,r,R. */
#include "grainpack/pack3d.h"

int gp_write_spheres_csv(gp_out *out, const gp_packing3d *packing)
{
    gp_out_puts(out, "x,y,z,r,R\n");
    for (size_t i = 0; i < packing->count; i++) {
        const gp_sphere *s = &packing->spheres[i];
        const double v[5] = {s->x, s->y, s->z, s->r, s->R};
        for (int k = 0; k < 5; k++) {
            if (k)
                gp_out_char(out, ',');
            gp_out_double(out, v[k]);
        }
        gp_out_char(out, '\n');
    }
    return gp_out_flush(out);
}
