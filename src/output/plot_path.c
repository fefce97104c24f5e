/* src/output/plot_path.c: the path (coupler-curve) figures of mech plot: which
 * points are traced (plot_path_plan: the output points that move) and each
 * figure (plot_path_svg, called by plot_figure_write; it draws up to
 * PLOT_MAX_SERIES paths, the plan gives one per point): y against x in mm on
 * equal axes (1 mm in x is 1 mm in y on the page), a start marker and arrows
 * in the direction of motion, curves thinned past THIN_FROM rows to within
 * PLOT_THIN_TOL px. docs/plots.md, "Path figures". */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output.h"

/* Page layout, px: the plot area is PATH_W x PATH_H, at AX_L, AX_T; the
 * legend is right of it as in the other figures. */
enum { PATH_W = AX_R - AX_L, PATH_H = 392, PATH_PAGE_H = AX_T + PATH_H + 66 };
enum { PATH_ARROWS = 6 };  /* arrows per curve, evenly spread along its length */

/* ------------------------------------------------------------------ */
/* Which points are traced.                                            */

/* Does point column pair (cx, cy) move over the table's rows? */
static int moves(const mech_table *t, int cx, int cy)
{
    double x0 = NAN, y0 = NAN;
    for (int r = 0; r < t->nrows; r++) {
        double x = mech_table_get(t, r, cx), y = mech_table_get(t, r, cy);
        if (!isfinite(x) || !isfinite(y))
            continue;
        if (isnan(x0))
            x0 = x, y0 = y;
        else if (fabs(x - x0) > 1e-12 || fabs(y - y0) > 1e-12)  /* m: ground points are exact */
            return 1;
    }
    return 0;
}

int plot_path_plan(const mech_model *m, const mech_table *t, plot_figure *figs, int max)
{
    char name[160];
    int nfig = 0;
    for (int i = 0; i < m->outputs.npoints && nfig < max; i++) {
        const char *pn = m->point_names[m->outputs.points[i]];
        snprintf(name, sizeof name, "%s.x", pn);
        int cx = mech_table_column(t, name);
        snprintf(name, sizeof name, "%s.y", pn);
        int cy = mech_table_column(t, name);
        if (cx < 0 || cy < 0 || !moves(t, cx, cy))
            continue;
        plot_figure *f = &figs[nfig++];
        memset(f, 0, sizeof *f);
        f->kind = PLOT_PATH;
        snprintf(f->name, sizeof f->name, "path-%s", pn);
        snprintf(f->title, sizeof f->title, "Path of point %s", pn);
        snprintf(f->ylabel, sizeof f->ylabel, "y");
        snprintf(f->yunit, sizeof f->yunit, "mm");
        f->yscale = 1e3;
        f->col[0] = cx;
        f->ycol[0] = cy;
        snprintf(f->label[0], sizeof f->label[0], "%s", pn);
        f->nseries = 1;
    }
    return nfig;
}

/* ------------------------------------------------------------------ */
/* One figure.                                                         */

typedef struct path_ctx {
    const mech_model *m;
    const mech_table *t;
    const plot_figure *f;
    double s;           /* px per mm, both axes */
    double xlo, ylo;    /* mm at the left and bottom edges of the plot area */
    plot_axis ax, ay;
} path_ctx;

/* Series s, row r in page px (plot_vertex_fn through path_vertex). */
static int to_page(const path_ctx *c, int s, int r, double *px, double *py)
{
    double x = mech_table_get(c->t, r, c->f->col[s]) * 1e3;
    double y = mech_table_get(c->t, r, c->f->ycol[s]) * 1e3;
    *px = AX_L + (x - c->xlo) * c->s;
    *py = AX_T + PATH_H - (y - c->ylo) * c->s;
    return isfinite(x) && isfinite(y);
}

typedef struct series_ref {
    const path_ctx *c;
    int s;
} series_ref;

static int path_vertex(const void *v, int r, double *px, double *py)
{
    const series_ref *k = v;
    return to_page(k->c, k->s, r, px, py);
}

/* The scale and the view: every finite position of every series, with a
 * margin of 4 % of the larger span, centred in the plot area at the one
 * scale that fits both spans; ticks every 1, 2 or 5 x 10^k mm on both. */
