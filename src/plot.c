/* src/plot.c: SVG output of a solved sweep: figures (quantities against the
 * driver, axes with 1-2-5 ticks, legend, line styles readable in black and
 * white) and the animated mechanism (SMIL, no script). docs/plots.md.
 *
 * Every file is written whole: to NAME.tmpPID beside the target, renamed
 * over it when complete (as src/output.c does for CSV). Coordinates are
 * rounded to what the eye can see: 0.01 px in figures, 0.1 px (4 significant
 * digits of a drawing about 800 px wide) in the animation. */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "internal.h"
#include "plot.h"

#define PLOT_PI 3.14159265358979323846
#define RAD2DEG (180.0 / PLOT_PI)

/* ------------------------------------------------------------------ */
/* Small helpers: numbers, text, whole-file writing.                   */

char *plot_fmt(char *buf, double v, int decimals)
{
    if (!isfinite(v)) {
        snprintf(buf, 32, "0");
        return buf;
    }
    snprintf(buf, 32, "%.*f", decimals, v);
    if (strchr(buf, '.')) {
        char *e = buf + strlen(buf) - 1;
        while (*e == '0')
            *e-- = '\0';
        if (*e == '.')
            *e = '\0';
    }
    if (strcmp(buf, "-0") == 0)
        snprintf(buf, 32, "0");
    return buf;
}

double plot_nice_step(double span, int target)
{
    static const double mult[] = {1.0, 2.0, 5.0, 10.0};
    if (!(span > 0) || !isfinite(span) || target < 1)
        return 1.0;
    double raw = span / target;
    double mag = pow(10.0, floor(log10(raw)));
    for (size_t i = 0; i < sizeof mult / sizeof mult[0]; i++)
        if (mult[i] * mag >= raw * (1 - 1e-9))
            return mult[i] * mag;
    return 10.0 * mag;
}

/* Write text with &, <, >, " escaped. */
static void put_text(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* " x,y" with `dec` decimals (the separator first). */
static void put_xy(FILE *f, const char *sep, double x, double y, int dec)
{
    char a[32], b[32];
    fprintf(f, "%s%s,%s", sep, plot_fmt(a, x, dec), plot_fmt(b, y, dec));
}

typedef int (*emit_fn)(FILE *f, const void *ctx);

/* SI unit of a column -> display unit and factor (docs/plots.md, Units). */
static const char *display_unit(const char *si, double *scale)
{
    *scale = 1.0;
    if (strcmp(si, "m") == 0)
        return *scale = 1e3, "mm";
    if (strcmp(si, "rad") == 0)
        return *scale = RAD2DEG, "deg";
    if (strcmp(si, "m/s^2") == 0)
        return "m/s\xc2\xb2";
    if (strcmp(si, "rad/s^2") == 0)
        return "rad/s\xc2\xb2";
    if (strcmp(si, "N*m") == 0)
        return "N\xc2\xb7m";
    return si;
}

/* ------------------------------------------------------------------ */
/* The figures a table calls for.                                      */

typedef struct plan {
    plot_figure *figs;  /* [max] */
    int n, max;
    const mech_table *t;
} plan;

/* A group of items (points, links, ...), each with `per` columns named
 * item + suffix[k]; split into figures of at most PLOT_MAX_SERIES series.
 * items[i] is the name, labels[i] its legend name; NULL suffix = none. */
static void add_group(plan *p, const char *stem, const char *title, const char *ylabel,
                      const char *const *items, const char *const *labels, int nitems,
                      const char *const *suffix, const char *const *suffix_label, int per)
{
    char name[160];
    /* keep the items that have all their columns */
    int *keep = xcalloc((size_t)nitems + 1, sizeof *keep);
    int nkeep = 0;
    if (!keep)
        return;
    for (int i = 0; i < nitems; i++) {
        int ok = 1;
        for (int k = 0; k < per && ok; k++) {
            snprintf(name, sizeof name, "%s%s", items[i], suffix[k]);
            ok = mech_table_column(p->t, name) >= 0;
        }
        if (ok)
            keep[nkeep++] = i;
    }
    int per_fig = PLOT_MAX_SERIES / per;
    int nfig = (nkeep + per_fig - 1) / per_fig;
    for (int fi = 0; fi < nfig && p->n < p->max; fi++) {
        plot_figure *f = &p->figs[p->n++];
        memset(f, 0, sizeof *f);
        int lo = fi * nkeep / nfig, hi = (fi + 1) * nkeep / nfig;
        if (nfig > 1)
            snprintf(f->name, sizeof f->name, "%s-%d", stem, fi + 1);
        else
            snprintf(f->name, sizeof f->name, "%s", stem);
        if (nfig > 1)
            snprintf(f->title, sizeof f->title, "%s (%d of %d)", title, fi + 1, nfig);
        else
            snprintf(f->title, sizeof f->title, "%s", title);
        for (int i = lo; i < hi; i++) {
            for (int k = 0; k < per; k++) {
                snprintf(name, sizeof name, "%s%s", items[keep[i]], suffix[k]);
                f->col[f->nseries] = mech_table_column(p->t, name);
                snprintf(f->label[f->nseries], sizeof f->label[0], "%s%s", labels[keep[i]],
                         suffix_label[k]);
                f->nseries++;
            }
        }
        snprintf(f->ylabel, sizeof f->ylabel, "%s", ylabel);
        const char *u = display_unit(p->t->columns[f->col[0]].unit, &f->yscale);
        snprintf(f->yunit, sizeof f->yunit, "%s", u);
    }
    free(keep);
}

int plot_plan(const mech_model *m, const mech_table *t, plot_figure *figs, int max)
{
    plan p = {figs, 0, max, t};
    int ni = m->outputs.npoints + m->outputs.nlinks + m->outputs.nsliders + m->njoints + 1;
    const char **items = xcalloc((size_t)ni, sizeof *items);
    char (*labels)[80] = xcalloc((size_t)ni, sizeof *labels);
    const char **lab = xcalloc((size_t)ni, sizeof *lab);
    if (!items || !labels || !lab) {
        free(items);
        free(labels);
        free(lab);
        return 0;
    }
    /* points: x and y of each, per level */
    static const char *const pos[] = {".x", ".y"}, *const vel[] = {".vx", ".vy"},
                             *const acc[] = {".ax", ".ay"};
    static const char *const pos_l[] = {".x", ".y"}, *const vel_l[] = {".vx", ".vy"},
                             *const acc_l[] = {".ax", ".ay"};
    int n = 0;
    for (int i = 0; i < m->outputs.npoints; i++, n++)
        items[n] = lab[n] = m->point_names[m->outputs.points[i]];
    add_group(&p, "points-position", "Point positions", "position", items, lab, n, pos, pos_l, 2);
    add_group(&p, "points-velocity", "Point velocities", "velocity", items, lab, n, vel, vel_l, 2);
    add_group(&p, "points-acceleration", "Point accelerations", "acceleration", items, lab, n,
              acc, acc_l, 2);
    /* links: angle, omega, alpha */
    static const char *const angle[] = {".angle"}, *const omega[] = {".omega"},
                             *const alpha[] = {".alpha"}, *const none[] = {""};
    n = 0;
    for (int i = 0; i < m->outputs.nlinks; i++, n++) {
        const mech_link *l = &m->links[m->outputs.links[i]];
        items[n] = l->name;
        if (l->symbol && strcmp(l->symbol, l->name) != 0)
            snprintf(labels[n], sizeof labels[n], "%s (%s)", l->name, l->symbol);
        else
            snprintf(labels[n], sizeof labels[n], "%s", l->name);
        lab[n] = labels[n];
    }
    add_group(&p, "links-angle", "Link angles", "angle", items, lab, n, angle, none, 1);
    add_group(&p, "links-velocity", "Link angular velocities", "angular velocity", items, lab, n,
              omega, none, 1);
    add_group(&p, "links-acceleration", "Link angular accelerations", "angular acceleration",
              items, lab, n, alpha, none, 1);
    /* sliders: s, v, a */
    static const char *const s_[] = {".s"}, *const v_[] = {".v"}, *const a_[] = {".a"};
    n = 0;
    for (int i = 0; i < m->outputs.nsliders; i++, n++)
        items[n] = lab[n] = m->joints[m->outputs.sliders[i]].name;
    add_group(&p, "sliders-displacement", "Slider displacements", "displacement", items, lab, n,
              s_, none, 1);
    add_group(&p, "sliders-velocity", "Slider velocities", "velocity", items, lab, n, v_, none, 1);
    add_group(&p, "sliders-acceleration", "Slider accelerations", "acceleration", items, lab, n,
              a_, none, 1);
    /* forces: one figure per joint, with and without friction when both exist */
    static const char *const fxy[] = {".Fx", ".Fy", ".Fx.nofriction", ".Fy.nofriction"};
    static const char *const fxy_l[] = {"Fx", "Fy", "Fx, no friction", "Fy, no friction"};
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        char stem[96], title[160], nf[96];
        snprintf(nf, sizeof nf, "%s.Fx.nofriction", jt->name);
        int per = mech_table_column(t, nf) >= 0 ? 4 : 2;
        snprintf(stem, sizeof stem, "force-%s", jt->name);
        snprintf(title, sizeof title, "Reaction at %s joint %s (%s-%s)",
                 jt->kind == MECH_JOINT_SLIDER ? "slider" : "revolute", jt->name,
                 m->links[jt->link[0]].name, m->links[jt->link[1]].name);
        const char *it[1] = {jt->name}, *lb[1] = {""};
        add_group(&p, stem, title, "force", it, lb, 1, fxy, fxy_l, per);
    }
    /* the driver torque (or force) */
    const char *drv = mech_table_column(t, "driver.torque") >= 0 ? "driver.torque"
                      : mech_table_column(t, "driver.force") >= 0 ? "driver.force" : NULL;
    if (drv) {
        char nf[64];
        snprintf(nf, sizeof nf, "%s.nofriction", drv);
        int both = mech_table_column(t, nf) >= 0;
        int torque = strcmp(drv, "driver.torque") == 0;
        /* with both: series "with friction", "no friction"; else one, named */
        static const char *const sfx[] = {"", ".nofriction"};
        static const char *const sfx_both[] = {"with friction", "no friction"};
        static const char *const sfx_one[] = {""};
        const char *it[1] = {drv};
        const char *lb[1] = {both ? "" : torque ? "driver torque" : "driver force"};
        add_group(&p, torque ? "driver-torque" : "driver-force",
                  torque ? "Driver torque" : "Driver force", torque ? "torque" : "force", it, lb,
                  1, sfx, both ? sfx_both : sfx_one, both ? 2 : 1);
    }
    free(items);
    free(labels);
    free(lab);
    return p.n;
}

