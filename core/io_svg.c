/* io_svg.c - a picture of a result: the domain, each grain coloured by its radius or by
 * the balance criterion F, with a colour bar and a caption. Without Laguerre cells the
 * grains are disks with their grain-boundary ring (the joint, from r to R) in dark grey;
 * with cells they are the (shrunk) cells on a dark grey ground, which is the boundary
 * band, optionally with the grain disks outlined. Kept compact for 10^5 grains: one
 * element per grain, grouped by colour class (one pass over the grains per class).
 * Coordinates are rounded to what a screen shows (see svg_decimals). On a periodic domain
 * the grains are drawn once as a symbol and used at every copy of the domain that can
 * reach the picture, clipped to it: the parts of a grain across a side show on the other
 * side, and "picture": {"tile": k} draws k copies along each periodic axis. */
#include <math.h>
#include <stdlib.h>

#include "writer.h"
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
    int by_F; /* 0: by radius */
} colouring;

static colouring choose_colouring(const gp_spec *spec, const gp_result *result)
{
    colouring c = {"grain radius", "r", 0.0, 0.0, 0};
    if (spec->picture_color == GP_PICTURE_COLOR_QUALITY && result->has_balance) {
        const gp_balance_result *b = &result->balance;
        c = (colouring){"balance criterion F", "F", 0.0, b->after_only ? b->after.max : b->before.max, 1};
        return c;
    }
    gp_distribution_support(&spec->dist, &c.lo, &c.hi);
    return c;
}

/* The colour class of grain j of a window. */
static int grain_class(const colouring *c, const gp_grain_window *win, size_t j)
{
    double v = c->by_F ? win->F[j] : win->disks[j].r;
    if (isnan(v))
        return NO_VALUE;
    if (!(c->hi > c->lo))
        return COLOR_CLASSES / 2;
    int k = (int)((v - c->lo) / (c->hi - c->lo) * COLOR_CLASSES);
    return k < 0 ? 0 : (k >= COLOR_CLASSES ? COLOR_CLASSES - 1 : k);
}

/* How the disks' joint rings are drawn: as a stroke centred between r and R, one width
 * for the whole picture when the joint is constant (within rounding: R - r of a constant
 * joint j differs from j by a few ulps of R). */
#define JOINT_CONSTANT_RTOL 1e-12

typedef struct rings {
    int has_joint, constant;
    double width;
} rings;

static rings ring_style(const gp_pack_stats *st)
{
    double tol = JOINT_CONSTANT_RTOL * (st->r_max + st->joint_max);
    rings s = {0, st->joint_max - st->joint_min <= tol, st->joint_min};
    s.has_joint = !s.constant || s.width > 0.0;
    return s;
}

/* What the steps share. */
typedef struct svg_state {
    colouring c;
    rings rings;
    double H; /* the picture's height: y is flipped (SVG's y points down) */
    double W; /* the picture's width: the domain's, times the copies along x */
    int kx, ky; /* copies of the domain along x and y (1 on walls) */
    int dec;  /* decimals of coordinates */
} svg_state;

/* Decimals of coordinates: a ten-thousandth of the picture (a tenth of a pixel of the
 * 1000-pixel picture, so ten times zoomed in a viewer still shows no rounding), or a
 * fiftieth of the smallest grain, whichever is finer. */
static int svg_decimals(const gp_spec *spec)
{
    double W = spec->domain.width, H = spec->domain.height, L = W > H ? W : H;
    double r_lo, r_hi;
    gp_distribution_support(&spec->dist, &r_lo, &r_hi);
    double resolution = fmin(L * 1e-4, r_lo / 50.0);
    int decimals = (int)ceil(-log10(resolution));
    return decimals < 0 ? 0 : (decimals > 9 ? 9 : decimals);
}

/* ' name="v"' with v at `dec` decimals (`name` a literal, up to the opening quote). */
#define attr(out, name, v, dec) \
    (GP_OUT_LITERAL(out, name), gp_out_fixed(out, v, dec), gp_out_char(out, '"'))

/* Opens the group of colour class cls. */
static void open_group(gp_writer *w, gp_out *out, int cls)
{
    svg_state *st = w->state;
    char color[8];
    class_color(cls, color);
    GP_OUT_LITERAL(out, "<g fill=\"");
    gp_out_puts(out, color);
    gp_out_char(out, '"');
    if (!w->result->has_cells && st->rings.has_joint) {
        gp_out_puts(out, " stroke=\"" JOINT "\"");
        if (st->rings.constant)
            attr(out, " stroke-width=\"", st->rings.width, st->dec + 1);
    }
    GP_OUT_LITERAL(out, ">\n");
}