static void path_view(path_ctx *c)
{
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int s = 0; s < c->f->nseries; s++)
        for (int r = 0; r < c->t->nrows; r++) {
            double x = mech_table_get(c->t, r, c->f->col[s]) * 1e3;
            double y = mech_table_get(c->t, r, c->f->ycol[s]) * 1e3;
            if (isfinite(x) && isfinite(y)) {
                xmin = fmin(xmin, x), xmax = fmax(xmax, x);
                ymin = fmin(ymin, y), ymax = fmax(ymax, y);
            }
        }
    if (!(xmax >= xmin))
        xmin = ymin = 0, xmax = ymax = 1;
    double big = fmax(fmax(xmax - xmin, ymax - ymin), 1e-9 * fmax(fabs(xmax), 1.0));
    double pad = 0.04 * big;
    c->s = fmin(PATH_W / (xmax - xmin + 2 * pad), PATH_H / (ymax - ymin + 2 * pad));
    c->xlo = 0.5 * (xmin + xmax) - 0.5 * PATH_W / c->s;
    c->ylo = 0.5 * (ymin + ymax) - 0.5 * PATH_H / c->s;
    double step = plot_nice_step(PATH_W / c->s, 8);
    plot_axis_fixed(&c->ax, c->xlo, c->xlo + PATH_W / c->s, step);
    plot_axis_fixed(&c->ay, c->ylo, c->ylo + PATH_H / c->s, step);
}

/* Root element (with the mapping from metres), title, defs, background,
 * titles. */
static void path_head(FILE *f, const path_ctx *c, const char *subtitle)
{
    /* screen x = ox + S x, y = oy - S y for x, y in metres, S = 1000 s */
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" "
               "xmlns:xlink=\"http://www.w3.org/1999/xlink\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\" font-family=\"DejaVu Sans,Arial,Helvetica,sans-serif\" "
               "font-size=\"12\" data-mech-transform=\"%.9g %.9g %.9g\" "
               "data-mech-plot=\"%d %d %d %d\">\n", FIG_W, PATH_PAGE_H, FIG_W, PATH_PAGE_H,
            1e3 * c->s, AX_L - c->xlo * c->s, AX_T + PATH_H + c->ylo * c->s, AX_L, AX_T,
            AX_R, AX_T + PATH_H);
    fputs("<!-- equal axes: screen x = ox + s*x, y = oy - s*y (x, y in metres); "
          "data-mech-transform holds s ox oy, data-mech-plot the plot area -->\n<title>", f);
    plot_put_text(f, c->f->title);
    fputs("</title>\n<defs>", f);
    for (int k = 0; k < 4; k++)
        fprintf(f, "<path id=\"m%d\" d=\"%s\"/>", k, plot_marker_path[k]);
    fprintf(f, "<path id=\"arrow\" d=\"M6,0L-4,-4.5-1.5,0-4,4.5z\"/>"
               "<clipPath id=\"plot\"><rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\"/>"
               "</clipPath></defs>\n", AX_L, AX_T, PATH_W, PATH_H);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"#fff\"/>\n", FIG_W, PATH_PAGE_H);
    fprintf(f, "<text x=\"%d\" y=\"24\" font-size=\"16\" font-weight=\"bold\">", AX_L);
    plot_put_text(f, c->f->title);
    fputs("</text>\n", f);
    if (subtitle) {
        fprintf(f, "<text x=\"%d\" y=\"44\" fill=\"#555\">", AX_L);
        plot_put_text(f, subtitle);
        fputs("</text>\n", f);
    }
}

/* Grid, ticks, frame and the axis titles x [mm], y [mm]. */
static void path_frame(FILE *f, const path_ctx *c)
{
    plot_area area = {AX_L, AX_R, AX_T, AX_T + PATH_H};
    fputs("<g fill=\"#000\" stroke-width=\"1\">\n", f);
    plot_put_ticks_in(f, &c->ax, 0, &area);
    plot_put_ticks_in(f, &c->ay, 1, &area);
    fputs("</g>\n", f);
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" "
               "stroke=\"#000\"/>\n", AX_L, AX_T, PATH_W, PATH_H);
    fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\" font-size=\"13\">",
            (AX_L + AX_R) / 2, AX_T + PATH_H + 44);
    plot_put_axis_title(f, "x", "mm", c->ax.exp10);
    fprintf(f, "</text>\n<text transform=\"translate(22,%d) rotate(-90)\" "
               "text-anchor=\"middle\" font-size=\"13\">", AX_T + PATH_H / 2);
    plot_put_axis_title(f, "y", "mm", c->ay.exp10);
    fputs("</text>\n", f);
}

