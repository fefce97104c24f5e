/* src/output/cam_profile.c: what `mech cam` writes to make a cam (docs/cams.md,
 * section 5): the profile, the pitch curve and the design quantities at
 * evenly spaced cam angles as a table (CSV), and the outline as SVG and as
 * DXF (R12 ASCII, millimetres), each written whole. The geometry is
 * src/load/cam_geometry.c's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "load.h"
#include "output.h"

static const double PI = 3.14159265358979323846;

int cam_find(const mech_model *m, const char *name, char *err, size_t size)
{
    int n = model_ncams(m);
    if (n == 0)
        return snprintf(err, size, "the file has no 'cams:'"), -1;
    if (!name && n > 1)
        return snprintf(err, size, "the file has %d cams: name one with --cam (the first is "
                        "'%s')", n, m->cams->cam[0].name), -1;
    for (int i = 0; i < n; i++)
        if (!name || strcmp(m->cams->cam[i].name, name) == 0)
            return i;
    return snprintf(err, size, "no cam '%s' in the file (the first is '%s')", name,
                    m->cams->cam[0].name), -1;
}

static int set_column(mech_table *t, int c, const char *name, const char *unit)
{
    t->columns[c].name = xstrdup(name);
    t->columns[c].unit = xstrdup(unit);
    return t->columns[c].name && t->columns[c].unit ? 0 : -1;
}

int cam_profile_table(const mech_model *m, int i, int n, mech_table *t)
{
    static const char *const names[] = {"x", "s", "ds", "dds", "pitch.x", "pitch.y",
                                        "profile.x", "profile.y", "pressure_angle",
                                        "rho_pitch", "rho_profile", "face", "ddds"};
    const mech_cam *c = &m->cams->cam[i];
    int lin = c->motion == CAM_TRANSLATING;
    const char *units[] = {"rad", lin ? "m" : "rad", lin ? "m/rad" : "rad/rad",
                           lin ? "m/rad^2" : "rad/rad^2", "m", "m", "m", "m", "rad", "m", "m",
                           "m", lin ? "m/rad^3" : "rad/rad^3"};
    enum { NCOL = sizeof names / sizeof names[0] };
    memset(t, 0, sizeof *t);
    t->columns = xcalloc(NCOL, sizeof *t->columns);
    t->values = xcalloc((size_t)n * NCOL, sizeof *t->values);
    if (!t->columns || !t->values)
        return MECH_ENOMEM;
    for (int k = 0; k < NCOL; k++, t->ncolumns++)
        if (set_column(t, k, names[k], units[k]) < 0)
            return MECH_ENOMEM;
    for (int r = 0; r < n; r++) {  /* a whole turn: the program repeats within it */
        cam_point g;
        cam_geometry(m, c, 2.0 * PI * r / n, &g);
        const double v[NCOL] = {g.x, g.s[0], g.s[1], g.s[2], g.pitch[0], g.pitch[1],
                                g.profile[0], g.profile[1], g.pressure, g.rho_pitch,
                                g.rho_profile, g.face, g.s[3]};
        memcpy(t->values + (size_t)r * NCOL, v, sizeof v);
    }
    t->nrows = t->nrequested = n;
    return MECH_OK;
}

/* ---- the outline ---------------------------------------------------------- */

typedef struct outline {
    const mech_model *m;
    const mech_cam *c;
    const mech_table *t;
} outline;

static double cell(const mech_table *t, int r, int c) { return t->values[(size_t)r * t->ncolumns + c]; }

enum { COL_PITCH_X = 4, COL_PROFILE_X = 6 };

/* The polyline of columns (cx, cx + 1) in mm as SVG points, y up. */
static void svg_polyline(FILE *f, const mech_table *t, int cx, const char *style)
{
    fprintf(f, "<polygon %s points=\"", style);
    for (int r = 0; r < t->nrows; r++)
        fprintf(f, "%s%.4f,%.4f", r ? " " : "", cell(t, r, cx) * 1e3, -cell(t, r, cx + 1) * 1e3);
    fprintf(f, "\"/>\n");
}