/* ------------------------------------------------------------------ */
/* One figure.                                                         */

/* Page layout, px. */
enum { FIG_W = 780, FIG_H = 450, AX_L = 86, AX_R = 590, AX_T = 62, AX_B = 384 };

typedef struct axis {
    double lo, hi;      /* displayed range */
    double step;        /* tick step (1, 2, 5 x 10^k) */
    int exp10;          /* labels are value / 10^exp10 */
    int dec;            /* decimals of the labels */
} axis;

/* Ticks for [lo, hi]; round_out widens the range to whole steps. */
static void axis_make(axis *a, double lo, double hi, int target, int round_out)
{
    if (!isfinite(lo) || !isfinite(hi)) {
        lo = 0;
        hi = 1;
    }
    double mag = fmax(fabs(lo), fabs(hi));
    if (hi - lo <= 1e-9 * mag || hi <= lo) { /* constant: a band around it */
        double w = mag > 0 ? 0.1 * mag : 1.0;
        lo -= w;
        hi += w;
    }
    if (round_out) { /* keep the curves off the frame */
        double pad = 0.02 * (hi - lo);
        lo -= pad;
        hi += pad;
    }
    a->step = plot_nice_step(hi - lo, target);
    if (round_out) {
        lo = floor(lo / a->step + 1e-9) * a->step;
        hi = ceil(hi / a->step - 1e-9) * a->step;
    }
    a->lo = lo;
    a->hi = hi;
    mag = fmax(fabs(lo), fabs(hi));
    a->exp10 = 0;
    if (mag >= 1e5 || a->step < 1e-3)
        a->exp10 = 3 * (int)floor(log10(mag) / 3.0);
    double s = a->step / pow(10.0, a->exp10);
    a->dec = s >= 1 ? 0 : (int)ceil(-log10(s) - 1e-9);
}

/* Axis title with its unit, and "x10^k" when the labels are scaled. */
static void put_axis_title(FILE *f, const char *what, const char *unit, int exp10)
{
    put_text(f, what);
    fputs(" [", f);
    if (exp10 != 0)
        fprintf(f, "\xc3\x97" "10<tspan dy=\"-6\" font-size=\"10\">%d</tspan>"
                   "<tspan dy=\"6\"> </tspan>", exp10);
    put_text(f, unit);
    fputs("]", f);
}

