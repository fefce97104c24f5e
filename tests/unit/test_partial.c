/* tests/unit/test_partial.c: partial sweeps (issue 17, item 1): every
 * requested row where the mechanism assembles on its branch is solved, the
 * missing ones are listed as gaps with their limits and kind.
 *
 * Truths are independent of the library: which rows exist follows from
 * |CA| between |b - c| and b + c (law of cosines), the limits from
 * cos q = (a^2 + d^2 - L^2) / (2 a d), the rows against the closed-form
 * four-bar and slider-crank of closed_forms.h. Run from the repository root.
 * Set MECH_HARD_VERBOSE=1 to print the measured numbers. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mech.h"
#include "helpers.h"

#define PI 3.14159265358979323846
#define TWO_PI (2.0 * PI)
#define DEG (PI / 180.0)

#include "closed_forms.h"

static void note(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    note_tagged("partial", fmt, ap);
    va_end(ap);
}

static double get(const mech_table *t, int row, const char *name)
{
    int c = mech_table_column(t, name);
    cr_assert_geq(c, 0, "no column '%s'", name);
    return mech_table_get(t, row, c);
}

/* Solve `path` over from..to (SI) in `steps` intervals; rc expected. */
static mech_table sweep(const char *path, double from, double to, int steps, int limit_rows,
                        int want_rc, mech_diag *d)
{
    mech_model *m = load_path(path);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.has_range = 1, o.from = from, o.to = to, o.steps = steps;
    o.limit_rows = limit_rows;
    mech_table t = {0};
    int rc = mech_solve(m, &o, &t, NULL, d);
    cr_assert_eq(rc, want_rc, "%s: rc %d, expected %d: %s", path, rc, want_rc,
                 d->count ? d->entries[0].message : "(no message)");
    mech_model_free(&m);
    return t;
}

/* Worst error of every four-bar column against the closed form, relative
 * to the largest value of its kind (angles: absolute, rad); rows with
 * |q - skip| < skip_width are left out (near a limit). */
static double fourbar_worst(const mech_table *t, const fourbar *g, double skip, double width)
{
    double worst = 0.0, scale[6] = {0};
    double v[NFOURBAR];
    for (int pass = 0; pass < 2; pass++)
        for (int i = 0; i < t->nrows; i++) {
            double q = get(t, i, "q");
            if (fabs(remainder(q - skip, TWO_PI)) < width || fabs(remainder(q + skip, TWO_PI)) < width)
                continue;
            fourbar_ref(g, q, 1, 0, v);
            for (int j = 0; j < NFOURBAR; j++) {
                int k = column_kind(FOURBAR_COLS[j]);
                if (pass == 0) {
                    scale[k] = k == 3 ? 1.0 : fmax(scale[k], fabs(v[j]));
                    continue;
                }
                double e = get(t, i, FOURBAR_COLS[j]) - v[j];
                if (k == 3)
                    e = remainder(e, TWO_PI);
                worst = fmax(worst, fabs(e) / scale[k]);
            }
        }
    return worst;
}

/* The crank angle (deg, in [0, 180]) where |CA| = L. */
static double crank_at(const fourbar *g, double L)
{
    return acos((g->a * g->a + g->d * g->d - L * L) / (2 * g->a * g->d)) / DEG;
}

/* Does the four-bar assemble at crank angle q (|b - c| <= |CA| <= b + c)? */
static int assembles(const fourbar *g, double q)
{
    double L = sqrt(g->a * g->a + g->d * g->d - 2 * g->a * g->d * cos(q));
    return L <= g->b + g->c && L >= fabs(g->b - g->c);
}

/* Every requested row that assembles is in the table, in order, and no
 * other; margin: rows within it of a limit are not counted either way. */
static void check_rows_exist(const mech_table *t, const fourbar *g, double from, double to,
                             int steps, double margin)
{
    int row = 0, expected = 0;
    for (int i = 0; i <= steps; i++) {
        double q = i == steps ? to : from + (to - from) * i / steps;
        int in = assembles(g, q);
        int near = assembles(g, q - margin) != in || assembles(g, q + margin) != in;
        int have = row < t->nrows && fabs(get(t, row, "q") - q) <= 1e-12;
        cr_assert(have == in || near, "row at %.6f deg: %s", q / DEG,
                  in ? "assembles but was not solved" : "solved but does not assemble");
        row += have;
        expected += in;
    }
    cr_assert_eq(row, t->nrows, "%d table rows are not requested positions", t->nrows - row);
    note("%d rows solved of %d that exist (%d requested)", t->nrows, expected, steps + 1);
}

