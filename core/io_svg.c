/* io_svg.c - a picture of a result: the domain, each grain coloured by its radius or by
 * the balance criterion F, with a colour bar and a caption. Without Laguerre cells the
 * grains are disks with their grain-boundary ring (the joint, from r to R) in dark grey;
 * with cells they are the (shrunk) cells on a dark grey ground, which is the boundary
 * band, optionally with the grain disks outlined. Kept compact for 10^5 grains: one
 * element per grain, grouped by colour class. */
#include <math.h>
#include <stdlib.h>

#include "grainpack/io.h"
#include "io_svg_mesh.h"

/* Colour classes of the scale; more would not be told apart on screen. */
#define COLOR_CLASSES 16
/* The class of grains without a value (F is not defined on the wall layer). */
#define NO_VALUE (-1)
/* Width of the picture in pixels for the domain's longer side. */
#define PICTURE_PX 1000.0

#define BACKGROUND "#f4f1ea" /* voids between packing disks */
#define JOINT "#3b3b3b"      /* grain-boundary ring, and the band between cells */
#define OUTLINE "#1d1d1d"
#define NO_VALUE_FILL "#c8c8c8"

/* A ramp from deep blue through teal and green to gold and coral, light enough at both
 * ends for the dark joint rings to stand out. */
static const unsigned char ramp[][3] = {
    {44, 62, 140}, {42, 157, 143}, {138, 177, 125}, {233, 196, 106}, {231, 111, 81}};

static void class_color(int cls, char out[8])
{
    if (cls == NO_VALUE) {
        snprintf(out, 8, "%s", NO_VALUE_FILL);
        return;
    }
    double t = COLOR_CLASSES > 1 ? (double)cls / (COLOR_CLASSES - 1) : 0.0;
    double pos = t * (double)(sizeof ramp / sizeof ramp[0] - 1);
    int i = (int)pos;
    if (i >= (int)(sizeof ramp / sizeof ramp[0]) - 1)
        i = (int)(sizeof ramp / sizeof ramp[0]) - 2;
    double f = pos - i;
    int rgb[3];
    for (int k = 0; k < 3; k++)
        rgb[k] = (int)lround(ramp[i][k] + f * (ramp[i + 1][k] - ramp[i][k]));
    snprintf(out, 8, "#%02x%02x%02x", rgb[0], rgb[1], rgb[2]);
}

/* What the colours say: the grain radius over the law's support, or F over
 * [0, F_max before balancing] (the same scale for a structure before and after). */
typedef struct colouring {
    const char *title, *symbol;
    double lo, hi;
    const double *F; /* NULL when colouring by radius */
} colouring;

static colouring choose_colouring(const gp_spec *spec, const gp_result *result)
{
    colouring c = {"grain radius", "r", 0.0, 0.0, NULL};
    if (spec->picture_color == GP_PICTURE_COLOR_QUALITY && result->has_balance) {
        const gp_balance_result *b = &result->balance;
        c = (colouring){"balance criterion F", "F", 0.0, b->after_only ? b->after.max : b->before.max, b->F};
        return c;
    }
    gp_distribution_support(&spec->dist, &c.lo, &c.hi);
    return c;
}

static int grain_class(const colouring *c, const gp_disk *d, size_t i)
{
    double v = c->F ? c->F[i] : d->r;
    if (isnan(v))
        return NO_VALUE;
    if (!(c->hi > c->lo))
        return COLOR_CLASSES / 2;
    int k = (int)((v - c->lo) / (c->hi - c->lo) * COLOR_CLASSES);
    return k < 0 ? 0 : (k >= COLOR_CLASSES ? COLOR_CLASSES - 1 : k);
}

/* How the disks' joint rings are drawn: as a stroke centred between r and R, one width
 * for the whole picture when the joint is constant. */
typedef struct rings {
    int has_joint, constant;
    double width;
} rings;

static rings ring_style(const gp_packing *p)
{
    rings s = {0, 1, p->count ? p->disks[0].R - p->disks[0].r : 0.0};
    for (size_t i = 1; i < p->count && s.constant; i++)
        s.constant = fabs((p->disks[i].R - p->disks[i].r) - s.width) <= 1e-12 * p->disks[0].R;
    s.has_joint = !s.constant || s.width > 0.0;
    return s;
}

