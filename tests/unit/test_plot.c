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

#include "plot.h"

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
