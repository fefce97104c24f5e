/* src/output/report_parts.c: the sections of the HTML report (src/output/report.c puts
 * them together): escaped text, inline SVG with its ids made unique, the
 * structure (what `mech check` prints, then tables of links, joints,
 * driver, parameters, outputs), the diagnostics (what `mech solve --stats`
 * prints, and every warning and note) and the JSON of the solved rows the
 * slider shows. docs/report.md. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "output.h"
#include "load.h"

#define RAD2DEG_R 57.295779513082321

/* ------------------------------------------------------------------ */
/* Inline SVG.                                                         */

/* The length of the reference starting at s that needs the prefix after
 * it (" id=\"", "url(#", "href=\"#"), or 0. */
static size_t id_reference(const char *s)
{
    static const char *const refs[] = {" id=\"", "url(#", "href=\"#"};
    for (size_t k = 0; k < sizeof refs / sizeof refs[0]; k++)
        if (strncmp(s, refs[k], strlen(refs[k])) == 0)
            return strlen(refs[k]);
    return 0;
}

void report_put_svg(FILE *f, const char *svg, const char *prefix)
{
    const char *s = svg;
    if (strncmp(s, "<?xml", 5) == 0) {  /* the declaration has no place in HTML */
        const char *end = strstr(s, "?>");
        s = end ? end + 2 : s;
        while (*s == '\n')
            s++;
    }
    for (; *s; s++) {
        size_t n = id_reference(s);
        if (n) {
            fwrite(s, 1, n, f);
            fputs(prefix, f);
            s += n - 1;
        } else {
            fputc(*s, f);
        }
    }
}

/* ------------------------------------------------------------------ */
/* Structure.                                                          */

static void row_text(FILE *f, const char *key, const char *value)
{
    fprintf(f, "<tr><th>%s</th><td>", key);
    plot_put_text(f, value);
    fputs("</td></tr>\n", f);
}

/* A crank's or slider's range and speed (laws of time: the sweep line says
 * it). */
static void driver_range_text(const mech_model *m, char *buf, size_t n)
{
    const mech_driver *dr = &m->driver;
    int angle = dr->kind == MECH_DRIVE_ANGLE;
    double k = angle ? RAD2DEG_R : 1e3;
    snprintf(buf, n, "from %.6g to %.6g %s, speed %.6g %s", dr->values[0] * k,
             dr->values[dr->nvalues - 1] * k, angle ? "deg" : "mm", dr->speed,
             angle ? "rad/s" : "m/s");
}

static void row_line(void *ctx, const char *label, const char *text)
{
    row_text(ctx, label, text);
}

/* The lines of `mech check` (model_describe), then the driver's range. */
static void put_summary(FILE *f, const mech_model *m, const mech_summary *s)
{
    char b[512];
    fputs("<table class=\"kv\">\n", f);
    model_describe(m, s, row_line, f);
    if (m->has_driver && m->driver.kind != MECH_DRIVE_TIME) {
        driver_range_text(m, b, sizeof b);
        row_text(f, "driver range", b);
    }
    fputs("</table>\n", f);
}

static void put_links(FILE *f, const mech_model *m)
{
    fputs("<h3>Links</h3>\n<table><thead><tr><th>link</th><th>points (x, y in its frame, "
          "mm)</th><th>mass</th></tr></thead>\n<tbody>\n", f);
    for (int i = 0; i < m->nlinks; i++) {
        const mech_link *l = &m->links[i];
        fputs("<tr><td>", f);
        plot_put_text(f, l->name);
        fputs("</td><td>", f);
        for (int k = 0; k < l->npoints; k++) {
            fputs(k ? ", " : "", f);
            plot_put_text(f, l->points[k].name);
            fprintf(f, " (%.6g, %.6g)", l->points[k].x * 1e3, l->points[k].y * 1e3);
        }
        if (l->has_mass)
            fprintf(f, "</td><td>%.6g kg, centre (%.6g, %.6g) mm, %.6g kg m^2</td></tr>\n",
                    l->mass, l->center[0] * 1e3, l->center[1] * 1e3, l->inertia);
        else
            fputs("</td><td></td></tr>\n", f);
    }
    fputs("</tbody></table>\n", f);
}

