/* tests/unit/test_fail.c: failure kinds as data (mech_fail_kind, issue 27
 * point 6). Each failure the library detects carries its kind in its
 * diagnostic entry and in mech_solve_stats.failure; mech sweep's status
 * column comes from the kinds (fail_variant_status of mech_diag_failure),
 * never from the messages' words. The truths:
 * - a crank far too long (issue 32 point 10): cannot assemble at the first
 *   driver value, residual |AC| - (coupler + rocker) at best (the loop's
 *   least-squares minimum: coupler and rocker stretched toward A), coupler
 *   and rocker named; it used to be a "singular position" whose condition
 *   (0.41) was far above the limit;
 * - each kind of failure on a mechanism built to have it (dead point,
 *   change point, no assembly, branch, self-locking friction, overflow,
 *   redundant constraints, invalid file, missing file);
 * - the status of a solve whose messages are reworded is unchanged. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "helpers.h"

/* The crank-rocker of mechanisms/fourbar.yaml (coupler 60 mm, rocker 50
 * mm, ground pivots 70 mm apart) with a crank of `crank` mm and no
 * guesses. */
static const char *long_crank(double crank, char *buf, size_t size)
{
    snprintf(buf, size,
             "name: long crank\n"
             "units: {length: mm, angle: deg}\n"
             "ground: {O: [0, 0], C: [70, 0]}\n"
             "links:\n"
             "  crank: {points: {O: [0, 0], A: [%g, 0]}}\n"
             "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
             "  rocker: {points: {C: [0, 0], B: [50, 0]}}\n"
             "driver:\n"
             "  link: crank\n"
             "  angle: {from: 0, to: 360, steps: 36}\n"
             "outputs: {points: [B]}\n", crank);
    return buf;
}

/* Solve a model given as text (or a file when text is NULL); the status. */
static int solve_it(const char *text, const char *path, mech_table *t, mech_solve_stats *st,
                    mech_diag *d)
{
    mech_model *m = test_load(text, path);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = 0;  /* as the file says */
    int rc = mech_solve(m, &o, t, st, d);
    mech_model_free(&m);
    return rc;
}

static size_t count_errors(const mech_diag *d)
{
    size_t n = 0;
    for (size_t i = 0; i < d->count; i++)
        n += d->entries[i].severity == MECH_SEV_ERROR;
    return n;
}

static const mech_diag_entry *first_error(const mech_diag *d)
{
    for (size_t i = 0; i < d->count; i++)
        if (d->entries[i].severity == MECH_SEV_ERROR)
            return &d->entries[i];
    return NULL;
}

/* An entry of the given severity and kind, or NULL. */
static const mech_diag_entry *entry_of(const mech_diag *d, mech_severity sev, mech_fail_kind k)
{
    for (size_t i = 0; i < d->count; i++)
        if (d->entries[i].severity == sev && d->entries[i].kind == k)
            return &d->entries[i];
    return NULL;
}

/* mech sweep's status word of a variant whose messages are d. */
static const char *status_word(const mech_diag *d)
{
    return mech_variant_status_name(fail_variant_status(mech_diag_failure(d)));
}

Test(fail, crank_far_too_long_cannot_assemble)
{
    static const double cranks[] = {200.0, 300.0, 1000.0};  /* mm */
    for (size_t k = 0; k < COUNT_OF(cranks); k++) {
        char text[1024];
        mech_diag d;
        mech_diag_init(&d);
        mech_table t = {0};
        mech_solve_stats st;
        int rc = solve_it(long_crank(cranks[k], text, sizeof text), NULL, &t, &st, &d);
        cr_assert_eq(rc, MECH_ESOLVE, "crank %g mm: status %d", cranks[k], rc);
        cr_expect_eq(t.nrows, 0);
        cr_assert_eq(count_errors(&d), 1, "crank %g mm: %zu errors", cranks[k], count_errors(&d));
        const mech_diag_entry *e = first_error(&d);
        cr_expect_eq(e->kind, MECH_FAIL_NO_ASSEMBLY, "crank %g mm: kind %s: %s", cranks[k],
                     mech_fail_name(e->kind), e->message);
        cr_expect(strstr(e->message, "cannot assemble at driver angle = 0 deg: loop 1 ("),
                  "%s", e->message);
        cr_expect(strstr(e->message, "where coupler and rocker are at the limit of their reach"),
                  "the links that cannot reach are not named: %s", e->message);
        cr_expect(!strstr(e->message, "singular"), "%s", e->message);
        /* the loop cannot close by less than |AC| - 110 mm (A at (crank, 0), C
           at (70, 0)); the starts stop where coupler and rocker are parallel
           (J singular), near that least-squares minimum (3 digits printed) */
        const char *r = strstr(e->message, "residual ");
        double resid = r ? strtod(r + 9, NULL) : NAN, truth = (cranks[k] - 70.0 - 110.0) * 1e-3;
        cr_expect(resid >= 0.995 * truth && resid <= 1.2 * truth,
                  "crank %g mm: residual %g m, the gap is %g m", cranks[k], resid, truth);
        cr_expect_eq(st.failure, MECH_FAIL_NO_ASSEMBLY, "stats: %s", mech_fail_name(st.failure));
        cr_expect_eq(st.failure_q, 0.0);
        cr_assert_eq(t.ngaps, 1);
        cr_expect_eq(t.gaps[0].kind, MECH_GAP_NO_ASSEMBLY, "gap kind %d", t.gaps[0].kind);
        cr_expect_eq(t.gaps[0].first_row, 0);
        cr_expect_eq(t.gaps[0].last_row, 36);
        mech_table_free(&t);
        mech_diag_free(&d);
    }
}