static const char *const series_colour[PLOT_MAX_SERIES] = {
    "#1f4e99", "#c0392b", "#1e7b3c", "#7d3c98", "#b86e00", "#0f7c8c", "#404040", "#a0306a"};
static const char *const series_dash[4] = {"", "7,4", "2,3", "9,3,2,3"};
/* markers centred on 0,0: circle, square, triangle, diamond */
static const char *const marker_path[4] = {
    "M-3.5,0a3.5,3.5 0 1 0 7,0a3.5,3.5 0 1 0-7,0z", "M-3.2-3.2h6.4v6.4h-6.4z",
    "M0-4.3L3.9,2.7H-3.9z", "M0-4.5L4.5,0 0,4.5-4.5,0z"};

/* Style s: colour s, marker shape s % 4 (open for s < 4, filled after),
 * dash (s + s / 4) % 4, so that no two of the 8 styles share shape, fill and dash. */
static void style_of(int s, const char **colour, const char **dash, int *shape, int *filled)
{
    *colour = series_colour[s % PLOT_MAX_SERIES];
    *dash = series_dash[(s + s / 4) % 4];
    *shape = s % 4;
    *filled = s >= 4;
}

typedef struct fig_ctx {
    const mech_model *m;
    const mech_table *t;
    const plot_figure *f;
    const char *subtitle;
} fig_ctx;

static double xval(const fig_ctx *c, int r)
{
    double q = mech_table_get(c->t, r, 0);
    return c->m->has_driver && c->m->driver.kind == MECH_DRIVE_SLIDER ? q * 1e3 : q * RAD2DEG;
}

static void x_title(const fig_ctx *c, FILE *f)
{
    const mech_model *m = c->m;
    if (m->has_driver && m->driver.kind == MECH_DRIVE_SLIDER) {
        fputs("displacement of slider ", f);
        put_text(f, m->joints[m->driver.index].name);
        fputs(" [mm]", f);
    } else {
        fputs("angle of ", f);
        put_text(f, m->has_driver ? m->links[m->driver.index].name : "the driver");
        fputs(" [deg]", f);
    }
}

static void put_ticks(FILE *f, const axis *a, int vertical, double p0, double p1)
{
    char b1[32], b2[32], b3[32];
    long k0 = (long)ceil(a->lo / a->step - 1e-6), k1 = (long)floor(a->hi / a->step + 1e-6);
    double scale = pow(10.0, -a->exp10);
    for (long k = k0; k <= k1; k++) {
        double v = (double)k * a->step;
        double pos = p0 + (v - a->lo) / (a->hi - a->lo) * (p1 - p0);
        plot_fmt(b3, v * scale, a->dec);
        if (vertical) {
            fprintf(f, "<path d=\"M%d,%sH%d\" stroke=\"%s\"/>", AX_L, plot_fmt(b1, pos, 2), AX_R,
                    k == 0 ? "#999" : "#e3e3e3");
            fprintf(f, "<path d=\"M%d,%sh-5\" stroke=\"#000\"/>", AX_L, b1);
            fprintf(f, "<text x=\"%d\" y=\"%s\" text-anchor=\"end\">%s</text>\n", AX_L - 8,
                    plot_fmt(b2, pos + 4, 2), b3);
        } else {
            fprintf(f, "<path d=\"M%s,%dV%d\" stroke=\"#e3e3e3\"/>", plot_fmt(b1, pos, 2),
                    AX_T, AX_B);
            fprintf(f, "<path d=\"M%s,%dv5\" stroke=\"#000\"/>", b1, AX_B);
            fprintf(f, "<text x=\"%s\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", b1, AX_B + 20,
                    b3);
        }
    }
}

/* A path's vertices, in pixels: "M" after a break, then "L", then blanks. */
typedef struct pen {
    FILE *f;
    int state;  /* 0: next vertex starts a piece (M); 1: the first L; 2: more */
} pen;

static void pen_to(pen *p, double px, double py)
{
    char b1[32], b2[32];
    fprintf(p->f, "%s%s,%s", p->state == 0 ? "M" : p->state == 1 ? "L" : " ",
            plot_fmt(b1, px, 2), plot_fmt(b2, py, 2));
    p->state = p->state == 0 ? 1 : 2;
}

/* The rows of one pixel column of the plot: the first, lowest, highest and
 * last point (pixels; lo/hi are the extremes of py, i.e. of the value). */
typedef struct column_run {
    long col;                  /* pixel column, floor(px - AX_L) */
    int n;                     /* rows in it so far */
    int row[4];                /* first, lo, hi, last */
    double px[4], py[4];
} column_run;

/* Draw a column's run: its up to 4 points in row order, each once. */
static void run_flush(column_run *c, pen *p)
{
    int done[4] = {0};
    for (int k = 0; k < 4 && c->n > 0; k++) {
        int best = -1;
        for (int i = 0; i < 4; i++)
            if (!done[i] && (best < 0 || c->row[i] < c->row[best]))
                best = i;
        if (best < 0)
            break;
        for (int i = 0; i < 4; i++)  /* the same row twice is drawn once */
            done[i] |= c->row[i] == c->row[best];
        pen_to(p, c->px[best], c->py[best]);
    }
    c->n = 0;
}

static void run_add(column_run *c, pen *p, int row, double px, double py, long col)
{
    if (c->n > 0 && col != c->col)
        run_flush(c, p);
    if (c->n == 0)
        for (int i = 0; i < 4; i++) {
            c->row[i] = row;
            c->px[i] = px;
            c->py[i] = py;
        }
    c->col = col;
    c->n++;
    int slot[2] = {py > c->py[1] ? 1 : -1, py < c->py[2] ? 2 : -1};  /* lo: larger py */
    for (int k = 0; k < 2; k++)
        if (slot[k] >= 0) {
            c->row[slot[k]] = row;
            c->px[slot[k]] = px;
            c->py[slot[k]] = py;
        }
    c->row[3] = row;
    c->px[3] = px;
    c->py[3] = py;
}

/* Rows beyond which a curve is thinned to its pixel columns: 4 per column,
 * as many as the thinned curve can have, so shorter sweeps are drawn (and
 * written) exactly as before. */
enum { THIN_FROM = 4 * 504 };

