/* tests/unit/helpers.h: what several test files need: load and check a
 * mechanism (from text or a path; the test fails if it does not load), the
 * kind of a result column from its name, and verbose notes. */
#ifndef MECH_TEST_HELPERS_H
#define MECH_TEST_HELPERS_H

#include <criterion/criterion.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mech.h"

/* Load (mech_load_string or mech_load_file) and mech_check; fails the test
 * with the diagnostics when either fails. `text` NULL: load `path`. */
static inline mech_model *test_load(const char *text, const char *path)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    mech_summary s;
    int rc = text ? mech_load_string(text, strlen(text), "<test>", &m, &d)
                  : mech_load_file(path, &m, &d);
    if (rc == MECH_OK)
        rc = mech_check(m, &s, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK, "the test mechanism does not load: %s", text ? text : path);
    return m;
}

static inline mech_model *load_text(const char *text) { return test_load(text, NULL); }
static inline mech_model *load_path(const char *path) { return test_load(NULL, path); }

/* mech_load_file_with of `path` with parameter `name` replaced by value in
 * `unit` (as `mech solve --set`; name NULL: as in the file), not checked;
 * fails the test with the diagnostics when it does not load. */
static inline mech_model *load_with_value(const char *path, const char *name, double value,
                                          const char *unit)
{
    char text[64];
    snprintf(text, sizeof text, "%.17g %s", value, unit);
    mech_override ov = {name, text};
    mech_model *m = NULL;
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_load_file_with(path, &ov, name ? 1 : 0, &m, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK, "%s does not load with %s = %s", path, name ? name : "-", text);
    return m;
}

/* The equations of m as `mech equations` prints them in `fmt` (named: with
 * the parameters' names, mech_system_new_named), in a string to free. */
static inline char *system_text(const mech_model *m, mech_format fmt, int named)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_system *s = NULL;
    int rc = named ? mech_system_new_named(m, &s, &d) : mech_system_new(m, &s, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK, "%s: no system", m->file);
    char *buf = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&buf, &len);
    cr_assert_not_null(mem);
    mech_system_print(s, fmt, mem);
    fclose(mem);
    mech_system_free(&s);
    return buf;
}

/* A measured figure, printed with the tag when MECH_HARD_VERBOSE is set
 * (the tests assert bounds; this shows how far inside them they are). */
static inline void note_tagged(const char *tag, const char *fmt, va_list ap)
{
    if (!getenv("MECH_HARD_VERBOSE"))
        return;
    fprintf(stderr, "[%s] ", tag);
    vfprintf(stderr, fmt, ap);
    fprintf(stderr, "\n");
}

static inline int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

/* The kind of a column: 0 length, 1 speed, 2 acceleration, 3 angle,
 * 4 angular speed, 5 angular acceleration. */
static inline int column_kind(const char *name)
{
    static const char *const suffix[] = {".x", ".y", ".s", ".vx", ".vy", ".v",
                                         ".ax", ".ay", ".a", ".angle", ".omega", ".alpha"};
    static const int kind[] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 4, 5};
    for (int i = 0; i < (int)(sizeof kind / sizeof *kind); i++)
        if (ends_with(name, suffix[i]))
            return kind[i];
    cr_assert_fail("column '%s' of no known kind", name);
    return -1;
}

/* Solve with options o (NULL: the defaults); the solve must succeed. */
static inline mech_table must_solve(const mech_model *m, const mech_solve_options *o)
{
    mech_solve_options def;
    mech_solve_options_default(&def);
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    int rc = mech_solve(m, o ? o : &def, &t, NULL, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK, "mech_solve failed (%d) on %s", rc, m->name);
    return t;
}

/* The column called name (it must exist), and its value in a row. */
static inline int table_col(const mech_table *t, const char *name)
{
    int c = mech_table_column(t, name);
    cr_assert_geq(c, 0, "no column '%s' in the table", name);
    return c;
}

static inline double table_at(const mech_table *t, int row, const char *name)
{
    return mech_table_get(t, row, table_col(t, name));
}

#endif
