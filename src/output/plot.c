/* src/output/plot.c: the figures of a solved sweep (mech plot): which figures a
 * table calls for (plot_plan: groups of series, split at PLOT_MAX_SERIES),
 * and each figure against the driver (plot_figure_write: axes, series in
 * line styles readable in black and white, markers, legend).
 * docs/plots.md. The animation is src/output/plot_anim.c; the SVG pieces both
 * use (numbers, text, axes, ticks, thinned paths) are src/output/plot_svg.c.
 *
 * Every file is written whole: to NAME.tmpPID beside the target, renamed
 * over it when complete (write_file_whole, src/output/output.c). Coordinates are
 * rounded to 0.01 px. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"
#include "output.h"

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
    const char **items; /* [outputs + joints + 1] scratch: a group's item names */
    char (*labels)[80]; /* [outputs + joints + 1] scratch: legend names built */
    const char **lab;   /* [outputs + joints + 1] scratch: a group's legend names */
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

/* Points: x and y of each output point, per level. */
static void plan_points(plan *p, const mech_model *m)
{
    static const char *const pos[] = {".x", ".y"}, *const vel[] = {".vx", ".vy"},
                             *const acc[] = {".ax", ".ay"};
    static const char *const pos_l[] = {".x", ".y"}, *const vel_l[] = {".vx", ".vy"},
                             *const acc_l[] = {".ax", ".ay"};
    const char **items = p->items, **lab = p->lab;
    int n = 0;
    for (int i = 0; i < m->outputs.npoints; i++, n++)
        items[n] = lab[n] = m->point_names[m->outputs.points[i]];
    add_group(p, "points-position", "Point positions", "position", items, lab, n, pos, pos_l, 2);
    add_group(p, "points-velocity", "Point velocities", "velocity", items, lab, n, vel, vel_l, 2);
    add_group(p, "points-acceleration", "Point accelerations", "acceleration", items, lab, n,
              acc, acc_l, 2);
}

/* Links: angle, omega, alpha of each output link (legend: name and symbol). */
static void plan_links(plan *p, const mech_model *m)
{
    static const char *const angle[] = {".angle"}, *const omega[] = {".omega"},
                             *const alpha[] = {".alpha"}, *const none[] = {""};
    const char **items = p->items, **lab = p->lab;
    char (*labels)[80] = p->labels;
    int n = 0;
    for (int i = 0; i < m->outputs.nlinks; i++, n++) {
        const mech_link *l = &m->links[m->outputs.links[i]];
        items[n] = l->name;
        if (l->symbol && strcmp(l->symbol, l->name) != 0)
            snprintf(labels[n], sizeof labels[n], "%s (%s)", l->name, l->symbol);
        else
            snprintf(labels[n], sizeof labels[n], "%s", l->name);
        lab[n] = labels[n];
    }
    add_group(p, "links-angle", "Link angles", "angle", items, lab, n, angle, none, 1);
    add_group(p, "links-velocity", "Link angular velocities", "angular velocity", items, lab, n,
              omega, none, 1);
    add_group(p, "links-acceleration", "Link angular accelerations", "angular acceleration",
              items, lab, n, alpha, none, 1);
}

/* Sliders: s, v, a of each output slider. */
static void plan_sliders(plan *p, const mech_model *m)
{
    static const char *const s_[] = {".s"}, *const v_[] = {".v"}, *const a_[] = {".a"},
                             *const none[] = {""};
    const char **items = p->items, **lab = p->lab;
    int n = 0;
    for (int i = 0; i < m->outputs.nsliders; i++, n++)
        items[n] = lab[n] = m->joints[m->outputs.sliders[i]].name;
    add_group(p, "sliders-displacement", "Slider displacements", "displacement", items, lab, n,
              s_, none, 1);
    add_group(p, "sliders-velocity", "Slider velocities", "velocity", items, lab, n, v_, none, 1);
    add_group(p, "sliders-acceleration", "Slider accelerations", "acceleration", items, lab, n,
              a_, none, 1);
}