static void draw_disks(FILE *out, const gp_result *result, const colouring *c, double H, int dec)
{
    const gp_packing *p = &result->packing;
    rings s = ring_style(p);
    for (int cls = c->F ? NO_VALUE : 0; cls < COLOR_CLASSES; cls++) {
        char color[8];
        class_color(cls, color);
        fprintf(out, "<g fill=\"%s\"", color);
        if (s.has_joint) {
            fprintf(out, " stroke=\"" JOINT "\"");
            if (s.constant)
                fprintf(out, " stroke-width=\"%.*f\"", dec + 1, s.width);
        }
        fputs(">\n", out);
        for (size_t i = 0; i < p->count; i++) {
            const gp_disk *d = &p->disks[i];
            if (grain_class(c, d, i) != cls)
                continue;
            fprintf(out, "<circle cx=\"%.*f\" cy=\"%.*f\" r=\"%.*f\"", dec, d->x, dec, H - d->y,
                    dec + 1, s.has_joint ? 0.5 * (d->r + d->R) : d->r);
            if (s.has_joint && !s.constant)
                fprintf(out, " stroke-width=\"%.*f\"", dec + 1, d->R - d->r);
            fputs("/>\n", out);
        }
        fputs("</g>\n", out);
    }
}

static void draw_cells(FILE *out, const gp_spec *spec, const gp_result *result,
                       const colouring *c, double H, int dec)
{
    const gp_packing *p = &result->packing;
    const gp_cells *cells = &result->cells;
    fprintf(out, "<rect x=\"0\" y=\"0\" width=\"%.17g\" height=\"%.17g\" fill=\"" JOINT "\"/>\n",
            spec->domain.width, H);
    for (int cls = c->F ? NO_VALUE : 0; cls < COLOR_CLASSES; cls++) {
        char color[8];
        class_color(cls, color);
        fprintf(out, "<g fill=\"%s\">\n", color);
        for (size_t i = 0; i < cells->count; i++) {
            if (grain_class(c, &p->disks[i], i) != cls)
                continue;
            fputs("<polygon points=\"", out);
            for (size_t k = cells->start[i]; k < cells->start[i + 1]; k++)
                fprintf(out, "%s%.*f,%.*f", k > cells->start[i] ? " " : "", dec, cells->xy[2 * k],
                        dec, H - cells->xy[2 * k + 1]);
            fputs("\"/>\n", out);
        }
        fputs("</g>\n", out);
    }
    if (!spec->picture_disks)
        return;
    double r_min, r_max;
    gp_distribution_support(&spec->dist, &r_min, &r_max);
    fprintf(out, "<g fill=\"none\" stroke=\"" OUTLINE "\" stroke-width=\"%.*f\">\n", dec + 1,
            0.04 * r_min);
    for (size_t i = 0; i < p->count; i++)
        fprintf(out, "<circle cx=\"%.*f\" cy=\"%.*f\" r=\"%.*f\"/>\n", dec, p->disks[i].x, dec,
                H - p->disks[i].y, dec + 1, p->disks[i].r);
    fputs("</g>\n", out);
}

/* The colour bar, its labels, and a caption of what the picture shows. */
static void draw_legend(FILE *out, const gp_spec *spec, const gp_result *result,
                        const colouring *c, double font, double bar_h, int dec)
{
    const gp_pack_stats *st = &result->stats;
    double W = spec->domain.width, H = spec->domain.height;
    double bar_y = H + 0.03 * (W > H ? W : H), seg_w = W / COLOR_CLASSES;
    for (int cls = 0; cls < COLOR_CLASSES; cls++) {
        char color[8];
        class_color(cls, color);
        fprintf(out, "<rect x=\"%.*f\" y=\"%.*f\" width=\"%.*f\" height=\"%.*f\" fill=\"%s\"/>\n",
                dec, seg_w * cls, dec, bar_y, dec, seg_w * 1.01, dec, bar_h, color);
    }
    double text_y = bar_y + bar_h + 1.1 * font;
    fprintf(out,
            "<g font-family=\"sans-serif\" font-size=\"%.*f\" fill=\"" OUTLINE "\">\n"
            "<text x=\"0\" y=\"%.*f\">%s = %.4g</text>\n"
            "<text x=\"%.*f\" y=\"%.*f\" text-anchor=\"middle\">%s%s</text>\n"
            "<text x=\"%.*f\" y=\"%.*f\" text-anchor=\"end\">%s = %.4g</text>\n",
            dec, font, dec, text_y, c->symbol, c->lo, dec, W / 2, dec, text_y, c->title,
            c->F ? " (grey: not interior, F undefined)" : "", dec, W, dec, text_y, c->symbol, c->hi);
    fprintf(out, "<text x=\"0\" y=\"%.*f\">%zu grains, packing density %.4f, grain fraction %.4f, seed %llu",
            dec, text_y + 1.4 * font, st->count, st->packing_density, st->grain_fraction,
            (unsigned long long)spec->seed);
    fputs("</text>\n", out);
    double line_y = text_y + 1.4 * font;
    const gp_balance_result *b = &result->balance;
    if (result->has_balance && b->after_only)
        fprintf(out, "<text x=\"0\" y=\"%.*f\">%s balancing: F_max %.3f, mean F %.3f</text>\n", dec,
                line_y += 1.4 * font, gp_balance_method_name(b->method), b->after.max, b->after.mean);
    else if (result->has_balance)
        fprintf(out, "<text x=\"0\" y=\"%.*f\">%s balancing: F_max %.3f to %.3f, mean F %.3f to %.3f</text>\n",
                dec, line_y += 1.4 * font, gp_balance_method_name(b->method), b->before.max,
                b->after.max, b->before.mean, b->after.mean);
    if (result->has_cells)
        fprintf(out, "<text x=\"0\" y=\"%.*f\">Laguerre cells (%s shrink): boundary band %.3f of the area</text>\n",
                dec, line_y += 1.4 * font, gp_shrink_name(result->cells.shrink), result->cell_stats.band_fraction);
    if (result->has_mesh) {
        const gp_mesh_stats *ms = &result->mesh.stats;
        fprintf(out, "<text x=\"0\" y=\"%.*f\">mesh%s: %zu triangles, %zu quadrilaterals, %zu nodes, angles %.1f to %.1f degrees</text>\n",
                dec, line_y += 1.4 * font, gp_svg_mesh_drawable(&result->mesh) ? "" : " (too fine to draw)",
                ms->triangles, ms->quads, ms->nodes, ms->min_angle, ms->max_angle);
    }
    fputs("</g>\n", out);
}

