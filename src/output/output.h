/* src/output/output.h: results out: whole-or-nothing files and CSV, golden comparison, SVG plots
 * and animation, the HTML report, the model's summary. The stage's one header: what its modules
 * share with each other and with the later stages (docs/architecture.md, "Stages"). */
#ifndef MECH_OUTPUT_STAGE_H
#define MECH_OUTPUT_STAGE_H

#include <stddef.h>
#include <stdio.h>

#include "mech.h"
#include "base.h"

/* ==== output ==== */
/* output.c: output files written whole or not at all (src/output/output.c;
 * the policy is docs/cli.md, section Files). */
/* Write what emit(f, ctx) prints (it returns 0 on success) to `path`:
 *   "-"                      standard output;
 *   a FIFO, a character device  opened and written straight through;
 *   a regular file or a new name  a temporary file beside it (mkstemp, mode
 *                            0666 less the umask), fsync'ed and renamed over
 *                            it when complete, removed on failure or on
 *                            SIGTERM/SIGINT/SIGHUP (output_catch_signals);
 *   a symbolic link          the same for its target (the link stays);
 *   anything else            refused (a directory, a socket, a block device).
 * Returns MECH_OK, or MECH_EIO / MECH_ENOMEM with the message in d.
 * Thread-safe. */
int write_file_whole(const char *path, int (*emit)(FILE *, const void *), const void *ctx,
                     mech_diag *d);
/* The same for a writer that opens the file by name (HDF5): a new or
 * regular file is written by emit_path(temporary name, ctx) and renamed
 * over `path`; standard output ("-"), a symbolic link, a FIFO or a device
 * go through write_file_whole with emit. */
int write_file_whole_by_name(const char *path, int (*emit_path)(const char *, const void *),
                             int (*emit)(FILE *, const void *), const void *ctx, mech_diag *d);

/* 1 when write_file_whole has reported a failed write to standard output
 * (so src/cli/main.c does not report it again). */
int output_stdout_reported(void);

/* Handlers of SIGTERM, SIGINT and SIGHUP (those not ignored) that remove
 * the temporary files being written, then die of the signal. Call once at
 * start-up, before any thread. */
void output_catch_signals(void);

/* ==== file_units ==== */
/* file_units.c: results in the file's `units:` (mech solve --units file).
 * v in the SI unit `unit` ("m/s") in the file's units: their text into buf
 * ("mm/s"), v in them returned; a unit the file does not change ("-",
 * "N", or no `units:`) as it is. */
double output_in_file_units(const mech_model *m, const char *unit, double v, char *buf,
                            size_t size);
/* Every column of t in the file's units, its header unit with it:
 * MECH_OK, or MECH_ENOMEM. */
int output_file_units(const mech_model *m, mech_table *t);

/* ==== output_h5 ==== */
/* output_h5.c: a table as HDF5 (docs/cli.md, "Output files"): one float64
 * dataset per column with its "unit", the root attributes "columns",
 * "units", "rows" and the caller's nattrs strings keys[i] = values[i] (the
 * manifest: version, command, input); written whole or not at all, like a
 * CSV (write_file_whole). MECH_OK, MECH_EIO or MECH_ENOMEM with d. */
int output_write_h5(const mech_table *t, const char *path, const char *const *keys,
                    const char *const *values, int nattrs, mech_diag *d);
/* 1 when the output name asks for HDF5: it ends in .h5 or .hdf5 */
int output_is_h5_name(const char *path);
/* 1 when `path` is a regular file that starts with HDF5's signature */
int output_file_is_h5(const char *path);

/* ==== compare ==== */
/* compare.c: compare a solver output CSV with a golden CSV (`mech compare`).
 *
 * Two layers: compare_read_csv() reads one file into a compare_table, with
 * every malformed line reported as FILE:LINE:COLUMN in a mech_diag;
 * compare_tables() matches the columns by name and checks every value with
 *     |out - golden| <= atol + rtol * |golden|
 * (NaN matches only NaN, inf only an inf of the same sign), printing one line
 * per column and a verdict. compare_csv_files() does both for two paths;
 * cmd_compare() (src/cli/cmd_compare.c) is the command line on top of it
 * (docs/cli.md, section mech compare).
 *
 * Status values (like the rest of libmech): MECH_OK the files match,
 * COMPARE_DIFFER (> 0) both files are valid but differ, MECH_EINPUT a
 * malformed file or a bad --columns name, MECH_EIO a file cannot be read,
 * MECH_ENOMEM out of memory. compare_exit_status() maps them to exit codes. */