/* The links a joint's reaction acts on and comes from (docs/forces.md,
 * "Sign conventions"): a revolute's is the force on the later link in the
 * file from the earlier one; a slider's, on the sliding link from the guide. */
static void reaction_links(const mech_joint *jt, int *on, int *from)
{
    int later = jt->kind != MECH_JOINT_SLIDER && jt->link[1] > jt->link[0];
    *on = later ? jt->link[1] : jt->link[0];
    *from = later ? jt->link[0] : jt->link[1];
}

/* Forces: one figure per joint, with and without friction when both exist;
 * the title and the legend say which link the force acts on. */
static void plan_forces(plan *p, const mech_model *m)
{
    static const char *const fxy[] = {".Fx", ".Fy", ".Fx.nofriction", ".Fy.nofriction"};
    static const char *const fxy_l[] = {"Fx", "Fy", "Fx, no friction", "Fy, no friction"};
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        char stem[96], title[160], nf[96];
        int on, from, n0 = p->n;
        reaction_links(jt, &on, &from);
        snprintf(nf, sizeof nf, "%s.Fx.nofriction", jt->name);
        int per = mech_table_column(p->t, nf) >= 0 ? 4 : 2;
        snprintf(stem, sizeof stem, "force-%s", jt->name);
        snprintf(title, sizeof title, "Reaction at %s joint %s: force on %s from %s",
                 jt->kind == MECH_JOINT_SLIDER ? "slider" : "revolute", jt->name,
                 m->links[on].name, m->links[from].name);
        const char *it[1] = {jt->name}, *lb[1] = {""};
        add_group(p, stem, title, "force", it, lb, 1, fxy, fxy_l, per);
        for (int k = n0; k < p->n; k++) {
            snprintf(p->figs[k].note[0], sizeof p->figs[k].note[0], "%s: force on %s",
                     jt->name, m->links[on].name);
            snprintf(p->figs[k].note[1], sizeof p->figs[k].note[1], "from %s",
                     m->links[from].name);
        }
    }
}

/* The drivers with rows (laws of time), their loads named by the driver:
 * their torques in one figure, their forces in another, each with and
 * without friction when both exist. */
static void plan_drivers(plan *p, const mech_model *m)
{
    const char **it = xcalloc((size_t)m->ndrivers + 1, sizeof *it);
    for (int kind = 0; it && kind < 2; kind++) {  /* 0 torques (links), 1 forces (sliders) */
        int n = 0;
        for (int i = 0; i < m->ndrivers; i++)
            if ((m->drivers[i].kind == MECH_DRIVE_SLIDER) == kind && !drivers_is_sweep(m, i))
                it[n++] = drivers_name(m, i);
        static const char *const sfx[2][2] = {{".torque", ".torque.nofriction"},
                                              {".force", ".force.nofriction"}};
        static const char *const both_label[] = {" with friction", " no friction"};
        static const char *const one_label[] = {""};
        char nf[160];
        snprintf(nf, sizeof nf, "%s%s", n ? it[0] : "", sfx[kind][1]);
        int both = n > 0 && mech_table_column(p->t, nf) >= 0;
        if (n > 0)
            add_group(p, kind ? "driver-forces" : "driver-torques",
                      kind ? "Driver forces" : "Driver torques", kind ? "force" : "torque", it,
                      it, n, sfx[kind], both ? both_label : one_label, both ? 2 : 1);
    }
    free(it);
}

/* The load of the driver that is the sweep ("driver.torque" or
 * "driver.force"), with and without friction when both exist. */