/* The curve of series s: whole up to THIN_FROM rows, else thinned to within
 * PLOT_THIN_TOL px (more only for a scribble of more than 2 THIN_FROM
 * vertices at that tolerance). */
static void path_curve(FILE *f, const path_ctx *c, int s, const char *colour, const char *dash)
{
    series_ref k = {c, s};
    fprintf(f, "<path stroke=\"%s\"%s%s%s d=\"", colour, *dash ? " stroke-dasharray=\"" : "",
            dash, *dash ? "\"" : "");
    plot_pen p = {f, 0, 2, 0};
    int n = c->t->nrows;
    if (n <= THIN_FROM)
        plot_draw_all(&p, path_vertex, &k, n);
    else
        plot_thin_draw(&p, plot_thin_tolerance(path_vertex, &k, n, 2 * THIN_FROM), path_vertex,
                       &k, n);
    fputs("\"/>\n", f);
}

/* The arrows of series s: PATH_ARROWS at even steps of its length on the
 * page, each along the curve from its row to the first row at least 2 px
 * ahead; then the start marker, the series' marker shape enlarged and
 * filled, at the first finite row. Each carries data-at="x,y" (px). */
static void path_marks(FILE *f, const path_ctx *c, int s, const char *colour, int shape)
{
    int n = c->t->nrows;
    if (c->f->dots[s]) {  /* points: the marker at every finite row */
        int filled;
        const char *col, *dash;
        plot_style(s, &col, &dash, &shape, &filled);
        fprintf(f, "<g stroke=\"%s\" fill=\"%s\">", colour, filled ? colour : "#fff");
        for (int r = 0; r < n; r++) {
            double px, py;
            char b1[32], b2[32];
            if (to_page(c, s, r, &px, &py))
                fprintf(f, "<use xlink:href=\"#m%d\" class=\"dot\" x=\"%s\" y=\"%s\"/>",
                        shape, plot_fmt(b1, px, 2), plot_fmt(b2, py, 2));
        }
        fputs("</g>\n", f);
        return;
    }
    double len = 0, px, py, qx, qy, lx = 0, ly = 0;
    int have = 0, first = -1;
    for (int r = 0; r < n; r++)
        if (to_page(c, s, r, &px, &py)) {
            if (have)
                len += hypot(px - lx, py - ly);
            else if (first < 0)
                first = r;
            lx = px, ly = py, have = 1;
        } else
            have = 0;
    char b1[32], b2[32], b3[32];
    fprintf(f, "<g fill=\"%s\" stroke=\"none\">", colour);
    double walked = 0;
    int next = 0;
    have = 0;
    for (int r = 0; r < n && next < PATH_ARROWS && len > 0; r++) {
        if (!to_page(c, s, r, &px, &py)) {
            have = 0;
            continue;
        }
        if (have)
            walked += hypot(px - lx, py - ly);
        lx = px, ly = py, have = 1;
        if (walked < (next + 0.5) * len / PATH_ARROWS)
            continue;
        int q = r + 1;
        while (q < n && to_page(c, s, q, &qx, &qy) && hypot(qx - px, qy - py) < 2)
            q++;
        if (q < n && to_page(c, s, q, &qx, &qy) && hypot(qx - px, qy - py) > 0)
            fprintf(f, "<use xlink:href=\"#arrow\" data-at=\"%s,%s\" transform=\"translate(%s,%s) "
                       "rotate(%s)\"/>", plot_fmt(b1, px, 2), plot_fmt(b2, py, 2), b1, b2,
                    plot_fmt(b3, atan2(qy - py, qx - px) * RAD2DEG, 1));
        next++;
    }
    if (first >= 0 && to_page(c, s, first, &px, &py))
        fprintf(f, "<use xlink:href=\"#m%d\" data-at=\"%s,%s\" stroke=\"#fff\" stroke-width=\"0.8\" "
                   "transform=\"translate(%s,%s) scale(1.6)\"/>", shape, plot_fmt(b1, px, 2),
                plot_fmt(b2, py, 2), b1, b2);
    fputs("</g>\n", f);
}

