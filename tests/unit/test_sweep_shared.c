/* tests/unit/test_sweep_shared.c: one analysis per sweep (variant_regs.c).
 * Every variant solved through the sweep's shared analysis
 * (sweep_variant_solve) against the same parameters loaded and solved on
 * their own (mech_load_file_with + mech_check + mech_solve, i.e. `mech
 * solve --set`): every column of every row to 1e-12 of the column's size;
 * and that the variants did go through the shared analysis (or were
 * re-analysed when their structure changes); every parameter of every file
 * in mechanisms/ likewise. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdarg.h>
#include <glob.h>
#include <sys/wait.h>
#include <unistd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"
#include "study.h"

static void note_hard(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void note_hard(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    note_tagged("sweep_shared", fmt, ap);
    va_end(ap);
}

/* A four-bar with its dimensions as parameters, masses and a polar coupler
 * point (its angle stays 30 deg when p changes: a folded number that must
 * stay equal), and a slider guide angle as a parameter (alpha: folded). */
static const char FOURBAR[] =
    "name: parametric four-bar\n"
    "units: {length: mm, angle: deg}\n"
    "parameters:\n"
    "  a: 20 mm\n  b: 60 mm\n  c: 50 mm\n  d: 70 mm\n  p: 40 mm\n  m2: 0.1 kg\n"
    "ground: {O: [0, 0], C: [d, 0]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [a, 0]}, mass: 0.05 kg, center: [10, 0],"
    " inertia: 2e-6 kg*m^2}\n"
    "  coupler:\n"
    "    points: {A: [0, 0], B: [b, 0], P: {length: p, angle: 30}}\n"
    "    mass: m2\n    center: [b/2, 5]\n    inertia: 3e-5 kg*m^2\n"
    "  rocker: {points: {C: [0, 0], B: [c, 0]}, mass: 0.08 kg, center: [c/2, 0],"
    " inertia: 2e-5 kg*m^2}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 72}, speed: 10 rad/s}\n"
    "initial: {coupler: 40, rocker: 100}\n"
    "branch:\n  - {points: [A, B, C], turn: cw}\n"
    "outputs: {points: [A, B, P], links: [crank, coupler, rocker], forces: true}\n";

static const char *write_temp(const char *text)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/mech-test-shared-%d.yaml", (int)getpid());
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f);
    fputs(text, f);
    fclose(f);
    return path;
}

/* The largest difference of the two tables, relative to each column's
 * largest magnitude (the columns of the reference); rows must match. The
 * power balance's residual (already relative, rounding noise of 1e-14) is
 * compared absolutely. */
static double table_difference(const mech_table *got, const mech_table *want)
{
    cr_assert_eq(got->nrows, want->nrows, "rows %d, alone %d", got->nrows, want->nrows);
    cr_assert_eq(got->ncolumns, want->ncolumns);
    double worst = 0.0;
    for (int c = 0; c < want->ncolumns; c++) {
        double scale = 0.0;
        for (int i = 0; i < want->nrows; i++)
            scale = fmax(scale, fabs(mech_table_get(want, i, c)));
        if (ends_with(want->columns[c].name, ".residual"))
            scale = 1.0;
        for (int i = 0; i < want->nrows; i++) {
            double e = fabs(mech_table_get(got, i, c) - mech_table_get(want, i, c));
            double rel = scale > 0.0 ? e / scale : e;
            if (rel > worst) {
                worst = rel;
                if (rel > 1e-12 && getenv("MECH_HARD_VERBOSE"))
                    fprintf(stderr, "column %s row %d: %.17g, alone %.17g\n",
                            want->columns[c].name, i, mech_table_get(got, i, c),
                            mech_table_get(want, i, c));
            }
        }
    }
    return worst;
}

/* Each variant (texts[k][i] for parameter names[k], nvar variants) solved
 * both ways; returns the largest relative difference over all variants. */
