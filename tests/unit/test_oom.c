/* tests/unit/test_oom.c: out-of-memory paths. The k-th allocation is made to
 * fail (xalloc_fail_countdown, src/base/base.h) for k = 1, 2, ... until the
 * operation succeeds: each failure must be reported as "out of memory" at a
 * real place, free what was built (no leak under LeakSanitizer) and touch
 * nothing it freed (AddressSanitizer, make test-san). */
#include <criterion/criterion.h>
#include <string.h>

#include "base.h"

/* Scalars, flow and block collections, nesting, and a repeated key (the
 * duplicate-key map of a closed mapping allocates too). */
static const char yaml_text[] =
    "name: oom\n"
    "ground: {O: [0, 0], C: [70, 0]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [20, 0]}}\n"
    "  rocker:\n"
    "    points:\n"
    "      - [1, 2]\n"
    "      - {x: 3}\n"
    "  crank: 2\n";

Test(oom, yaml_tree_reports_every_failed_allocation)
{
    int failures = 0;
    for (long k = 1; k < 100000; k++) {
        mech_diag d;
        mech_diag_init(&d);
        xalloc_fail_countdown = k;
        ynode *root = ytree_parse(yaml_text, strlen(yaml_text), "oom.yaml", NULL, &d);
        int failed = xalloc_fail_countdown == 0;  /* allocation k happened, and failed */
        xalloc_fail_countdown = 0;
        if (!failed) {  /* fewer than k allocations: the whole tree, no error */
            cr_expect_not_null(root);
            cr_expect_eq(d.nerrors, 0);
            ytree_free(root);
            mech_diag_free(&d);
            break;
        }
        failures++;
        cr_expect_null(root, "allocation %ld failed, yet a tree was returned", k);
        cr_expect_eq(d.nerrors, 1, "allocation %ld failed: %zu errors", k, d.nerrors);
        if (d.nerrors >= 1) {
            const mech_diag_entry *e = &d.entries[0];
            cr_expect(strstr(e->message, "out of memory"), "allocation %ld: '%s'", k, e->message);
            cr_expect_eq(e->kind, MECH_FAIL_NOMEM, "allocation %ld: kind %s", k,
                         mech_fail_name(e->kind));
            cr_expect(e->mark.line >= 1 && e->mark.line <= 10 && e->mark.col >= 1 &&
                      e->mark.col <= 50, "allocation %ld: error at %d:%d, outside the text", k,
                      e->mark.line, e->mark.col);
        }
        ytree_free(root);
        mech_diag_free(&d);
    }
    cr_expect_gt(failures, 20, "only %d allocations were tried", failures);
}

/* The whole way from text to a solved table (load, check, analysis, sweep
 * with forces): an allocation that fails is reported as out of memory,
 * with that kind, and the call fails with MECH_ENOMEM (never as an
 * invalid file or a mechanism that cannot be solved). */
static const char fourbar_text[] =
    "name: oom four-bar\n"
    "units: {length: mm, angle: deg}\n"
    "parameters: {r: 20 mm}\n"
    "ground: {O: [0, 0], C: [70, 0]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [r, 0]}, mass: 0.05 kg, center: [10, 0], inertia: 2e-6}\n"
    "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
    "  rocker: {points: {C: [0, 0], B: [50, 0]}}\n"
    "driver: {link: crank, angle: {from: 0, to: 30, steps: 3}, speed: 10 rad/s}\n"
    "initial: {coupler: 40, rocker: 100}\n"
    "outputs: {points: [B], links: [rocker], forces: true}\n"
    "loads:\n"
    "  - {force: [\"-0.5 N*s/m * B.vx\", 0 N], at: B, link: rocker}\n";

/* fourbar_text (text NULL: the file path, laws of time) */
static void solve_every_allocation_failing(const char *text, const char *path)
{
    int failures = 0;
    for (long k = 1; k < 100000; k++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_table t = {0};
        mech_summary sum;
        mech_solve_stats st;
        xalloc_fail_countdown = k;
        int rc = text ? mech_load_string(text, strlen(text), "oom.yaml", &m, &d)
                      : mech_load_file(path, &m, &d);
        if (rc == MECH_OK)
            rc = mech_check(m, &sum, &d);
        if (rc == MECH_OK) {
            mech_solve_options o;
            mech_solve_options_default(&o);
            rc = mech_solve(m, &o, &t, &st, &d);
        }
        int failed = xalloc_fail_countdown == 0;
        xalloc_fail_countdown = 0;
        mech_table_free(&t);
        mech_model_free(&m);
        if (!failed) {
            cr_expect_eq(rc, MECH_OK, "no allocation failed, yet status %d", rc);
            mech_diag_free(&d);
            break;
        }
        if (rc != MECH_OK) {  /* some failures are survived (a diagnostic's own copy) */
            failures++;
            cr_expect_eq(rc, MECH_ENOMEM, "allocation %ld failed: status %d", k, rc);
            cr_expect_eq(mech_diag_failure(&d), MECH_FAIL_NOMEM, "allocation %ld: kind %s: %s", k,
                         mech_fail_name(mech_diag_failure(&d)),
                         d.count ? d.entries[0].message : "(no message)");
        }
        mech_diag_free(&d);
    }
    cr_expect_gt(failures, 50, "only %d allocations failed the solve", failures);
}

Test(oom, solve_reports_out_of_memory_with_its_kind)
{
    solve_every_allocation_failing(fourbar_text, NULL);  /* with a load of the motion */
    solve_every_allocation_failing(NULL, "mechanisms/five-bar.yaml");  /* laws of time */
}
