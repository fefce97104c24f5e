/* tests/unit/test_plot.c: the pieces of src/plot*.c a reader of the figures
 * relies on: tick steps are 1, 2 or 5 x 10^k, numbers are printed without
 * noise, the figures follow the outputs, and every file is written whole.
 * (Rendering is checked in a browser by tests/browser/run.sh.) */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "output.h"

Test(plot, nice_steps_are_1_2_5_times_a_power_of_ten)
{
    /* span / target, then the next of 1, 2, 5, 10 x 10^k at or above it */
    cr_expect_eq(plot_nice_step(360, 9), 50);
    cr_expect_eq(plot_nice_step(100, 10), 10);
    cr_expect_eq(plot_nice_step(1.2, 7), 0.2);
    cr_expect_eq(plot_nice_step(0.03, 6), 0.005);
    cr_expect_eq(plot_nice_step(7e4, 7), 1e4);
    for (double span = 1e-6; span < 1e6; span *= 1.37) {
        double s = plot_nice_step(span, 7);
        double m = s / pow(10.0, floor(log10(s) + 1e-12));
        cr_expect(fabs(m - 1) < 1e-9 || fabs(m - 2) < 1e-9 || fabs(m - 5) < 1e-9,
                  "span %g: step %g is not 1, 2 or 5 x 10^k", span, s);
        cr_expect(span / s <= 7 * (1 + 1e-9), "span %g: step %g gives > 7 intervals", span, s);
    }
}

Test(plot, numbers_without_noise)
{
    char b[32];
    cr_expect_str_eq(plot_fmt(b, 1.50, 2), "1.5");
    cr_expect_str_eq(plot_fmt(b, 120.0, 2), "120");
    cr_expect_str_eq(plot_fmt(b, -0.001, 2), "0");
    cr_expect_str_eq(plot_fmt(b, 0.1 + 0.2, 3), "0.3");
    cr_expect_str_eq(plot_fmt(b, -12.345, 1), "-12.3");
    cr_expect_str_eq(plot_fmt(b, NAN, 1), "0");
}

static mech_model *load(const char *text)
{
    mech_model *m = NULL;
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_load_string(text, strlen(text), "test.yaml", &m, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK);
    return m;
}

static const char fourbar[] =
    "name: four-bar\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0], C: [70, 0]}\n"
    "links:\n"
    "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [60, 0], P: [30, 20]}}\n"
    "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 36}}\n"
    "initial: {coupler: 40, rocker: 100}\n";

