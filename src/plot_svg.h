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

/* An axis over exactly [lo, hi] with tick step `step`: the label scaling
 * and decimals as plot_axis_make chooses them. */
void plot_axis_fixed(plot_axis *a, double lo, double hi, double step);

/* Axis title with its unit, and "x10^k" when the labels are scaled. */
void plot_put_axis_title(FILE *f, const char *what, const char *unit, int exp10);

/* Grid lines, tick marks and labels of axis a along the plot area, from
 * pixel p0 (a->lo) to p1 (a->hi); vertical: the y axis. */
void plot_put_ticks(FILE *f, const plot_axis *a, int vertical, double p0, double p1);

/* The plot area of a figure whose size is not the fixed AX_* one (the
 * path figures), px. */
typedef struct plot_area {
    double l, r, t, b;
} plot_area;

/* plot_put_ticks for a plot area of any size. */
void plot_put_ticks_in(FILE *f, const plot_axis *a, int vertical, const plot_area *area);

/* ---- series styles ------------------------------------------------- */

/* Style s of a figure's series: colour s, marker shape s % 4 (open for
 * s < 4, filled after), dash (s + s / 4) % 4, so that no two of the 8
 * styles share shape, fill and dash. Markers are <path id="mK"> with the
 * shapes plot_marker_path[K], centred on 0,0: circle, square, triangle,
 * diamond. */
void plot_style(int s, const char **colour, const char **dash, int *shape, int *filled);
extern const char *const plot_marker_path[4];

/* ---- polylines: path data, thinned ---------------------------------- */

/* A path's vertices, in pixels: "M" after a break, then "L", then blanks.
 * With f NULL the vertices are only counted. */
typedef struct plot_pen {
    FILE *f;
    int state;  /* 0: next vertex starts a piece (M); 1: the first L; 2: more */
    int dec;    /* decimals of the coordinates */
    long nvert; /* vertices so far */
} plot_pen;

/* The next vertex (px, py), with p->dec decimals. */
void plot_pen_to(plot_pen *p, double px, double py);

/* The tolerance of the thinning, page px: every point of a long curve lies
 * within it of the drawn polyline, and the drawn polyline within it of the
 * full one (docs/plots.md, "Long sweeps"). */
#define PLOT_THIN_TOL 0.25

/* Vertex i of a curve in page px; returns 0 when it is not finite (the
 * curve is broken there). */
typedef int (*plot_vertex_fn)(const void *ctx, int i, double *px, double *py);

/* Draw vertices 0 .. n-1 of a curve (pen->f NULL: count them), thinned to
 * within `tol` px: a vertex is dropped only when every vertex since the
 * last one drawn lies within tol of the segment from that one to the next
 * one drawn (the sleeve of Zhao and Saalfeld, one pass, no memory per
 * vertex), so the extremes of a spike are kept. Pieces between non-finite
 * vertices are drawn separately. Returns the vertices drawn. */
long plot_thin_draw(plot_pen *pen, double tol, plot_vertex_fn fn, const void *ctx, int n);

/* Draw every vertex 0 .. n-1 of a curve, broken at non-finite ones. */
void plot_draw_all(plot_pen *pen, plot_vertex_fn fn, const void *ctx, int n);

/* The smallest tolerance, PLOT_THIN_TOL doubled as often as needed, that
 * leaves at most maxv vertices of the curve (a scribble denser than the
 * pixels would otherwise be written whole). */
double plot_thin_tolerance(plot_vertex_fn fn, const void *ctx, int n, long maxv);

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

/* A path figure (kind PLOT_PATH) as a whole document (src/plot_path.c);
 * returns 0, or -1 when writing failed. */
int plot_path_svg(FILE *f, const mech_model *m, const mech_table *t, const plot_figure *fg,
                  const char *subtitle);

#endif