/* One file per kind: the kind of its first error (or of a warning), and
 * the solve statistics' failure. */
typedef struct kind_case {
    const char *path;
    mech_fail_kind kind;         /* of the first error, or of a warning when ok */
    int status;                  /* mech_solve's */
    mech_fail_kind failure;      /* mech_solve_stats.failure */
} kind_case;

Test(fail, each_failure_has_its_kind)
{
    static const kind_case cases[] = {
        {"tests/solve/non-grashof.yaml", MECH_FAIL_NO_ASSEMBLY, MECH_ESOLVE,
         MECH_FAIL_NO_ASSEMBLY},
        {"tests/solve/dead-centre.yaml", MECH_FAIL_DEAD_POINT, MECH_ESOLVE, MECH_FAIL_DEAD_POINT},
        {"tests/hard/dead-centre-slider.yaml", MECH_FAIL_DEAD_POINT, MECH_ESOLVE,
         MECH_FAIL_DEAD_POINT},
        {"tests/hard/change-point.yaml", MECH_FAIL_CHANGE_POINT, MECH_ESOLVE,
         MECH_FAIL_CHANGE_POINT},
        {"tests/hard/change-point-undeclared.yaml", MECH_FAIL_CHANGE_POINT, MECH_OK,
         MECH_FAIL_NONE},
        {"tests/hard/redundant-parallelogram.yaml", MECH_FAIL_REDUNDANT, MECH_OK, MECH_FAIL_NONE},
        {"mechanisms/fourbar.yaml", MECH_FAIL_NONE, MECH_OK, MECH_FAIL_NONE},
    };
    for (size_t k = 0; k < COUNT_OF(cases); k++) {
        const kind_case *c = &cases[k];
        mech_diag d;
        mech_diag_init(&d);
        mech_table t = {0};
        mech_solve_stats st;
        int rc = solve_it(NULL, c->path, &t, &st, &d);
        cr_expect_eq(rc, c->status, "%s: status %d", c->path, rc);
        const mech_diag_entry *e = first_error(&d);
        if (c->status != MECH_OK) {
            cr_assert_not_null(e, "%s: no error", c->path);
            cr_expect_eq(e->kind, c->kind, "%s: kind %s: %s", c->path, mech_fail_name(e->kind),
                         e->message);
        } else if (c->kind != MECH_FAIL_NONE) {
            cr_expect_not_null(entry_of(&d, MECH_SEV_WARNING, c->kind), "%s: no %s warning",
                               c->path, mech_fail_name(c->kind));
        }
        cr_expect_eq(st.failure, c->failure, "%s: stats.failure %s", c->path,
                     mech_fail_name(st.failure));
        cr_expect_eq(mech_diag_failure(&d), c->failure, "%s", c->path);
        cr_expect(c->failure == MECH_FAIL_NONE ? isnan(st.failure_q) : isfinite(st.failure_q),
                  "%s: failure_q %g", c->path, st.failure_q);
        mech_table_free(&t);
        mech_diag_free(&d);
    }
}

/* The slider-crank of mechanisms/slider-crank.yaml with a piston of 1 kg
 * and slider friction mu: with mu = 10 the friction's fixed point does not
 * converge (self-locking), with a driver speed of 1e160 rad/s the rates
 * overflow. */