static double compare_variants(sweep_shared *sh, const char *file, const char *const *names,
                               int nnames, const char *const *texts, int nvar, int with_forces)
{
    double worst = 0.0;
    for (int v = 0; v < nvar; v++) {
        mech_override ov[8];
        for (int k = 0; k < nnames; k++)
            ov[k] = (mech_override){names[k], texts[v * nnames + k]};
        mech_diag d;
        mech_diag_init(&d);
        mech_table shared = {0}, alone = {0};
        int rc1 = sweep_variant_solve(sh, ov, nnames, &shared, NULL, &d);
        mech_model *m = NULL;
        mech_summary s;
        int rc2 = mech_load_file_with(file, ov, nnames, &m, &d);
        if (rc2 == MECH_OK)
            rc2 = mech_check(m, &s, &d);
        if (rc2 == MECH_OK) {
            mech_solve_options o;
            mech_solve_options_default(&o);
            o.forces = with_forces;
            rc2 = mech_solve(m, &o, &alone, NULL, &d);
        }
        if (rc1 != rc2)
            mech_diag_print(&d, stderr);
        cr_assert_eq(rc1, rc2, "variant %d: status %d through the shared analysis, %d alone",
                     v, rc1, rc2);
        double e = table_difference(&shared, &alone);
        worst = fmax(worst, e);
        cr_expect_leq(e, 1e-12, "variant %d (%s=%s): relative difference %.3g", v, names[0],
                      texts[v * nnames], e);
        mech_table_free(&shared);
        mech_table_free(&alone);
        mech_model_free(&m);
        mech_diag_free(&d);
    }
    return worst;
}

Test(sweep_shared, conveyor_every_variant_as_solved_alone)
{
    static const char *const names[] = {"l1", "l2", "a"};
    enum { NV = 24 };
    static char buf[NV][3][32];
    const char *texts[NV * 3];
    for (int v = 0; v < NV; v++) {
        snprintf(buf[v][0], 32, "%.10g mm", 50.0 + 14.0 * (v % 6) / 5.0);
        snprintf(buf[v][1], 32, "%.10g mm", 420.0 + 5.0 * (v / 6));
        snprintf(buf[v][2], 32, "%.10g mm", 45.0 + v % 4);
        for (int k = 0; k < 3; k++)
            texts[v * 3 + k] = buf[v][k];
    }
    sweep_shared *sh = sweep_shared_new("mechanisms/conveyor.yaml", 1);
    double e = compare_variants(sh, "mechanisms/conveyor.yaml", names, 3, texts, NV, 1);
    long shared, alone;
    sweep_variant_counts(sh, &shared, &alone);
    sweep_shared_free(&sh);
    cr_assert_eq(shared, NV, "%ld of %d variants through the shared analysis (%ld alone)",
                 shared, NV, alone);
    note_hard("conveyor: %d variants, largest relative difference %.3g", NV, e);
}

Test(sweep_shared, offset_slider_crank_every_variant)
{
    static const char *const names[] = {"r", "l", "e"};
    static const char *const texts[] = {"40 mm", "120 mm", "30 mm", "35 mm", "110 mm", "0 mm",
                                        "45 mm", "150 mm", "-20 mm", "30.5 mm", "99 mm", "12 mm"};
    sweep_shared *sh = sweep_shared_new("mechanisms/offset-slider-crank.yaml", 0);
    double e = compare_variants(sh, "mechanisms/offset-slider-crank.yaml", names, 3, texts, 4, 0);
    long shared, alone;
    sweep_variant_counts(sh, &shared, &alone);
    sweep_shared_free(&sh);
    /* e = 0 makes the ground vector O -> G of length 0 (its terms vanish from
       the numeric system), e = -20 mm turns its angle from +90 to -90 deg (a
       folded number: its derivative by e is 0): both are analysed alone */
    cr_assert_eq(shared, 2, "%ld through the shared analysis, %ld alone", shared, alone);
    cr_assert_eq(alone, 2, "%ld through the shared analysis, %ld alone", shared, alone);
    note_hard("offset slider-crank: largest relative difference %.3g", e);
}

