/* tests/codegen_driver.c: the sweep of `mech solve` run through the code
 * `mech codegen --prefix gen` wrote (tests/codegen.sh compiles the two
 * together with cc -std=c11 -Wall -Wextra -Werror -pedantic).
 *
 *   codegen-driver REF.csv [TOL]
 *   codegen-driver --at Q [X0 X1 ...]
 *
 * REF.csv is `mech solve`'s table of the same file. For each of its rows,
 * in order, gen_solve solves the row's q (the file's driver speed and
 * acceleration) from gen_predict's continuation of the previous rows
 * (row 0: gen_init's guesses), and every
 * column of REF that the generated code outputs (matched by name and unit)
 * must agree within TOL (default 1e-13) times the largest magnitude in that
 * column of REF (a power-balance column, itself a relative residual made
 * of rounding: within TOL absolutely, and below 1e-9, the balance the
 * forces must keep). Prints the worst error against that bound; exit 0 when
 * every value agrees, 1 otherwise (or when a row does not solve), 2 for a
 * malformed REF. With --at, one position Q (SI) from gen_init's guesses, or
 * from X0 X1 ... (SI): prints "status S iterations I rcond R branch B det D" and
 * the output columns, exit 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"

enum { MAX_COLS = 4096, MAX_ROWS = 200000, LINE = 1 << 18 };

static char line[LINE];
static int col_of[MAX_COLS];  /* REF column -> generated column, or -1 */
static double colmax[GEN_NOUT];

/* The generated column called "name [unit]", or -1. */
static int find_column(const char *cell)
{
    for (int c = 0; c < GEN_NOUT; c++) {
        char want[256];
        snprintf(want, sizeof want, "%s [%s]", gen_column_names[c], gen_column_units[c]);
        if (strcmp(want, cell) == 0)
            return c;
    }
    return -1;
}

static int read_header(FILE *f, int *ncols)
{
    if (!fgets(line, sizeof line, f))
        return -1;
    line[strcspn(line, "\r\n")] = '\0';
    int n = 0, matched = 0;
    for (char *cell = strtok(line, ","); cell && n < MAX_COLS; cell = strtok(NULL, ","), n++) {
        col_of[n] = find_column(cell);
        matched += col_of[n] >= 0;
    }
    *ncols = n;
    if (matched != GEN_NOUT) {
        fprintf(stderr, "codegen-driver: %d of the %d generated columns are in the reference\n",
                matched, GEN_NOUT);
        return -1;
    }
    return 0;
}

/* The rows of REF, in the generated columns' order (rows[r * GEN_NOUT + c]). */
static double *read_rows(FILE *f, int ncols, int *nrows)
{
    double *rows = malloc((size_t)MAX_ROWS * GEN_NOUT * sizeof *rows);
    int n = 0;
    while (rows && n < MAX_ROWS && fgets(line, sizeof line, f)) {
        char *p = line;
        for (int k = 0; k < ncols; k++) {
            char *end;
            double v = strtod(p, &end);
            if (end == p) {
                fprintf(stderr, "codegen-driver: row %d, column %d is not a number\n", n + 1, k);
                free(rows);
                return NULL;
            }
            if (col_of[k] >= 0) {
                rows[(size_t)n * GEN_NOUT + col_of[k]] = v;
                colmax[col_of[k]] = fmax(colmax[col_of[k]], fabs(v));
            }
            p = *end == ',' ? end + 1 : end;
        }
        n++;
    }
    *nrows = n;
    return rows;
}

static int solve_at(int argc, char **argv)
{
    static gen_state s;
    gen_init(&s);
    for (int i = 3; i < argc && i - 3 < GEN_NX; i++)
        s.x[i - 3] = strtod(argv[i], NULL);
    int st = gen_solve(&s, strtod(argv[2], NULL), GEN_DRIVER_SPEED, GEN_DRIVER_ACCEL);
    printf("status %d iterations %d rcond %.3g branch %d det %d\n", st, s.iterations, gen_rcond(&s),
           s.branch, s.det_sign);
    for (int c = 0; c < GEN_NOUT && st == GEN_OK; c++)
        printf("%s %.17g\n", gen_column_names[c], s.out[c]);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "--at") == 0)
        return solve_at(argc, argv);
    if (argc < 2) {
        fprintf(stderr, "usage: codegen-driver REF.csv [TOL]\n");
        return 2;
    }
    double tol = argc > 2 ? strtod(argv[2], NULL) : 1e-13;
    FILE *f = fopen(argv[1], "r");
    int ncols = 0, nrows = 0;
    double *rows = f && read_header(f, &ncols) == 0 ? read_rows(f, ncols, &nrows) : NULL;
    if (f)
        fclose(f);
    if (!rows || nrows == 0) {
        fprintf(stderr, "codegen-driver: cannot read %s\n", argv[1]);
        free(rows);
        return 2;
    }
    static gen_state s;
    gen_init(&s);
    double worst = 0.0;
    int worst_row = 0, worst_col = 0, bad = 0, iters = 0;
    for (int r = 0; r < nrows && !bad; r++) {
        const double *ref = rows + (size_t)r * GEN_NOUT;
        double q = ref[GEN_COL_Q];
        gen_predict(&s, q);
        int st = gen_solve(&s, q, GEN_DRIVER_SPEED, GEN_DRIVER_ACCEL);
        if (st != GEN_OK) {
            fprintf(stderr, "codegen-driver: row %d (q = %.17g): status %d\n", r, q, st);
            bad = 1;
            break;
        }
        iters += s.iterations;
        for (int c = 0; c < GEN_NOUT; c++) {
            int balance = strncmp(gen_column_names[c], "power.residual", 14) == 0;
            double scale = balance || !(colmax[c] > 0.0) ? 1.0 : colmax[c];
            double e = fabs(s.out[c] - ref[c]) / scale;
            if (balance && !(fabs(s.out[c]) <= 1e-9)) {
                fprintf(stderr, "codegen-driver: row %d: %s = %g, the power does not balance\n",
                        r, gen_column_names[c], s.out[c]);
                bad = 1;
            }
            if (!(e <= worst)) {
                worst = e;
                worst_row = r;
                worst_col = c;
            }
        }
    }
    if (!bad)
        printf("%d rows, %.2f iterations per row, worst |gen - ref| / column max %.3g "
               "(%s, row %d)\n", nrows, (double)iters / nrows, worst,
               gen_column_names[worst_col], worst_row);
    free(rows);
    return bad || !(worst <= tol) ? 1 : 0;
}