/* The legend: each series' line and start marker with the point's name,
 * then what the marks mean and the driver position at the start. */
static void path_legend(FILE *f, const path_ctx *c)
{
    const plot_figure *fg = c->f;
    int lx = AX_R + 14, ly = AX_T, h = 12 + 22 * fg->nseries;
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"#fff\" "
               "stroke=\"#999\"/>\n", lx, ly, FIG_W - lx - 6, h + 62);
    for (int s = 0; s < fg->nseries; s++) {
        const char *colour, *dash;
        int shape, filled, y = ly + 17 + 22 * s;
        plot_style(s, &colour, &dash, &shape, &filled);
        if (fg->dots[s])
            fprintf(f, "<use xlink:href=\"#m%d\" x=\"%d\" y=\"%d\" stroke=\"%s\" fill=\"%s\"/>",
                    shape, lx + 26, y, colour, filled ? colour : "#fff");
        else
            fprintf(f, "<path d=\"M%d,%dh36\" fill=\"none\" stroke=\"%s\" stroke-width=\"1.6\"%s%s%s/>"
                       "<use xlink:href=\"#m%d\" x=\"%d\" y=\"%d\" fill=\"%s\" stroke=\"#fff\"/>",
                    lx + 8, y, colour, *dash ? " stroke-dasharray=\"" : "", dash,
                    *dash ? "\"" : "", shape, lx + 14, y, colour);
        fprintf(f, "<text x=\"%d\" y=\"%d\">", lx + 50, y + 4);
        plot_put_text(f, fg->label[s]);
        fputs("</text>\n", f);
    }
    const mech_model *m = c->m;
    int slider = m->has_driver && m->driver.kind == MECH_DRIVE_SLIDER;
    char b[32];
    int time = m->has_driver && m->driver.kind == MECH_DRIVE_TIME;  /* laws of t: s */
    double q0 = c->t->nrows > 0 ? mech_table_get(c->t, 0, 0) *
                                      (time ? 1.0 : slider ? 1e3 : RAD2DEG) : 0;
    fprintf(f, "<use xlink:href=\"#m0\" x=\"%d\" y=\"%d\" fill=\"#555\" stroke=\"#fff\"/>"
               "<text x=\"%d\" y=\"%d\" font-size=\"11\">start: %s %s</text>\n"
               "<use xlink:href=\"#arrow\" x=\"%d\" y=\"%d\" fill=\"#555\"/>"
               "<text x=\"%d\" y=\"%d\" font-size=\"11\">direction of motion</text>\n",
            lx + 14, ly + h + 8, lx + 26, ly + h + 12, plot_fmt(b, q0, 2),
            time ? "s" : slider ? "mm" : "deg",
            lx + 14, ly + h + 30, lx + 26, ly + h + 34);
}

int plot_path_svg(FILE *f, const mech_model *m, const mech_table *t, const plot_figure *fg,
                  const char *subtitle)
{
    path_ctx c = {.m = m, .t = t, .f = fg};
    path_view(&c);
    path_head(f, &c, subtitle);
    path_frame(f, &c);
    fputs("<g clip-path=\"url(#plot)\" fill=\"none\" stroke-width=\"1.6\" "
          "stroke-linejoin=\"round\">\n", f);
    for (int s = 0; s < fg->nseries; s++) {
        const char *colour, *dash;
        int shape, filled;
        plot_style(s, &colour, &dash, &shape, &filled);
        if (!fg->dots[s])
            path_curve(f, &c, s, colour, dash);
    }
    for (int s = 0; s < fg->nseries; s++) {  /* marks above every curve */
        const char *colour, *dash;
        int shape, filled;
        plot_style(s, &colour, &dash, &shape, &filled);
        path_marks(f, &c, s, colour, shape);
    }
    fputs("</g>\n", f);
    path_legend(f, &c);
    fputs("</svg>\n", f);
    return ferror(f) ? -1 : 0;
}

int plot_plan_all(const mech_model *m, const mech_table *t, plot_figure *figs, int max)
{
    int n = plot_plan(m, t, figs, max);
    return n + plot_path_plan(m, t, figs + n, max - n);
}