Test(sweep_shared, fourbar_every_variant_with_forces)
{
    const char *file = write_temp(FOURBAR);
    static const char *const names[] = {"a", "b", "c", "d", "p", "m2"};
    enum { NV = 16 };
    static char buf[NV][6][32];
    const char *texts[NV * 6];
    for (int v = 0; v < NV; v++) {
        snprintf(buf[v][0], 32, "%g mm", 18.0 + (v % 4));
        snprintf(buf[v][1], 32, "%g mm", 58.0 + 2.0 * (v / 4));
        snprintf(buf[v][2], 32, "%g mm", 50.0 + 0.5 * v);
        snprintf(buf[v][3], 32, "%g mm", 70.0 - 0.25 * v);
        snprintf(buf[v][4], 32, "%g mm", 30.0 + 1.5 * v);
        snprintf(buf[v][5], 32, "%g kg", 0.1 + 0.01 * v);
        for (int k = 0; k < 6; k++)
            texts[v * 6 + k] = buf[v][k];
    }
    sweep_shared *sh = sweep_shared_new(file, 1);
    double e = compare_variants(sh, file, names, 6, texts, NV, 1);
    long shared, alone;
    sweep_variant_counts(sh, &shared, &alone);
    sweep_shared_free(&sh);
    remove(file);
    cr_assert_eq(shared, NV, "%ld through the shared analysis, %ld alone", shared, alone);
    note_hard("four-bar: largest relative difference %.3g", e);
}

/* A variant whose structure differs from the base (here: a mass of 0, so
 * "nothing loads" may change; a crank too long to assemble everywhere) is
 * analysed on its own, with the same result as solving it alone. */
Test(sweep_shared, structure_changes_are_reanalysed)
{
    const char *file = write_temp(FOURBAR);
    static const char *const names[] = {"m2", "a"};
    static const char *const texts[] = {"0 kg", "20 mm", "0.2 kg", "20 mm", "0.2 kg", "45 mm"};
    sweep_shared *sh = sweep_shared_new(file, 1);
    compare_variants(sh, file, names, 2, texts, 3, 1);
    long shared, alone;
    sweep_variant_counts(sh, &shared, &alone);
    sweep_shared_free(&sh);
    remove(file);
    cr_assert_eq(shared, 1, "%ld through the shared analysis, %ld alone", shared, alone);
    cr_assert_eq(alone, 2, "%ld through the shared analysis, %ld alone", shared, alone);
}

/* A parameter in a driver's law of time: the system folds the law's
 * numbers, so a variant that changes them is analysed on its own (the
 * shared analysis would keep the base's law), with the result of solving
 * it alone. */
Test(sweep_shared, law_parameter_is_reanalysed)
{
    static const char text[] =
        "name: four-bar with a parameter in its law\n"
        "units: {length: mm, angle: deg}\n"
        "parameters: {w: 10 rad/s}\n"
        "ground: {O: [0, 0], C: [70, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0], P: [30, 15]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
        "initial: {coupler: 60, rocker: 100}\n"
        "sweep: {time: {from: 0 s, to: 0.1 s, steps: 4}}\n"
        "drivers: [{link: crank, angle: \"w * t\"}]\n"
        "outputs: {points: [P]}\n";
    const char *file = write_temp(text);
    static const char *const names[] = {"w"};
    static const char *const texts[] = {"10 rad/s", "20 rad/s"};
    sweep_shared *sh = sweep_shared_new(file, 0);
    compare_variants(sh, file, names, 1, texts, 2, 0);
    long shared, alone;
    sweep_variant_counts(sh, &shared, &alone);
    sweep_shared_free(&sh);
    remove(file);
    cr_assert(shared == 1 && alone == 1, "%ld through the shared analysis, %ld alone", shared,
              alone);
}