static const fourbar NON_GRASHOF = {.a = 0.045, .b = 0.040, .c = 0.055, .d = 0.070,
                                    .px = 0.020, .py = 0.010, .sign = +1};

/* A non-Grashof crank over a full turn: rows inside both limits
 * (0..109 and 251..360 deg), none outside; one gap whose limits are the
 * closed form's +-109.4712206 deg to 1e-9 deg. */
Test(partial, non_grashof_full_turn)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = sweep("tests/hard/non-grashof-crank.yaml", 0, TWO_PI, 360, 0, MECH_ESOLVE, &d);
    check_rows_exist(&t, &NON_GRASHOF, 0, TWO_PI, 360, 0);
    cr_assert_eq(t.nrows, 220);
    double lim = crank_at(&NON_GRASHOF, NON_GRASHOF.b + NON_GRASHOF.c);
    cr_assert_eq(t.ngaps, 1);
    const mech_gap *g = &t.gaps[0];
    cr_assert_eq(g->kind, MECH_GAP_NO_ASSEMBLY);
    cr_assert(g->first_row == 110 && g->last_row == 250, "rows %d..%d", g->first_row, g->last_row);
    cr_assert(g->from_limit && g->to_limit);
    note("limits %.12f, %.12f deg; closed form +-%.12f: off %.2g, %.2g deg", g->from / DEG,
         g->to / DEG, lim, g->from / DEG - lim, g->to / DEG - (360 - lim));
    /* issue 17 asks for 1e-9 deg; the refinement to 1e-12 of the row spacing
     * gives 1.2e-10 (without it 5.4e-10) */
    cr_assert(fabs(g->from / DEG - lim) <= 3e-10, "limit %.12f deg, closed form %.12f",
              g->from / DEG, lim);
    cr_assert(fabs(g->to / DEG - (360 - lim)) <= 3e-10, "limit %.12f deg, closed form %.12f",
              g->to / DEG, 360 - lim);
    double err = fourbar_worst(&t, &NON_GRASHOF, 0, 0);
    note("non-Grashof full turn: worst error %.2g", err);
    cr_assert(err <= 1e-10, "rows off the closed form by %.3g", err);
    mech_table_free(&t);
    mech_diag_free(&d);
}

/* With limit rows: two more rows, at the limits, positions on the closed
 * form (the rates there are those of a toggle: not compared). */
Test(partial, non_grashof_limit_rows)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = sweep("tests/hard/non-grashof-crank.yaml", 0, TWO_PI, 360, 1, MECH_ESOLVE, &d);
    cr_assert_eq(t.nrows, 222);
    double lim = crank_at(&NON_GRASHOF, NON_GRASHOF.b + NON_GRASHOF.c) * DEG;
    cr_assert(fabs(get(&t, 110, "q") - lim) <= 1e-9 * DEG);
    cr_assert(fabs(get(&t, 111, "q") - (TWO_PI - lim)) <= 1e-9 * DEG);
    double v[NFOURBAR], worst = 0;
    for (int i = 110; i <= 111; i++) {
        fourbar_ref(&NON_GRASHOF, get(&t, i, "q"), 1, 0, v);
        for (int j = 0; j < NFOURBAR; j++)
            if (column_kind(FOURBAR_COLS[j]) == 0)
                worst = fmax(worst, fabs(get(&t, i, FOURBAR_COLS[j]) - v[j]) / 0.1);
    }
    note("limit rows: positions off the closed form by %.2g (relative to 0.1 m)", worst);
    cr_assert(worst <= 1e-6, "limit rows off the closed form by %.3g", worst);
    mech_table_free(&t);
    mech_diag_free(&d);
}

static const fourbar TWO_INTERVALS = {.a = 0.040, .b = 0.060, .c = 0.020, .d = 0.050,
                                      .px = 0.030, .py = 0.010, .sign = +1};

