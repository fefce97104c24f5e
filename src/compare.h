/* src/compare.h: compare a solver output CSV with a golden CSV (`mech compare`).
 *
 * Two layers: compare_read_csv() reads one file into a compare_table, with
 * every malformed line reported as FILE:LINE:COLUMN in a mech_diag;
 * compare_tables() matches the columns by name and checks every value with
 *     |out - golden| <= atol + rtol * |golden|
 * (NaN matches only NaN, inf only an inf of the same sign), printing one line
 * per column and a verdict. compare_csv_files() does both for two paths;
 * cmd_compare() (src/cmd_compare.c) is the command line on top of it
 * (docs/cli.md, section mech compare).
 *
 * Status values (like the rest of libmech): MECH_OK the files match,
 * COMPARE_DIFFER (> 0) both files are valid but differ, MECH_EINPUT a
 * malformed file or a bad --columns name, MECH_EIO a file cannot be read,
 * MECH_ENOMEM out of memory. compare_exit_status() maps them to exit codes. */
#ifndef MECH_COMPARE_H
#define MECH_COMPARE_H

#include <stddef.h>
#include <stdio.h>

#include "mech.h"

/* Default tolerances. Another compiler, optimisation level or libm changes
 * the last digits (about 1e-15 relative; more near toggle positions, where
 * the Jacobian is ill-conditioned), and Newton stops at 1e-12 relative to
 * the largest length: rtol 1e-9 leaves room for both yet catches a changed
 * formula. atol covers values that are exactly 0 in one file and rounding
 * noise in the other (e.g. 6.1e-17 for cos(pi/2)). */
#define COMPARE_RTOL 1e-9
#define COMPARE_ATOL 1e-12

enum { COMPARE_DIFFER = 1 };  /* status: valid files, some value, column or row count differs */

typedef struct compare_options {
    double rtol;                /* relative tolerance, >= 0 (default COMPARE_RTOL) */
    double atol;                /* absolute tolerance, >= 0 (default COMPARE_ATOL) */
    const char *const *columns; /* [ncolumns] names of GOLDEN columns to compare, borrowed;
                                   ncolumns == 0: every column of GOLDEN */
    size_t ncolumns;
    int table;                  /* 1: print the per-column table before the verdict (default) */
} compare_options;

void compare_options_default(compare_options *o);

/* One CSV file as read: the header's names and units, then the numbers. */
typedef struct compare_table {
    char **names;    /* [ncols] column names (text before " ["), owned */
    char **units;    /* [ncols] units (text inside the brackets), owned */
    size_t ncols;
    double *values;  /* [nrows * ncols] row-major, owned */
    size_t nrows;    /* data rows */
} compare_table;

/* Read the CSV at `path` into *t (overwritten). Returns MECH_OK; or
 * MECH_EINPUT with every malformed line in d (FILE:LINE:COLUMN), MECH_EIO
 * (cannot open or read) or MECH_ENOMEM, and then *t is empty. */
int compare_read_csv(const char *path, compare_table *t, mech_diag *d);
void compare_table_free(compare_table *t);  /* accepts an empty table */

/* 1 when `out` passes against `golden`: both NaN; equal infinities; or both
 * finite with |out - golden| <= atol + rtol * |golden|. */
int compare_values_match(double out, double golden, double rtol, double atol);

/* Compare two tables read from the files named out_name and golden_name
 * (used in messages). Prints the table (when o->table) and a one-line
 * verdict to `report` (NULL: print nothing); a --columns name that GOLDEN
 * lacks goes to d. `o` may be NULL for the defaults. Returns MECH_OK,
 * COMPARE_DIFFER, MECH_EINPUT (bad column name) or MECH_ENOMEM. */
int compare_tables(const compare_table *out, const compare_table *golden, const char *out_name,
                   const char *golden_name, const compare_options *o, FILE *report, mech_diag *d);

/* Read both files and compare them: the report goes to `report`, the
 * diagnostics of both files to `errors` (either may be NULL). Returns a
 * status as compare_tables; a malformed file (MECH_EINPUT) outranks an
 * unreadable one (MECH_EIO), as in `mech check`. */
int compare_csv_files(const char *out, const char *golden, const compare_options *o,
                      FILE *report, FILE *errors);

/* The same with OUT the solver's table in memory (called out_name in
 * messages) instead of a file: what `mech batch --golden` compares, with no
 * temporary file. */
int compare_result_file(const mech_table *out, const char *out_name, const char *golden,
                        const compare_options *o, FILE *report, FILE *errors);

/* Exit code of a status: 0 match, 1 differ, 2 malformed or bad usage, 3 unreadable
 * or out of memory. */
int compare_exit_status(int status);

#endif /* MECH_COMPARE_H */