static int emit_figure(FILE *f, const void *vctx)
{
    const fig_ctx *c = vctx;
    const mech_table *t = c->t;
    const plot_figure *fg = c->f;
    char b1[32], b2[32];
    /* ranges */
    double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
    for (int r = 0; r < t->nrows; r++) {
        double x = xval(c, r);
        if (isfinite(x)) {
            xlo = fmin(xlo, x);
            xhi = fmax(xhi, x);
        }
        for (int s = 0; s < fg->nseries; s++) {
            double y = mech_table_get(t, r, fg->col[s]) * fg->yscale;
            if (isfinite(y)) {
                ylo = fmin(ylo, y);
                yhi = fmax(yhi, y);
            }
        }
    }
    axis ax, ay;
    axis_make(&ax, xlo, xhi, 9, 0);
    axis_make(&ay, ylo, yhi, 7, 1);
    ax.exp10 = 0; /* driver axis: plain degrees or millimetres */
    ax.dec = ax.step >= 1 ? 0 : (int)ceil(-log10(ax.step) - 1e-9);
#define PX(x) (AX_L + ((x) - ax.lo) / (ax.hi - ax.lo) * (AX_R - AX_L))
#define PY(y) (AX_B - ((y) - ay.lo) / (ay.hi - ay.lo) * (AX_B - AX_T))
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" "
               "xmlns:xlink=\"http://www.w3.org/1999/xlink\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\" font-family=\"DejaVu Sans,Arial,Helvetica,sans-serif\" "
               "font-size=\"12\">\n", FIG_W, FIG_H, FIG_W, FIG_H);
    fputs("<title>", f);
    put_text(f, fg->title);
    fputs("</title>\n<defs>", f);
    for (int k = 0; k < 4; k++)
        fprintf(f, "<path id=\"m%d\" d=\"%s\"/>", k, marker_path[k]);
    fprintf(f, "<clipPath id=\"plot\"><rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\"/>"
               "</clipPath></defs>\n", AX_L, AX_T, AX_R - AX_L, AX_B - AX_T);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"#fff\"/>\n", FIG_W, FIG_H);
    /* titles */
    fprintf(f, "<text x=\"%d\" y=\"24\" font-size=\"16\" font-weight=\"bold\">", AX_L);
    put_text(f, fg->title);
    fputs("</text>\n", f);
    if (c->subtitle) {
        fprintf(f, "<text x=\"%d\" y=\"44\" fill=\"#555\">", AX_L);
        put_text(f, c->subtitle);
        fputs("</text>\n", f);
    }
    /* grid, ticks and labels */
    fputs("<g fill=\"#000\" stroke-width=\"1\">\n", f);
    put_ticks(f, &ax, 0, AX_L, AX_R);
    put_ticks(f, &ay, 1, AX_B, AX_T);
    fputs("</g>\n", f);
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" "
               "stroke=\"#000\"/>\n", AX_L, AX_T, AX_R - AX_L, AX_B - AX_T);
    fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\" font-size=\"13\">",
            (AX_L + AX_R) / 2, AX_B + 44);
    x_title(c, f);
    fputs("</text>\n", f);
    fprintf(f, "<text transform=\"translate(22,%d) rotate(-90)\" text-anchor=\"middle\" "
               "font-size=\"13\">", (AX_T + AX_B) / 2);
    put_axis_title(f, fg->ylabel, fg->yunit, ay.exp10);
    fputs("</text>\n", f);
    /* series: a path broken at non-finite values, then markers */
    int every = t->nrows > 12 ? t->nrows / 12 : 1;
    fputs("<g clip-path=\"url(#plot)\" fill=\"none\" stroke-width=\"1.6\" "
          "stroke-linejoin=\"round\">\n", f);
    for (int s = 0; s < fg->nseries; s++) {
        const char *colour, *dash;
        int shape, filled;
        style_of(s, &colour, &dash, &shape, &filled);
        fprintf(f, "<path stroke=\"%s\"%s%s%s d=\"", colour, *dash ? " stroke-dasharray=\"" : "",
                dash, *dash ? "\"" : "");
        /* A 10^6-step sweep would write 10^6 vertices (350 MB of SVG) that
         * land on 504 pixel columns: past THIN_FROM rows each column keeps
         * its first, lowest, highest and last point, in row order. Every
         * point dropped lies in its column between the kept extremes, on a
         * stretch the kept vertices span, so the drawn curve is the same
         * to the pixel, spikes included. */
        pen p = {f, 0};
        column_run run = {0};
        int thin = t->nrows > THIN_FROM;
        for (int r = 0; r < t->nrows; r++) {
            double x = xval(c, r), y = mech_table_get(t, r, fg->col[s]) * fg->yscale;
            if (!isfinite(x) || !isfinite(y)) {
                run_flush(&run, &p);
                p.state = 0;
                continue;
            }
            double px = PX(x), py = PY(y);
            if (thin)
                run_add(&run, &p, r, px, py, (long)floor(px - AX_L));
            else
                pen_to(&p, px, py);
        }
        run_flush(&run, &p);
        fputs("\"/>\n", f);
        fprintf(f, "<g stroke=\"%s\" fill=\"%s\">", colour, filled ? colour : "#fff");
        for (int r = (s * every) / (fg->nseries > 0 ? fg->nseries : 1); r < t->nrows; r += every) {
            double x = xval(c, r), y = mech_table_get(t, r, fg->col[s]) * fg->yscale;
            if (isfinite(x) && isfinite(y))
                fprintf(f, "<use xlink:href=\"#m%d\" x=\"%s\" y=\"%s\"/>", shape,
                        plot_fmt(b1, PX(x), 2), plot_fmt(b2, PY(y), 2));
        }
        fputs("</g>\n", f);
    }
    fputs("</g>\n", f);
    /* legend */
    int lx = AX_R + 14, ly = AX_T;
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"#fff\" "
               "stroke=\"#999\"/>\n", lx, ly, FIG_W - lx - 6, 12 + 22 * fg->nseries);
    for (int s = 0; s < fg->nseries; s++) {
        const char *colour, *dash;
        int shape, filled;
        style_of(s, &colour, &dash, &shape, &filled);
        int y = ly + 17 + 22 * s;
        fprintf(f, "<path d=\"M%d,%dh36\" fill=\"none\" stroke=\"%s\" stroke-width=\"1.6\"%s%s%s/>",
                lx + 8, y, colour, *dash ? " stroke-dasharray=\"" : "", dash, *dash ? "\"" : "");
        fprintf(f, "<use xlink:href=\"#m%d\" x=\"%d\" y=\"%d\" stroke=\"%s\" fill=\"%s\"/>", shape,
                lx + 26, y, colour, filled ? colour : "#fff");
        fprintf(f, "<text x=\"%d\" y=\"%d\">", lx + 50, y + 4);
        put_text(f, fg->label[s]);
        fputs("</text>\n", f);
    }
    fputs("</svg>\n", f);