Test(plot, figures_follow_the_outputs)
{
    mech_model *m = load(fourbar);
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_table t = {0};
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
    plot_figure f[64];
    int n = plot_plan(m, &t, f, 64);
    /* 5 points (10 series: split in 2) x 3 levels, 3 links x 3 levels */
    cr_expect_eq(n, 9);
    cr_expect_str_eq(f[0].name, "points-position-1");
    cr_expect_str_eq(f[1].name, "points-position-2");
    cr_expect_eq(f[0].nseries + f[1].nseries, 10);
    cr_expect_str_eq(f[0].yunit, "mm");
    cr_expect_float_eq(f[0].yscale, 1e3, 1e-12);
    cr_expect_str_eq(f[6].name, "links-angle");
    cr_expect_str_eq(f[6].yunit, "deg");
    for (int k = 0; k < n; k++)
        cr_expect(f[k].nseries >= 1 && f[k].nseries <= PLOT_MAX_SERIES);
    /* written whole: the file appears complete, no temporary is left */
    char dir[] = "/tmp/mech-plot-XXXXXX", path[96];
    cr_assert(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/f.svg", dir);
    cr_expect_eq(plot_figure_write(m, &t, &f[6], m->name, path, &d), MECH_OK);
    FILE *fp = fopen(path, "r");
    cr_assert(fp);
    char buf[65536];
    size_t len = fread(buf, 1, sizeof buf - 1, fp);
    buf[len] = '\0';
    fclose(fp);
    cr_expect(strstr(buf, "<svg") && strstr(buf, "</svg>\n"));
    cr_expect(strstr(buf, "angle [deg]"));
    unlink(path);
    cr_expect_eq(rmdir(dir), 0, "a temporary file was left in %s", dir);
    /* an unwritable place: MECH_EIO, nothing created */
    cr_expect_eq(plot_figure_write(m, &t, &f[6], NULL, "/nonexistent/dir/f.svg", &d), MECH_EIO);
    mech_diag_free(&d);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* The vertices of the first series' path in an SVG figure (its "d"), as
 * pixel y values; returns how many, and the smallest and largest y (top
 * and bottom of the curve) as printed. */
static int path_vertices(const char *svg, char *ymin, char *ymax, size_t size)
{
    const char *d = strstr(svg, "<path stroke=\"#1f4e99\"");
    cr_assert(d, "no series path");
    d = strstr(d, " d=\"") + 4;
    const char *end = strchr(d, '"');
    int n = 0;
    double lo = INFINITY, hi = -INFINITY;
    for (const char *p = d; p < end;) {
        p += strspn(p, "ML ");
        char *e;
        strtod(p, &e);  /* x */
        cr_assert_eq(*e, ',', "a vertex is x,y: %.40s", p);
        const char *ys = e + 1;
        double y = strtod(ys, &e);
        size_t len = (size_t)(e - ys);
        if (y < lo) {
            lo = y;
            snprintf(ymin, size, "%.*s", (int)len, ys);
        }
        if (y > hi) {
            hi = y;
            snprintf(ymax, size, "%.*s", (int)len, ys);
        }
        n++;
        p = e;
    }
    return n;
}

static char *read_whole(const char *path, size_t *len)
{
    FILE *fp = fopen(path, "rb");
    cr_assert(fp);
    fseek(fp, 0, SEEK_END);
    *len = (size_t)ftell(fp);
    rewind(fp);
    char *buf = malloc(*len + 1);
    cr_assert(buf && fread(buf, 1, *len, fp) == *len);
    buf[*len] = '\0';
    fclose(fp);
    return buf;
}

/* A table of n rows: q from 0 to 360 deg, column 1 a sine with a one-row
 * spike up (row n/3, +5) and down (row 2n/3, -7). */
static void spiky_table(mech_table *t, int n)
{
    t->ncolumns = 2;
    t->nrows = n;
    t->columns = calloc(2, sizeof *t->columns);
    t->columns[0] = (mech_column){strdup("q"), strdup("rad")};
    t->columns[1] = (mech_column){strdup("y"), strdup("-")};
    t->values = malloc(2 * (size_t)n * sizeof *t->values);
    for (int r = 0; r < n; r++) {
        double q = 6.283185307179586 * r / (n - 1);
        t->values[2 * r] = q;
        t->values[2 * r + 1] = r == n / 3 ? 5.0 : r == 2 * n / 3 ? -7.0 : sin(q);
    }
}

/* A 200 000-step figure is thinned to its pixel columns (it took 70 MB for
 * a four-bar's figures) and keeps the curve's extremes: the one-row spikes
 * are drawn to the same pixel as in a short table with the same range. */
Test(plot, long_sweeps_are_thinned_to_the_pixel_columns)
{
    mech_model *m = load(fourbar);
    plot_figure fg = {.name = "y", .title = "spikes", .ylabel = "y", .yunit = "-",
                      .yscale = 1.0, .col = {1}, .label = {"y"}, .nseries = 1};
    char dir[] = "/tmp/mech-plot-XXXXXX", path[96];
    cr_assert(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/f.svg", dir);
    mech_diag d;
    mech_diag_init(&d);
    char top[2][32], bottom[2][32];
    int nvert[2];
    size_t bytes[2];
    const int rows[2] = {200001, 1000};  /* thinned; drawn whole (same axes) */
    for (int k = 0; k < 2; k++) {
        mech_table t = {0};
        spiky_table(&t, rows[k]);
        cr_assert_eq(plot_figure_write(m, &t, &fg, NULL, path, &d), MECH_OK);
        char *svg = read_whole(path, &bytes[k]);
        nvert[k] = path_vertices(svg, top[k], bottom[k], sizeof top[k]);
        free(svg);
        mech_table_free(&t);
    }
    cr_expect_lt(bytes[0], 200000, "a 200 000-row figure takes %zu bytes", bytes[0]);
    cr_expect_leq(nvert[0], 4 * 505, "%d vertices for 505 pixel columns", nvert[0]);
    cr_expect_eq(nvert[1], 1000, "a short table is drawn whole");
    cr_expect_str_eq(top[0], top[1], "the spike up is lost");
    cr_expect_str_eq(bottom[0], bottom[1], "the spike down is lost");
    unlink(path);
    rmdir(dir);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* ---- path figures, thinning, the animation's scale bar, force legends ---- */

/* The numbers of attribute `attr` of the first element that has it. */
static int attr_numbers(const char *svg, const char *attr, double *v, int n)
{
    char key[64];
    snprintf(key, sizeof key, " %s=\"", attr);
    const char *p = strstr(svg, key);
    cr_assert(p, "no %s in the SVG", attr);
    p += strlen(key);
    for (int i = 0; i < n; i++) {
        char *e;
        v[i] = strtod(p, &e);
        cr_assert(e != p, "%s: %d numbers expected", attr, n);
        p = e;
    }
    return n;
}

/* The vertices of the path data after `start` (its d="..."), in px: a
 * malloc'ed array of 2 * *n numbers; pieces (M) are not told apart. */
static double *path_data(const char *start, int *n)
{
    const char *d = strstr(start, " d=\"");
    cr_assert(d);
    d += 4;
    const char *end = strchr(d, '"');
    size_t cap = 1024;
    double *v = malloc(cap * sizeof *v);
    *n = 0;
    for (const char *p = d; p < end;) {
        p += strspn(p, "ML ");
        if (p >= end)
            break;
        char *e;
        double x = strtod(p, &e);
        cr_assert_eq(*e, ',', "a vertex is x,y: %.40s", p);
        double y = strtod(e + 1, &e);
        if ((size_t)(2 * *n + 2) > cap)
            v = realloc(v, (cap *= 2) * sizeof *v);
        v[2 * *n] = x;
        v[2 * *n + 1] = y;
        (*n)++;
        p = e;
    }
    return v;
}

/* Distance from (x, y) to the segment (ax, ay)-(bx, by). */
static double seg_dist(double x, double y, double ax, double ay, double bx, double by)
{
    double vx = bx - ax, vy = by - ay, l2 = vx * vx + vy * vy;
    double u = l2 > 0 ? ((x - ax) * vx + (y - ay) * vy) / l2 : 0;
    u = u < 0 ? 0 : u > 1 ? 1 : u;
    return hypot(x - ax - u * vx, y - ay - u * vy);
}

/* The drawn polyline v[0 .. nv-1] against the full one, px[0 .. n-1],
 * py[...]: the vertices drawn are full points in row order (to the 0.01 px
 * printed), and every full point between two drawn vertices lies within
 * tol of the segment joining them. Returns the largest such distance. */
static double thinned_against_full(const double *v, int nv, const double *px, const double *py,
                                   int n, double tol)
{
    int r = 0, prev = -1;
    double worst = 0;
    for (int k = 0; k < nv; k++) {
        while (r < n && !(fabs(px[r] - v[2 * k]) <= 0.006 && fabs(py[r] - v[2 * k + 1]) <= 0.006))
            r++;
        cr_assert_lt(r, n, "vertex %d (%g, %g) is no full point after row %d", k, v[2 * k],
                     v[2 * k + 1], prev);
        for (int i = prev + 1; prev >= 0 && i < r; i++) {
            double dd = seg_dist(px[i], py[i], v[2 * k - 2], v[2 * k - 1], v[2 * k], v[2 * k + 1]);
            worst = fmax(worst, dd);
            cr_assert_leq(dd, tol, "row %d is %g px from the drawn segment", i, dd);
        }
        prev = r++;
    }
    /* rows 0.01 px apart match a vertex more than once: the last vertex is
       the last row's position */
    cr_expect(fabs(px[n - 1] - v[2 * nv - 2]) <= 0.006 && fabs(py[n - 1] - v[2 * nv - 1]) <= 0.006,
              "the last row is not drawn");
    return worst;
}

static mech_table solve_steps(const mech_model *m, int steps)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.want = MECH_WANT_POSITION;
    if (steps > 0) {
        o.has_range = 1;
        o.from = 0;
        o.to = 2 * 3.141592653589793;
        o.steps = steps;
    }
    mech_table t = {0};
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
    mech_diag_free(&d);
    return t;
}

static char *write_and_read(const mech_model *m, const mech_table *t, const plot_figure *f,
                            size_t *len)
{
    char dir[] = "/tmp/mech-plot-XXXXXX", path[96];
    cr_assert(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/f.svg", dir);
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(plot_figure_write(m, t, f, m->name, path, &d), MECH_OK);
    mech_diag_free(&d);
    char *svg = read_whole(path, len);
    unlink(path);
    rmdir(dir);
    return svg;
}

/* The crank pin A of the four-bar (20 mm crank about O) draws a circle:
 * on equal axes it is as wide as it is tall on the page, every vertex is
 * its solved position mapped through data-mech-transform, the start marker
 * sits on row 0, and the arrows point the way the crank turns
 * (counter-clockwise: at angle theta the velocity is (-sin, cos)). */
Test(plot, path_figures_on_equal_axes_with_start_and_direction)
{
    mech_model *m = load(fourbar);
    mech_table t = solve_steps(m, 720);
    plot_figure f[8];
    int n = plot_path_plan(m, &t, f, 8);
    cr_assert_eq(n, 3, "A, B and P move; O and C are ground points");
    cr_expect_str_eq(f[0].name, "path-A");
    cr_expect_str_eq(f[1].name, "path-B");
    cr_expect_str_eq(f[2].name, "path-P");
    cr_expect_eq(f[0].kind, PLOT_PATH);
    size_t len;
    char *svg = write_and_read(m, &t, &f[0], &len);
    cr_expect(strstr(svg, ">x [mm]<") && strstr(svg, ">y [mm]<"), "units on both axes");
    double tr[3];
    attr_numbers(svg, "data-mech-transform", tr, 3);
    int nv;
    double *v = path_data(strstr(svg, "<path stroke=\"#1f4e99\""), &nv);
    cr_assert_eq(nv, t.nrows, "a short sweep is drawn whole");
    int cx = mech_table_column(&t, "A.x"), cy = mech_table_column(&t, "A.y");
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int r = 0; r < nv; r++) {
        double x = tr[1] + tr[0] * mech_table_get(&t, r, cx);
        double y = tr[2] - tr[0] * mech_table_get(&t, r, cy);
        cr_expect(fabs(v[2 * r] - x) <= 0.006 && fabs(v[2 * r + 1] - y) <= 0.006,
                  "row %d drawn at %g,%g, solved at %g,%g", r, v[2 * r], v[2 * r + 1], x, y);
        xmin = fmin(xmin, v[2 * r]), xmax = fmax(xmax, v[2 * r]);
        ymin = fmin(ymin, v[2 * r + 1]), ymax = fmax(ymax, v[2 * r + 1]);
    }
    /* 720 steps: the polygon's width and height differ by < 1e-4 of them */
    cr_expect_float_eq(xmax - xmin, ymax - ymin, 0.02, "circle %g px wide, %g px tall",
                       xmax - xmin, ymax - ymin);
    cr_expect_float_eq(xmax - xmin, 40e-3 * tr[0], 0.02, "the diameter is 40 mm");
    /* the start marker on row 0 */
    double at[2];
    attr_numbers(strstr(svg, "xlink:href=\"#m0\" data-at"), "data-at", at, 1);
    const char *mk = strstr(svg, "xlink:href=\"#m0\" data-at=\"");
    cr_assert(mk);
    cr_assert_eq(sscanf(mk + strlen("xlink:href=\"#m0\" data-at=\""), "%lf,%lf", &at[0], &at[1]), 2);
    cr_expect(fabs(at[0] - v[0]) < 0.01 && fabs(at[1] - v[1]) < 0.01, "start marker not on row 0");
    /* arrows: rotate(deg) along (-sin, cos) of the crank angle, page y down */
    int narrows = 0;
    for (const char *a = strstr(svg, "#arrow\" data-at=\""); a;
         a = strstr(a + 1, "#arrow\" data-at=\"")) {
        double ax, ay, rot;
        cr_assert_eq(sscanf(a + strlen("#arrow\" data-at=\""), "%lf,%lf", &ax, &ay), 2);
        const char *rp = strstr(a, "rotate(");
        cr_assert(rp);
        rot = strtod(rp + 7, NULL);
        double th = atan2(-(ay - tr[2]) / tr[0], (ax - tr[1]) / tr[0]);
        double want = atan2(-cos(th), -sin(th)) * 180 / 3.141592653589793;
        double diff = fmod(fabs(rot - want) + 180, 360) - 180;
        cr_expect_leq(fabs(diff), 2.0, "arrow at %g,%g points %g deg, the motion %g deg", ax, ay,
                      rot, want);
        narrows++;
    }
    cr_expect_eq(narrows, 6);
    free(v);
    free(svg);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* A 200 000-step path figure and the animation's traces: bounded size, and
 * every solved position within PLOT_THIN_TOL (0.25 px, plus 0.005 px of
 * printing) of the drawn polyline, whose vertices are solved positions. */
Test(plot, long_paths_are_thinned_within_a_quarter_pixel)
{
    mech_model *m = load(fourbar);
    mech_table t = solve_steps(m, 200000);
    plot_figure f[8];
    cr_assert_eq(plot_path_plan(m, &t, f, 8), 3);
    size_t len;
    char *svg = write_and_read(m, &t, &f[2], &len);  /* P: the coupler curve */
    double tr[3];
    attr_numbers(svg, "data-mech-transform", tr, 3);
    int nv;
    double *v = path_data(strstr(svg, "<path stroke=\"#1f4e99\""), &nv);
    double *px = malloc((size_t)t.nrows * sizeof *px), *py = malloc((size_t)t.nrows * sizeof *py);
    int cx = mech_table_column(&t, "P.x"), cy = mech_table_column(&t, "P.y");
    for (int r = 0; r < t.nrows; r++) {
        px[r] = tr[1] + tr[0] * mech_table_get(&t, r, cx);
        py[r] = tr[2] - tr[0] * mech_table_get(&t, r, cy);
    }
    double worst = thinned_against_full(v, nv, px, py, t.nrows, 0.255);
    cr_expect_lt(len, 60000, "a 200 000-row path figure takes %zu bytes", len);
    cr_expect_lt(nv, 2000, "%d vertices", nv);
    cr_expect_gt(worst, 0.05, "nothing was thinned (worst %g px)", worst);
    free(v);
    free(svg);
    /* the animation's trace of P, on its own page scale */
    plot_anim_options o;
    plot_anim_options_default(&o);
    o.frame = 0;
    int trace[1] = {-1};
    for (int p = 0; p < m->npoint_names; p++)
        if (strcmp(m->point_names[p], "P") == 0)
            trace[0] = p;
    o.trace = trace;
    o.ntrace = 1;
    char dir[] = "/tmp/mech-plot-XXXXXX", path[96];
    cr_assert(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/a.svg", dir);
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(plot_animation_write(m, &t, &o, path, &d), MECH_OK);
    mech_diag_free(&d);
    svg = read_whole(path, &len);
    unlink(path);
    rmdir(dir);
    attr_numbers(svg, "data-mech-transform", tr, 3);
    v = path_data(strstr(svg, "data-trace=\"P\""), &nv);
    for (int r = 0; r < t.nrows; r++) {
        px[r] = tr[1] + tr[0] * mech_table_get(&t, r, cx);
        py[r] = tr[2] - tr[0] * mech_table_get(&t, r, cy);
    }
    /* the animation prints 0.1 px: vertices within 0.05, so 0.25 + 0.1 */
    (void)worst;
    int r = 0;
    for (int k = 0; k < nv; k++) {  /* each vertex a solved row, in order */
        while (r < t.nrows && !(fabs(px[r] - v[2 * k]) <= 0.051 && fabs(py[r] - v[2 * k + 1]) <= 0.051))
            r++;
        cr_assert_lt(r, t.nrows, "trace vertex %d is no solved position", k);
    }
    for (int i = 0; i < t.nrows; i += 7) {  /* every solved position near the trace */
        double best = INFINITY;
        for (int k = 0; k + 1 < nv; k++)
            best = fmin(best, seg_dist(px[i], py[i], v[2 * k], v[2 * k + 1], v[2 * k + 2],
                                       v[2 * k + 3]));
        cr_assert_leq(best, 0.35, "row %d is %g px from the trace", i, best);
    }
    cr_expect_lt(nv, 2000, "%d trace vertices", nv);
    free(v);
    free(svg);
    free(px);
    free(py);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* The time figures: the same tolerance against the full curve (the spiky
 * table of 200 001 rows, mapped through data-mech-axes). */
Test(plot, long_curves_are_thinned_within_a_quarter_pixel)
{
    mech_model *m = load(fourbar);
    plot_figure fg = {.name = "y", .title = "spikes", .ylabel = "y", .yunit = "-",
                      .yscale = 1.0, .col = {1}, .label = {"y"}, .nseries = 1};
    mech_table t = {0};
    spiky_table(&t, 200001);
    size_t len;
    char *svg = write_and_read(m, &t, &fg, &len);
    double a[4];
    attr_numbers(svg, "data-mech-axes", a, 4);
    int nv;
    double *v = path_data(strstr(svg, "<path stroke=\"#1f4e99\""), &nv);
    double *px = malloc((size_t)t.nrows * sizeof *px), *py = malloc((size_t)t.nrows * sizeof *py);
    for (int r = 0; r < t.nrows; r++) {
        px[r] = a[1] + a[0] * mech_table_get(&t, r, 0) * 180 / 3.141592653589793;
        py[r] = a[3] - a[2] * mech_table_get(&t, r, 1);
    }
    thinned_against_full(v, nv, px, py, t.nrows, 0.255);
    cr_expect_lt(nv, 600, "%d vertices for a sine and two spikes", nv);
    free(v);
    free(px);
    free(py);
    free(svg);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* The animation's scale bar: 1, 2 or 5 x 10^k mm, as long on the page as
 * that length through data-mech-transform, and labelled with it. */
Test(plot, animation_scale_bar_has_its_labelled_length)
{
    mech_model *m = load(fourbar);
    mech_table t = solve_steps(m, 0);
    plot_anim_options o;
    plot_anim_options_default(&o);
    char dir[] = "/tmp/mech-plot-XXXXXX", path[96];
    cr_assert(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/a.svg", dir);
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(plot_animation_write(m, &t, &o, path, &d), MECH_OK);
    mech_diag_free(&d);
    size_t len;
    char *svg = read_whole(path, &len);
    unlink(path);
    rmdir(dir);
    double tr[3], bar[4];
    attr_numbers(svg, "data-mech-transform", tr, 3);
    attr_numbers(svg, "data-mech-scale-bar", bar, 4);
    cr_expect_float_eq(bar[2] - bar[1], bar[0] * tr[0], 0.01, "bar %g px, %g m at %g px/m",
                       bar[2] - bar[1], bar[0], tr[0]);
    cr_expect(bar[2] - bar[1] >= 60 && bar[2] - bar[1] <= 150, "bar %g px", bar[2] - bar[1]);
    char label[32];
    snprintf(label, sizeof label, ">%g mm</text>", bar[0] * 1e3);
    cr_expect(strstr(svg, label), "no label %s", label);
    double k = bar[0] * 1e3 / pow(10, floor(log10(bar[0] * 1e3) + 1e-9));
    cr_expect(fabs(k - 1) < 1e-9 || fabs(k - 2) < 1e-9 || fabs(k - 5) < 1e-9, "%g mm", bar[0] * 1e3);
    free(svg);
    mech_table_free(&t);
    mech_model_free(&m);
}

/* Force legends name the link the reaction acts on (docs/forces.md: a
 * revolute's force is on the later link in the file, from the earlier; the
 * conveyor's links are crank, coupler, tray, rocker4, rocker5). */
Test(plot, force_legends_say_which_link)
{
    mech_model *m = NULL;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_load_file("mechanisms/conveyor.yaml", &m, &d), MECH_OK);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.steps = 36;
    o.has_range = 1;
    o.from = 0;
    o.to = 6.283185307179586;
    mech_table t = {0};
    cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
    plot_figure f[64];
    int n = plot_plan(m, &t, f, 64), seen = 0;
    for (int k = 0; k < n; k++) {
        if (strcmp(f[k].name, "force-B") == 0) {
            cr_expect_str_eq(f[k].note[0], "B: force on tray");
            cr_expect_str_eq(f[k].note[1], "from coupler");
            size_t len;
            char *svg = write_and_read(m, &t, &f[k], &len);
            cr_expect(strstr(svg, ">B: force on tray</text>"));
            cr_expect(strstr(svg, "force on tray from coupler</title>"));
            free(svg);
            seen++;
        } else if (strcmp(f[k].name, "force-O") == 0) {
            cr_expect_str_eq(f[k].note[0], "O: force on crank");
            cr_expect_str_eq(f[k].note[1], "from ground");
            seen++;
        } else if (strcmp(f[k].name, "driver-torque") == 0) {
            cr_expect_str_eq(f[k].note[0], "torque on crank");
            seen++;
        }
    }
    cr_expect_eq(seen, 3);
    mech_diag_free(&d);
    mech_table_free(&t);
    mech_model_free(&m);
}