static void plan_driver(plan *p, const mech_model *m)
{
    const mech_table *t = p->t;
    plan_drivers(p, m);
    int sweep = drivers_sweep(m);
    if (sweep < 0)
        return;
    const char *drv = mech_table_column(t, "driver.torque") >= 0 ? "driver.torque"
                      : mech_table_column(t, "driver.force") >= 0 ? "driver.force" : NULL;
    if (!drv)
        return;
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
    int n0 = p->n;
    add_group(p, torque ? "driver-torque" : "driver-force",
              torque ? "Driver torque" : "Driver force", torque ? "torque" : "force", it, lb,
              1, sfx, both ? sfx_both : sfx_one, both ? 2 : 1);
    /* applied by the ground to the driver link (docs/forces.md); a driving
       slider's force acts along its guide on the sliding link */
    const mech_motion *dr = &m->drivers[sweep];
    int on = dr->kind == MECH_DRIVE_ANGLE ? dr->index : m->joints[dr->index].link[0];
    for (int k = n0; k < p->n && on >= 0; k++) {
        snprintf(p->figs[k].note[0], sizeof p->figs[k].note[0], "%s on %s",
                 torque ? "torque" : "force", m->links[on].name);
        snprintf(p->figs[k].note[1], sizeof p->figs[k].note[1], "from %s",
                 torque ? m->links[0].name : "the guide");
    }
}

int plot_plan(const mech_model *m, const mech_table *t, plot_figure *figs, int max)
{
    plan p = {figs, 0, max, t, NULL, NULL, NULL};
    int ni = m->outputs.npoints + m->outputs.nlinks + m->outputs.nsliders + m->njoints + 1;
    p.items = xcalloc((size_t)ni, sizeof *p.items);
    p.labels = xcalloc((size_t)ni, sizeof *p.labels);
    p.lab = xcalloc((size_t)ni, sizeof *p.lab);
    if (p.items && p.labels && p.lab) {
        plan_points(&p, m);
        plan_links(&p, m);
        plan_sliders(&p, m);
        plan_forces(&p, m);
        plan_driver(&p, m);
    }
    free(p.items);
    free(p.labels);
    free(p.lab);
    return p.n;
}

/* ------------------------------------------------------------------ */
/* One figure.                                                         */

typedef struct fig_ctx {
    const mech_model *m;
    const mech_table *t;
    const plot_figure *f;
    const char *subtitle;
} fig_ctx;

/* The driver value of row r in display units: deg, or mm for a slider. */
static double xval(const fig_ctx *c, int r)
{
    double q = mech_table_get(c->t, r, 0);
    if (c->f->xlabel[0])
        return q * RAD2DEG;  /* an angle of its own (a cam's) */
    if (c->m->has_driver && c->m->driver.kind == MECH_DRIVE_TIME)
        return q;  /* drivers as laws of time: t in s */
    return c->m->has_driver && c->m->driver.kind == MECH_DRIVE_SLIDER ? q * 1e3 : q * RAD2DEG;
}

static void x_title(const fig_ctx *c, FILE *f)
{
    const mech_model *m = c->m;
    if (c->f->xlabel[0]) {
        plot_put_text(f, c->f->xlabel);
    } else if (m->has_driver && m->driver.kind == MECH_DRIVE_TIME) {
        fputs("time t [s]", f);
    } else if (m->has_driver && m->driver.kind == MECH_DRIVE_SLIDER) {
        fputs("displacement of slider ", f);
        plot_put_text(f, drivers_name(m, drivers_sweep(m)));
        fputs(" [mm]", f);
    } else {
        fputs("angle of ", f);
        plot_put_text(f, m->has_driver ? drivers_name(m, drivers_sweep(m)) : "the driver");
        fputs(" [deg]", f);
    }
}

/* Pixel position of x on the plot area (axis ax) and of y (axis ay). */
static double px_of(const plot_axis *ax, double x)
{
    return AX_L + (x - ax->lo) / (ax->hi - ax->lo) * (AX_R - AX_L);
}

static double py_of(const plot_axis *ay, double y)
{
    return AX_B - (y - ay->lo) / (ay->hi - ay->lo) * (AX_B - AX_T);
}