#undef PX
#undef PY
    return ferror(f) ? -1 : 0;
}

int plot_figure_write(const mech_model *m, const mech_table *t, const plot_figure *f,
                      const char *subtitle, const char *path, mech_diag *d)
{
    fig_ctx c = {m, t, f, subtitle};
    return write_file_whole(path, emit_figure, &c, d);
}

/* ------------------------------------------------------------------ */
/* The animation.                                                      */

void plot_anim_options_default(plot_anim_options *o)
{
    memset(o, 0, sizeof *o);
    o->duration = 4.0;
    o->frame = -1;
    o->max_frames = 1000;
    o->pause_at = -1;
}

enum { ANIM_DRAW = 760, ANIM_PAD = 40, ANIM_TOP = 56, ANIM_DEC = 1 };

/* One drawn shape whose vertices follow the mechanism: a link (bar or
 * plate), a slider block, or a moving guide. */
typedef struct anim_ctx {
    const mech_model *m;
    const mech_table *t;
    const plot_anim_options *o;
    int np;            /* point names */
    int nrows;
    double *X, *Y;     /* [nrows * np] screen position of each point name per row */
    double *ang;       /* [nrows * nlinks] link angle, rad (ground 0) */
    int *rows;         /* [nframes] table rows shown */
    int nframes;
    double s, ox, oy;  /* screen = (ox + s x, oy - s y) */
    int width, height;
    double (*guide)[2];/* [njoints] guide segment: s from, s to (world, m) */
    int **hull;        /* [nlinks] point indices of the drawn outline, or NULL */
    int *nhull;        /* [nlinks] */
    unsigned char *on_ground, *pinned; /* [np] point on the ground; on 2+ links or sliding */
} anim_ctx;

static double cross3(const mech_point *o, const mech_point *a, const mech_point *b)
{
    return (a->x - o->x) * (b->y - o->y) - (a->y - o->y) * (b->x - o->x);
}

static const mech_point *cmp_pts; /* qsort context (single-threaded) */
static int cmp_xy(const void *a, const void *b)
{
    const mech_point *p = &cmp_pts[*(const int *)a], *q = &cmp_pts[*(const int *)b];
    return p->x < q->x ? -1 : p->x > q->x ? 1 : p->y < q->y ? -1 : p->y > q->y ? 1 : 0;
}

/* Convex hull of a link's points in its own frame (Andrew's monotone chain);
 * out[] gets point indices counter-clockwise; returns their count (2 for a
 * bar: collinear points give the two extreme ones). */
static int link_hull(const mech_link *l, int *out)
{
    int n = l->npoints;
    int *idx = xcalloc((size_t)n, sizeof *idx);
    if (!idx)
        return 0;
    for (int i = 0; i < n; i++)
        idx[i] = i;
    cmp_pts = l->points;
    qsort(idx, (size_t)n, sizeof *idx, cmp_xy);
    int k = 0;
    for (int i = 0; i < n; i++) {
        while (k >= 2 && cross3(&l->points[out[k - 2]], &l->points[out[k - 1]],
                                &l->points[idx[i]]) <= 0)
            k--;
        out[k++] = idx[i];
    }
    for (int i = n - 2, lo = k + 1; i >= 0; i--) {
        while (k >= lo && cross3(&l->points[out[k - 2]], &l->points[out[k - 1]],
                                 &l->points[idx[i]]) <= 0)
            k--;
        out[k++] = idx[i];
    }
    free(idx);
    return k > 1 ? k - 1 : k;
}

static void anim_free(anim_ctx *c)
{
    free(c->X);
    free(c->Y);
    free(c->ang);
    free(c->rows);
    free(c->guide);
    if (c->hull)
        for (int i = 0; i < c->m->nlinks; i++)
            free(c->hull[i]);
    free(c->hull);
    free(c->nhull);
    free(c->on_ground);
    free(c->pinned);
}

/* Sliding point (name id), through point (name id) and guide link of joint j. */
static void slider_points(const mech_model *m, int j, int *slide, int *through, int *guide)
{
    const mech_joint *jt = &m->joints[j];
    *slide = m->links[jt->link[0]].points[jt->point[0]].id;
    *through = m->links[jt->link[1]].points[jt->point[1]].id;
    *guide = jt->link[1];
}

