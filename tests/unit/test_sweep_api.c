/* tests/unit/test_sweep_api.c: mech_sweep, `mech sweep` as a library call
 * (src/study/sweep_run.c): the stroke of an in-line slider-crank is twice its
 * crank radius (an exact truth), every variant of a grid comes once with its
 * parameters in SI, the shards of a grid are the grid's rows bit for bit,
 * random samples lie within the tolerances and depend on the seed and the
 * index only, a variant that cannot assemble is a row with its status, the
 * sweep's own argument errors are named as such, and two sweeps of two files
 * in one process each solve through their own one analysis. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "mech.h"

enum { MAXROWS = 64 };

/* The rows of one run, by shard row. */
typedef struct rows {
    int n, calls;
    long index[MAXROWS];
    mech_variant_status status[MAXROWS];
    int nrows[MAXROWS];
    double params[MAXROWS][4], metrics[MAXROWS][4];
    int skip_from;  /* done(): rows at or after it are "there already" */
} rows;

static void take(void *ctx, const mech_variant *v)
{
    rows *r = ctx;
    r->calls++;
    cr_assert(v->row >= 0 && v->row < MAXROWS);
    r->index[v->row] = v->index;
    r->status[v->row] = v->status;
    r->nrows[v->row] = v->rows;
    for (int k = 0; k < 4; k++) {
        r->params[v->row][k] = k < 2 ? v->params[k] : NAN;
        r->metrics[v->row][k] = k < 2 ? v->metrics[k] : NAN;
    }
    cr_expect(strncmp(v->messages, "variant ", 8) == 0, "messages: %s", v->messages);
}

static int skip(void *ctx, long row)
{
    const rows *r = ctx;
    return r->skip_from > 0 && row >= r->skip_from;
}

/* A sweep of `path` with the specs (vary/list by their first letter), the
 * metrics, the options; its rows into *out. Returns the prepare's status. */
static int run(const char *path, const char *const *grid, const char *const *metrics,
               const mech_sweep_options *o, rows *out, mech_sweep_stats *st)
{
    mech_sweep *s = NULL;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_sweep_new(&s), MECH_OK);
    for (; grid && *grid; grid++)
        cr_assert_eq((*grid)[0] == 'l' && (*grid)[1] == '=' ? mech_sweep_list(s, *grid + 2, &d)
                                                            : mech_sweep_vary(s, *grid, &d),
                     MECH_OK, "%s", *grid);
    for (; metrics && *metrics; metrics++)
        cr_assert_eq(mech_sweep_metric(s, *metrics, &d), MECH_OK, "%s", *metrics);
    int rc = mech_sweep_prepare(s, path, o, &d);
    if (rc == MECH_OK) {
        mech_sweep_sink sink = {take, skip, out};
        cr_assert_eq(mech_sweep_run(s, &sink, st, &d), MECH_OK);
        out->n = (int)mech_sweep_count(s);
    }
    mech_diag_free(&d);
    mech_sweep_free(&s);
    cr_expect_null(s);
    return rc;
}

Test(sweep_api, the_stroke_is_twice_the_crank)
{
    rows r = {0};
    mech_sweep_stats st;
    mech_sweep_options o;
    mech_sweep_options_default(&o);
    o.nthreads = 2;
    cr_assert_eq(run("mechanisms/slider-crank.yaml", (const char *[]){"r=30mm:50mm:5", NULL},
                     (const char *[]){"range:B.x", "maxabs:B.x", NULL}, &o, &r, &st),
                 MECH_OK);
    cr_assert_eq(r.n, 5);
    cr_assert_eq(r.calls, 5, "each variant once");
    cr_expect_eq(st.solved, 5);
    cr_expect_eq(st.shared + st.alone, 5);
    for (int i = 0; i < 5; i++) {
        double radius = 0.030 + 0.005 * i, rod = 0.140;
        cr_expect_eq(r.index[i], i);
        cr_expect_eq(r.status[i], MECH_VARIANT_OK);
        cr_expect_eq(r.nrows[i], 73);
        cr_expect_float_eq(r.params[i][0], radius, 1e-15, "r of variant %d", i);
        /* the piston's travel from r + l (crank at 0 deg) to l - r (180 deg) */
        cr_expect_float_eq(r.metrics[i][0], 2 * radius, 1e-12, "stroke of variant %d: %.17g",
                           i, r.metrics[i][0]);
        cr_expect_float_eq(r.metrics[i][1], radius + rod, 1e-12);
    }
}