static void close_group(gp_writer *w, gp_out *out, int param)
{
    (void)w;
    (void)param;
    GP_OUT_LITERAL(out, "</g>\n");
}

static void disk(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int cls)
{
    svg_state *st = w->state;
    if (grain_class(&st->c, win, j) != cls)
        return;
    const gp_disk *d = &win->disks[j];
    int dec = st->dec;
    attr(out, "<circle cx=\"", d->x, dec);
    attr(out, " cy=\"", st->H - d->y, dec);
    attr(out, " r=\"", st->rings.has_joint ? 0.5 * (d->r + d->R) : d->r, dec + 1);
    if (st->rings.has_joint && !st->rings.constant)
        attr(out, " stroke-width=\"", d->R - d->r, dec + 1);
    GP_OUT_LITERAL(out, "/>\n");
}

static void cell(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int cls)
{
    svg_state *st = w->state;
    if (grain_class(&st->c, win, j) != cls)
        return;
    GP_OUT_LITERAL(out, "<polygon points=\"");
    for (size_t k = win->start[j]; k < win->start[j + 1]; k++) {
        const double *v = &win->xy[2 * (k - win->vertex_base)];
        if (k > win->start[j])
            gp_out_char(out, ' ');
        gp_out_fixed(out, v[0], st->dec);
        gp_out_char(out, ',');
        gp_out_fixed(out, st->H - v[1], st->dec);
    }
    GP_OUT_LITERAL(out, "\"/>\n");
}

static void outline_group(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    svg_state *st = w->state;
    double r_min, r_max;
    gp_distribution_support(&w->spec->dist, &r_min, &r_max);
    gp_out_puts(out, "<g fill=\"none\" stroke=\"" OUTLINE "\"");
    attr(out, " stroke-width=\"", 0.04 * r_min, st->dec + 1);
    GP_OUT_LITERAL(out, ">\n");
}

static void outline(gp_writer *w, gp_out *out, const gp_grain_window *win, size_t j, int param)
{
    (void)param;
    svg_state *st = w->state;
    const gp_disk *d = &win->disks[j];
    attr(out, "<circle cx=\"", d->x, st->dec);
    attr(out, " cy=\"", st->H - d->y, st->dec);
    attr(out, " r=\"", d->r, st->dec + 1);
    GP_OUT_LITERAL(out, "/>\n");
}

/* A rectangle over the domain, x = 0, y = 0, with what follows as its last attributes. */
static void domain_rect(gp_writer *w, gp_out *out, const char *rest)
{
    svg_state *st = w->state;
    GP_OUT_LITERAL(out, "<rect x=\"0\" y=\"0\" width=\"");
    gp_out_double(out, st->W);
    GP_OUT_LITERAL(out, "\" height=\"");
    gp_out_double(out, st->H);
    gp_out_puts(out, rest);
}

/* Periodic domains: the grains that follow go into a symbol, not drawn by themselves. */
static void tile_open(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    GP_OUT_LITERAL(out, "<defs>\n<clipPath id=\"gp-domain\">");
    domain_rect(w, out, "\"/></clipPath>\n<g id=\"gp-tile\">\n");
}

/* Closes the symbol and draws it at every copy that reaches the picture: the k copies
 * along each periodic axis and one more on either side, whose grains across a side
 * show their parts inside. */
static void tile_close(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    svg_state *st = w->state;
    double W = w->spec->domain.width, H = w->spec->domain.height;
    GP_OUT_LITERAL(out, "</g>\n</defs>\n<g clip-path=\"url(#gp-domain)\">\n");
    int px = (w->spec->domain.periodic & GP_PERIODIC_X) != 0;
    int py = (w->spec->domain.periodic & GP_PERIODIC_Y) != 0;
    for (int i = px ? -1 : 0; i <= (px ? st->kx : 0); i++)
        for (int j = py ? -1 : 0; j <= (py ? st->ky : 0); j++) {
            attr(out, "<use href=\"#gp-tile\" x=\"", i * W, st->dec);
            attr(out, " y=\"", -j * H, st->dec);
            GP_OUT_LITERAL(out, "/>\n");
        }
    GP_OUT_LITERAL(out, "</g>\n");
}

