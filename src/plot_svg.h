/* src/plot_svg.h: private to the SVG writers (plot.c, plot_anim.c,
 * plot_svg.c): the helpers they share, defined in plot_svg.c. Not for the
 * other modules; their interface is src/plot.h. */
#ifndef MECH_PLOT_SVG_H
#define MECH_PLOT_SVG_H

#include <stdio.h>

#include "internal.h"
#include "plot.h"

#define PLOT_PI 3.14159265358979323846
#define RAD2DEG (180.0 / PLOT_PI)

/* Page layout of a figure, px: the page, then the plot area's left, right,
 * top and bottom edges. */
enum { FIG_W = 780, FIG_H = 450, AX_L = 86, AX_R = 590, AX_T = 62, AX_B = 384 };

/* Write text with &, <, >, " escaped. */
void plot_put_text(FILE *f, const char *s);

/* sep, then "x,y" with `dec` decimals. */
void plot_put_xy(FILE *f, const char *sep, double x, double y, int dec);

/* ---- axes ---------------------------------------------------------- */

typedef struct plot_axis {
    double lo, hi;      /* displayed range */
    double step;        /* tick step (1, 2, 5 x 10^k) */
    int exp10;          /* labels are value / 10^exp10 */
    int dec;            /* decimals of the labels */
} plot_axis;

/* Ticks for [lo, hi], about `target` intervals; round_out widens the range
 * by 2 % and to whole steps, a constant range becomes a band of +-10 %. */
void plot_axis_make(plot_axis *a, double lo, double hi, int target, int round_out);

/* Axis title with its unit, and "x10^k" when the labels are scaled. */
void plot_put_axis_title(FILE *f, const char *what, const char *unit, int exp10);

/* Grid lines, tick marks and labels of axis a along the plot area, from
 * pixel p0 (a->lo) to p1 (a->hi); vertical: the y axis. */
void plot_put_ticks(FILE *f, const plot_axis *a, int vertical, double p0, double p1);

/* ---- polylines: path data, thinned to the pixel columns -------------- */

/* A path's vertices, in pixels: "M" after a break, then "L", then blanks. */
typedef struct plot_pen {
    FILE *f;
    int state;  /* 0: next vertex starts a piece (M); 1: the first L; 2: more */
} plot_pen;

/* The next vertex (px, py), 2 decimals. */
void plot_pen_to(plot_pen *p, double px, double py);

/* The rows of one pixel column of the plot: the first, lowest, highest and
 * last point (pixels; lo/hi are the extremes of py, i.e. of the value). */
typedef struct plot_run {
    long col;                  /* pixel column, floor(px - AX_L) */
    int n;                     /* rows in it so far */
    int row[4];                /* first, lo, hi, last */
    double px[4], py[4];
} plot_run;

/* Rows beyond which a curve is thinned to its pixel columns: 4 per column,
 * as many as the thinned curve can have, so shorter sweeps are drawn (and
 * written) exactly as before. */
enum { THIN_FROM = 4 * 504 };

/* Add row `row` at (px, py) in pixel column col; a new column draws the
 * previous one's run first. */
void plot_run_add(plot_run *c, plot_pen *p, int row, double px, double py, long col);

/* Draw a column's run: its up to 4 points in row order, each once; empties it. */
void plot_run_flush(plot_run *c, plot_pen *p);

#endif