static void put_joints(FILE *f, const mech_model *m)
{
    fputs("<h3>Joints</h3>\n<table><thead><tr><th>joint</th><th>kind</th><th>links</th>"
          "<th>friction</th></tr></thead>\n<tbody>\n", f);
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        fputs("<tr><td>", f);
        plot_put_text(f, jt->name);
        if (jt->kind == MECH_JOINT_REVOLUTE)
            fputs("</td><td>revolute", f);
        else
            fprintf(f, "</td><td>%s slider, guide at %.6g deg", jt->locked ? "prismatic"
                    : "pin-in-slot", jt->angle * RAD2DEG_R);
        fputs("</td><td>", f);
        plot_put_text(f, m->links[jt->link[0]].name);
        fputs(jt->kind == MECH_JOINT_SLIDER ? " on " : ", ", f);
        plot_put_text(f, m->links[jt->link[1]].name);
        if (jt->friction > 0)
            fprintf(f, "</td><td>%.6g</td></tr>\n", jt->friction);
        else
            fputs("</td><td></td></tr>\n", f);
    }
    fputs("</tbody></table>\n", f);
}

/* Loops listed in the file, parameters and the outputs named. */
static void put_lists(FILE *f, const mech_model *m)
{
    if (m->nloops) {
        fputs("<h3>Loops (listed in the file)</h3>\n<ul>\n", f);
        for (int i = 0; i < m->nloops; i++) {
            fputs("<li>", f);
            for (int k = 0; k < m->loops[i].npoints; k++) {
                fputs(k ? " - " : "", f);
                plot_put_text(f, m->point_names[m->loops[i].points[k]]);
            }
            fputs("</li>\n", f);
        }
        fputs("</ul>\n", f);
    }
    if (m->nparams) {
        fputs("<h3>Parameters (SI units)</h3>\n<table><tbody>\n", f);
        for (int i = 0; i < m->nparams; i++) {
            fputs("<tr><td>", f);
            plot_put_text(f, m->params[i].name);
            fprintf(f, "</td><td class=\"num\">%.9g</td></tr>\n", m->params[i].value);
        }
        fputs("</tbody></table>\n", f);
    }
}

void report_put_structure(FILE *f, const report_input *in)
{
    fputs("<section id=\"structure\">\n<h2>Structure</h2>\n"
          "<p>As <code>mech check</code> prints it:</p>\n", f);
    put_summary(f, in->m, in->summary);
    put_links(f, in->m);
    put_joints(f, in->m);
    put_lists(f, in->m);
    fputs("</section>\n", f);
}

/* ------------------------------------------------------------------ */
/* Diagnostics.                                                        */

/* The lines of `mech solve --stats` (src/cli/cmd_solve.c), less the times. */
static void put_stats(FILE *f, const mech_model *m, const mech_solve_stats *st)
{
    int angle = m->driver.kind == MECH_DRIVE_ANGLE;
    char b[256];
    fputs("<table class=\"kv\" id=\"stats\">\n", f);
    snprintf(b, sizeof b, "%d steps, %d of %d unknowns solved (%d of %d blocks)", st->steps,
             st->nsolved, st->nunknowns, st->nblocks_solved, st->nblocks);
    row_text(f, "sweep", b);
    snprintf(b, sizeof b, "%.2f per step, at most %d",
             st->steps ? (double)st->iterations / st->steps : 0.0, st->max_iterations);
    row_text(f, "Newton iterations", b);
    snprintf(b, sizeof b, "%.3g m", st->worst_residual);
    row_text(f, "worst residual", b);
    if (st->steps) {
        snprintf(b, sizeof b, "%.3g at q = %.6g %s", st->min_rcond,
                 angle ? st->worst_rcond_q * RAD2DEG_R
                 : m->driver.kind == MECH_DRIVE_TIME ? st->worst_rcond_q : st->worst_rcond_q * 1e3,
                 angle ? "deg" : m->driver.kind == MECH_DRIVE_TIME ? "s" : "mm");
        row_text(f, "smallest rcond", b);
    }
    snprintf(b, sizeof b, "%d full, %d refactor", st->factorizations, st->refactorizations);
    row_text(f, "factorizations", b);
    if (st->worst_power_residual > 0.0 || st->max_friction_iterations > 0) {
        snprintf(b, sizeof b, "worst relative residual %.3g; friction iterations at most %d",
                 st->worst_power_residual, st->max_friction_iterations);
        row_text(f, "power balance", b);
    }
    snprintf(b, sizeof b, "%.3g us per step (sweep %.3g s, set-up %.3g s)",
             st->steps ? st->seconds / st->steps * 1e6 : 0.0, st->seconds, st->setup_seconds);
    row_text(f, "time", b);
    fputs("</table>\n", f);
}