Test(sweep_api, shards_are_the_grid_bit_for_bit)
{
    const char *const grid[] = {"r=30mm:40mm:3", "l=l=130mm,140mm,150mm", NULL};
    const char *const metrics[] = {"range:B.vx", "min:rod.angle", NULL};
    mech_sweep_options o;
    mech_sweep_options_default(&o);
    rows all = {0};
    cr_assert_eq(run("mechanisms/slider-crank.yaml", grid, metrics, &o, &all, NULL), MECH_OK);
    cr_assert_eq(all.n, 9);
    for (int k = 0; k < 2; k++) {
        rows part = {0};
        o.shard_k = k;
        o.shard_m = 2;
        o.index_offset = 100;
        cr_assert_eq(run("mechanisms/slider-crank.yaml", grid, metrics, &o, &part, NULL), MECH_OK);
        cr_assert_eq(part.n, k == 0 ? 5 : 4);
        for (int i = 0; i < part.n; i++) {
            int g = k + 2 * i;  /* the grid's variant */
            cr_expect_eq(part.index[i], 100 + g);
            for (int c = 0; c < 2; c++) {
                cr_expect(memcmp(&part.params[i][c], &all.params[g][c], sizeof(double)) == 0);
                cr_expect(memcmp(&part.metrics[i][c], &all.metrics[g][c], sizeof(double)) == 0,
                          "variant %d metric %d: %.17g, unsharded %.17g", g, c,
                          part.metrics[i][c], all.metrics[g][c]);
            }
        }
    }
    /* the last parameter varies fastest */
    cr_expect_float_eq(all.params[1][0], 0.030, 1e-15);
    cr_expect_float_eq(all.params[1][1], 0.140, 1e-15);
    cr_expect_float_eq(all.params[3][0], 0.035, 1e-15);
}

Test(sweep_api, random_samples_within_the_tolerances)
{
    mech_sweep_options o;
    mech_sweep_options_default(&o);
    o.nrandom = 40;
    o.seed = 7;
    rows a = {0}, b = {0}, c = {0};
    cr_assert_eq(run("tests/sweep/tol-slider-crank.yaml", NULL, NULL, &o, &a, NULL), MECH_OK);
    o.nthreads = 1;
    cr_assert_eq(run("tests/sweep/tol-slider-crank.yaml", NULL, NULL, &o, &b, NULL), MECH_OK);
    o.seed = 8;
    cr_assert_eq(run("tests/sweep/tol-slider-crank.yaml", NULL, NULL, &o, &c, NULL), MECH_OK);
    int differ = 0;
    double lo = 1, hi = 0;
    for (int i = 0; i < 40; i++) {
        cr_expect_eq(a.status[i], MECH_VARIANT_OK);
        cr_expect(fabs(a.params[i][0] - 0.040) <= 0.05e-3 * (1 + 1e-12), "r = %.17g",
                  a.params[i][0]);
        cr_expect(fabs(a.params[i][1] - 0.120) <= 0.1e-3 * (1 + 1e-12), "l = %.17g",
                  a.params[i][1]);
        cr_expect(memcmp(a.params[i], b.params[i], 2 * sizeof(double)) == 0, "seed 7, -j 1");
        differ += a.params[i][0] != c.params[i][0];
        lo = fmin(lo, a.params[i][0]);
        hi = fmax(hi, a.params[i][0]);
    }
    cr_expect_eq(differ, 40, "another seed, other samples");
    cr_expect_gt(hi - lo, 0.05e-3, "40 samples spread over most of +-0.05 mm: %.3g", hi - lo);
}