/* Two intervals, [51.3178, 125.0996] deg and [234.9004, 308.6822] deg, swept
 * 0..360: rows in both, two gaps' inner limits and the range ends. */
Test(partial, two_intervals_both_solved)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = sweep("tests/hard/non-grashof-two-intervals.yaml", 0, TWO_PI, 360, 0,
                         MECH_ESOLVE, &d);
    check_rows_exist(&t, &TWO_INTERVALS, 0, TWO_PI, 360, 0);
    double q1 = crank_at(&TWO_INTERVALS, TWO_INTERVALS.b - TWO_INTERVALS.c),
           q2 = crank_at(&TWO_INTERVALS, TWO_INTERVALS.b + TWO_INTERVALS.c);
    cr_assert_eq(t.ngaps, 3, "%d gaps", t.ngaps);
    /* [0, 51.3178) before, (125.0996, 234.9004) between, (308.6822, 360] after */
    double want[4] = {q1, q2, 360 - q2, 360 - q1};
    double got[4] = {t.gaps[0].to, t.gaps[1].from, t.gaps[1].to, t.gaps[2].from};
    cr_assert(!t.gaps[0].from_limit && t.gaps[0].to_limit && t.gaps[1].from_limit &&
              t.gaps[1].to_limit && t.gaps[2].from_limit && !t.gaps[2].to_limit);
    for (int k = 0; k < 4; k++) {
        note("limit %d: %.12f deg, closed form %.12f", k, got[k] / DEG, want[k]);
        cr_assert(fabs(got[k] / DEG - want[k]) <= 3e-10, "limit %.12f deg, closed form %.12f",
                  got[k] / DEG, want[k]);
    }
    double err = fourbar_worst(&t, &TWO_INTERVALS, 0, 0);
    note("two intervals: worst error %.2g", err);
    cr_assert(err <= 1e-10, "rows off the closed form by %.3g", err);
    mech_table_free(&t);
    mech_diag_free(&d);
}

static const double DC_R = 0.030, DC_L = 0.100;

/* Slider-driven rows: crank angle by the law of cosines (upper branch),
 * crank speed from dx/dtheta = -r sin - r^2 sin cos / sqrt(l^2 - r^2 sin^2). */
static double dead_centre_worst(const mech_table *t)
{
    double worst = 0;
    for (int i = 0; i < t->nrows; i++) {
        double x = get(t, i, "q");
        double th = acos((DC_R * DC_R + x * x - DC_L * DC_L) / (2 * DC_R * x));
        double s = sin(th), c = cos(th);
        double dx = -DC_R * s - DC_R * DC_R * s * c / sqrt(DC_L * DC_L - DC_R * DC_R * s * s);
        double w = 1.0 / dx;  /* 1 m/s */
        worst = fmax(worst, fabs(remainder(get(t, i, "crank.angle") - th, TWO_PI)));
        double v[NSLIDER];  /* the crank-driven closed form at that angle: A, B */
        const slidercrank g = {.r = DC_R, .l = DC_L, .e = 0};
        slider_ref(&g, th, 1, 0, v);
        static const int pos[] = {0, 1, 6, 7};
        for (int j = 0; j < 4; j++)
            worst = fmax(worst, fabs(get(t, i, SLIDER_COLS[pos[j]]) - v[pos[j]]) / DC_L);
        worst = fmax(worst, fabs(get(t, i, "crank.omega") - w) / fabs(w) * 1e-2);
    }
    return worst;
}

/* The piston drives 100 -> 140 mm: rows 100..129 mm, then a gap from the
 * dead centre (130 mm, crank and rod in line) to the end of the range. */