void report_put_diagnostics(FILE *f, const report_input *in)
{
    static const char *const sev[] = {"error", "warning", "note"};
    fputs("<section id=\"diagnostics\">\n<h2>Diagnostics</h2>\n"
          "<p>How the solve went, as <code>mech solve --stats</code> prints it:</p>\n", f);
    put_stats(f, in->m, in->stats);
    if (in->ngaps > 0) {
        fprintf(f, "<h3>Gaps (%d)</h3>\n<ul id=\"gaps\">\n", in->ngaps);
        for (int i = 0; i < in->ngaps; i++) {
            fputs("<li class=\"error\">gap: ", f);
            plot_put_text(f, in->gaps[i]);
            fputs("</li>\n", f);
        }
        fputs("</ul>\n", f);
    }
    const mech_diag *d = in->diag;
    fprintf(f, "<h3>Errors, warnings and notes (%zu)</h3>\n", d ? d->count : (size_t)0);
    if (!d || d->count == 0) {
        fputs("<p>None.</p>\n</section>\n", f);
        return;
    }
    fputs("<ul id=\"messages\">\n", f);
    for (size_t i = 0; i < d->count; i++) {
        const mech_diag_entry *e = &d->entries[i];
        fprintf(f, "<li class=\"%s\">", sev[e->severity]);
        plot_put_text(f, e->file);
        if (e->mark.line > 0)
            fprintf(f, ":%d:%d", e->mark.line, e->mark.col);
        fprintf(f, ": %s: ", sev[e->severity]);
        plot_put_text(f, e->message);
        fputs("</li>\n", f);
    }
    fputs("</ul>\n</section>\n", f);
}

/* ------------------------------------------------------------------ */
/* The rows behind the slider.                                         */

/* '<' and '&' as \u escapes so that "</script" can never appear. */
void report_put_json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 0x20 || c == '<' || c == '&' || c == '>')
            fprintf(f, "\\u%04x", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

void report_put_json(FILE *f, const report_input *in)
{
    const mech_table *t = in->t;
    char num[FMT_DOUBLE_MAX];
    fmt_double(in->duration, num);  /* finite: a solved sweep's length */
    fprintf(f, "{\"duration\":%s,\"columns\":[", num);
    for (int c = 0; c < t->ncolumns; c++) {
        fputs(c ? ",\n{\"name\":" : "{\"name\":", f);
        report_put_json_string(f, t->columns[c].name);
        fputs(",\"unit\":", f);
        report_put_json_string(f, t->columns[c].unit);
        fputc('}', f);
    }
    fputs("],\n\"rows\":[", f);
    for (int k = 0; k < in->nframes; k++) {
        int r = in->frame_rows[k];
        fprintf(f, "%s[%d", k ? ",\n" : "\n", r);
        for (int c = 0; c < t->ncolumns; c++) {
            double v = mech_table_get(t, r, c);
            if (isfinite(v)) {
                fmt_double(v, num);
                fprintf(f, ",%s", num);
            } else
                fputs(",null", f);
        }
        fputc(']', f);
    }
    fputs("]}", f);
}