/* Default tolerances. Another compiler, optimisation level or libm changes
 * the last digits (about 1e-15 relative; more near toggle positions, where
 * the Jacobian is ill-conditioned), and Newton stops at 1e-12 relative to
 * the largest length: rtol 1e-9 leaves room for both yet catches a changed
 * formula. atol covers values that are exactly 0 in one file and rounding
 * noise in the other (e.g. 6.1e-17 for cos(pi/2)). */
#define COMPARE_RTOL 1e-9
#define COMPARE_ATOL 1e-12

enum { COMPARE_DIFFER = 1 };  /* status: valid files, some value, column or row count differs */

typedef struct compare_options {
    double rtol;                /* relative tolerance, >= 0 (default COMPARE_RTOL) */
    double atol;                /* absolute tolerance, >= 0 (default COMPARE_ATOL) */
    const char *const *columns; /* [ncolumns] names of GOLDEN columns to compare, borrowed;
                                   ncolumns == 0: every column of GOLDEN */
    size_t ncolumns;
    int table;                  /* 1: print the per-column table before the verdict (default) */
} compare_options;

void compare_options_default(compare_options *o);

/* One CSV file as read: the header's names and units, then the numbers. */
typedef struct compare_table {
    char **names;    /* [ncols] column names (text before " ["), owned */
    char **units;    /* [ncols] units (text inside the brackets), owned */
    size_t ncols;
    double *values;  /* [nrows * ncols] row-major, owned (NaN in a text cell) */
    size_t nrows;    /* data rows */
    int *word;       /* [nrows * ncols] a text cell's word in words[], -1 for a number;
                        NULL when no cell is text (owned) */
    char **words;    /* [nwords] the distinct words of the text cells, owned */
    size_t nwords;
} compare_table;

/* Read the CSV at `path` into *t (overwritten). Returns MECH_OK; or
 * MECH_EINPUT with every malformed line in d (FILE:LINE:COLUMN), MECH_EIO
 * (cannot open or read) or MECH_ENOMEM, and then *t is empty. */
int compare_read_csv(const char *path, compare_table *t, mech_diag *d);
/* The same from an open stream f (read from where it is), named `name` in
 * messages; f is not closed. A cell that is a word ([A-Za-z][A-Za-z0-9._-]*,
 * not nan or inf) in a column of unit '-' is a text cell (mech sweep's
 * status): NaN in values, the word in word[]/words[]. */
int compare_read_csv_stream(FILE *f, const char *name, compare_table *t, mech_diag *d);
/* The index of word w in t->words, added when new; -1 out of memory. */
int compare_table_intern(compare_table *t, const char *w);
/* The text of cell (row, col), or NULL when it is a number. */
const char *compare_cell_text(const compare_table *t, size_t row, size_t col);
/* The same for mech's HDF5 output (output_h5.c); compare_read_csv calls it
 * for a file with HDF5's signature. */
int compare_read_h5(const char *path, compare_table *t, mech_diag *d);
void compare_table_free(compare_table *t);  /* accepts an empty table */
/* output_h5.c: a table read back (or made from text, mech sweep's) as
 * HDF5, as output_write_h5 writes a solver's; a column with a text cell
 * is a dataset of strings (numbers in it as the CSV writes them). */
int output_write_h5_table(const compare_table *t, const char *path, const char *const *keys,
                          const char *const *values, int nattrs, mech_diag *d);
/* The root attributes names[0..n) of the HDF5 file at path, each a string
 * (owned by the caller) or NULL when it has none (or not one string): 0,
 * or -1 when the file cannot be opened. */
int output_h5_attrs(const char *path, const char *const *names, char **values, int n);

/* 1 when `out` passes against `golden`: both NaN; equal infinities; or both
 * finite with |out - golden| <= atol + rtol * |golden|. */
int compare_values_match(double out, double golden, double rtol, double atol);

/* Compare two tables read from the files named out_name and golden_name
 * (used in messages). Prints the table (when o->table) and a one-line
 * verdict to `report` (NULL: print nothing); a --columns name that GOLDEN
 * lacks goes to d. `o` may be NULL for the defaults. Returns MECH_OK,
 * COMPARE_DIFFER, MECH_EINPUT (bad column name) or MECH_ENOMEM. */