Test(partial, slider_to_and_past_dead_centre)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = sweep("tests/hard/dead-centre-slider.yaml", 0.100, 0.140, 40, 0, MECH_ESOLVE, &d);
    cr_assert_eq(t.nrows, 30, "%d rows (100..129 mm expected)", t.nrows);
    cr_assert_eq(t.ngaps, 1);
    const mech_gap *g = &t.gaps[0];
    cr_assert_eq(g->kind, MECH_GAP_DEAD_POINT);
    cr_assert(g->first_row == 30 && g->last_row == 40);
    note("dead centre found at %.12f mm (130 exactly)", g->from * 1e3);
    /* 4.6e-14 m (without the refinement to 1e-12 of the row spacing: 9.3e-13) */
    cr_assert(g->from_limit && fabs(g->from - (DC_R + DC_L)) <= 2e-13, "limit %.15g m", g->from);
    double err = dead_centre_worst(&t);
    note("slider to dead centre: worst error %.2g", err);
    cr_assert(err <= 1e-10, "rows off the law of cosines by %.3g", err);
    mech_table_free(&t);
    mech_diag_free(&d);
}

/* From past the dead centre back: 140 -> 100 mm. The first rows do not
 * assemble (a gap from the range's start), then every row from 129 mm. */
Test(partial, slider_from_past_dead_centre)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = sweep("tests/hard/dead-centre-slider.yaml", 0.140, 0.100, 40, 0, MECH_ESOLVE, &d);
    cr_assert_eq(t.nrows, 30, "%d rows (129..100 mm expected)", t.nrows);
    cr_assert_eq(t.ngaps, 1);
    const mech_gap *g = &t.gaps[0];
    cr_assert(g->first_row == 0 && g->last_row == 10, "rows %d..%d", g->first_row, g->last_row);
    cr_assert(!g->from_limit && g->to_limit);
    note("dead centre found at %.12f mm from the far side", g->to * 1e3);
    cr_assert(fabs(g->to - (DC_R + DC_L)) <= 2e-13, "limit %.15g m", g->to);
    double err = dead_centre_worst(&t);
    cr_assert(err <= 1e-10, "rows off the law of cosines by %.3g", err);
    mech_table_free(&t);
    mech_diag_free(&d);
}

static const fourbar CHANGE = {.a = 0.030, .b = 0.060, .c = 0.050, .d = 0.080,
                               .px = 0.040, .py = 0.015, .sign = +1};

/* A change point with the branch declared at every position: every row but
 * the crossing (180 deg), all on the declared assembly. */
Test(partial, change_point_declared_branch_all_other_rows)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = sweep("tests/hard/change-point.yaml", 0, TWO_PI, 360, 0, MECH_ESOLVE, &d);
    cr_assert_eq(t.nrows, 360);
    cr_assert_eq(t.ngaps, 1);
    cr_assert_eq(t.gaps[0].kind, MECH_GAP_CHANGE_POINT);
    cr_assert(t.gaps[0].first_row == 180 && t.gaps[0].last_row == 180);
    double err = fourbar_worst(&t, &CHANGE, PI, 10 * DEG);
    note("change point, declared branch: %d rows, worst error away from 180 deg %.2g", t.nrows,
         err);
    cr_assert(err <= 1e-10, "rows off the declared branch's closed form by %.3g", err);
    mech_table_free(&t);
    mech_diag_free(&d);
}

/* ---- redundant constraints: rates to rounding from a rough guess -------- */

/* The redundant parallelogram of tests/hard/redundant-parallelogram.yaml
 * from `initial`: every crank at the driver's angle q, the coupler
 * translating (angle 0). Exact: angles q, 0; omegas 1, 0; alphas 0 (1 rad/s);
 * F = E + 40 mm (cos q, sin q). Worst errors: [0] positions (angles in rad,
 * lengths relative to 100 mm), [1] velocities (relative to 1 rad/s and
 * 40 mm/s), [2] accelerations (relative to 40 mm/s^2; alphas to 1 rad/s^2). */
