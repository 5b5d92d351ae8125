/* io_svg.c - a picture of a packing: the domain, each grain coloured by its radius, its
 * grain-boundary ring (the joint, from r to R) in dark grey, a colour bar and a caption.
 * Kept compact for 10^5 disks: one <circle> per grain, grouped by colour class. */
#include <math.h>
#include <stdlib.h>

#include "grainpack/io.h"

/* Colour classes of the radius scale; more would not be told apart on screen. */
#define COLOR_CLASSES 16
/* Width of the picture in pixels for the domain's longer side. */
#define PICTURE_PX 1000.0

#define BACKGROUND "#f4f1ea" /* voids between packing disks */
#define JOINT "#3b3b3b"      /* grain-boundary ring */
#define OUTLINE "#1d1d1d"

/* A ramp from deep blue through teal and green to gold and coral, light enough at both
 * ends for the dark joint rings to stand out. */
static const unsigned char ramp[][3] = {
    {44, 62, 140}, {42, 157, 143}, {138, 177, 125}, {233, 196, 106}, {231, 111, 81}};

static void class_color(int cls, char out[8])
{
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

static int radius_class(double r, double r_lo, double r_hi)
{
    if (!(r_hi > r_lo))
        return COLOR_CLASSES / 2;
    int c = (int)((r - r_lo) / (r_hi - r_lo) * COLOR_CLASSES);
    return c < 0 ? 0 : (c >= COLOR_CLASSES ? COLOR_CLASSES - 1 : c);
}

int gp_write_svg(FILE *out, const gp_spec *spec, const gp_result *result)
{
    const gp_packing *p = &result->packing;
    const gp_pack_stats *st = &result->stats;
    double W = spec->domain.width, H = spec->domain.height;
    double L = W > H ? W : H;
    double r_lo, r_hi;
    gp_distribution_support(&spec->dist, &r_lo, &r_hi);

    /* decimals: a ten-thousandth of the picture, or a fiftieth of the smallest grain */
    double resolution = fmin(L * 1e-4, r_lo / 50.0);
    int decimals = (int)ceil(-log10(resolution));
    decimals = decimals < 0 ? 0 : (decimals > 9 ? 9 : decimals);

    double margin = 0.03 * L, font = 0.022 * L, bar_h = 0.025 * L;
    double legend_h = bar_h + 3.5 * font;
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

    /* one group per colour class; the ring is the stroke, centred between r and R */
    int constant_joint = 1;
    for (size_t i = 1; i < p->count && constant_joint; i++)
        constant_joint = fabs((p->disks[i].R - p->disks[i].r) - (p->disks[0].R - p->disks[0].r)) <=
                         1e-12 * p->disks[0].R;
    double ring0 = p->count ? p->disks[0].R - p->disks[0].r : 0.0;
    int has_joint = !constant_joint || ring0 > 0.0;
    for (int cls = 0; cls < COLOR_CLASSES; cls++) {
        char color[8];
        class_color(cls, color);
        fprintf(out, "<g fill=\"%s\"", color);
        if (has_joint) {
            fprintf(out, " stroke=\"" JOINT "\"");
            if (constant_joint)
                fprintf(out, " stroke-width=\"%.*f\"", decimals + 1, ring0);
        }
        fputs(">\n", out);
        for (size_t i = 0; i < p->count; i++) {
            const gp_disk *d = &p->disks[i];
            if (radius_class(d->r, r_lo, r_hi) != cls)
                continue;
            double ring = d->R - d->r;
            fprintf(out, "<circle cx=\"%.*f\" cy=\"%.*f\" r=\"%.*f\"", decimals, d->x, decimals,
                    H - d->y, decimals + 1, has_joint ? 0.5 * (d->r + d->R) : d->r);
            if (has_joint && !constant_joint)
                fprintf(out, " stroke-width=\"%.*f\"", decimals + 1, ring);
            fputs("/>\n", out);
        }
        fputs("</g>\n", out);
    }
    fprintf(out,
            "<rect x=\"0\" y=\"0\" width=\"%.17g\" height=\"%.17g\" fill=\"none\" "
            "stroke=\"" OUTLINE "\" stroke-width=\"%.*f\"/>\n",
            W, H, decimals, 0.002 * L);

    /* colour bar of the grain radius, then a caption */
    double bar_y = H + margin, seg_w = W / COLOR_CLASSES;
    for (int cls = 0; cls < COLOR_CLASSES; cls++) {
        char color[8];
        class_color(cls, color);
        fprintf(out, "<rect x=\"%.*f\" y=\"%.*f\" width=\"%.*f\" height=\"%.*f\" fill=\"%s\"/>\n",
                decimals, seg_w * cls, decimals, bar_y, decimals, seg_w * 1.01, decimals, bar_h,
                color);
    }
    double text_y = bar_y + bar_h + 1.1 * font;
    fprintf(out,
            "<g font-family=\"sans-serif\" font-size=\"%.*f\" fill=\"" OUTLINE "\">\n"
            "<text x=\"0\" y=\"%.*f\">r = %g</text>\n"
            "<text x=\"%.*f\" y=\"%.*f\" text-anchor=\"middle\">grain radius</text>\n"
            "<text x=\"%.*f\" y=\"%.*f\" text-anchor=\"end\">r = %g</text>\n"
            "<text x=\"0\" y=\"%.*f\">%zu grains, packing density %.4f, grain fraction %.4f, "
            "seed %llu</text>\n</g>\n",
            decimals, font, decimals, text_y, r_lo, decimals, W / 2, decimals, text_y, decimals, W,
            decimals, text_y, r_hi, decimals, text_y + 1.4 * font, st->count, st->packing_density,
            st->grain_fraction, (unsigned long long)spec->seed);
    fputs("</svg>\n", out);
    return ferror(out) ? GP_EIO : 0;
}