static const char *slider_crank(double mu, const char *speed, char *buf, size_t size)
{
    snprintf(buf, size,
             "name: slider-crank\n"
             "units: {length: mm, angle: deg}\n"
             "ground: {O: [0, 0]}\n"
             "links:\n"
             "  crank: {points: {O: [0, 0], A: [40, 0]}}\n"
             "  rod: {points: {A: [0, 0], B: [140, 0]}}\n"
             "  piston: {points: {B: [0, 0]}, mass: 1 kg, center: [0, 0], inertia: 1e-4 kg*m^2}\n"
             "joints:\n"
             "  - {slider: B, link: piston, on: ground, through: O, angle: 0 deg, name: x_B,"
             " friction: %g}\n"
             "driver: {link: crank, angle: {from: 0, to: 360, steps: 72}, speed: %s}\n"
             "initial: {rod: -10, x_B: 180}\n"
             "outputs: {points: [B], forces: true}\n", mu, speed);
    return buf;
}

Test(fail, friction_and_overflow_stop_the_sweep_with_their_kinds)
{
    char text[1024];
    struct {
        double mu;
        const char *speed;
        mech_fail_kind kind;
        const char *status;
    } cases[] = {{10.0, "3000 rpm", MECH_FAIL_NOT_CONVERGED, "self-locking"},
                 {0.0, "1e160 rad/s", MECH_FAIL_NON_FINITE, "non-finite"}};
    for (size_t k = 0; k < COUNT_OF(cases); k++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_table t = {0};
        mech_solve_stats st;
        int rc = solve_it(slider_crank(cases[k].mu, cases[k].speed, text, sizeof text), NULL, &t,
                          &st, &d);
        cr_expect_eq(rc, MECH_ESOLVE);
        const mech_diag_entry *e = first_error(&d);
        cr_assert_not_null(e);
        cr_expect_eq(e->kind, cases[k].kind, "kind %s: %s", mech_fail_name(e->kind), e->message);
        cr_expect_eq(st.failure, cases[k].kind, "stats %s", mech_fail_name(st.failure));
        /* the row that failed is the first not in the table */
        double step = 5.0 * 3.14159265358979323846 / 180.0;
        cr_expect(fabs(st.failure_q - t.nrows * step) < 1e-9, "failure at %g, %d rows",
                  st.failure_q, t.nrows);
        cr_expect_str_eq(status_word(&d), cases[k].status);
        mech_table_free(&t);
        mech_diag_free(&d);
    }
}

Test(fail, not_on_the_declared_branch)
{
    /* the crank-rocker with a crank of 120 mm, from the guesses, assembles at
       0 deg with A-B-C turning counter-clockwise, not as declared */
    char text[1200], *at;
    long_crank(120.0, text, sizeof text - 100);
    at = text + strlen(text);
    snprintf(at, 100, "initial: {coupler: 40, rocker: 100}\nbranch:\n  - {points: [A, B, C], "
             "turn: cw}\n");
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    mech_solve_stats st;
    cr_expect_eq(solve_it(text, NULL, &t, &st, &d), MECH_ESOLVE);
    const mech_diag_entry *e = first_error(&d);
    cr_assert_not_null(e);
    cr_expect_eq(e->kind, MECH_FAIL_BRANCH, "kind %s: %s", mech_fail_name(e->kind), e->message);
    cr_expect_eq(t.gaps[0].kind, MECH_GAP_BRANCH);
    mech_table_free(&t);
    mech_diag_free(&d);
}

Test(fail, input_and_io_errors)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    const char *bad = "name: x\nground: {O: [0, 0]\n";
    cr_expect_eq(mech_load_string(bad, strlen(bad), "bad.yaml", &m, &d), MECH_EINPUT);
    cr_assert(d.count >= 1);
    cr_expect_eq(d.entries[0].kind, MECH_FAIL_INPUT, "%s", mech_fail_name(d.entries[0].kind));
    cr_expect_eq(mech_diag_failure(&d), MECH_FAIL_INPUT);
    mech_diag_free(&d);
    cr_expect_eq(mech_load_file("tests/no-such-file.yaml", &m, &d), MECH_EIO);
    cr_assert(d.count >= 1);
    cr_expect_eq(d.entries[0].kind, MECH_FAIL_IO, "%s", mech_fail_name(d.entries[0].kind));
    mech_diag_free(&d);
    mech_table t = {0};
    cr_expect_eq(mech_table_write_csv(&t, "/no-such-dir/x.csv", &d), MECH_EIO);
    cr_expect_eq(mech_diag_failure(&d), MECH_FAIL_IO);
    mech_diag_free(&d);
}