static void redundant_errors(const char *initial, double err[3])
{
    char text[2048];
    snprintf(text, sizeof text,
             "name: redundant parallelogram\n"
             "units: {length: mm, angle: deg}\n"
             "ground: {O: [0, 0], E: [50, 0], C: [100, 0]}\n"
             "links:\n"
             "  crank:   {points: {O: [0, 0], A: [40, 0]}}\n"
             "  coupler: {points: {A: [0, 0], B: [100, 0], F: [50, 0]}}\n"
             "  rocker:  {points: {C: [0, 0], B: [40, 0]}}\n"
             "  extra:   {points: {E: [0, 0], F: [40, 0]}}\n"
             "driver: {link: crank, angle: {from: 30, to: 150, steps: 120}, speed: 1 rad/s}\n"
             "initial: %s\n"
             "outputs: {points: [F], links: [coupler, rocker, extra]}\n", initial);
    mech_model *m = load_text(text);
    mech_table t = must_solve(m, NULL);
    cr_assert_eq(t.nrows, 121);
    memset(err, 0, 3 * sizeof *err);
    for (int i = 0; i < t.nrows; i++) {
        double q = get(&t, i, "q");
        double p[] = {remainder(get(&t, i, "coupler.angle"), TWO_PI),
                      remainder(get(&t, i, "rocker.angle") - q, TWO_PI),
                      remainder(get(&t, i, "extra.angle") - q, TWO_PI),
                      (get(&t, i, "F.x") - (0.050 + 0.040 * cos(q))) / 0.1,
                      (get(&t, i, "F.y") - 0.040 * sin(q)) / 0.1};
        double v[] = {get(&t, i, "coupler.omega"), get(&t, i, "rocker.omega") - 1,
                      get(&t, i, "extra.omega") - 1,
                      (get(&t, i, "F.vx") + 0.040 * sin(q)) / 0.04,
                      (get(&t, i, "F.vy") - 0.040 * cos(q)) / 0.04};
        double a[] = {get(&t, i, "coupler.alpha"), get(&t, i, "rocker.alpha"),
                      get(&t, i, "extra.alpha"), (get(&t, i, "F.ax") + 0.040 * cos(q)) / 0.04,
                      (get(&t, i, "F.ay") + 0.040 * sin(q)) / 0.04};
        for (int k = 0; k < 5; k++) {
            err[0] = fmax(err[0], fabs(p[k]));
            err[1] = fmax(err[1], fabs(v[k]));
            err[2] = fmax(err[2], fabs(a[k]));
        }
    }
    mech_table_free(&t);
    mech_model_free(&m);
}

/* Issue 17, item 3: positions, velocities, accelerations to 1e-13, 1e-12,
 * 1e-12 whatever the guess (before: 3.4e-10 and 7.9e-8 on the first rows
 * from a rough guess). */
Test(partial, redundant_rates_to_rounding_from_rough_guess)
{
    static const char *const guesses[] = {"{coupler: 2, rocker: 32, extra: 28}",
                                          "{coupler: 10, rocker: 45, extra: 15}",
                                          "{coupler: -15, rocker: 10, extra: 60}",
                                          "{coupler: 0, rocker: 30, extra: 30}",
                                          "{coupler: 20, rocker: 20, extra: 20}",
                                          "{coupler: 25, rocker: 10, extra: 0}"};
    for (int g = 0; g < 6; g++) {
        double err[3];
        redundant_errors(guesses[g], err);
        note("redundant parallelogram from %s: positions %.2g, velocities %.2g, "
             "accelerations %.2g", guesses[g], err[0], err[1], err[2]);
        cr_assert(err[0] <= 1e-13 && err[1] <= 1e-12 && err[2] <= 1e-12,
                  "from %s: positions %.3g, velocities %.3g, accelerations %.3g", guesses[g],
                  err[0], err[1], err[2]);
    }
}

/* ---- branch conditions users can state (issue 17, item 4) -------------- */

/* A crank-rocker (crank 30, coupler 80 with P at (40, 20), rocker 60, ground
 * 90 mm), ground point G at (70, 0) mm, swept 60..420 deg; no guesses, so
 * row 0 comes from scattered starts and only `branch` picks the assembly. */
static const fourbar CR = {.a = 0.030, .b = 0.080, .c = 0.060, .d = 0.090,
                           .px = 0.040, .py = 0.020, .sign = +1};