static int emit_svg(FILE *f, const void *vctx)
{
    const outline *o = vctx;
    const mech_table *t = o->t;
    const mech_point *oc = &o->m->links[o->c->cam].points[o->c->cam_pivot[0]];
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int r = 0; r < t->nrows; r++)
        for (int k = 0; k < 4; k++) {
            double v = cell(t, r, COL_PITCH_X + k) * 1e3 * (k % 2 ? -1 : 1);
            lo[k % 2] = fmin(lo[k % 2], v), hi[k % 2] = fmax(hi[k % 2], v);
        }
    double pad = 0.05 * fmax(hi[0] - lo[0], hi[1] - lo[1]) + 1.0;
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" viewBox=\"%.4f %.4f %.4f %.4f\" "
               "width=\"%.4fmm\" height=\"%.4fmm\">\n",
            lo[0] - pad, lo[1] - pad, hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad,
            hi[0] - lo[0] + 2 * pad, hi[1] - lo[1] + 2 * pad);
    fprintf(f, "<title>cam '%s' of %s: the profile (solid), the pitch curve (dashed), the base "
               "circle (dotted), in mm in the cam's frame</title>\n", o->c->name,
            o->m->name ? o->m->name : o->m->file);
    double w = 0.004 * fmax(hi[0] - lo[0], hi[1] - lo[1]);
    fprintf(f, "<g stroke-width=\"%.4f\">\n", w);
    svg_polyline(f, t, COL_PROFILE_X, "fill=\"none\" stroke=\"black\" class=\"profile\"");
    svg_polyline(f, t, COL_PITCH_X, "fill=\"none\" stroke=\"#1f77b4\" stroke-dasharray=\"4 2\" "
                                    "class=\"pitch\"");
    fprintf(f, "<circle cx=\"%.4f\" cy=\"%.4f\" r=\"%.4f\" fill=\"none\" stroke=\"grey\" "
               "stroke-dasharray=\"1 2\" class=\"base\"/>\n",
            oc->x * 1e3, -oc->y * 1e3, o->c->base * 1e3);
    fprintf(f, "<path d=\"M%.4f %.4fh%.4fM%.4f %.4fv%.4f\" stroke=\"red\" class=\"centre\"/>\n",
            oc->x * 1e3 - 2 * pad, -oc->y * 1e3, 4 * pad, oc->x * 1e3, -oc->y * 1e3 - 2 * pad,
            4 * pad);
    fprintf(f, "</g>\n</svg>\n");
    return ferror(f) ? -1 : 0;
}

int cam_outline_svg(const mech_model *m, int i, const mech_table *t, const char *path,
                    mech_diag *d)
{
    outline o = {m, &m->cams->cam[i], t};
    return write_file_whole(path, emit_svg, &o, d);
}

/* DXF R12: the profile as a closed POLYLINE on layer PROFILE, the pitch
 * curve on PITCH, the base circle and the centre on BASE; millimetres. */
static void dxf_polyline(FILE *f, const mech_table *t, int cx, const char *layer)
{
    fprintf(f, "0\nPOLYLINE\n8\n%s\n66\n1\n70\n1\n", layer);
    for (int r = 0; r < t->nrows; r++)
        fprintf(f, "0\nVERTEX\n8\n%s\n10\n%.6f\n20\n%.6f\n30\n0.0\n", layer,
                cell(t, r, cx) * 1e3, cell(t, r, cx + 1) * 1e3);
    fprintf(f, "0\nSEQEND\n8\n%s\n", layer);
}

static int emit_dxf(FILE *f, const void *vctx)
{
    const outline *o = vctx;
    const mech_point *oc = &o->m->links[o->c->cam].points[o->c->cam_pivot[0]];
    fprintf(f, "0\nSECTION\n2\nHEADER\n9\n$INSUNITS\n70\n4\n0\nENDSEC\n0\nSECTION\n2\nENTITIES\n");
    dxf_polyline(f, o->t, COL_PROFILE_X, "PROFILE");
    dxf_polyline(f, o->t, COL_PITCH_X, "PITCH");
    fprintf(f, "0\nCIRCLE\n8\nBASE\n10\n%.6f\n20\n%.6f\n30\n0.0\n40\n%.6f\n", oc->x * 1e3,
            oc->y * 1e3, o->c->base * 1e3);
    fprintf(f, "0\nPOINT\n8\nBASE\n10\n%.6f\n20\n%.6f\n30\n0.0\n", oc->x * 1e3, oc->y * 1e3);
    fprintf(f, "0\nENDSEC\n0\nEOF\n");
    return ferror(f) ? -1 : 0;
}

