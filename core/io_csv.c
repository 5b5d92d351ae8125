/* io_csv.c - one line per disk: x,y,r,R (r the grain radius, R = r + j(r)). */
#include "writer.h"

static void header(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    (void)param;
    GP_OUT_LITERAL(out, "x,y,r,R\n");
}

static void disk_line(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)w;
    (void)param;
    const gp_disk *d = &win->disks[j];
    gp_out_double(out, d->x);
    gp_out_char(out, ',');
    gp_out_double(out, d->y);
    gp_out_char(out, ',');
    gp_out_double(out, d->r);
    gp_out_char(out, ',');
    gp_out_double(out, d->R);
    gp_out_char(out, '\n');
}

int gp_plan_csv(gp_writer *w)
{
    gp_writer_text(w, header, 0);
    gp_writer_grains(w, disk_line, GP_GRAINS_DISKS, 0);
    return 0;
}