/* The axes: x the driver's range (plain degrees or millimetres), y every
 * finite value of every series, widened to whole ticks. */
static void fig_axes(const fig_ctx *c, plot_axis *ax, plot_axis *ay)
{
    const mech_table *t = c->t;
    const plot_figure *fg = c->f;
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
    plot_axis_make(ax, xlo, xhi, 9, 0);
    plot_axis_make(ay, ylo, yhi, 7, 1);
    ax->exp10 = 0; /* driver axis: plain degrees or millimetres */
    ax->dec = ax->step >= 1 ? 0 : (int)ceil(-log10(ax->step) - 1e-9);
}

/* The document's start: root element, title, markers and clip path,
 * background, the figure's title and subtitle. */
static void fig_head(FILE *f, const fig_ctx *c, const plot_axis *ax, const plot_axis *ay)
{
    const plot_figure *fg = c->f;
    /* data-mech-axes "sx ox sy oy": page x = ox + sx X, y = oy - sy Y for X, Y
       in the axes' display units (what px_of, py_of compute; for tests) */
    double sx = (AX_R - AX_L) / (ax->hi - ax->lo), sy = (AX_B - AX_T) / (ay->hi - ay->lo);
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" "
               "xmlns:xlink=\"http://www.w3.org/1999/xlink\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\" font-family=\"DejaVu Sans,Arial,Helvetica,sans-serif\" "
               "font-size=\"12\" data-mech-axes=\"%.12g %.12g %.12g %.12g\">\n", FIG_W, FIG_H,
            FIG_W, FIG_H, sx, AX_L - ax->lo * sx, sy, AX_B + ay->lo * sy);
    fputs("<title>", f);
    plot_put_text(f, fg->title);
    fputs("</title>\n<defs>", f);
    for (int k = 0; k < 4; k++)
        fprintf(f, "<path id=\"m%d\" d=\"%s\"/>", k, plot_marker_path[k]);
    fprintf(f, "<clipPath id=\"plot\"><rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\"/>"
               "</clipPath></defs>\n", AX_L, AX_T, AX_R - AX_L, AX_B - AX_T);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"#fff\"/>\n", FIG_W, FIG_H);
    /* titles */
    fprintf(f, "<text x=\"%d\" y=\"24\" font-size=\"16\" font-weight=\"bold\">", AX_L);
    plot_put_text(f, fg->title);
    fputs("</text>\n", f);
    if (c->subtitle) {
        fprintf(f, "<text x=\"%d\" y=\"44\" fill=\"#555\">", AX_L);
        plot_put_text(f, c->subtitle);
        fputs("</text>\n", f);
    }
}

/* Grid, ticks and labels, the frame of the plot area, the axis titles. */
static void fig_frame(FILE *f, const fig_ctx *c, const plot_axis *ax, const plot_axis *ay)
{
    const plot_figure *fg = c->f;
    fputs("<g fill=\"#000\" stroke-width=\"1\">\n", f);
    plot_put_ticks(f, ax, 0, AX_L, AX_R);
    plot_put_ticks(f, ay, 1, AX_B, AX_T);
    fputs("</g>\n", f);
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"none\" "
               "stroke=\"#000\"/>\n", AX_L, AX_T, AX_R - AX_L, AX_B - AX_T);
    fprintf(f, "<text x=\"%d\" y=\"%d\" text-anchor=\"middle\" font-size=\"13\">",
            (AX_L + AX_R) / 2, AX_B + 44);
    x_title(c, f);
    fputs("</text>\n", f);
    fprintf(f, "<text transform=\"translate(22,%d) rotate(-90)\" text-anchor=\"middle\" "
               "font-size=\"13\">", (AX_T + AX_B) / 2);
    plot_put_axis_title(f, fg->ylabel, fg->yunit, ay->exp10);
    fputs("</text>\n", f);
}

