/* tests/unit/test_oom.c: out-of-memory paths. The k-th allocation is made to
 * fail (xalloc_fail_countdown, src/internal.h) for k = 1, 2, ... until the
 * operation succeeds: each failure must be reported as "out of memory" at a
 * real place, free what was built (no leak under LeakSanitizer) and touch
 * nothing it freed (AddressSanitizer, make test-san). */
#include <criterion/criterion.h>
#include <string.h>

#include "internal.h"

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
            cr_expect(e->mark.line >= 1 && e->mark.line <= 10 && e->mark.col >= 1 &&
                      e->mark.col <= 50, "allocation %ld: error at %d:%d, outside the text", k,
                      e->mark.line, e->mark.col);
        }
        ytree_free(root);
        mech_diag_free(&d);
    }
    cr_expect_gt(failures, 20, "only %d allocations were tried", failures);
}