int cam_outline_dxf(const mech_model *m, int i, const mech_table *t, const char *path,
                    mech_diag *d)
{
    outline o = {m, &m->cams->cam[i], t};
    return write_file_whole(path, emit_dxf, &o, d);
}

int cam_steps(double step)
{
    double n = ceil(2.0 * PI / step - 1e-9);  /* a whole turn of the cam */
    return n < 3 ? 3 : n > 1e7 ? 10000000 : (int)n;
}

double cam_default_step(void) { return PI / 180.0; }

/* ---- the figures of mech plot and mech report ---------------------------- */

int cam_plan(const mech_model *m, int i, plot_figure *figs)
{
    static const char *const stem[] = {"lift", "velocity", "acceleration", "jerk"};
    static const char *const what[] = {"lift s", "ds/dx", "d2s/dx2", "d3s/dx3"};
    static const int col[] = {1, 2, 3, 12};  /* s, ds, dds, ddds of cam_profile_table */
    const mech_cam *c = &m->cams->cam[i];
    int lin = c->motion == CAM_TRANSLATING;
    for (int k = 0; k < 4; k++) {
        plot_figure *f = &figs[k];
        memset(f, 0, sizeof *f);
        snprintf(f->name, sizeof f->name, "cam-%.40s-%s", c->name, stem[k]);
        snprintf(f->title, sizeof f->title, "Cam '%.40s': the follower's %s against the cam's "
                 "angle", c->name, what[k]);
        snprintf(f->ylabel, sizeof f->ylabel, "%s", what[k]);
        snprintf(f->yunit, sizeof f->yunit, "%s%s", lin ? "mm" : "deg",
                 k == 0 ? "" : k == 1 ? "/rad" : k == 2 ? "/rad^2" : "/rad^3");
        f->yscale = lin ? 1e3 : 180.0 / PI;
        f->col[0] = col[k];
        snprintf(f->label[0], sizeof f->label[0], "%s", what[k]);
        f->nseries = 1;
        snprintf(f->xlabel, sizeof f->xlabel, "cam angle x of '%.30s' [deg]", c->name);
    }
    plot_figure *f = &figs[4];
    memset(f, 0, sizeof *f);
    snprintf(f->name, sizeof f->name, "cam-%.40s-profile", c->name);
    snprintf(f->title, sizeof f->title, "Cam '%.40s': the profile and the pitch curve in its "
             "frame", c->name);
    snprintf(f->ylabel, sizeof f->ylabel, "y");
    snprintf(f->yunit, sizeof f->yunit, "mm");
    f->yscale = 1e3;
    f->kind = PLOT_PATH;
    f->col[0] = 6, f->ycol[0] = 7;  /* profile.x, profile.y */
    f->col[1] = 4, f->ycol[1] = 5;  /* pitch.x, pitch.y */
    snprintf(f->label[0], sizeof f->label[0], "profile");
    snprintf(f->label[1], sizeof f->label[1], "pitch curve");
    f->nseries = c->contact == CAM_KNIFE_EDGE ? 1 : 2;  /* a knife's pitch curve is its profile */
    return CAM_FIGURES;
}

int cam_figures_each(const mech_model *m, cam_figure_fn write, void *ctx, mech_diag *d)
{
    int rc = MECH_OK;
    for (int i = 0; i < model_ncams(m) && rc == MECH_OK; i++) {
        mech_table t;
        plot_figure figs[CAM_FIGURES];
        rc = cam_profile_table(m, i, cam_steps(cam_default_step()), &t);
        if (rc != MECH_OK)
            rc = diag_nomem(d, m->file, (mech_mark){0, 0});
        int n = rc == MECH_OK ? cam_plan(m, i, figs) : 0;
        for (int k = 0; k < n && rc == MECH_OK; k++)
            rc = write(ctx, &t, &figs[k]);
        mech_table_free(&t);
    }
    return rc;
}