static mech_table crank_rocker_with(const char *branch, int want_rc, mech_diag *d)
{
    char text[1024];
    snprintf(text, sizeof text,
             "name: crank-rocker with a stated branch\n"
             "units: {length: mm, angle: deg}\n"
             "ground: {O: [0, 0], C: [90, 0], G: [70, 0]}\n"
             "links:\n"
             "  crank:   {points: {O: [0, 0], A: [30, 0]}}\n"
             "  coupler: {points: {A: [0, 0], B: [80, 0], P: [40, 20]}}\n"
             "  rocker:  {points: {C: [0, 0], B: [60, 0]}}\n"
             "driver: {link: crank, angle: {from: 60, to: 420, steps: 360}, speed: 1 rad/s}\n"
             "branch: [%s]\n"
             "outputs: {points: [A, B, P], links: [crank, coupler, rocker]}\n", branch);
    mech_model *m = load_text(text);
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_table t = {0};
    int rc = mech_solve(m, &o, &t, NULL, d);
    cr_assert_eq(rc, want_rc, "branch %s: rc %d: %s", branch, rc,
                 d->count ? d->entries[0].message : "");
    mech_model_free(&m);
    return t;
}

/* Each new kind of condition selects each assembly: every row on the
 * closed form of the assembly it names (sign +1: B left of A -> C). */
Test(partial, branch_kinds_select_each_assembly)
{
    static const struct { const char *branch; int sign; } cases[] = {
        {"{point: B, right_of: G, first_only: true}", +1},  /* B.x at 60 deg: 87.4 mm */
        {"{point: B, left_of: G, first_only: true}", -1},   /* 50.9 mm */
        {"{point: B, above: O}", +1},                        /* at every position */
        {"{point: B, below: C}", -1},
        {"{points: [A, B, C], turn: cw, first_only: true}", +1},
        {"{points: [A, B, C], turn: ccw, first_only: true}", -1}};
    for (size_t k = 0; k < sizeof cases / sizeof *cases; k++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_table t = crank_rocker_with(cases[k].branch, MECH_OK, &d);
        fourbar g = CR;
        g.sign = cases[k].sign;
        double err = fourbar_worst(&t, &g, 0, 0);
        note("branch %s: %d rows, worst error against the sign %+d closed form %.2g",
             cases[k].branch, t.nrows, cases[k].sign, err);
        cr_assert_eq(t.nrows, 361);
        cr_assert(err <= 1e-10, "branch %s: off the %+d assembly by %.3g", cases[k].branch,
                  cases[k].sign, err);
        mech_table_free(&t);
        mech_diag_free(&d);
    }
}

/* The slider's sign picks the piston's side: an offset slider-crank (crank
 * 30, rod 100, offset 10 mm) assembles with the piston right of the crank
 * (x_B = r cos q + w) or left (x_B = r cos q - w), w = sqrt(l^2 - (e - r sin q)^2). */
Test(partial, branch_slider_sign_selects_each_side)
{
    for (int sign = -1; sign <= 1; sign += 2) {
        char text[1024];
        snprintf(text, sizeof text,
                 "name: offset slider-crank\n"
                 "units: {length: mm, angle: deg}\n"
                 "ground: {O: [0, 0], G: [0, 10]}\n"
                 "links:\n"
                 "  crank:  {points: {O: [0, 0], A: [30, 0]}}\n"
                 "  rod:    {points: {A: [0, 0], B: [100, 0]}}\n"
                 "  piston: {points: {B: [0, 0]}}\n"
                 "joints:\n"
                 "  - {slider: B, link: piston, on: ground, through: G, angle: 0, name: x_B}\n"
                 "driver: {link: crank, angle: {from: 0, to: 360, steps: 72}, speed: 1 rad/s}\n"
                 "branch: [{slider: x_B, sign: %s}]\n"
                 "outputs: {points: [B], sliders: [x_B]}\n", sign > 0 ? "positive" : "negative");
        mech_model *m = load_text(text);
        mech_solve_options o;
        mech_solve_options_default(&o);
        mech_diag d;
        mech_diag_init(&d);
        mech_table t = {0};
        cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
        double worst = 0;
        for (int i = 0; i < t.nrows; i++) {
            double q = get(&t, i, "q"), u = 0.010 - 0.030 * sin(q);
            double x = 0.030 * cos(q) + sign * sqrt(0.100 * 0.100 - u * u);
            worst = fmax(worst, fabs(get(&t, i, "x_B.s") - x) / 0.1);
            worst = fmax(worst, fabs(get(&t, i, "B.x") - x) / 0.1);
        }
        note("slider sign %+d: %d rows, worst error %.2g", sign, t.nrows, worst);
        cr_assert_eq(t.nrows, 73);
        cr_assert(worst <= 1e-12, "slider sign %+d: off by %.3g", sign, worst);
        mech_table_free(&t);
        mech_diag_free(&d);
        mech_model_free(&m);
    }
}