/* The status comes from the kinds: a message that says "singular" or
 * "friction does not converge" in words changes nothing, and a solve whose
 * messages are all reworded keeps its status. */
Test(fail, sweep_status_from_kinds_not_words)
{
    mech_diag d;
    mech_diag_init(&d);
    cr_expect_str_eq(status_word(&d), "ok");
    diag_add(&d, MECH_SEV_WARNING, MECH_FAIL_REDUNDANT, "f", (mech_mark){0, 0},
             "singular, redundant");
    cr_expect_eq(mech_diag_failure(&d), MECH_FAIL_NONE, "a warning is not a failure");
    diag_fail(&d, MECH_FAIL_NO_ASSEMBLY, "f", (mech_mark){0, 0},
              "a singular position: joint friction does not converge");
    cr_expect_str_eq(status_word(&d), "no-assembly");
    diag_fail(&d, MECH_FAIL_DEAD_POINT, "f", (mech_mark){0, 0}, "cannot assemble");
    cr_expect_str_eq(status_word(&d), "singular");
    diag_fail(&d, MECH_FAIL_NO_ASSEMBLY, "f", (mech_mark){0, 0}, "later");
    cr_expect_eq(mech_diag_failure(&d), MECH_FAIL_DEAD_POINT, "singular is graver");
    diag_fail(&d, MECH_FAIL_NOT_CONVERGED, "f", (mech_mark){0, 0}, "words");
    cr_expect_str_eq(status_word(&d), "self-locking");
    mech_diag_free(&d);

    /* a real solve, its messages reworded */
    mech_table t = {0};
    mech_solve_stats st;
    cr_expect_eq(solve_it(NULL, "tests/solve/dead-centre.yaml", &t, &st, &d), MECH_ESOLVE);
    const char *before = status_word(&d);
    cr_expect_str_eq(before, "singular");
    for (size_t i = 0; i < d.count; i++) {
        free(d.entries[i].message);
        d.entries[i].message = xstrdup("reworded: cannot assemble");
    }
    cr_expect_str_eq(status_word(&d), before);
    mech_table_free(&t);
    mech_diag_free(&d);
}

Test(fail, names_and_words_of_the_kinds)
{
    static const char *const names[] = {"none", "input", "io", "no-memory", "no-assembly",
                                        "dead-point", "change-point", "branch", "jump",
                                        "redundant", "not-converged", "non-finite",
                                        "far-from-guess", "on-ground-point", "still-slider",
                                        "folded-loop", "still-outputs"};
    for (int k = 0; k < (int)COUNT_OF(names); k++)
        cr_expect_str_eq(mech_fail_name((mech_fail_kind)k), names[k]);
    cr_expect_str_eq(mech_fail_name((mech_fail_kind)COUNT_OF(names)), "unknown");
    cr_expect_str_eq(mech_fail_name((mech_fail_kind)-1), "unknown");
    cr_expect_eq(fail_kind_status(MECH_FAIL_NOMEM), MECH_ENOMEM);
    cr_expect_eq(fail_kind_status(MECH_FAIL_IO), MECH_EIO);
    cr_expect_eq(fail_kind_status(MECH_FAIL_INPUT), MECH_EINPUT);
    cr_expect_eq(fail_kind_status(MECH_FAIL_JUMP), MECH_ESOLVE);
    for (int k = 0; k < (int)COUNT_OF(names); k++)  /* the kinds --strict makes errors */
        cr_expect_eq(fail_is_suspect_assembly((mech_fail_kind)k),
                     k >= MECH_FAIL_FAR_FROM_GUESS && k <= MECH_FAIL_STILL_OUTPUTS);
    mech_diag d;
    mech_diag_init(&d);
    cr_expect_eq(diag_nomem(&d, "f", (mech_mark){2, 3}), MECH_ENOMEM);
    cr_expect_str_eq(d.entries[0].message, "out of memory");
    cr_expect_eq(d.entries[0].kind, MECH_FAIL_NOMEM);
    mech_diag copy;
    mech_diag_init(&copy);
    diag_copy(&copy, &d.entries[0]);
    cr_expect_eq(copy.entries[0].kind, MECH_FAIL_NOMEM);
    cr_expect_eq(copy.entries[0].severity, MECH_SEV_ERROR);
    cr_expect_eq(copy.entries[0].mark.line, 2);
    mech_diag_free(&copy);
    mech_diag_free(&d);
}