int gp_write_svg(FILE *out, const gp_spec *spec, const gp_result *result)
{
    const gp_pack_stats *st = &result->stats;
    double W = spec->domain.width, H = spec->domain.height;
    double L = W > H ? W : H;
    double r_lo, r_hi;
    gp_distribution_support(&spec->dist, &r_lo, &r_hi);
    colouring c = choose_colouring(spec, result);

    /* decimals: a ten-thousandth of the picture, or a fiftieth of the smallest grain */
    double resolution = fmin(L * 1e-4, r_lo / 50.0);
    int decimals = (int)ceil(-log10(resolution));
    decimals = decimals < 0 ? 0 : (decimals > 9 ? 9 : decimals);

    double margin = 0.03 * L, font = 0.022 * L, bar_h = 0.025 * L;
    double legend_h = bar_h + (3.5 + 1.4 * (result->has_balance + result->has_cells + result->has_mesh)) * font;
    double vw = W + 2 * margin, vh = H + 2 * margin + legend_h;
    double px = PICTURE_PX / L;
    fprintf(out,
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
            "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"%.*f %.*f %.*f %.*f\" "
            "width=\"%.0f\" height=\"%.0f\">\n",
            decimals, -margin, decimals, -margin, decimals, vw, decimals, vh, vw * px, vh * px);
    fprintf(out, "<title>grainpack: %zu grains in %g x %g, packing density %.4f</title>\n",
            st->count, W, H, st->packing_density);
    fprintf(out, "<rect x=\"%.*f\" y=\"%.*f\" width=\"%.*f\" height=\"%.*f\" fill=\"white\"/>\n",
            decimals, -margin, decimals, -margin, decimals, vw, decimals, vh);
    fprintf(out, "<rect x=\"0\" y=\"0\" width=\"%.17g\" height=\"%.17g\" fill=\"" BACKGROUND "\"/>\n",
            W, H);
    if (result->has_cells)
        draw_cells(out, spec, result, &c, H, decimals);
    else
        draw_disks(out, result, &c, H, decimals);
    if (result->has_mesh) {
        gp_out mesh_out;
        if (gp_out_init_file(&mesh_out, out))
            return GP_ENOMEM;
        int rc = gp_svg_mesh(&mesh_out, result, H, decimals);
        gp_out_free(&mesh_out);
        if (rc)
            return rc;
    }
    fprintf(out,
            "<rect x=\"0\" y=\"0\" width=\"%.17g\" height=\"%.17g\" fill=\"none\" "
            "stroke=\"" OUTLINE "\" stroke-width=\"%.*f\"/>\n",
            W, H, decimals, 0.002 * L);
    draw_legend(out, spec, result, &c, font, bar_h, decimals);
    fputs("</svg>\n", out);
    return ferror(out) ? GP_EIO : 0;
}