/* Read the table, choose the frames, the scale and the outlines. */
static int anim_prepare(anim_ctx *c, mech_diag *d)
{
    const mech_model *m = c->m;
    const mech_table *t = c->t;
    char name[160];
    c->np = m->npoint_names;
    c->nrows = t->nrows;
    if (c->nrows < 1)
        return diag_error(d, m->file, (mech_mark){0, 0}, "nothing to draw: no solved position");
    size_t cells = (size_t)c->nrows * (size_t)(c->np > 0 ? c->np : 1);
    c->X = xcalloc(cells, sizeof *c->X);
    c->Y = xcalloc(cells, sizeof *c->Y);
    c->ang = xcalloc((size_t)c->nrows * (size_t)m->nlinks, sizeof *c->ang);
    c->guide = xcalloc((size_t)m->njoints + 1, sizeof *c->guide);
    c->hull = xcalloc((size_t)m->nlinks, sizeof *c->hull);
    c->nhull = xcalloc((size_t)m->nlinks, sizeof *c->nhull);
    c->on_ground = xcalloc((size_t)c->np + 1, 1);
    c->pinned = xcalloc((size_t)c->np + 1, 1);
    c->rows = xcalloc((size_t)c->nrows, sizeof *c->rows);
    if (!c->X || !c->Y || !c->ang || !c->guide || !c->hull || !c->nhull || !c->on_ground ||
        !c->pinned || !c->rows)
        return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    /* world positions first (X, Y hold metres until the scale is known) */
    for (int p = 0; p < c->np; p++) {
        snprintf(name, sizeof name, "%s.x", m->point_names[p]);
        int cx = mech_table_column(t, name);
        snprintf(name, sizeof name, "%s.y", m->point_names[p]);
        int cy = mech_table_column(t, name);
        if (cx < 0 || cy < 0)
            return diag_error(d, m->file, (mech_mark){0, 0},
                              "internal: no position column for point '%s'", m->point_names[p]);
        for (int r = 0; r < c->nrows; r++) {
            c->X[(size_t)r * c->np + p] = mech_table_get(t, r, cx);
            c->Y[(size_t)r * c->np + p] = mech_table_get(t, r, cy);
        }
    }
    for (int i = 1; i < m->nlinks; i++) {
        snprintf(name, sizeof name, "%s.angle", m->links[i].name);
        int ca = mech_table_column(t, name);
        if (ca < 0)
            return diag_error(d, m->file, (mech_mark){0, 0},
                              "internal: no angle column for link '%s'", m->links[i].name);
        for (int r = 0; r < c->nrows; r++)
            c->ang[(size_t)r * m->nlinks + i] = mech_table_get(t, r, ca);
    }
    /* which points are pins, which are on the ground */
    int *count = xcalloc((size_t)c->np + 1, sizeof *count);
    if (!count)
        return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    for (int i = 0; i < m->nlinks; i++)
        for (int k = 0; k < m->links[i].npoints; k++) {
            count[m->links[i].points[k].id]++;
            if (i == 0)
                c->on_ground[m->links[i].points[k].id] = 1;
        }
    for (int p = 0; p < c->np; p++)
        c->pinned[p] = count[p] >= 2;
    free(count);
    /* bounding box of every point over every row */
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (size_t k = 0; k < cells && c->np > 0; k++) {
        if (!isfinite(c->X[k]) || !isfinite(c->Y[k]))
            continue;
        xmin = fmin(xmin, c->X[k]);
        xmax = fmax(xmax, c->X[k]);
        ymin = fmin(ymin, c->Y[k]);
        ymax = fmax(ymax, c->Y[k]);
    }
    if (!(xmax >= xmin) || !(ymax >= ymin))
        xmin = ymin = 0, xmax = ymax = 1;
    double size = fmax(fmax(xmax - xmin, ymax - ymin), 1e-9);
    /* guides: the line through `through` covering every slider position */
    double margin = 0.08 * size;
    for (int j = 0; j < m->njoints; j++) {
        if (m->joints[j].kind != MECH_JOINT_SLIDER)
            continue;
        c->pinned[m->links[m->joints[j].link[0]].points[m->joints[j].point[0]].id] = 1;
        int sp, tp, g;
        slider_points(m, j, &sp, &tp, &g);
        double smin = 0, smax = 0;
        for (int r = 0; r < c->nrows; r++) {
            double a = c->ang[(size_t)r * m->nlinks + g] + m->joints[j].angle;
            double dx = c->X[(size_t)r * c->np + sp] - c->X[(size_t)r * c->np + tp];
            double dy = c->Y[(size_t)r * c->np + sp] - c->Y[(size_t)r * c->np + tp];
            double sv = dx * cos(a) + dy * sin(a);
            if (isfinite(sv)) {
                smin = fmin(smin, sv);
                smax = fmax(smax, sv);
            }
        }
        c->guide[j][0] = smin - margin;
        c->guide[j][1] = smax + margin;
        for (int r = 0; r < c->nrows; r++) {
            double a = c->ang[(size_t)r * m->nlinks + g] + m->joints[j].angle;
            for (int e = 0; e < 2; e++) {
                double x = c->X[(size_t)r * c->np + tp] + c->guide[j][e] * cos(a);
                double y = c->Y[(size_t)r * c->np + tp] + c->guide[j][e] * sin(a);
                if (isfinite(x) && isfinite(y)) {
                    xmin = fmin(xmin, x);
                    xmax = fmax(xmax, x);
                    ymin = fmin(ymin, y);
                    ymax = fmax(ymax, y);
                }
            }
        }
    }
    /* scale: the larger side is ANIM_DRAW px; pads leave room for symbols */
    size = fmax(fmax(xmax - xmin, ymax - ymin), 1e-9);
    c->s = ANIM_DRAW / size;
    c->width = (int)ceil((xmax - xmin) * c->s) + 2 * ANIM_PAD;
    c->height = (int)ceil((ymax - ymin) * c->s) + ANIM_PAD + ANIM_TOP;
    if (c->width < 320)
        c->width = 320;
    c->ox = (c->width - (xmax - xmin) * c->s) / 2 - xmin * c->s;
    c->oy = ANIM_TOP + ymax * c->s;
    for (size_t k = 0; k < cells && c->np > 0; k++) {
        c->X[k] = c->ox + c->s * c->X[k];
        c->Y[k] = c->oy - c->s * c->Y[k];
    }
    /* frames */
    if (c->o->frame >= 0) {
        if (c->o->frame >= c->nrows)
            return diag_error(d, m->file, (mech_mark){0, 0},
                              "--frame %d: the sweep has %d positions (frames 0 to %d)",
                              c->o->frame, c->nrows, c->nrows - 1);
        c->rows[0] = c->o->frame;
        c->nframes = 1;
    } else {
        int nf = c->nrows;
        if (c->o->max_frames > 1 && nf > c->o->max_frames)
            nf = c->o->max_frames;
        for (int k = 0; k < nf; k++)
            c->rows[k] = nf > 1 ? (int)((long long)k * (c->nrows - 1) / (nf - 1)) : 0;
        c->nframes = nf;
    }
    /* outlines of the links in their own frames */
    for (int i = 1; i < m->nlinks; i++) {
        if (m->links[i].npoints < 2)
            continue;
        c->hull[i] = xcalloc((size_t)m->links[i].npoints + 1, sizeof *c->hull[i]);
        if (!c->hull[i])
            return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
        c->nhull[i] = link_hull(&m->links[i], c->hull[i]);
    }
    return MECH_OK;
}

/* A shape's vertices in row r: fills xs, ys (screen), returns their count. */
typedef int (*shape_fn)(const anim_ctx *c, int which, int r, double *xs, double *ys);

static int link_shape(const anim_ctx *c, int i, int r, double *xs, double *ys)
{
    const mech_link *l = &c->m->links[i];
    for (int k = 0; k < c->nhull[i]; k++) {
        int p = l->points[c->hull[i][k]].id;
        xs[k] = c->X[(size_t)r * c->np + p];
        ys[k] = c->Y[(size_t)r * c->np + p];
    }
    return c->nhull[i];
}

