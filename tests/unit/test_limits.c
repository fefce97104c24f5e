/* tests/unit/test_limits.c: the limits on untrusted input (docs/limits.md)
 * that need files too large for tests/bad/: each is refused with a
 * FILE:LINE:COL message, and a mechanism of 100 000 four-bar loops, the
 * size the limits are chosen to allow, loads, checks and builds its
 * equations in linear time. (Small limit cases are files in tests/bad/.) */
#include <criterion/criterion.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mech.h"

/* A growing text. */
typedef struct buf {
    char *s;
    size_t len, cap;
} buf;

static void add(buf *b, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    cr_assert(n >= 0);
    if (b->len + (size_t)n + 1 > b->cap) {
        b->cap = 2 * (b->len + (size_t)n + 1);
        b->s = realloc(b->s, b->cap);
        cr_assert_not_null(b->s, "out of memory");
    }
    va_start(ap, fmt);
    vsnprintf(b->s + b->len, (size_t)n + 1, fmt, ap);
    va_end(ap);
    b->len += (size_t)n;
}

static const char FOURBAR_HEAD[] =
    "name: limits\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0], C: [70, 0]}\n"
    "links:\n"
    "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
    "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 4}}\n";

/* Load text that must fail; the first error must be `want` at line:col. */
static void expect_refused(const buf *b, int line, int col, const char *want)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    int rc = mech_load_string(b->s, b->len, "big.yaml", &m, &d);
    cr_assert_eq(rc, MECH_EINPUT, "the file must be refused");
    cr_assert_null(m);
    cr_assert_geq(d.count, 1);
    cr_expect_eq(d.entries[0].mark.line, line, "line %d, want %d: %s", d.entries[0].mark.line,
                 line, d.entries[0].message);
    cr_expect_eq(d.entries[0].mark.col, col, "column %d, want %d", d.entries[0].mark.col, col);
    cr_expect_str_eq(d.entries[0].message, want);
    mech_diag_free(&d);
}

Test(limits, file_larger_than_32_mib)
{
    buf b = {0};
    b.len = (32u << 20) + 1;
    b.s = malloc(b.len);
    cr_assert_not_null(b.s);
    memset(b.s, ' ', b.len);
    expect_refused(&b, 0, 0, "file too large (33554433 bytes; at most 33554432)");
    free(b.s);
}

Test(limits, too_many_parameters)
{
    buf b = {0};
    add(&b, "%sparameters:\n", FOURBAR_HEAD);
    for (int i = 0; i <= 100000; i++)
        add(&b, "  p%d: %d\n", i, i);
    expect_refused(&b, 10, 3, "too many parameters (100001; at most 100000)");
    free(b.s);
}

/* 100 000 parameters, each defined from the one before: name lookups are
 * hashed, so this is linear (it was quadratic). */
Test(limits, many_parameters_load)
{
    buf b = {0};
    add(&b, "%sparameters:\n  p0: 1 mm\n", FOURBAR_HEAD);
    for (int i = 1; i < 100000; i++)
        add(&b, "  p%d: p%d + 1 mm\n", i, i - 1);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    cr_assert_eq(mech_load_string(b.s, b.len, "params.yaml", &m, &d), MECH_OK);
    cr_assert_eq(m->nparams, 100000);
    cr_expect_float_eq(m->params[99999].value, 100.0, 1e-9, "100 000 mm = 100 m");
    mech_model_free(&m);
    mech_diag_free(&d);
    free(b.s);
}

Test(limits, too_many_points_on_a_moving_link)
{
    buf b = {0};
    add(&b, "name: limits\nground: {O: [0, 0]}\nlinks:\n  crank:\n    points:\n");
    for (int i = 0; i <= 10000; i++)
        add(&b, "      P%d: [%d, 0]\n", i, i);
    add(&b, "driver: {link: crank, angle: 0}\n");
    expect_refused(&b, 6, 7, "link 'crank' has 10001 points; at most 10000");
    free(b.s);
}

