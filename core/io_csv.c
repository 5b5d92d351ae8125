/* io_csv.c - one line per disk: x,y,r,R (r the grain radius, R = r + j(r)). */
#include "grainpack/io.h"

int gp_write_csv(FILE *out, const gp_result *result)
{
    fputs("x,y,r,R\n", out);
    const gp_packing *p = &result->packing;
    for (size_t i = 0; i < p->count; i++)
        fprintf(out, "%.17g,%.17g,%.17g,%.17g\n", p->disks[i].x, p->disks[i].y, p->disks[i].r,
                p->disks[i].R);
    return ferror(out) ? GP_EIO : 0;
}