/* The block of slider j: a rectangle along the guide around the sliding point. */
static int block_shape(const anim_ctx *c, int j, int r, double *xs, double *ys)
{
    int sp, tp, g;
    slider_points(c->m, j, &sp, &tp, &g);
    double a = c->ang[(size_t)r * c->m->nlinks + g] + c->m->joints[j].angle;
    double hl = c->m->joints[j].locked ? 17 : 11, hw = c->m->joints[j].locked ? 10 : 6;
    double ux = cos(a), uy = -sin(a); /* screen y points down */
    double vx = -uy, vy = ux;
    double x = c->X[(size_t)r * c->np + sp], y = c->Y[(size_t)r * c->np + sp];
    static const int sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; k++) {
        xs[k] = x + sx[k] * hl * ux + sy[k] * hw * vx;
        ys[k] = y + sx[k] * hl * uy + sy[k] * hw * vy;
    }
    return 4;
}

/* The guide line of slider j. */
static int guide_shape(const anim_ctx *c, int j, int r, double *xs, double *ys)
{
    int sp, tp, g;
    slider_points(c->m, j, &sp, &tp, &g);
    double a = c->ang[(size_t)r * c->m->nlinks + g] + c->m->joints[j].angle;
    for (int e = 0; e < 2; e++) {
        xs[e] = c->X[(size_t)r * c->np + tp] + c->s * c->guide[j][e] * cos(a);
        ys[e] = c->Y[(size_t)r * c->np + tp] - c->s * c->guide[j][e] * sin(a);
    }
    return 2;
}

static void put_vertices(FILE *f, const double *xs, const double *ys, int n)
{
    for (int k = 0; k < n; k++)
        put_xy(f, k ? " " : "", xs[k], ys[k], ANIM_DEC);
}

/* A <polygon> or <polyline> (tag) whose "points" follow shape(which);
 * `attrs` are its other attributes; `moving` 0 for a static shape. */
static void put_shape(FILE *f, const anim_ctx *c, const char *tag, const char *attrs,
                      shape_fn shape, int which, int moving, double *xs, double *ys)
{
    int n = shape(c, which, c->rows[0], xs, ys);
    if (n < 2)
        return;
    fprintf(f, "<%s %s points=\"", tag, attrs);
    put_vertices(f, xs, ys, n);
    if (!moving || c->nframes < 2) {
        fputs("\"/>\n", f);
        return;
    }
    char b[32];
    fprintf(f, "\"><animate attributeName=\"points\" dur=\"%ss\" repeatCount=\"indefinite\" "
               "values=\"", plot_fmt(b, c->o->duration, 3));
    for (int k = 0; k < c->nframes; k++) {
        if (k)
            fputc(';', f);
        shape(c, which, c->rows[k], xs, ys);
        put_vertices(f, xs, ys, n);
    }
    fprintf(f, "\"/></%s>\n", tag);
}

static const char *const link_fill[6] = {"#9ec5e8", "#f2b8a0", "#b5dcae", "#d3bde6", "#f1d79a",
                                         "#a8dcd9"};
static const char *const link_stroke[6] = {"#2c5d8f", "#a5462a", "#3c7a34", "#6a4391", "#9a7415",
                                           "#2a7d78"};

/* Ground pivot symbol at (x, y): a triangle, its base and hatching. */
static void put_pivot(FILE *f, double x, double y, int test)
{
    char a[32], b[32];
    fprintf(f, "<g transform=\"translate(%s,%s)\" stroke=\"%s\" stroke-width=\"1.3\">"
               "<path d=\"M0,0L-9,15H9z\" fill=\"%s\"/><path d=\"M-15,15H15\"/>"
               "<path d=\"M-13,21l5-6M-7,21l5-6M-1,21l5-6M5,21l5-6M11,21l4-4.8\"/></g>\n",
            plot_fmt(a, x, ANIM_DEC), plot_fmt(b, y, ANIM_DEC), test ? "#555" : "#333",
            test ? "#ccc" : "#e8e8e8");
}

/* Hatching beside a ground guide from (x0,y0) to (x1,y1): short strokes every 10 px. */
static void put_guide_hatch(FILE *f, double x0, double y0, double x1, double y1, int test)
{
    double len = hypot(x1 - x0, y1 - y0);
    if (!(len > 0))
        return;
    double ux = (x1 - x0) / len, uy = (y1 - y0) / len, nx = uy, ny = -ux; /* one side */
    char a[32], b[32], e[32], g[32];
    fprintf(f, "<path stroke=\"%s\" stroke-width=\"1\" d=\"", test ? "#777" : "#666");
    for (double s = 4; s < len - 4; s += 10) {
        double x = x0 + s * ux + 13 * nx, y = y0 + s * uy + 13 * ny;
        fprintf(f, "M%s,%sl%s,%s", plot_fmt(a, x, ANIM_DEC), plot_fmt(b, y, ANIM_DEC),
                plot_fmt(e, 6 * ux - 6 * nx, ANIM_DEC), plot_fmt(g, 6 * uy - 6 * ny, ANIM_DEC));
    }
    fputs("\"/>\n", f);
}

/* Unique test colour of point name p: red 255, green and blue from p, never grey. */
static void test_colour(int p, char *buf, size_t n)
{
    unsigned g = (unsigned)(p * 37 + 11) % 251u, b = (unsigned)(p * 101 + 3) % 241u;
    snprintf(buf, n, "#ff%02x%02x", g, b);
}