int compare_tables(const compare_table *out, const compare_table *golden, const char *out_name,
                   const char *golden_name, const compare_options *o, FILE *report, mech_diag *d);

/* Read both files and compare them: the report goes to `report`, the
 * diagnostics of both files to `errors` (either may be NULL). Returns a
 * status as compare_tables; a malformed file (MECH_EINPUT) outranks an
 * unreadable one (MECH_EIO), as in `mech check`. */
int compare_csv_files(const char *out, const char *golden, const compare_options *o,
                      FILE *report, FILE *errors);

/* The same with OUT the solver's table in memory (called out_name in
 * messages) instead of a file: what `mech batch --golden` compares, with no
 * temporary file. */
int compare_result_file(const mech_table *out, const char *out_name, const char *golden,
                        const compare_options *o, FILE *report, FILE *errors);

/* Exit code of a status: 0 match, 1 differ, 2 malformed or bad usage, 3 unreadable
 * or out of memory. */
int compare_exit_status(int status);

/* ==== plot ==== */
/* plot.c: SVG figures of a solved sweep and an animated SVG of the
 * mechanism (docs/plots.md). Used by src/cli/cmd_plot.c (`mech plot`,
 * `mech animate`). Defined in src/output/plot.c (plot_plan, plot_figure_write),
 * src/output/plot_path.c (plot_path_plan), src/output/plot_anim.c
 * (plot_anim_options_default, plot_animation_write) and src/output/plot_svg.c
 * (plot_nice_step, plot_fmt); src/output/output.h is private to those files.
 *
 * Display units (docs/plots.md, "Units"): lengths mm, angles deg, linear
 * velocities m/s and accelerations m/s^2, angular velocities rad/s and
 * accelerations rad/s^2, forces N, torques N*m; the x axis is the driver in
 * deg (crank) or mm (driving slider). The CSV stays in SI. */
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
    unsigned char dots[PLOT_MAX_SERIES]; /* 1: series s is points (mech fit's targets): its
                                         marker at every finite row, class "dot", no
                                         line, arrows or start marker */
    char xlabel[64];                  /* not empty: column 0 is an angle (rad) drawn in
                                         deg under this title, not the driver */
} plot_figure;

/* The figures a table calls for, in order: points (positions, velocities,
 * accelerations; x and y of each point), links (angle, omega, alpha),
 * sliders (s, v, a), then per joint the reaction components Fx, Fy (with
 * the frictionless ones when the table has them) and the driver torque or
 * force. Groups with more than PLOT_MAX_SERIES series are split evenly.
 * Returns the number of figures written to figs[0 .. max-1] (at most max). */
int plot_plan(const mech_model *m, const mech_table *t, plot_figure *figs, int max);

/* The path (coupler-curve) figures of a table, defined in src/output/plot_path.c:
 * one per output point of m that moves and has position columns in t
 * ("path-P", in the order of the outputs), so each curve fills its figure.
 * Each is kind PLOT_PATH, written by plot_figure_write: y against x in mm
 * on equal axes, a start marker, arrows in the direction of motion (a
 * PLOT_PATH figure may hold up to PLOT_MAX_SERIES paths, on one scale).
 * Returns the number of figures written to figs[0 .. max-1]. */
int plot_path_plan(const mech_model *m, const mech_table *t, plot_figure *figs, int max);

/* Every figure `mech plot` draws, in its order: plot_plan's figures, then
 * plot_path_plan's (defined in src/output/plot_path.c). The report (src/output/report.c)
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
 * attributes (src/output/plot_svg.c; the report uses it too). */
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
    /* mech draw (a still, frame >= 0 or one row): */
    int labels;            /* 1: the links' and joints' names too (the points' are always) */
    const mech_pose *ghost;/* a pose drawn dashed and grey behind the mechanism, with a
                              legend (ghost_legend, then "as assembled"), or NULL */
    const char *ghost_legend; /* "as guessed (initial:)" */
    const char *caption;   /* the caption's second line instead of the driver's, or NULL */
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
/* The same SVG document written to f (mech watch keeps it in memory). */
int plot_animation_fprint(const mech_model *m, const mech_table *t,
                          const plot_anim_options *o, FILE *f, mech_diag *d);

/* ==== plot_svg ==== */
/* plot_svg.c: private to the SVG writers (plot.c, plot_anim.c,
 * plot_svg.c): the helpers they share, defined in plot_svg.c. Not for the
 * other modules; their interface is src/output/output.h. */
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