/* Every parameter of every mechanism in mechanisms/, at 0.97, 1.01 and 1.03
 * times its value, with forces: the same status and every column to 1e-12.
 * One child process per parameter (one sweep each);
 * its exit status is the number of variants solved through the shared
 * analysis, or 100 for a difference. */
static int parameter_child(const char *file, const mech_param *p)
{
    static const double factor[] = {0.97, 1.01, 1.03};
    sweep_shared *sh = sweep_shared_new(file, 1);
    for (int k = 0; k < 3; k++) {
        char text[64];
        snprintf(text, sizeof text, "%.17g %s", p->value * factor[k], p->unit);
        mech_override ov = {p->name, text};
        mech_diag d;
        mech_diag_init(&d);
        mech_table shared = {0}, alone = {0};
        int rc1 = sweep_variant_solve(sh, &ov, 1, &shared, NULL, &d);
        mech_model *m = NULL;
        mech_summary s;
        int rc2 = mech_load_file_with(file, &ov, 1, &m, &d);
        if (rc2 == MECH_OK)
            rc2 = mech_check(m, &s, &d);
        if (rc2 == MECH_OK) {
            mech_solve_options o;
            mech_solve_options_default(&o);
            o.forces = 1;
            rc2 = mech_solve(m, &o, &alone, NULL, &d);
        }
        int same = rc1 == rc2 && shared.nrows == alone.nrows &&
                   shared.ncolumns == alone.ncolumns;
        double e = same ? table_difference(&shared, &alone) : INFINITY;
        if (!(e <= 1e-12))
            fprintf(stderr, "%s, %s = %s: status %d and %d, difference %.3g\n", file, p->name,
                    text, rc1, rc2, e);
        mech_table_free(&shared);
        mech_table_free(&alone);
        mech_model_free(&m);
        mech_diag_free(&d);
        if (!(e <= 1e-12))
            return 100;
    }
    long shared, alone;
    sweep_variant_counts(sh, &shared, &alone);
    sweep_shared_free(&sh);
    return (int)shared;
}

Test(sweep_shared, every_parameter_of_every_mechanism)
{
    glob_t g;
    cr_assert_eq(glob("mechanisms/*.yaml", 0, NULL, &g), 0);
    int variants = 0, through = 0;
    for (size_t i = 0; i < g.gl_pathc; i++) {
        mech_model *m = load_path(g.gl_pathv[i]);
        for (int k = 0; k < m->nparams; k++) {
            fflush(NULL);
            pid_t pid = fork();
            cr_assert_geq(pid, 0);
            if (pid == 0)
                _exit(parameter_child(g.gl_pathv[i], &m->params[k]));
            int status = 0;
            waitpid(pid, &status, 0);
            cr_assert(WIFEXITED(status) && WEXITSTATUS(status) <= 3,
                      "%s, parameter %s: a variant differs from solving it alone",
                      g.gl_pathv[i], m->params[k].name);
            if (m->state_loads) {  /* loads that depend on the motion: each alone */
                cr_assert_eq(WEXITSTATUS(status), 0, "%s, parameter %s: a variant with loads "
                             "that depend on the motion went through the shared analysis",
                             g.gl_pathv[i], m->params[k].name);
                continue;
            }
            variants += 3;
            through += WEXITSTATUS(status);
        }
        mech_model_free(&m);
    }
    globfree(&g);
    /* the others: a variant that does not assemble, a slider's angle, a
       point moved off its line (docs/batch.md, "One analysis per sweep") */
    cr_assert_geq(through, variants * 8 / 10, "%d of %d variants through the shared analysis",
                  through, variants);
    note_hard("%d variants of every parameter of every mechanism, %d through the shared "
              "analysis", variants, through);
}

/* ---- what the shared analysis folds, and the numbers it takes ------------ */