static int emit_animation(FILE *f, const void *vctx)
{
    const anim_ctx *c = vctx;
    const mech_model *m = c->m;
    int test = c->o->test_colours;
    char b1[32], b2[32], b3[32];
    int maxv = 4;
    for (int i = 0; i < m->nlinks; i++)
        if (c->nhull[i] > maxv)
            maxv = c->nhull[i];
    double *xs = xcalloc((size_t)maxv, sizeof *xs), *ys = xcalloc((size_t)maxv, sizeof *ys);
    if (!xs || !ys) {
        free(xs);
        free(ys);
        return -1;
    }
    const char *dur = plot_fmt(b3, c->o->duration, 3);
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\" font-family=\"DejaVu Sans,Arial,Helvetica,sans-serif\" "
               "font-size=\"12\" data-mech-transform=\"%.9g %.9g %.9g\">\n",
            c->width, c->height, c->width, c->height, c->s, c->ox, c->oy);
    fputs("<!-- screen x = ox + s*x, y = oy - s*y (x, y in metres); "
          "data-mech-transform holds s ox oy -->\n<title>", f);
    put_text(f, m->name ? m->name : m->file);
    fputs("</title>\n", f);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"#fff\"/>\n", c->width, c->height);
    /* caption */
    fputs("<text x=\"12\" y=\"22\" font-size=\"15\" font-weight=\"bold\" fill=\"#222\">", f);
    put_text(f, m->name ? m->name : m->file);
    fputs("</text>\n<text x=\"12\" y=\"40\" fill=\"#555\">", f);
    int slider_drv = m->has_driver && m->driver.kind == MECH_DRIVE_SLIDER;
    double qk = slider_drv ? 1e3 : RAD2DEG;
    const char *qu = slider_drv ? "mm" : "deg";
    if (c->nframes == 1)
        fprintf(f, "driver %s = %s %s (position %d of %d)",
                slider_drv ? "displacement" : "angle",
                plot_fmt(b1, mech_table_get(c->t, c->rows[0], 0) * qk, 3), qu, c->rows[0],
                c->nrows);
    else
        fprintf(f, "driver from %s to %s %s, %d frames in %s s",
                plot_fmt(b1, mech_table_get(c->t, 0, 0) * qk, 3),
                plot_fmt(b2, mech_table_get(c->t, c->nrows - 1, 0) * qk, 3), qu, c->nframes, dur);
    fputs("</text>\n", f);
    /* traced paths of the output points */
    for (int k = 0; k < c->o->ntrace; k++) {
        int p = c->o->trace[k];
        if (c->on_ground[p])
            continue;
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.2\" "
                   "stroke-dasharray=\"4,2\" points=\"", test ? "#bbb" : "#e07b39");
        int step = c->nrows > 2000 ? c->nrows / 2000 : 1;
        for (int r = 0, first = 1; r < c->nrows; r += step, first = 0)
            put_xy(f, first ? "" : " ", c->X[(size_t)r * c->np + p], c->Y[(size_t)r * c->np + p],
                   ANIM_DEC);
        fputs("\"/>\n", f);
    }
    /* guides */
    for (int j = 0; j < m->njoints; j++) {
        if (m->joints[j].kind != MECH_JOINT_SLIDER)
            continue;
        int g = m->joints[j].link[1];
        put_shape(f, c, "polyline", test ? "stroke=\"#888\" stroke-width=\"2\" fill=\"none\""
                                         : "stroke=\"#555\" stroke-width=\"2\" fill=\"none\"",
                  guide_shape, j, g != 0, xs, ys);
        if (g == 0) {
            guide_shape(c, j, c->rows[0], xs, ys);
            put_guide_hatch(f, xs[0], ys[0], xs[1], ys[1], test);
        }
    }
    /* ground pivots: ground points that are pins */
    for (int k = 0; k < m->links[0].npoints; k++) {
        int p = m->links[0].points[k].id;
        if (c->pinned[p])
            put_pivot(f, c->X[p], c->Y[p], test);
    }
    /* links: plates (3+ points not on a line) and bars */
    for (int i = 1; i < m->nlinks; i++) {
        char attrs[200];
        int n = c->nhull[i];
        if (n < 2)
            continue;
        const char *fill = test ? "#d6d6d6" : link_fill[i % 6];
        const char *stroke = test ? "#8a8a8a" : link_stroke[i % 6];
        if (n >= 3)
            snprintf(attrs, sizeof attrs, "fill=\"%s\" fill-opacity=\"%s\" stroke=\"%s\" "
                     "stroke-width=\"2.5\" stroke-linejoin=\"round\"", fill, test ? "1" : "0.75",
                     stroke);
        else
            snprintf(attrs, sizeof attrs, "fill=\"none\" stroke=\"%s\" stroke-width=\"8\" "
                     "stroke-linecap=\"round\"", stroke);
        put_shape(f, c, n >= 3 ? "polygon" : "polyline", attrs, link_shape, i, 1, xs, ys);
    }
    /* slider blocks */
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER)
            put_shape(f, c, "polygon",
                      test ? "fill=\"#c4c4c4\" stroke=\"#666\" stroke-width=\"1.5\""
                           : "fill=\"#cfd6de\" stroke=\"#34495e\" stroke-width=\"1.5\" "
                             "stroke-linejoin=\"round\"",
                      block_shape, j, 1, xs, ys);
    /* points: a disc (pins) or a dot, with the name; test mode: unique colours */
    for (int p = 0; p < c->np; p++) {
        size_t at = (size_t)c->rows[0] * c->np + p;
        fprintf(f, "<g id=\"P-%s\" transform=\"translate(%s,%s)\">", m->point_names[p],
                plot_fmt(b1, c->X[at], ANIM_DEC), plot_fmt(b2, c->Y[at], ANIM_DEC));
        if (test) {
            char col[16];
            test_colour(p, col, sizeof col);
            fprintf(f, "<circle r=\"5\" fill=\"%s\" data-point=\"%s\"/>", col, m->point_names[p]);
        } else {
            if (c->pinned[p])
                fputs("<circle r=\"4.5\" fill=\"#fff\" stroke=\"#111\" stroke-width=\"1.6\"/>", f);
            else
                fputs("<circle r=\"3\" fill=\"#111\"/>", f);
            fprintf(f, "<text x=\"7\" y=\"-7\" font-size=\"11\" fill=\"#111\">%s</text>",
                    m->point_names[p]);
        }
        if (!c->on_ground[p] && c->nframes > 1) {
            fprintf(f, "<animateTransform attributeName=\"transform\" type=\"translate\" "
                       "dur=\"%ss\" repeatCount=\"indefinite\" values=\"", dur);
            for (int k = 0; k < c->nframes; k++) {
                size_t q = (size_t)c->rows[k] * c->np + p;
                fprintf(f, "%s%s %s", k ? ";" : "", plot_fmt(b1, c->X[q], ANIM_DEC),
                        plot_fmt(b2, c->Y[q], ANIM_DEC));
            }
            fputs("\"/>", f);
        }
        fputs("</g>\n", f);
    }
    if (c->o->pause_at >= 0 && c->nframes > 1) /* tests: a still of the running animation */
        fprintf(f, "<script>var s = document.documentElement; s.pauseAnimations(); "
                   "s.setCurrentTime(%.9g); window.addEventListener('load', function () "
                   "{ s.pauseAnimations(); s.setCurrentTime(%.9g); });</script>\n",
                c->o->pause_at, c->o->pause_at);
    fputs("</svg>\n", f);
    free(xs);
    free(ys);
    return ferror(f) ? -1 : 0;
}

int plot_animation_write(const mech_model *m, const mech_table *t, const plot_anim_options *o,
                         const char *path, mech_diag *d)
{
    anim_ctx c;
    memset(&c, 0, sizeof c);
    c.m = m;
    c.t = t;
    c.o = o;
    int rc = anim_prepare(&c, d);
    if (rc == MECH_OK)
        rc = write_file_whole(path, emit_animation, &c, d);
    anim_free(&c);
    return rc;
}