/* A path figure (kind PLOT_PATH) as a whole document (src/output/plot_path.c);
 * returns 0, or -1 when writing failed. */
int plot_path_svg(FILE *f, const mech_model *m, const mech_table *t, const plot_figure *fg,
                  const char *subtitle);

/* ==== report ==== */
/* report.c: the self-contained HTML report of one mechanism (`mech
 * report`, docs/report.md): structure, equations, every figure of `mech
 * plot`, the animation with a slider over the driver positions and the
 * values of the output columns there, and the solve's diagnostics. Defined
 * in src/output/report.c (capturing the SVGs, the page) and src/output/report_parts.c
 * (the sections' HTML); used by src/cli/cmd_report.c. */
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

/* The animation's section: the SVG, its slider and Play button and the
 * table of the values at the slider's position (the script fills them;
 * the page holds those of the first frame already). */
void report_put_animation(FILE *f, const report_input *in);
/* The page's <style> element (report.c; mech watch's page has it too). */
extern const char report_page_style[];
/* The script of the slider (report.c), without its <script> tags:
 * binds #slider, #play, #where and the values' cells to the animation
 * #anim svg and the JSON of #mech-data (mech watch runs it again on every
 * new drawing). */
extern const char report_slider_script[];

/* ---- src/output/report_parts.c: the sections, written to f. ---- */

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
/* s as a JSON string: quotes, backslashes and control characters escaped,
 * and '<', '>' and '&' as \u escapes. */
void report_put_json_string(FILE *f, const char *s);

/* ---- report_watch.c: the live page of mech watch (docs/cli.md). ---- */

/* The page: a header, the error box, an empty place for the drawing, and
 * the script that long-polls /state and puts each new drawing in. */
void report_watch_page(FILE *f, const char *file);
/* What the page puts in its place for a good state: the animation's
 * section with its slider and values (report_put_animation), the
 * diagnostics (report_put_diagnostics) and the rows' JSON (#mech-data). */
void report_watch_fragment(FILE *f, const report_input *in);

/* ==== describe ==== */
/* describe.c: a checked model's summary as labelled lines: what `mech
 * check` prints ("  LABEL      TEXT") and `mech report` shows in its
 * structure table, from one function so that the two always agree. */
typedef void (*describe_emit)(void *ctx, const char *label, const char *text);

/* emit(ctx, label, text) for each line, in order: links, joints, unknowns,
 * loops, mobility, the driver (or the sweep of time and one line per law),
 * outputs, then one line per spring, load that depends on the motion and
 * gear pair. */
void model_describe(const mech_model *m, const mech_summary *s, describe_emit emit, void *ctx);


/* ==== fit_setup ==== */
/* fit_setup.c: mech fit's problem stated from the command's options or the
 * file's fit: section (docs/synthesis.md): the free parameters and bounds,
 * the targets read and converted to SI, the columns and weights. Declared
 * for the files that include study.h first (fit_setup.c, cmd_fit.c): this
 * header does not pull study.h's (and the symbolic stage's) names into
 * every file of the output stage. */
#ifdef MECH_STUDY_STAGE_H
enum { FIT_MAX_COLS = 64 };
typedef struct fit_request {
    const char *file;                 /* the mechanism */
    const char *free;                 /* "r=15mm:25mm,l", or NULL: the fit: section's */
    const char *target;               /* or NULL: the section's (relative to the file) */
    const char *const *columns;
    int ncolumns;
    const char *const *weights;       /* "COLUMN=W" */
    int nweights;
    int whole_range, free_timing;     /* 1: on */
    const char *transmission;         /* "A,B,MIN" (links and least angle), or NULL: the
                                         fit: section's */
} fit_request;

typedef struct fit_setup {
    fit_problem fp;
    const char *names[FIT_MAX_FREE];
    char *free_copy;
    const char *bound_text[FIT_MAX_FREE][2];  /* LO, HI as given, or NULL */
    char unit[FIT_MAX_FREE][32];
    mech_mark mark[FIT_MAX_FREE];
    double lo[FIT_MAX_VARS], hi[FIT_MAX_VARS], p0[FIT_MAX_FREE];  /* lo, hi: also the timing's */
    const char *cols[FIT_MAX_COLS];
    char col_unit[FIT_MAX_COLS][16];
    double weight[FIT_MAX_COLS];
    int csv_col[FIT_MAX_COLS];  /* the CSV's column of each target column */
    compare_table csv;
    double *q, *target;
    char target_path[4096];
    int bounds_given;  /* the bounds are the fit: section's, already in SI */
    int whole_range;
} fit_setup;