Test(sweep_api, a_variant_that_cannot_assemble_is_a_row)
{
    mech_sweep_options o;
    mech_sweep_options_default(&o);
    rows r = {0};
    cr_assert_eq(run("mechanisms/slider-crank.yaml", (const char *[]){"l=r=40mm,150mm", NULL},
                     (const char *[]){"max:B.x", NULL}, &o, &r, NULL),
                 MECH_OK);
    cr_expect_eq(r.status[0], MECH_VARIANT_OK);
    cr_expect_eq(r.status[1], MECH_VARIANT_NO_ASSEMBLY);
    cr_expect_lt(r.nrows[1], 73);
    cr_expect(isnan(r.metrics[1][0]));
    cr_expect_str_eq(mech_variant_status_name(r.status[1]), "no-assembly");
}

Test(sweep_api, rows_there_already_are_left_out)
{
    mech_sweep_options o;
    mech_sweep_options_default(&o);
    rows r = {.skip_from = 2};
    cr_assert_eq(run("mechanisms/slider-crank.yaml", (const char *[]){"r=30mm:40mm:5", NULL},
                     NULL, &o, &r, NULL),
                 MECH_OK);
    cr_expect_eq(r.calls, 2);
}

/* The first error's message and file after prepare of this sweep. */
static void expect_refused(const char *path, const char *grid, const char *metric,
                           long nrandom, const char *want)
{
    mech_sweep *s = NULL;
    mech_diag d;
    mech_diag_init(&d);
    mech_sweep_new(&s);
    int rc = grid ? mech_sweep_vary(s, grid, &d) : MECH_OK;
    if (rc == MECH_OK && metric)
        rc = mech_sweep_metric(s, metric, &d);
    mech_sweep_options o;
    mech_sweep_options_default(&o);
    o.nrandom = nrandom;
    if (rc == MECH_OK)
        rc = mech_sweep_prepare(s, path, &o, &d);
    cr_expect_eq(rc, MECH_EINPUT, "%s", want);
    cr_assert_geq(d.count, 1);
    cr_expect_str_eq(d.entries[0].file, MECH_SWEEP_ARGUMENTS);
    cr_expect(strstr(d.entries[0].message, want), "'%s' in '%s'", want, d.entries[0].message);
    mech_sweep_sink sink = {take, NULL, NULL};
    if (rc == MECH_EINPUT && mech_sweep_vary(s, "r=1mm:2mm:2", &d) == MECH_OK)
        cr_expect_neq(mech_sweep_run(s, &sink, NULL, &d), MECH_OK, "a refused sweep runs");
    mech_diag_free(&d);
    mech_sweep_free(&s);
}

Test(sweep_api, the_arguments_refused)
{
    const char *sc = "mechanisms/slider-crank.yaml";
    expect_refused(sc, NULL, NULL, 0, "nothing to vary");
    expect_refused(sc, "r=30mm:40mm:2", NULL, 5, "does not combine with --vary");
    expect_refused(sc, "r=30mm:40:2", NULL, 0, "--vary needs NAME=FROM:TO:COUNT");
    expect_refused(sc, "r=1x:2x:2", NULL, 0, "is not a number with a unit");
    expect_refused(sc, "r=30mm:40mm:2", "range:Bx", 0, "no column 'Bx'");
    expect_refused(sc, "r=30mm:40mm:2", "flywheel:2", 0, "flywheel:CS needs 0 < CS < 1");
    expect_refused(sc, NULL, NULL, 3, "has a tolerance");
}

/* Each sweep keeps its own parsed file and analysis (they were the
 * process's, for the first file asked for: a second sweep in the same
 * process, as from Python, was analysed variant by variant). */
Test(sweep_api, each_sweep_its_own_analysis)
{
    mech_sweep_options o;
    mech_sweep_options_default(&o);
    rows a = {0}, b = {0};
    mech_sweep_stats sa, sb;
    cr_assert_eq(run("mechanisms/slider-crank.yaml", (const char *[]){"r=30mm:40mm:4", NULL},
                     NULL, &o, &a, &sa), MECH_OK);
    cr_assert_eq(run("mechanisms/offset-slider-crank.yaml", (const char *[]){"l=l=119mm,120mm,121mm", NULL},
                     NULL, &o, &b, &sb), MECH_OK);
    cr_expect_eq(sa.shared, 4, "slider-crank: %ld shared, %ld alone", sa.shared, sa.alone);
    cr_expect_eq(sb.shared, 3, "offset slider-crank: %ld shared, %ld alone", sb.shared, sb.alone);
}