/* A geared five-bar (docs/format.md section 6.4) with a spring, friction in
 * the pin B, forces, and parameters in the gear pair's phase (ph), the
 * coupler's and the rod's length and the coupler's mass (l), and the
 * driver's speed (w). */
static const char GEARED[] =
    "name: geared five-bar with a spring and friction\n"
    "units: {length: mm, angle: deg}\n"
    "parameters: {l: 60 mm, ph: 90, w: 20 rad/s}\n"
    "ground: {O: [0, 0], C: [60, 0], S: [30, -40]}\n"
    "links:\n"
    "  crank1: {points: {O: [0, 0], A: [15, 0]}, mass: 0.1 kg, center: [0, 0],"
    " inertia: 2e-5 kg*m^2}\n"
    "  crank2: {points: {C: [0, 0], D: [15, 0]}, mass: 0.3 kg, center: [0, 0],"
    " inertia: 2.4e-4 kg*m^2}\n"
    "  coupler: {points: {A: [0, 0], B: [l, 0], P: {length: 30, angle: -30}},"
    " mass: 0.05 kg * l / 60 mm, center: [l/2, 0], inertia: 1.5e-5 kg*m^2}\n"
    "  rod: {points: {D: [0, 0], B: [l, 0]}, mass: 0.05 kg, center: [l/2, 0],"
    " inertia: 1.5e-5 kg*m^2}\n"
    "joints:\n"
    "  - {revolute: B, friction: 0.1, pin_radius: 5 mm}\n"
    "driver: {link: crank1, angle: {from: 0, to: 720, steps: 72}, speed: w}\n"
    "initial: {crank2: 90, coupler: 70, rod: 110}\n"
    "branch:\n  - {points: [A, B, D], turn: cw}\n"
    "gears:\n"
    "  - {name: g12, gear: crank1, with: crank2, teeth: [20, 40], module: 2 mm,"
    " offset: [0, ph]}\n"
    "springs:\n"
    "  - {name: s, between: [P, S], links: [coupler, ground], stiffness: 200 N/m,"
    " free_length: 40 mm}\n"
    "outputs: {points: [A, B, D, P], links: [crank1, crank2, coupler, rod], forces: true}\n";

/* A law of time with a parameter (drivers.c folds it into the driver rows). */
static const char LAWS[] =
    "name: five-bar driven by laws of time\n"
    "units: {length: mm, angle: deg}\n"
    "parameters: {amp: 20 deg}\n"
    "ground: {O: [0, 0], E: [50, 0]}\n"
    "links:\n"
    "  crank1: {points: {O: [0, 0], A: [25, 0]}}\n"
    "  arm1: {points: {A: [0, 0], P: [60, 0]}}\n"
    "  arm2: {points: {B: [0, 0], P: [60, 0]}}\n"
    "  crank2: {points: {E: [0, 0], B: [25, 0]}}\n"
    "initial: {arm1: 60 deg, arm2: 120 deg}\n"
    "branch:\n  - {points: [A, P, B], turn: cw}\n"
    "sweep: {time: {from: 0 s, to: 1 s, steps: 50}}\n"
    "drivers:\n"
    "  - {link: crank1, angle: \"90 deg + 360 deg/s * t\"}\n"
    "  - {link: crank2, angle: \"60 deg + amp * sin(2 * pi * t / 1 s)\"}\n"
    "outputs: {points: [P], links: [arm1, arm2]}\n";

/* A gear pair's phase and a law of time are folded into the system's rows:
 * a variant that changes one is analysed on its own (through the shared
 * analysis it kept the base's numbers and gave the base's table). The first
 * value is the file's own. */
