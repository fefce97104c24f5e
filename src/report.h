/* src/report.h: the self-contained HTML report of one mechanism (`mech
 * report`, docs/report.md): structure, equations, every figure of `mech
 * plot`, the animation with a slider over the driver positions and the
 * values of the output columns there, and the solve's diagnostics. Defined
 * in src/report.c (capturing the SVGs, the page) and src/report_parts.c
 * (the sections' HTML); used by src/cmd_report.c. */
#ifndef MECH_REPORT_H
#define MECH_REPORT_H

#include <stdio.h>

#include "mech.h"
#include "plot.h"

/* What the page shows; everything is borrowed from the caller. */
typedef struct report_input {
    const mech_model *m;          /* the loaded model (structure, driver) */
    const mech_summary *summary;  /* mech_check's counts */
    const char *equations;        /* mech_system_print's text */
    const mech_table *t;          /* the solved table of the outputs (figures, values) */
    const mech_solve_stats *stats;/* of the solve of t */
    const mech_diag *diag;        /* warnings and notes of the load and the solves */
    char *const *figures;         /* [nfigures] SVG documents of plot_figure_write */
    int nfigures;
    const char *animation;        /* SVG document of plot_animation_write */
    const int *frame_rows;        /* [nframes] row of t shown by animation frame k */
    int nframes;
    double duration;              /* seconds of one pass of the animation */
    char *const *gaps;            /* [ngaps] requested rows not solved, as mech solve
                                     says them ("rows 112 to 251 of 361 ... not solved: ...") */
    int ngaps;
} report_input;

/* Write the page to `path` whole (write_file_whole; "-" = stdout).
 * Returns MECH_OK, or MECH_EIO / MECH_ENOMEM with a message in d. */
int report_write(const report_input *in, const char *path, mech_diag *d);

/* The SVG documents of every figure plot_plan gives for table t of model
 * m (figures drawn through a temporary directory, read back, removed):
 * *svgs[*n] are malloc'ed strings (report_free_strings frees them).
 * Returns MECH_OK, or MECH_EIO / MECH_ENOMEM with a message in d. */
int report_figures(const mech_model *m, const mech_table *t, char ***svgs, int *n,
                   mech_diag *d);

/* The animation's SVG document (plot_animation_write with options o) in
 * *svg (malloc'ed). Returns MECH_OK or the status of the drawing. */
int report_animation(const mech_model *m, const mech_table *t, const plot_anim_options *o,
                     char **svg, mech_diag *d);

void report_free_strings(char **s, int n);

/* ---- src/report_parts.c: the sections, written to f. ---- */

/* An SVG document inline: its XML declaration dropped, every id, url(#..)
 * and href="#.." prefixed with `prefix` (the figures' ids would clash). */
void report_put_svg(FILE *f, const char *svg, const char *prefix);
/* The structure: what `mech check` prints, then links, joints, driver,
 * parameters, outputs as tables. */
void report_put_structure(FILE *f, const report_input *in);
/* The solve's statistics and every warning and note, as `mech solve
 * --stats` prints them. */
void report_put_diagnostics(FILE *f, const report_input *in);
/* The table of the animation's frames as JSON: columns (name, unit) and
 * one array per frame: [row, value, ...] (%.17g, as the CSV; null when
 * not finite). '<' never appears, so it may sit in a <script>. */
void report_put_json(FILE *f, const report_input *in);

#endif