static void head(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    svg_state *st = w->state;
    const gp_pack_stats *stats = &w->result->stats;
    double W = st->W, H = st->H;
    double L = W > H ? W : H;
    int dec = st->dec;
    double margin = 0.03 * L, font = 0.022 * L, bar_h = 0.025 * L;
    /* the mesh's caption takes two lines: on one, it ran past the right edge */
    double legend_h = bar_h + (3.5 + 1.4 * (w->result->has_balance + w->result->has_cells + 2 * w->result->has_mesh)) * font;
    double vw = W + 2 * margin, vh = H + 2 * margin + legend_h;
    double px = PICTURE_PX / L;
    gp_out_puts(out, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                     "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"");
    gp_out_fixed(out, -margin, dec);
    gp_out_char(out, ' ');
    gp_out_fixed(out, -margin, dec);
    gp_out_char(out, ' ');
    gp_out_fixed(out, vw, dec);
    gp_out_char(out, ' ');
    gp_out_fixed(out, vh, dec);
    attr(out, "\" width=\"", vw * px, 0);
    attr(out, " height=\"", vh * px, 0);
    GP_OUT_LITERAL(out, ">\n<title>grainpack: ");
    gp_out_uint(out, stats->count);
    GP_OUT_LITERAL(out, " grains in ");
    gp_out_double(out, w->spec->domain.width);
    GP_OUT_LITERAL(out, " x ");
    gp_out_double(out, w->spec->domain.height);
    if (w->spec->domain.periodic)
        gp_out_printf(out, ", periodic along %s, %d x %d copies",
                      w->spec->domain.periodic == GP_PERIODIC_X   ? "x"
                      : w->spec->domain.periodic == GP_PERIODIC_Y ? "y"
                                                                  : "x and y",
                      st->kx, st->ky);
    gp_out_printf(out, ", packing density %.4f</title>\n", stats->packing_density);
    attr(out, "<rect x=\"", -margin, st->dec);
    attr(out, " y=\"", -margin, st->dec);
    attr(out, " width=\"", vw, st->dec);
    attr(out, " height=\"", vh, st->dec);
    GP_OUT_LITERAL(out, " fill=\"white\"/>\n");
    domain_rect(w, out, "\" fill=\"" BACKGROUND "\"/>\n");
    if (w->result->has_cells) /* the band between the cells */
        domain_rect(w, out, "\" fill=\"" JOINT "\"/>\n");
}

/* The mesh's edges over the grains (nothing when too fine to draw). */
static void mesh_edges(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    svg_state *st = w->state;
    gp_svg_mesh(out, w->result, st->H, st->dec);
}

/* The domain's outline, the colour bar, its labels, and a caption of what the picture
 * shows. */
static void legend(gp_writer *w, gp_out *out, int param)
{
    (void)param;
    svg_state *st = w->state;
    const colouring *c = &st->c;
    const gp_result *result = w->result;
    const gp_pack_stats *stats = &result->stats;
    double W = st->W, H = st->H, L = W > H ? W : H;
    double font = 0.022 * L, bar_h = 0.025 * L;
    int dec = st->dec;
    domain_rect(w, out, "\" fill=\"none\" stroke=\"" OUTLINE "\"");
    attr(out, " stroke-width=\"", 0.002 * L, dec);
    GP_OUT_LITERAL(out, "/>\n");
    double bar_y = H + 0.03 * L, seg_w = W / COLOR_CLASSES;
    for (int cls = 0; cls < COLOR_CLASSES; cls++) {
        char color[8];
        class_color(cls, color);
        attr(out, "<rect x=\"", seg_w * cls, dec);
        attr(out, " y=\"", bar_y, dec);
        attr(out, " width=\"", seg_w * 1.01, dec);
        attr(out, " height=\"", bar_h, dec);
        GP_OUT_LITERAL(out, " fill=\"");
        gp_out_puts(out, color);
        GP_OUT_LITERAL(out, "\"/>\n");
    }
    double text_y = bar_y + bar_h + 1.1 * font;
    attr(out, "<g font-family=\"sans-serif\" font-size=\"", font, dec);
    gp_out_puts(out, " fill=\"" OUTLINE "\">\n");
    attr(out, "<text x=\"0\" y=\"", text_y, dec);
    gp_out_printf(out, ">%s = %.4g</text>\n", c->symbol, c->lo);
    attr(out, "<text x=\"", W / 2, dec);
    attr(out, " y=\"", text_y, dec);
    gp_out_printf(out, " text-anchor=\"middle\">%s%s</text>\n", c->title,
                  c->by_F ? " (grey: undefined)" : "");
    attr(out, "<text x=\"", W, dec);
    attr(out, " y=\"", text_y, dec);
    gp_out_printf(out, " text-anchor=\"end\">%s = %.4g</text>\n", c->symbol, c->hi);
    double line_y = text_y + 1.4 * font;
    attr(out, "<text x=\"0\" y=\"", line_y, dec);
    gp_out_printf(out, ">%zu grains, packing density %.4f, grain fraction %.4f, seed %llu</text>\n",
                  stats->count, stats->packing_density, stats->grain_fraction,
                  (unsigned long long)w->spec->seed);
    const gp_balance_result *b = &result->balance;
    if (result->has_balance) {
        attr(out, "<text x=\"0\" y=\"", line_y += 1.4 * font, dec);
        if (b->after_only)
            gp_out_printf(out, ">%s balancing: F_max %.3f, mean F %.3f</text>\n",
                          gp_balance_method_name(b->method), b->after.max, b->after.mean);
        else
            gp_out_printf(out, ">%s balancing: F_max %.3f to %.3f, mean F %.3f to %.3f</text>\n",
                          gp_balance_method_name(b->method), b->before.max, b->after.max,
                          b->before.mean, b->after.mean);
    }
    if (result->has_cells) {
        attr(out, "<text x=\"0\" y=\"", line_y += 1.4 * font, dec);
        gp_out_printf(out, ">Laguerre cells (%s shrink): boundary band %.3f of the area</text>\n",
                      gp_shrink_name(result->cells.shrink), result->cell_stats.band_fraction);
    }
    if (result->has_mesh) {
        const gp_mesh_stats *ms = &result->mesh.stats;
        attr(out, "<text x=\"0\" y=\"", line_y += 1.4 * font, dec);
        gp_out_printf(out, ">mesh%s: %zu triangles, %zu quadrilaterals, %zu nodes</text>\n",
                      gp_svg_mesh_drawable(&result->mesh) ? "" : " (too fine to draw)",
                      ms->triangles, ms->quads, ms->nodes);
        attr(out, "<text x=\"0\" y=\"", line_y += 1.4 * font, dec);
        gp_out_printf(out, ">element angles %.1f to %.1f degrees</text>\n", ms->min_angle, ms->max_angle);
    }
    GP_OUT_LITERAL(out, "</g>\n</svg>\n");
}

int gp_plan_svg(gp_writer *w)
{
    svg_state *st = calloc(1, sizeof *st);
    if (!st)
        return GP_ENOMEM;
    w->state = st;
    st->c = choose_colouring(w->spec, w->result);
    st->rings = ring_style(&w->result->stats);
    unsigned periodic = w->spec->domain.periodic;
    int tile = w->spec->picture_tile > 1 ? w->spec->picture_tile : 1;
    st->kx = (periodic & GP_PERIODIC_X) ? tile : 1;
    st->ky = (periodic & GP_PERIODIC_Y) ? tile : 1;
    st->W = st->kx * w->spec->domain.width;
    st->H = st->ky * w->spec->domain.height;
    st->dec = svg_decimals(w->spec);
    unsigned needs = GP_GRAINS_DISKS | (st->c.by_F ? GP_GRAINS_F : 0);
    gp_writer_text(w, head, 0);
    if (periodic)
        gp_writer_text(w, tile_open, 0);
    for (int cls = st->c.by_F ? NO_VALUE : 0; cls < COLOR_CLASSES; cls++) {
        gp_writer_text(w, open_group, cls);
        if (w->result->has_cells)
            gp_writer_grains(w, cell, needs | GP_GRAINS_POLYGONS, cls);
        else
            gp_writer_grains(w, disk, needs, cls);
        gp_writer_text(w, close_group, 0);
    }
    if (w->result->has_cells && w->spec->picture_disks) {
        gp_writer_text(w, outline_group, 0);
        gp_writer_grains(w, outline, GP_GRAINS_DISKS, 0);
        gp_writer_text(w, close_group, 0);
    }
    if (periodic)
        gp_writer_text(w, tile_close, 0);
    if (w->result->has_mesh)
        gp_writer_text(w, mesh_edges, 0);
    gp_writer_text(w, legend, 0);
    return 0;
}
