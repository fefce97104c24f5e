/* tests/unit/test_alloc.c: xcalloc_large (src/base/util.c), the allocation
 * of result tables: zeroed like calloc at every size, 2 MiB aligned from 8
 * MiB up (what the huge-page advice needs), NULL on overflow and under the
 * out-of-memory hook, and released by free() (valgrind and ASan see it). */
#include <criterion/criterion.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"

/* 1 when every byte of the block is 0. */
static int all_zero(const unsigned char *p, size_t bytes)
{
    for (size_t i = 0; i < bytes; i++)
        if (p[i])
            return 0;
    return 1;
}

Test(alloc, large_block_is_zeroed_and_aligned)
{
    size_t n = ((size_t)9 << 20) / sizeof(double) + 3;  /* 9 MiB and a little */
    double *v = xcalloc_large(n, sizeof *v);
    cr_assert_not_null(v);
    cr_assert_eq((uintptr_t)v % ((uintptr_t)2 << 20), 0, "not 2 MiB aligned: %p", (void *)v);
    cr_assert(all_zero((const unsigned char *)v, n * sizeof *v));
    v[0] = 1.0;
    v[n - 1] = 2.0;  /* the whole request is usable */
    cr_assert_eq(v[n - 1], 2.0);
    free(v);
}

Test(alloc, small_block_is_an_ordinary_zeroed_one)
{
    for (size_t n = 0; n < 5000; n = 2 * n + 1) {
        double *v = xcalloc_large(n, sizeof *v);
        cr_assert_not_null(v, "n = %zu", n);
        cr_assert(all_zero((const unsigned char *)v, n * sizeof *v), "n = %zu", n);
        free(v);
    }
}

Test(alloc, overflow_and_failure_give_null)
{
    cr_assert_null(xcalloc_large(SIZE_MAX / 4, 8));
    cr_assert_null(xcalloc_large(SIZE_MAX / 2 + 2, 2));
    xalloc_fail_countdown = 1;
    cr_assert_null(xcalloc_large((size_t)4 << 20, 8), "the out-of-memory hook is ignored");
    cr_assert_eq(xalloc_fail_countdown, 0);
    void *p = xcalloc_large((size_t)4 << 20, 8);  /* the next one succeeds */
    cr_assert_not_null(p);
    free(p);
}