static void reanalysed(const char *text, const char *name, const char *const *values, int with_forces)
{
    const char *file = write_temp(text);
    sweep_shared *sh = sweep_shared_new(file, with_forces);
    compare_variants(sh, file, (const char *const[]){name}, 1, values, 3, with_forces);
    long shared, alone;
    sweep_variant_counts(sh, &shared, &alone);
    sweep_shared_free(&sh);
    cr_assert_eq(alone, 2, "%ld through the shared analysis, %ld alone", shared, alone);
    remove(file);
}

Test(sweep_shared, gear_phases_are_not_folded_from_the_base)
{
    reanalysed(GEARED, "ph", (const char *const[]){"90", "95", "100"}, 1);
}

Test(sweep_shared, laws_of_time_are_not_folded_from_the_base)
{
    reanalysed(LAWS, "amp", (const char *const[]){"20 deg", "10 deg", "30 deg"}, 0);
}

static mech_model *load_with(const char *file, const mech_override *ov, int nov)
{
    mech_model *m = NULL;
    mech_summary s;
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_load_file_with(file, ov, nov, &m, &d);
    if (rc == MECH_OK)
        rc = mech_check(m, &s, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    cr_assert_eq(rc, MECH_OK);
    mech_diag_free(&d);
    return m;
}

/* Structure apart from numbers: a variant solved through a view of the base
 * A's analysis (the base's structure, every number the plans take from a
 * model computed from the variant B by solver_plan_numbers and
 * forces_plan_numbers) gives, bit for bit, the table of B's own analysis
 * with the same leaves (its numbers computed by the same functions at its
 * set-up). A and B differ in a length (lengths and angles that are leaves,
 * the length scale, the link frames' attachment points), a mass (the force
 * plan's model) and the driver's speed (the friction's speed scale): a
 * number a plan took at set-up and the view did not take again would keep
 * A's value and change the table. */
Test(sweep_shared, a_variant_takes_every_number_from_its_model)
{
    const char *file = write_temp(GEARED);
    static const char *const names[] = {"l", "w"};
    mech_override ov[2] = {{"l", "63 mm"}, {"w", "27 rad/s"}};
    mech_model *a = load_with(file, NULL, 0), *b = load_with(file, ov, 2);
    mech_model *bv = load_with(file, ov, 2);
    variant_base *va = NULL, *vb = NULL;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(vbase_new(a, names, 2, 1, &va, &d), MECH_OK);
    cr_assert_eq(vbase_new(b, names, 2, 1, &vb, &d), MECH_OK);
    mech_table through = {0}, own = {0};
    cr_assert_eq(vbase_solve(va, bv, NULL, &through, &d), MECH_OK, "B through A's analysis");
    cr_assert_eq(mech_analysis_solve(vbase_analysis(vb), NULL, 0, &own, NULL, &d), MECH_OK);
    cr_assert_eq(through.nrows, 73);
    cr_assert_eq(through.nrows, own.nrows);
    cr_assert_eq(through.ncolumns, own.ncolumns);
    int friction = mech_table_column(&own, "friction.power");
    cr_assert_geq(friction, 0, "a friction column");
    for (int r = 0; r < own.nrows; r++)
        for (int c = 0; c < own.ncolumns; c++) {
            double x = mech_table_get(&through, r, c), y = mech_table_get(&own, r, c);
            cr_assert(memcmp(&x, &y, sizeof x) == 0, "row %d, %s: %.17g through A's analysis, "
                      "%.17g in B's own", r, own.columns[c].name, x, y);
        }
    /* and B's numbers are not A's: the same row of A differs */
    mech_table ta = {0};
    cr_assert_eq(mech_analysis_solve(vbase_analysis(va), NULL, 0, &ta, NULL, &d), MECH_OK);
    cr_assert_neq(mech_table_get(&ta, 10, friction), mech_table_get(&own, 10, friction));
    mech_table_free(&ta);
    mech_table_free(&through);
    mech_table_free(&own);
    vbase_free(&va);
    vbase_free(&vb);
    mech_model_free(&bv);
    mech_diag_free(&d);
    remove(file);
}