/* Series s of a figure as page pixels (plot_vertex_fn). */
typedef struct curve_ctx {
    const fig_ctx *c;
    const plot_axis *ax, *ay;
    int s;
} curve_ctx;

static int curve_vertex(const void *vctx, int r, double *px, double *py)
{
    const curve_ctx *k = vctx;
    double x = xval(k->c, r), y = mech_table_get(k->c->t, r, k->c->f->col[k->s]) * k->c->f->yscale;
    *px = px_of(k->ax, x);
    *py = py_of(k->ay, y);
    return isfinite(x) && isfinite(y);
}

/* A curve of more than 4 points per pixel column, that the thinning to
 * PLOT_THIN_TOL cannot bring to that many vertices (a scribble at the scale
 * of the pixels): each column keeps its first, lowest, highest and last
 * point, in row order, so the curve covers the same pixels. */
static void curve_columns(plot_pen *p, const curve_ctx *k, int nrows)
{
    plot_run run = {0};
    for (int r = 0; r < nrows; r++) {
        double px, py;
        if (!curve_vertex(k, r, &px, &py)) {
            plot_run_flush(&run, p);
            p->state = 0;
            continue;
        }
        plot_run_add(&run, p, r, px, py, (long)floor(px - AX_L));
    }
    plot_run_flush(&run, p);
}

/* The curve of series s: a path broken at non-finite values. */
static void fig_curve(FILE *f, const fig_ctx *c, const plot_axis *ax, const plot_axis *ay,
                      int s, const char *colour, const char *dash)
{
    const mech_table *t = c->t;
    fprintf(f, "<path stroke=\"%s\"%s%s%s d=\"", colour, *dash ? " stroke-dasharray=\"" : "",
            dash, *dash ? "\"" : "");
    /* A 10^6-step sweep would write 10^6 vertices (350 MB of SVG) on 504
     * pixel columns: past THIN_FROM rows the curve is thinned to within
     * PLOT_THIN_TOL px of every row (extremes kept), or, when that leaves
     * more than THIN_FROM vertices, to its pixel columns. */
    curve_ctx k = {c, ax, ay, s};
    plot_pen p = {f, 0, 2, 0};
    if (t->nrows <= THIN_FROM) {
        plot_draw_all(&p, curve_vertex, &k, t->nrows);
    } else {
        plot_pen count = {NULL, 0, 2, 0};
        if (plot_thin_draw(&count, PLOT_THIN_TOL, curve_vertex, &k, t->nrows) <= THIN_FROM)
            plot_thin_draw(&p, PLOT_THIN_TOL, curve_vertex, &k, t->nrows);
        else
            curve_columns(&p, &k, t->nrows);
    }
    fputs("\"/>\n", f);
}

/* The markers of series s: one every `every` rows, staggered by series. */
static void fig_markers(FILE *f, const fig_ctx *c, const plot_axis *ax, const plot_axis *ay,
                        int s, int every)
{
    const mech_table *t = c->t;
    const plot_figure *fg = c->f;
    const char *colour, *dash;
    int shape, filled;
    char b1[32], b2[32];
    plot_style(s, &colour, &dash, &shape, &filled);
    fprintf(f, "<g stroke=\"%s\" fill=\"%s\">", colour, filled ? colour : "#fff");
    int dots = fg->dots[s];  /* points: every row, each marked */
    for (int r = dots ? 0 : (s * every) / (fg->nseries > 0 ? fg->nseries : 1); r < t->nrows;
         r += dots ? 1 : every) {
        double x = xval(c, r), y = mech_table_get(t, r, fg->col[s]) * fg->yscale;
        if (isfinite(x) && isfinite(y))
            fprintf(f, "<use xlink:href=\"#m%d\"%s x=\"%s\" y=\"%s\"/>", shape,
                    dots ? " class=\"dot\"" : "", plot_fmt(b1, px_of(ax, x), 2),
                    plot_fmt(b2, py_of(ay, y), 2));
    }
    fputs("</g>\n", f);
}