Test(limits, too_many_loops_listed)
{
    buf b = {0};
    add(&b, "%sloops:\n", FOURBAR_HEAD);
    for (int i = 0; i <= 1000; i++)
        add(&b, "  - [O, A, B, C, O]\n");
    expect_refused(&b, 10, 3, "too many loops listed (1001; at most 1000); leave 'loops' out "
                              "and they are found automatically");
    free(b.s);
}

/* A chain of n four-bars: crank, then coupler_i and rocker_i pivoted at the
 * ground point C_i; each rocker carries the next coupler's pin. */
static void fourbar_chain(buf *b, int n)
{
    add(b, "name: chain\nunits: {length: mm, angle: deg}\nground:\n  O: [0, 0]\n");
    for (int i = 0; i < n; i++)
        add(b, "  C%d: [%d, 0]\n", i, 70 + 100 * i);
    add(b, "links:\n  crank: {points: {O: [0, 0], A0: [20, 0]}}\n");
    for (int i = 0; i < n; i++) {
        add(b, "  coupler%d: {points: {A%d: [0, 0], B%d: [60, 0]}}\n", i, i, i);
        if (i + 1 < n)
            add(b, "  rocker%d: {points: {C%d: [0, 0], B%d: [50, 0], A%d: [-20, 0]}}\n", i, i,
                i, i + 1);
        else
            add(b, "  rocker%d: {points: {C%d: [0, 0], B%d: [50, 0]}}\n", i, i, i);
    }
    add(b, "driver: {link: crank, angle: {from: 0, to: 30, steps: 2}}\n");
}

/* The size the limits are chosen to allow (100 001 ground points, 200 001
 * moving links): loads, checks and builds its equations, in linear time. */
static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* (No Criterion .timeout: with several, its runner leaks under LeakSanitizer.
 * A quadratic step would take hours here; the bound below catches it.) */
Test(limits, chain_of_100000_fourbars)
{
    double t0 = now();
    buf b = {0};
    fourbar_chain(&b, 100000);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    cr_assert_eq(mech_load_string(b.s, b.len, "chain.yaml", &m, &d), MECH_OK, "%s",
                 d.count ? d.entries[0].message : "");
    free(b.s);
    mech_summary s;
    cr_assert_eq(mech_check(m, &s, &d), MECH_OK);
    cr_expect_eq(s.nlinks, 200002);
    cr_expect_eq(s.nloops, 100000);
    cr_expect_eq(s.mobility, 1);
    mech_system *sys = NULL;
    cr_assert_eq(mech_system_new(m, &sys, &d), MECH_OK);
    cr_expect_eq(mech_system_size(sys), 200000);
    mech_system_free(&sys);
    mech_model_free(&m);
    mech_diag_free(&d);
    double seconds = now() - t0;  /* 7 s optimised, 25 s with sanitizers, on one core */
    cr_expect_lt(seconds, 180.0, "100 000 loops took %.0f s: is some step quadratic?", seconds);
}

/* One pin shared by 100 000 links: the implied revolutes are named O, O_2,
 * O_3, ... without trying every taken suffix again (that was quadratic). */
Test(limits, one_pin_on_many_links)
{
    enum { N = 100000 };
    buf b = {0};
    add(&b, "name: fan\nground: {O: [0, 0]}\nlinks:\n");
    for (int i = 0; i < N; i++)
        add(&b, "  l%d: {points: {O: [0, 0], P%d: [1, 0]}}\n", i, i);
    add(&b, "driver: {link: l0, angle: 0}\n");
    double t0 = now();
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    cr_assert_eq(mech_load_string(b.s, b.len, "fan.yaml", &m, &d), MECH_OK);
    cr_assert_eq(m->njoints, N);
    cr_expect_str_eq(m->joints[0].name, "O");
    cr_expect_str_eq(m->joints[1].name, "O_2");
    cr_expect_str_eq(m->joints[N - 1].name, "O_100000");
    cr_expect_lt(now() - t0, 60.0, "one pin on %d links: is naming quadratic?", N);
    mech_model_free(&m);
    mech_diag_free(&d);
    free(b.s);
}