/* The problem of request rq on the loaded, checked model m into *s (zeroed
 * by the caller; it borrows rq's texts and m's fit: section). MECH_OK, or
 * the error in d (file:line:column where there is one). */
int fit_setup_read(fit_setup *s, const fit_request *rq, const mech_model *m, mech_diag *d);
/* The number of starts: asked, else the section's, else 16 when every free
 * parameter has bounds, else 1; an error when more than one and none has. */
int fit_setup_starts(const fit_setup *s, const mech_model *m, int asked, int *n, mech_diag *d);
void fit_setup_free(fit_setup *s);

/* fit_plot.c: the figure of a fit (docs/synthesis.md, "The figure"). */
typedef struct fit_curves {
    const mech_table *curve;    /* the target columns' objects solved over the driver's range */
    const char *curve_label;    /* its legend: "fitted", "this file" */
    const mech_table *start;    /* the start's curve, drawn dashed; NULL: none */
    const double *timing;       /* [nq] the target rows' driver positions (free timing's
                                   fitted ones); NULL: the targets' CSV's */
} fit_curves;
/* The figure of s's targets and the curves c into path (one SVG, whole or
 * nothing, plot_figure_write): the paths of up to two points whose x and y
 * are targets, else up to two target columns against the driver. */
int fit_figure_write(const fit_setup *s, const mech_model *m, const fit_curves *c,
                     const char *subtitle, const char *path, mech_diag *d);

#endif /* MECH_STUDY_STAGE_H */

/* The figure of the loaded, checked model m whose file has a fit: section
 * (m->fit): m's own curve (its --set values included) against the
 * section's targets, into path ("STEM-fit.svg" of mech plot, a figure of
 * mech report). MECH_OK: written. MECH_EINPUT: left out, the reasons (the
 * targets unreadable, the section incomplete, the mechanism assembling
 * nowhere) as warnings in d, so that the command's other figures go on.
 * Otherwise (no memory, the SVG not written) the error in d. */
int fit_figure_of_model(const mech_model *m, const char *path, mech_diag *d);

/* fit_setup.c: a quantity "15mm", "0.5 rad", "15" (a bare number in the
 * file's unit of si_unit) in SI into *v; 0, or -1 when it is not of
 * si_unit's dimension. */
int output_parse_quantity(const mech_model *m, const char *text, const char *si_unit, double *v);

/* ==== cam_profile ==== */
/* cam_profile.c: what mech cam writes (docs/cams.md 5). The cam called
 * name (NULL: the file's only one): its index, or -1 with why in err. */
int cam_find(const mech_model *m, const char *name, char *err, size_t size);
/* Cam i at n evenly spaced angles over its program's period into *t
 * (zeroed first; mech_table_free): x, s, ds, dds, pitch.x, pitch.y,
 * profile.x, profile.y, pressure_angle, rho_pitch, rho_profile, face (SI;
 * positions in the cam's own frame). MECH_OK or MECH_ENOMEM. */
int cam_profile_table(const mech_model *m, int i, int n, mech_table *t);
/* The outline of that table (profile, pitch curve, base circle, centre) in
 * mm, written whole: SVG, or DXF R12 (layers PROFILE, PITCH, BASE). */
int cam_outline_svg(const mech_model *m, int i, const mech_table *t, const char *path,
                    mech_diag *d);
int cam_outline_dxf(const mech_model *m, int i, const mech_table *t, const char *path,
                    mech_diag *d);
/* The number of angles at most `step` apart over a turn (3 to 1e7),
 * and the default step (1 deg). */
int cam_steps(double step);
double cam_default_step(void);
/* The figures of cam i (mech plot, mech report) over its profile table:
 * the lift and its three derivatives against the cam's angle, and the
 * profile with the pitch curve (a path, mm). Returns 5 (figs[0..4]). */
enum { CAM_FIGURES = 5 };
int cam_plan(const mech_model *m, int i, plot_figure *figs);
/* write(ctx, table, figure) for every figure of every cam, in order (each
 * cam's table at 1 deg); the first status that is not MECH_OK stops it. */
typedef int (*cam_figure_fn)(void *ctx, const mech_table *t, const plot_figure *f);
int cam_figures_each(const mech_model *m, cam_figure_fn write, void *ctx, mech_diag *d);

#endif