/* Every series, clipped to the plot area: its curve, then its markers. */
static void fig_series(FILE *f, const fig_ctx *c, const plot_axis *ax, const plot_axis *ay)
{
    const plot_figure *fg = c->f;
    int every = c->t->nrows > 12 ? c->t->nrows / 12 : 1;
    fputs("<g clip-path=\"url(#plot)\" fill=\"none\" stroke-width=\"1.6\" "
          "stroke-linejoin=\"round\">\n", f);
    for (int s = 0; s < fg->nseries; s++) {
        const char *colour, *dash;
        int shape, filled;
        plot_style(s, &colour, &dash, &shape, &filled);
        if (!fg->dots[s])
            fig_curve(f, c, ax, ay, s, colour, dash);
        fig_markers(f, c, ax, ay, s, every);
    }
    fputs("</g>\n", f);
}

/* The legend, right of the plot: its heading (fg->note: which link a force
 * acts on), then each series' style and name. */
static void fig_legend(FILE *f, const fig_ctx *c)
{
    const plot_figure *fg = c->f;
    int lx = AX_R + 14, ly = AX_T;
    int nnote = (fg->note[0][0] != '\0') + (fg->note[1][0] != '\0');
    fprintf(f, "<rect x=\"%d\" y=\"%d\" width=\"%d\" height=\"%d\" fill=\"#fff\" "
               "stroke=\"#999\"/>\n", lx, ly, FIG_W - lx - 6,
            12 + 22 * fg->nseries + 16 * nnote + (nnote ? 4 : 0));
    for (int k = 0, y = ly + 16; k < 2; k++)
        if (fg->note[k][0]) {
            fprintf(f, "<text x=\"%d\" y=\"%d\" font-size=\"11\" class=\"legend-note\">",
                    lx + 8, y);
            plot_put_text(f, fg->note[k]);
            fputs("</text>\n", f);
            y += 16;
        }
    ly += 16 * nnote + (nnote ? 4 : 0);
    for (int s = 0; s < fg->nseries; s++) {
        const char *colour, *dash;
        int shape, filled;
        plot_style(s, &colour, &dash, &shape, &filled);
        int y = ly + 17 + 22 * s;
        if (!fg->dots[s])
            fprintf(f, "<path d=\"M%d,%dh36\" fill=\"none\" stroke=\"%s\" stroke-width=\"1.6\"%s%s%s/>",
                    lx + 8, y, colour, *dash ? " stroke-dasharray=\"" : "", dash,
                    *dash ? "\"" : "");
        fprintf(f, "<use xlink:href=\"#m%d\" x=\"%d\" y=\"%d\" stroke=\"%s\" fill=\"%s\"/>", shape,
                lx + 26, y, colour, filled ? colour : "#fff");
        fprintf(f, "<text x=\"%d\" y=\"%d\">", lx + 50, y + 4);
        plot_put_text(f, fg->label[s]);
        fputs("</text>\n", f);
    }
}

static int emit_figure(FILE *f, const void *vctx)
{
    const fig_ctx *c = vctx;
    if (c->f->kind == PLOT_PATH)
        return plot_path_svg(f, c->m, c->t, c->f, c->subtitle);
    plot_axis ax, ay;
    fig_axes(c, &ax, &ay);
    fig_head(f, c, &ax, &ay);
    fig_frame(f, c, &ax, &ay);
    fig_series(f, c, &ax, &ay);
    fig_legend(f, c);
    fputs("</svg>\n", f);
    return ferror(f) ? -1 : 0;
}

int plot_figure_write(const mech_model *m, const mech_table *t, const plot_figure *f,
                      const char *subtitle, const char *path, mech_diag *d)
{
    fig_ctx c = {m, t, f, subtitle};
    return write_file_whole(path, emit_figure, &c, d);
}