/* A condition that can never hold is refused at load. */
Test(partial, branch_never_holding_refused)
{
    static const char *const bad[] = {
        "{point: B, right_of: B}", "{point: O, right_of: C}", "{point: O, above: C}",
        "{point: A, above: A2}", "{slider: x_B, sign: up}", "{point: B, right_of: C, above: C}"};
    static const char *const says[] = {"twice", "not right of", "not above", "one place",
                                       "positive", "one of"};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        char text[1024];
        snprintf(text, sizeof text,
                 "name: refused\n"
                 "ground: {O: [0, 0], C: [0.09, 0]}\n"
                 "links:\n"
                 "  crank:   {points: {O: [0, 0], A: [0.03, 0], A2: [0.03, 0]}}\n"
                 "  coupler: {points: {A: [0, 0], B: [0.08, 0]}}\n"
                 "  rocker:  {points: {C: [0, 0], B: [0.06, 0]}}\n"
                 "driver: {link: crank, angle: {from: 0 deg, to: 1 deg, steps: 1}}\n"
                 "branch: [%s]\n", bad[k]);
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        int rc = mech_load_string(text, strlen(text), "refused.yaml", &m, &d);
        const char *msg = d.count ? d.entries[0].message : "";
        for (size_t e = 0; e < d.count; e++)
            if (strstr(d.entries[e].message, "branch"))
                msg = d.entries[e].message;
        note("%s: %s", bad[k], msg);
        cr_assert_neq(rc, MECH_OK, "'%s' accepted", bad[k]);
        cr_assert(strstr(msg, says[k]), "'%s': message '%s' does not say '%s'", bad[k], msg,
                  says[k]);
        mech_model_free(&m);
        mech_diag_free(&d);
    }
}

/* A first-position-only branch through a change point (crank 30, coupler
 * 60, rocker 50, ground 80 mm: the branches cross at 180 deg): no row on
 * the crossing (361 intervals), every row solved; the smooth continuation
 * is the declared (open) assembly before 180 deg and the crossed one after. */
Test(partial, change_point_crossed_with_first_only_branch)
{
    const char *text =
        "name: change point, branch at the first position only\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {O: [0, 0], C: [80, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [30, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0], P: [40, 15]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
        "driver: {link: crank, angle: {from: 0, to: 360, steps: 361}, speed: 1 rad/s}\n"
        "branch: [{points: [A, B, C], turn: cw, first_only: true}]\n"
        "outputs: {points: [A, B, P], links: [crank, coupler, rocker]}\n";
    mech_model *m = load_text(text);
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    int rc = mech_solve(m, &o, &t, NULL, &d);
    cr_assert_eq(rc, MECH_OK, "rc %d: %s", rc, d.count ? d.entries[0].message : "");
    cr_assert_eq(t.nrows, 362);
    mech_table before = t, after = t;
    before.nrows = 181;  /* 0 .. 179.5 deg */
    after.values = t.values + (size_t)181 * (size_t)t.ncolumns;
    after.nrows = 181;
    fourbar open = CHANGE, crossed = CHANGE;
    crossed.sign = -1;
    double e1 = fourbar_worst(&before, &open, PI, 10 * DEG);
    double e2 = fourbar_worst(&after, &crossed, PI, 10 * DEG);
    note("change point, first-only branch: %d rows; before 180 deg on the open assembly %.2g, "
         "after on the crossed %.2g", t.nrows, e1, e2);
    cr_assert(e1 <= 1e-10 && e2 <= 1e-10, "off the smooth branch: %.3g, %.3g", e1, e2);
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* ---- limits named as an engineer names them (issue 17, item 2) --------- */

static int any_message(const mech_diag *d, const char *text)
{
    for (size_t i = 0; i < d->count; i++)
        if (strstr(d->entries[i].message, text))
            return 1;
    return 0;
}

/* |CA| = b + c: coupler and rocker extended in line; |CA| = b - c: folded;
 * the piston's dead centre: crank and rod in line. The limit's value to the
 * digits reached (109.4712206 deg: the closed form is 109.47122063449). */
Test(partial, limits_named)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = sweep("tests/hard/non-grashof-crank.yaml", 0, TWO_PI, 360, 0, MECH_ESOLVE, &d);
    cr_assert(any_message(&d, "(limit positions; at 109.4712206 deg, coupler and rocker "
                              "extended in line)"), "%s", d.entries[0].message);
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_diag_init(&d);
    t = sweep("tests/hard/non-grashof-two-intervals.yaml", 0, TWO_PI, 360, 0, MECH_ESOLVE, &d);
    cr_assert(any_message(&d, "at 125.0996322 deg, coupler and rocker extended in line"));
    cr_assert(any_message(&d, "at 308.6821875 deg, coupler and rocker folded in line"));
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_diag_init(&d);
    t = sweep("tests/hard/dead-centre-slider.yaml", 0.100, 0.140, 40, 0, MECH_ESOLVE, &d);
    cr_assert(any_message(&d, "a dead point, toggle or limit position (crank and rod extended "
                              "in line: dead centre of the slider)"), "%s", d.entries[0].message);
    mech_table_free(&t);
    mech_diag_free(&d);
}

