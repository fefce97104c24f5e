/* tests/codegen_rcond.c: the reciprocal condition of the code `mech codegen
 * --prefix gen` wrote against the interpreter's (tests/codegen.sh compiles
 * the two together).
 *
 *   codegen-rcond DIAG.csv [MIN]
 *
 * DIAG.csv is `mech solve FILE --diagnostics`: its first column is the
 * driver position q, its column "rcond [-]" the interpreter's reciprocal
 * condition at each row's solution. Each row is solved as
 * tests/codegen_driver.c does (gen_predict from the previous rows, row 0
 * from gen_init). Then: gen_rcond(&s) must equal the interpreter's rcond
 * bit for bit, and where the solve kept a lower bound in s.rcond
 * (s.rcond_exact == 0: no decision depended on the exact value), that bound
 * must be at most the interpreter's value, positive and at least the
 * singular threshold, and the whole Jacobian's bound kept in s.rcond_whole
 * at most the value gen_rcond computes then. Prints
 *
 *   rows N bound B exact E loosest L
 *
 * (B rows where the solve kept the bound, E where it computed the
 * condition, L the largest exact value / bound of the two), exit 0 when every
 * row holds, 1 otherwise, 2 for a malformed DIAG.
 *
 * With MIN (the generated source compiled with its MIN_RCOND set to MIN),
 * each row must be GEN_SINGULAR exactly where the interpreter's rcond is
 * below MIN (rows within 1e-9 of MIN are not judged), the others GEN_OK
 * with the interpreter's rcond within 1e-9 relatively (a row after a
 * singular one starts from another guess): the bound never hides a
 * singular position. It then prints "rows N singular S" instead. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "gen.h"

enum { LINE = 1 << 18 };

static char line[LINE];

int main(int argc, char **argv)
{
    FILE *f = argc == 2 || argc == 3 ? fopen(argv[1], "r") : NULL;
    double min = argc == 3 ? strtod(argv[2], NULL) : 0.0;
    if (!f) {
        fprintf(stderr, "usage: codegen-rcond DIAG.csv [MIN]\n");
        return 2;
    }
    int rc_col = -1, ncols = 0;
    if (!fgets(line, sizeof line, f))
        return 2;
    line[strcspn(line, "\r\n")] = '\0';
    for (char *cell = strtok(line, ","); cell; cell = strtok(NULL, ","), ncols++)
        if (strcmp(cell, "rcond [-]") == 0)
            rc_col = ncols;
    if (rc_col < 0) {
        fprintf(stderr, "codegen-rcond: no column 'rcond [-]'\n");
        return 2;
    }
    static gen_state s;
    int rows = 0, bound = 0, exact = 0, bad = 0, singular = 0;
    double loosest = 1.0;
    gen_init(&s);
    while (fgets(line, sizeof line, f)) {
        double q = 0.0, ref = 0.0;
        char *p = line;
        for (int k = 0; k <= rc_col; k++) {
            char *end;
            double v = strtod(p, &end);
            if (end == p) {
                fprintf(stderr, "codegen-rcond: row %d, column %d is not a number\n", rows + 1, k);
                return 2;
            }
            if (k == 0)
                q = v;
            if (k == rc_col)
                ref = v;
            p = *end == ',' ? end + 1 : end;
        }
        if (rows > 0)
            gen_predict(&s, q);
        int st = gen_solve(&s, q, GEN_DRIVER_SPEED, GEN_DRIVER_ACCEL);
        if (min > 0.0) {
            int want = ref < min ? GEN_SINGULAR : GEN_OK;
            double r = gen_rcond(&s);
            if (fabs(ref - min) > 1e-9 * min && (st != want || fabs(r - ref) > 1e-9 * ref)) {
                fprintf(stderr, "codegen-rcond: row %d (q %.17g): status %d rcond %.17g, the "
                        "interpreter's rcond %.17g against MIN_RCOND %g\n", rows + 1, q, st, r,
                        ref, min);
                bad++;
            }
            singular += st == GEN_SINGULAR;
            rows++;
            continue;
        }
        if (st != GEN_OK) {
            fprintf(stderr, "codegen-rcond: row %d (q %.17g) does not solve: status %d\n", rows + 1,
                    q, st);
            return 1;
        }
        int kept = !s.rcond_exact;
        double lo = s.rcond, lo_whole = s.rcond_whole, r = gen_rcond(&s);
        if (kept) {
            bound++;
            if (!(lo > 0.0 && lo <= ref && lo >= 1e-6)) {
                fprintf(stderr, "codegen-rcond: row %d: the bound %.17g is not a lower bound of "
                        "the interpreter's rcond %.17g above 1e-6\n", rows + 1, lo, ref);
                bad++;
            }
            if (!(lo_whole > 0.0 && lo_whole <= s.rcond_whole)) {
                fprintf(stderr, "codegen-rcond: row %d: the whole matrix's bound %.17g is not a "
                        "lower bound of its rcond %.17g\n", rows + 1, lo_whole, s.rcond_whole);
                bad++;
            }
            loosest = fmax(loosest, fmax(ref / lo, s.rcond_whole / lo_whole));
        } else {
            exact++;
        }
        if (r != ref) {
            fprintf(stderr, "codegen-rcond: row %d: gen_rcond %.17g, the interpreter's %.17g\n",
                    rows + 1, r, ref);
            bad++;
        }
        if (!s.rcond_exact || s.rcond != r) {
            fprintf(stderr, "codegen-rcond: row %d: gen_rcond did not keep its value\n", rows + 1);
            bad++;
        }
        rows++;
    }
    fclose(f);
    if (min > 0.0)
        printf("rows %d singular %d\n", rows, singular);
    else
        printf("rows %d bound %d exact %d loosest %.3g\n", rows, bound, exact, loosest);
    return bad || rows == 0 ? 1 : 0;
}
