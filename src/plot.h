/* src/plot.h: SVG figures of a solved sweep and an animated SVG of the
 * mechanism (docs/plots.md). Used by src/cmd_plot.c (`mech plot`,
 * `mech animate`). Defined in src/plot.c (plot_plan, plot_figure_write),
 * src/plot_path.c (plot_path_plan), src/plot_anim.c
 * (plot_anim_options_default, plot_animation_write) and src/plot_svg.c
 * (plot_nice_step, plot_fmt); src/plot_svg.h is private to those files.
 *
 * Display units (docs/plots.md, "Units"): lengths mm, angles deg, linear
 * velocities m/s and accelerations m/s^2, angular velocities rad/s and
 * accelerations rad/s^2, forces N, torques N*m; the x axis is the driver in
 * deg (crank) or mm (driving slider). The CSV stays in SI. */
#ifndef MECH_PLOT_H
#define MECH_PLOT_H

#include <stdio.h>

#include "mech.h"

#define PLOT_MAX_SERIES 8   /* series per figure: 8 line styles (dash x marker) */

/* What a figure draws: series against the driver, or paths (y against x). */
typedef enum { PLOT_AGAINST_DRIVER = 0, PLOT_PATH = 1 } plot_kind;

/* One figure: up to PLOT_MAX_SERIES columns of a table against column 0 (q),
 * or (kind PLOT_PATH) the paths of up to PLOT_MAX_SERIES points: column
 * ycol[s] against column col[s]. A zeroed figure is PLOT_AGAINST_DRIVER. */
typedef struct plot_figure {
    char name[96];                    /* file stem, e.g. "points-position-1" */
    char title[160];                  /* "Point positions: D, L, J" */
    char ylabel[48];                  /* quantity, e.g. "position" */
    char yunit[24];                   /* display unit, e.g. "mm" */
    double yscale;                    /* SI value * yscale = displayed value */
    int col[PLOT_MAX_SERIES];         /* [nseries] table columns */
    char label[PLOT_MAX_SERIES][48];  /* [nseries] legend texts */
    int nseries;
    plot_kind kind;
    int ycol[PLOT_MAX_SERIES];        /* [nseries] PLOT_PATH: the y column of series s */
    char note[2][48];                 /* legend heading lines, e.g. "B: force on rocker",
                                         "from coupler" (empty: none) */
} plot_figure;

/* The figures a table calls for, in order: points (positions, velocities,
 * accelerations; x and y of each point), links (angle, omega, alpha),
 * sliders (s, v, a), then per joint the reaction components Fx, Fy (with
 * the frictionless ones when the table has them) and the driver torque or
 * force. Groups with more than PLOT_MAX_SERIES series are split evenly.
 * Returns the number of figures written to figs[0 .. max-1] (at most max). */
int plot_plan(const mech_model *m, const mech_table *t, plot_figure *figs, int max);

/* The path (coupler-curve) figures of a table, defined in src/plot_path.c:
 * one per output point of m that moves and has position columns in t
 * ("path-P", in the order of the outputs), so each curve fills its figure.
 * Each is kind PLOT_PATH, written by plot_figure_write: y against x in mm
 * on equal axes, a start marker, arrows in the direction of motion (a
 * PLOT_PATH figure may hold up to PLOT_MAX_SERIES paths, on one scale).
 * Returns the number of figures written to figs[0 .. max-1]. */
int plot_path_plan(const mech_model *m, const mech_table *t, plot_figure *figs, int max);

/* Every figure `mech plot` draws, in its order: plot_plan's figures, then
 * plot_path_plan's (defined in src/plot_path.c). The report (src/report.c)
 * uses this too, so both always draw the same set. */
int plot_plan_all(const mech_model *m, const mech_table *t, plot_figure *figs, int max);

/* Write one figure of table t as a standalone SVG document to `path`
 * (a temporary file beside it, renamed when complete; "-" = stdout).
 * `subtitle` (the mechanism's name, may be NULL) is printed under the title.
 * Returns MECH_OK or MECH_EIO with a message in d. */
int plot_figure_write(const mech_model *m, const mech_table *t, const plot_figure *f,
                      const char *subtitle, const char *path, mech_diag *d);

/* The tick step of an axis: the smallest of 1, 2, 5 x 10^k that cuts `span`
 * into at most `target` intervals (span > 0, target >= 1). */
double plot_nice_step(double span, int target);

/* Print v rounded to `decimals` digits after the point, without trailing
 * zeros and without "-0" (so 1.50 -> "1.5", -0.001 at 2 decimals -> "0").
 * buf must hold 32 bytes; returns buf. */
char *plot_fmt(char *buf, double v, int decimals);

/* Write text with &, <, >, " escaped: safe in XML and HTML text and
 * attributes (src/plot_svg.c; the report uses it too). */
void plot_put_text(FILE *f, const char *s);

/* Options of the animation. */
typedef struct plot_anim_options {
    double duration;       /* seconds for one pass through the driver range (default 4) */
    int frame;             /* >= 0: a still picture of row `frame`, no animation */
    int test_colours;      /* 1: grey drawing, every point a disc of its own colour */
    int max_frames;        /* rows used at most (evenly subsampled; default 1000) */
    double pause_at;       /* >= 0: an inline script pauses the animation at this
                              time, s (for tests; default -1: no script) */
    const int *trace;      /* [ntrace] point name ids whose paths are drawn */
    int ntrace;
} plot_anim_options;

void plot_anim_options_default(plot_anim_options *o);

/* The rows an animation of nrows rows shows as frames: at most max_frames
 * (when > 1) evenly spread, first and last included, into rows[] (room for
 * min(nrows, max_frames)); returns their count. mech report's slider uses
 * the same rows. */
int plot_anim_frame_rows(int nrows, int max_frames, int *rows);

/* Write the animated (or still) SVG of the mechanism. The table must hold the
 * positions ("P.x", "P.y") of every point name and the angle ("L.angle") of
 * every moving link, one row per driver position.
 * Returns MECH_OK, MECH_EINPUT (a column missing, frame out of range) or
 * MECH_EIO, with a message in d. */
int plot_animation_write(const mech_model *m, const mech_table *t,
                         const plot_anim_options *o, const char *path, mech_diag *d);

#endif