/* The redundancy report names the equation with the largest component of
 * the left null vector w of J (w^T J = 0). By hand, with the coupler at 0
 * and both cranks at q (b = 100, c = 40 mm): the rows of J over (coupler,
 * rocker, extra) are loop 1 (B-C-O-A-B) x: [0, c sin q, 0], y: [b, -c cos q,
 * 0]; loop 2 (F-E-O-A-F) x: [0, 0, c sin q], y: [b/2, 0, -c cos q]; so
 * w = (cot q, 1, -2 cot q, -2): at 30 deg the largest is loop 2's x
 * equation (3.46), at 70 deg loop 2's y equation (2). */
Test(partial, redundancy_names_largest_left_null_component)
{
    static const double qs[] = {30, 70};
    for (int k = 0; k < 2; k++) {
        double q = qs[k] * DEG, w[4] = {1 / tan(q), 1, -2 / tan(q), -2};
        int big = 0;
        for (int i = 1; i < 4; i++)
            if (fabs(w[i]) > fabs(w[big]))
                big = i;
        static const char *const eq[4] = {"x equation of loop 1 (B-C-O-A-B)",
                                          "y equation of loop 1 (B-C-O-A-B)",
                                          "x equation of loop 2 (F-E-O-A-F)",
                                          "y equation of loop 2 (F-E-O-A-F)"};
        char text[1024], want[128];
        snprintf(text, sizeof text,
                 "name: redundant parallelogram\n"
                 "units: {length: mm, angle: deg}\n"
                 "ground: {O: [0, 0], E: [50, 0], C: [100, 0]}\n"
                 "links:\n"
                 "  crank:   {points: {O: [0, 0], A: [40, 0]}}\n"
                 "  coupler: {points: {A: [0, 0], B: [100, 0], F: [50, 0]}}\n"
                 "  rocker:  {points: {C: [0, 0], B: [40, 0]}}\n"
                 "  extra:   {points: {E: [0, 0], F: [40, 0]}}\n"
                 "driver: {link: crank, angle: {from: %g, to: %g, steps: 1}}\n"
                 "initial: {coupler: 1, rocker: %g, extra: %g}\n", qs[k], qs[k] + 1, qs[k] + 2,
                 qs[k] - 2);
        snprintf(want, sizeof want, "implied by the others: the %s;", eq[big]);
        mech_model *m = load_text(text);
        mech_solve_options o;
        mech_solve_options_default(&o);
        mech_diag d;
        mech_diag_init(&d);
        mech_table t = {0};
        cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
        note("at %g deg: expected '%s'", qs[k], want);
        cr_assert(any_message(&d, want), "at %g deg no message says '%s': %s", qs[k], want,
                  d.count > 1 ? d.entries[1].message : "");
        mech_table_free(&t);
        mech_diag_free(&d);
        mech_model_free(&m);
    }
}
