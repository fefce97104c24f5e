/* tests/unit/test_compare.c: `mech compare` (src/output/compare.c): reading the
 * solver's CSV, the tolerance rule, the report and the errors.
 *
 * Each test writes its small CSV files into its own directory from mkdtemp
 * (Criterion runs tests in parallel processes) and removes them at the end.
 * The report and the diagnostics are captured with open_memstream and
 * checked as text: the line of a column, the verdict, FILE:LINE:COLUMN.
 *
 * Values near a tolerance boundary are chosen with a margin of about 1% of
 * the tolerance (1e-9 relative at 100 is 1e-7; the values sit at 0.99e-7 and
 * 1.01e-7), far above the rounding of the decimal input (1.4e-14 at 100). */
#include <criterion/criterion.h>
#include <criterion/redirect.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli.h"
#include "output.h"

/* ---- a private directory per test --------------------------------------- */

#define MAX_FILES 8
static char dir[256];
static char paths[MAX_FILES][320];  /* files written by put(), removed by cleanup() */
static int npaths;

static void setup(void)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(dir, sizeof dir, "%s/mech-compare-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    cr_assert_not_null(mkdtemp(dir), "mkdtemp %s", dir);
    npaths = 0;
}

static void cleanup(void)
{
    for (int i = 0; i < npaths; i++)
        remove(paths[i]);
    rmdir(dir);
}

/* Write `text` to a new file `name` in the test's directory; returns its path. */
static const char *put(const char *name, const char *text)
{
    cr_assert_lt(npaths, MAX_FILES);
    char *path = paths[npaths++];
    snprintf(path, sizeof paths[0], "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    cr_assert_not_null(f, "cannot write %s", path);
    fputs(text, f);
    fclose(f);
    return path;
}

/* ---- running a comparison ----------------------------------------------- */

typedef struct run {
    int rc;          /* compare_csv_files status */
    char *report;    /* what went to the report stream, owned */
    char *errors;    /* what went to the error stream, owned */
    const char *out, *golden;  /* the paths */
} run;

static run compare_with(const char *out_text, const char *golden_text, const compare_options *o)
{
    run r = {0};
    size_t n1, n2;
    r.out = put("out.csv", out_text);
    r.golden = put("golden.csv", golden_text);
    FILE *rep = open_memstream(&r.report, &n1);
    FILE *err = open_memstream(&r.errors, &n2);
    cr_assert(rep && err);
    r.rc = compare_csv_files(r.out, r.golden, o, rep, err);
    fclose(rep);
    fclose(err);
    return r;
}

static run compare_texts(const char *out_text, const char *golden_text)
{
    return compare_with(out_text, golden_text, NULL);
}

static void run_free(run *r)
{
    free(r->report);
    free(r->errors);
}

/* The line of `text` that starts with `prefix` followed by a blank, or NULL
 * (a static copy without its newline). */
static const char *line_of(const char *text, const char *prefix)
{
    static char buf[1024];
    size_t n = strlen(prefix);
    for (const char *s = text; s && *s; s = strchr(s, '\n'), s = s ? s + 1 : NULL)
        if (strncmp(s, prefix, n) == 0 && (s[n] == ' ' || s[n] == ':')) {
            size_t len = strcspn(s, "\n");
            snprintf(buf, sizeof buf, "%.*s", (int)(len < sizeof buf ? len : sizeof buf - 1), s);
            return buf;
        }
    return NULL;
}

/* The words of a table line: column unit abs rel row status... */
static int words(const char *line, char w[][64], int max)
{
    int n = 0;
    for (const char *s = line; s && *s && n < max;) {
        s += strspn(s, " ");
        size_t len = strcspn(s, " ");
        if (len == 0)
            break;
        snprintf(w[n++], 64, "%.*s", (int)(len < 63 ? len : 63), s);
        s += len;
    }
    return n;
}

#define expect_has(text, part)                                                               \
    cr_expect((text) && strstr((text), (part)) != NULL, "expected '%s' in:\n%s", (part),     \
              (text) ? (text) : "(null)")

/* The table line of column `name` must have the first failing row `row`
 * ("-" when none) and the status `status`. */
static void expect_column(const run *r, const char *name, const char *row, const char *status)
{
    const char *line = line_of(r->report, name);
    cr_expect_not_null(line, "no line for column %s in:\n%s", name, r->report);
    if (!line)
        return;
    char w[8][64];
    int n = words(line, w, 8);
    cr_expect_geq(n, 6, "short line: %s", line);
    if (n < 6)
        return;
    cr_expect_str_eq(w[4], row, "first bad row of %s: %s", name, line);
    cr_expect_str_eq(w[5], status, "status of %s: %s", name, line);
}

/* The verdict: the last line of the report, starting "compare: ". */
static const char *verdict(const run *r)
{
    const char *v = NULL;
    for (const char *s = r->report; s && (s = strstr(s, "compare: ")); s++)
        if (s == r->report || s[-1] == '\n')
            v = s;
    cr_expect_not_null(v, "no verdict in:\n%s", r->report);
    return v ? v : "";
}

static const char golden3[] =
    "# mech solve fourbar.yaml\n"
    "q [rad],B.x [m],B.vx [m/s]\n"
    "0,100,0.5\n"
    "0.1,100,-0.25\n"
    "0.2,100,1e-3\n";

/* ---- identical files --------------------------------------------------- */

TestSuite(compare, .init = setup, .fini = cleanup);

Test(compare, identical_files_match)
{
    run r = compare_texts(golden3, golden3);
    cr_expect_eq(r.rc, MECH_OK, "errors:\n%s\nreport:\n%s", r.errors, r.report);
    cr_expect_eq(compare_exit_status(r.rc), 0);
    expect_column(&r, "q", "-", "ok");
    expect_column(&r, "B.x", "-", "ok");
    expect_column(&r, "B.vx", "-", "ok");
    cr_expect_str_eq(verdict(&r), "compare: 3 columns, 3 rows: all within rtol 1e-09 atol 1e-12\n");
    cr_expect_str_eq(r.errors, "");
    run_free(&r);
}

Test(compare, crlf_comments_and_blanks_are_accepted)
{
    run r = compare_texts("# a comment\r\n\r\nq [rad] , B.x [m],B.vx [m/s]\r\n"
                          "0, 100 ,0.5\r\n# between rows\r\n0.1,100,-0.25\r\n0.2,100,1e-3",
                          golden3);
    cr_expect_eq(r.rc, MECH_OK, "errors:\n%s\nreport:\n%s", r.errors, r.report);
    expect_has(verdict(&r), "3 columns, 3 rows");
    run_free(&r);
}

/* ---- the tolerance rule ------------------------------------------------- */

Test(compare, value_match_rule)
{
    /* |out - golden| <= atol + rtol*|golden|, with tolerance 1e-12 + 1e-9*100 = 1.00001e-7 */
    cr_expect(compare_values_match(100 + 0.99e-7, 100, 1e-9, 1e-12));
    cr_expect(!compare_values_match(100 + 1.01e-7, 100, 1e-9, 1e-12));
    cr_expect(!compare_values_match(100 - 1.01e-7, 100, 1e-9, 1e-12));
    /* rtol scales with the golden value, not the output */
    cr_expect(!compare_values_match(200, 100, 0.6, 0));
    cr_expect(compare_values_match(100, 200, 0.6, 0));
    /* atol alone near 0 */
    cr_expect(compare_values_match(0.9e-12, 0, 1e-9, 1e-12));
    cr_expect(!compare_values_match(1.1e-12, 0, 1e-9, 1e-12));
    cr_expect(compare_values_match(-0.0, 0.0, 0, 0));
    /* a huge difference that overflows to inf fails */
    cr_expect(!compare_values_match(1.7e308, -1.7e308, 1, 0));
}

Test(compare, nan_and_inf_rule)
{
    cr_expect(compare_values_match(NAN, NAN, 1e-9, 1e-12));
    cr_expect(compare_values_match(-NAN, NAN, 1e-9, 1e-12));
    cr_expect(!compare_values_match(NAN, 0, 1e-9, 1e-12));
    cr_expect(!compare_values_match(0, NAN, 1e-9, 1e-12));
    cr_expect(!compare_values_match(NAN, 1, 1e300, 1e300));  /* no tolerance covers NaN */
    cr_expect(compare_values_match(INFINITY, INFINITY, 1e-9, 1e-12));
    cr_expect(compare_values_match(-INFINITY, -INFINITY, 1e-9, 1e-12));
    cr_expect(!compare_values_match(INFINITY, -INFINITY, 1e-9, 1e-12));
    cr_expect(!compare_values_match(1e308, INFINITY, 1e-9, 1e-12));
    cr_expect(!compare_values_match(INFINITY, 1e308, 1e300, 1e300));
    cr_expect(!compare_values_match(INFINITY, NAN, 1e-9, 1e-12));
}

Test(compare, just_outside_rtol_fails_at_the_right_row)
{
    /* row 2 is just inside (0.99e-7), row 3 just outside (1.01e-7) */
    run r = compare_texts("q [rad],B.x [m],B.vx [m/s]\n"
                          "0,100,0.5\n"
                          "0.1,100.000000099,-0.25\n"
                          "0.2,100.000000101,1e-3\n",
                          golden3);
    cr_expect_eq(r.rc, COMPARE_DIFFER, "errors:\n%s\nreport:\n%s", r.errors, r.report);
    cr_expect_eq(compare_exit_status(r.rc), 1);
    expect_column(&r, "q", "-", "ok");
    expect_column(&r, "B.x", "3", "FAIL");
    expect_column(&r, "B.vx", "-", "ok");
    cr_expect_str_eq(verdict(&r),
                     "compare: 1 of 3 columns differs (first: B.x at row 3: 100.000000101 vs 100)\n");
    run_free(&r);
}

Test(compare, looser_rtol_passes)
{
    compare_options o;
    compare_options_default(&o);
    o.rtol = 1e-8;
    run r = compare_with("q [rad],B.x [m],B.vx [m/s]\n0,100,0.5\n0.1,100,-0.25\n"
                         "0.2,100.000000101,1e-3\n",
                         golden3, &o);
    cr_expect_eq(r.rc, MECH_OK, "report:\n%s", r.report);
    expect_has(verdict(&r), "all within rtol 1e-08 atol 1e-12");
    run_free(&r);
}

Test(compare, worst_errors_are_reported)
{
    run r = compare_texts("q [rad],B.x [m],B.vx [m/s]\n0,100,0.5\n0.1,100,-0.25\n0.2,100,0.002\n",
                          golden3);
    cr_expect_eq(r.rc, COMPARE_DIFFER);
    const char *line = line_of(r.report, "B.vx");
    char w[8][64];
    cr_assert_geq(words(line, w, 8), 6, "%s", r.report);
    cr_expect_eq(strtod(w[2], NULL), 0.001, "abs error %s", line);  /* |0.002 - 0.001| */
    cr_expect_eq(strtod(w[3], NULL), 1.0, "rel error %s", line);    /* 0.001 / 0.001 */
    cr_expect_str_eq(w[4], "3");
    run_free(&r);
}

Test(compare, nan_matches_only_nan_in_files)
{
    static const char golden[] = "t [s],w [rad/s]\n0,nan\n1,inf\n2,-inf\n3,nan\n";
    run r = compare_texts("t [s],w [rad/s]\n0,-nan\n1,inf\n2,-inf\n3,0\n", golden);
    cr_expect_eq(r.rc, COMPARE_DIFFER, "errors:\n%s\nreport:\n%s", r.errors, r.report);
    expect_column(&r, "w", "4", "FAIL");
    expect_has(verdict(&r), "(first: w at row 4: 0 vs nan)");
    run_free(&r);
    npaths = 0;
    r = compare_texts("t [s],w [rad/s]\n0,nan\n1,-inf\n2,-inf\n3,nan\n", golden);
    expect_column(&r, "w", "2", "FAIL");
    run_free(&r);
    npaths = 0;
    r = compare_texts(golden, golden);
    cr_expect_eq(r.rc, MECH_OK, "report:\n%s", r.report);
    expect_column(&r, "w", "-", "ok");
    run_free(&r);
}

/* ---- columns and rows --------------------------------------------------- */

Test(compare, missing_column_fails_extra_column_is_listed)
{
    run r = compare_texts("q [rad],B.vx [m/s],iterations [-]\n0,0.5,3\n0.1,-0.25,4\n0.2,1e-3,3\n",
                          golden3);
    cr_expect_eq(r.rc, COMPARE_DIFFER, "report:\n%s", r.report);
    expect_has(line_of(r.report, "B.x"), "FAIL (missing from OUT)");
    expect_column(&r, "B.vx", "-", "ok");
    expect_has(r.report, "extra in OUT (not compared): iterations [-]\n");
    cr_expect_str_eq(verdict(&r), "compare: 1 of 3 columns differs (first: B.x missing from OUT)\n");
    run_free(&r);
}

Test(compare, extra_column_alone_does_not_fail)
{
    run r = compare_texts("q [rad],iterations [-],B.x [m],B.vx [m/s]\n"
                          "0,3,100,0.5\n0.1,4,100,-0.25\n0.2,3,100,1e-3\n",
                          golden3);
    cr_expect_eq(r.rc, MECH_OK, "report:\n%s", r.report);
    expect_has(r.report, "extra in OUT (not compared): iterations [-]");
    run_free(&r);
}

Test(compare, unit_mismatch_fails)
{
    run r = compare_texts("q [rad],B.x [mm],B.vx [m/s]\n0,100,0.5\n0.1,100,-0.25\n0.2,100,1e-3\n",
                          golden3);
    cr_expect_eq(r.rc, COMPARE_DIFFER, "report:\n%s", r.report);
    expect_has(line_of(r.report, "B.x"), "FAIL (unit [mm] in OUT)");
    expect_has(verdict(&r), "(first: B.x in [mm] in OUT, [m] in GOLDEN)");
    run_free(&r);
}

Test(compare, row_count_mismatch_fails)
{
    run r = compare_texts("q [rad],B.x [m],B.vx [m/s]\n0,100,0.5\n0.1,100,-0.25\n", golden3);
    cr_expect_eq(r.rc, COMPARE_DIFFER, "report:\n%s", r.report);
    expect_column(&r, "B.x", "-", "ok");
    cr_expect_str_eq(verdict(&r), "compare: row counts differ: OUT has 2 rows, GOLDEN has 3; "
                                  "the first 2 rows of 3 columns are within rtol 1e-09 atol 1e-12\n");
    run_free(&r);
}

Test(compare, columns_restrict_the_comparison)
{
    static const char out[] = "q [rad],B.x [m],B.vx [m/s]\n0,100,0.5\n0.1,100,-0.25\n0.2,100,7\n";
    const char *only_x[] = {"B.x", "q"};
    compare_options o;
    compare_options_default(&o);
    o.columns = only_x;
    o.ncolumns = 2;
    run r = compare_with(out, golden3, &o);
    cr_expect_eq(r.rc, MECH_OK, "B.vx differs but is not compared:\n%s", r.report);
    expect_column(&r, "B.x", "-", "ok");
    cr_expect_null(line_of(r.report, "B.vx"), "B.vx is in the table:\n%s", r.report);
    expect_has(verdict(&r), "2 columns, 3 rows");
    run_free(&r);

    const char *with_vx[] = {"B.vx"};
    o.columns = with_vx;
    o.ncolumns = 1;
    npaths = 0;
    r = compare_with(out, golden3, &o);
    cr_expect_eq(r.rc, COMPARE_DIFFER, "report:\n%s", r.report);
    expect_column(&r, "B.vx", "3", "FAIL");
    run_free(&r);
}

Test(compare, unknown_column_name_is_a_usage_error)
{
    const char *names[] = {"B.vy"};
    compare_options o;
    compare_options_default(&o);
    o.columns = names;
    o.ncolumns = 1;
    run r = compare_with(golden3, golden3, &o);
    cr_expect_eq(r.rc, MECH_EINPUT);
    cr_expect_eq(compare_exit_status(r.rc), 2);
    expect_has(r.errors, "--columns: no column 'B.vy' (did you mean 'B.vx'?)");
    cr_expect_str_eq(r.report, "", "nothing compared");
    run_free(&r);
}

/* ---- malformed and unreadable files ------------------------------------ */

/* "PATH:LINE:COL: error: " followed by `message`, somewhere in r->errors. */
static void expect_error(const run *r, const char *path, int line, int col, const char *message)
{
    char want[512];
    snprintf(want, sizeof want, "%s:%d:%d: error: %s", path, line, col, message);
    expect_has(r->errors, want);
}

Test(compare, malformed_rows_give_line_and_column)
{
    run r = compare_texts("# comment\n"
                          "q [rad],B.x [m],B.vx [m/s]\n"
                          "0,100,0.5\n"
                          "0.1,100,-0.25,9\n"
                          "0.2,1OO,1e-3\n"
                          "0.3,100\n"
                          "0.4, ,1\n",
                          golden3);
    cr_expect_eq(r.rc, MECH_EINPUT, "errors:\n%s", r.errors);
    cr_expect_eq(compare_exit_status(r.rc), 2);
    expect_error(&r, r.out, 4, 15, "row has 4 fields, expected 3 as in the header (line 2)");
    expect_error(&r, r.out, 5, 5, "'1OO' in column 'B.x' is not a number");
    expect_error(&r, r.out, 6, 8, "row has 2 fields, expected 3 as in the header (line 2)");
    expect_error(&r, r.out, 7, 6, "empty field in column 'B.x' (expected a number)");
    cr_expect_str_eq(r.report, "", "no report for a malformed file");
    run_free(&r);
}

/* Cells are numbers as the solver writes them: 1e999 read as inf and then
 * "matched" an inf, and hex was taken; both are errors at their place. */
Test(compare, cells_are_finite_decimal_numbers_or_nan_inf)
{
    static const char golden[] = "q [rad],B.x [m]\n0,inf\n1,8\n2,1\n3,-inf\n4,5\n";
    run r = compare_texts("q [rad],B.x [m]\n0,1e999\n1,0x1p3\n2,Infinity\n3,-1e999\n4,5.\n",
                          golden);
    cr_expect_eq(r.rc, MECH_EINPUT, "errors:\n%s\nreport:\n%s", r.errors, r.report);
    expect_error(&r, r.out, 2, 3, "'1e999' in column 'B.x' is not a finite number");
    expect_error(&r, r.out, 3, 3, "'0x1p3' in column 'B.x' is not a number");
    expect_error(&r, r.out, 4, 3, "'Infinity' in column 'B.x' is not a number");
    expect_error(&r, r.out, 5, 3, "'-1e999' in column 'B.x' is not a finite number");
    cr_expect_null(strstr(r.errors, ":6:"), "'5.' is a number: %s", r.errors);
    run_free(&r);
    npaths = 0;
    /* what %.17g writes is read back: signs, exponents, nan, -nan, inf */
    r = compare_texts("a [m],b [m]\n-1.5e-07,nan\n+2,-nan\n.5,inf\n1E+300,-inf\n1e-999,0\n",
                      "a [m],b [m]\n-1.5e-07,nan\n2,nan\n0.5,inf\n1e300,-inf\n0,0\n");
    cr_expect_eq(r.rc, MECH_OK, "errors:\n%s\nreport:\n%s", r.errors, r.report);
    run_free(&r);
}

/* Out of memory is not a malformed file: exit 3 with its message, not 2. */
Test(compare, out_of_memory_is_exit_3)
{
    cr_expect_eq(compare_exit_status(MECH_ENOMEM), 3);
    cr_expect_eq(compare_exit_status(MECH_EINPUT), 2);
    cr_expect_eq(compare_exit_status(MECH_EIO), 3);
}

Test(compare, malformed_header)
{
    run r = compare_texts(golden3, "q [rad],B.x,B.x [m], [s]\n0,1,2,3\n");
    cr_expect_eq(r.rc, MECH_EINPUT, "errors:\n%s", r.errors);
    expect_error(&r, r.golden, 1, 9, "column 'B.x' has no unit (expected 'NAME [UNIT]')");
    expect_error(&r, r.golden, 1, 22, "column '[s]' has no name (expected 'NAME [UNIT]')");
    run_free(&r);
    npaths = 0;
    r = compare_texts(golden3, "a [m],b [m],a [s]\n");
    expect_error(&r, r.golden, 1, 13, "duplicate column 'a' (first at column 1)");
    run_free(&r);
    npaths = 0;
    r = compare_texts(golden3, "# nothing but a comment\n");
    expect_error(&r, r.golden, 2, 1, "no header line");
    run_free(&r);
}

Test(compare, unreadable_file)
{
    char missing[320];
    snprintf(missing, sizeof missing, "%s/no-such.csv", dir);
    const char *golden = put("golden.csv", golden3);
    FILE *err = tmpfile();
    cr_assert_not_null(err);
    int rc = compare_csv_files(missing, golden, NULL, NULL, err);
    cr_expect_eq(rc, MECH_EIO);
    cr_expect_eq(compare_exit_status(rc), 3);
    /* a directory opens but cannot be read */
    rc = compare_csv_files(golden, dir, NULL, NULL, err);
    cr_expect_eq(rc, MECH_EIO);
    /* a malformed file outranks an unreadable one, as in `mech check` */
    const char *bad = put("bad.csv", "q [rad]\nx\n");
    rc = compare_csv_files(missing, bad, NULL, NULL, err);
    cr_expect_eq(rc, MECH_EINPUT);
    fclose(err);
}

/* ---- no fixed limits ------------------------------------------------------ */

Test(compare, long_lines_and_many_columns)
{
    enum { NCOLS = 3000 };
    size_t cap = (size_t)NCOLS * 300;
    char *out = malloc(cap), *golden = malloc(cap);
    cr_assert(out && golden);
    size_t n = 0;
    for (int i = 0; i < NCOLS; i++)  /* names of 100+ characters */
        n += (size_t)snprintf(golden + n, cap - n, "%s%0100d.x [m]", i ? "," : "", i);
    n += (size_t)snprintf(golden + n, cap - n, "\n");
    for (int i = 0; i < NCOLS; i++)
        n += (size_t)snprintf(golden + n, cap - n, "%s%.17g", i ? "," : "", i / 7.0);
    snprintf(golden + n, cap - n, "\n");
    memcpy(out, golden, strlen(golden) + 1);
    char *last = strrchr(out, ',');  /* the last value, (NCOLS-1)/7, becomes 0 */
    strcpy(last + 1, "0\n");
    run r = compare_texts(out, golden);
    cr_expect_eq(r.rc, COMPARE_DIFFER, "errors:\n%s", r.errors);
    char want[400];
    snprintf(want, sizeof want, "compare: 1 of %d columns differs (first: %0100d.x at row 1: 0 vs",
             NCOLS, NCOLS - 1);
    expect_has(verdict(&r), want);
    run_free(&r);
    free(out);
    free(golden);
}

/* ---- the command line ----------------------------------------------------- */

TestSuite(compare_cli, .init = setup, .fini = cleanup);

static int cmd(int argc, const char **argv)
{
    return cmd_compare(argc, (char **)argv);
}

Test(compare_cli, exit_statuses)
{
    const char *same = put("same.csv", golden3);
    const char *other = put("other.csv", "q [rad],B.x [m],B.vx [m/s]\n0,100,0.5\n0.1,101,-0.25\n"
                                         "0.2,100,1e-3\n");
    const char *bad = put("bad.csv", "q [rad],B.x [m],B.vx [m/s]\n0,100\n");
    char missing[320];
    snprintf(missing, sizeof missing, "%s/none.csv", dir);
    cr_expect_eq(cmd(3, (const char *[]){"compare", same, same, NULL}), 0);
    cr_expect_eq(cmd(3, (const char *[]){"compare", other, same, NULL}), 1);
    cr_expect_eq(cmd(5, (const char *[]){"compare", "--rtol", "0.02", other, same, NULL}), 0);
    cr_expect_eq(cmd(4, (const char *[]){"compare", "--rtol=0.02", other, same, NULL}), 0);
    cr_expect_eq(cmd(5, (const char *[]){"compare", other, same, "--columns", "q,B.vx", NULL}),
                 0);
    cr_expect_eq(cmd(3, (const char *[]){"compare", bad, same, NULL}), 2);
    cr_expect_eq(cmd(3, (const char *[]){"compare", missing, same, NULL}), 3);
    cr_expect_eq(cmd(5, (const char *[]){"compare", "--columns", "B.vy", same, same, NULL}), 2);
}

Test(compare_cli, bad_usage)
{
    const char *f = put("f.csv", golden3);
    cr_expect_eq(cmd(1, (const char *[]){"compare", NULL}), 2);
    cr_expect_eq(cmd(2, (const char *[]){"compare", f, NULL}), 2);
    cr_expect_eq(cmd(4, (const char *[]){"compare", f, f, f, NULL}), 2);
    cr_expect_eq(cmd(4, (const char *[]){"compare", f, f, "--rtol", NULL}), 2);
    cr_expect_eq(cmd(5, (const char *[]){"compare", "--rtol", "-1", f, f, NULL}), 2);
    cr_expect_eq(cmd(5, (const char *[]){"compare", "--atol", "1e", f, f, NULL}), 2);
    cr_expect_eq(cmd(5, (const char *[]){"compare", "--atol", "nan", f, f, NULL}), 2);
    cr_expect_eq(cmd(5, (const char *[]){"compare", "--columns", "q,,B.x", f, f, NULL}), 2);
    cr_expect_eq(cmd(4, (const char *[]){"compare", "--frob", f, f, NULL}), 2);
}

Test(compare_cli, help, .init = cr_redirect_stdout)
{
    char *help = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&help, &size);
    cmd_opts_help(&cmd_compare_spec, f);  /* the help generated from the option table */
    fclose(f);
    cr_expect_eq(cmd(2, (const char *[]){"compare", "--help", NULL}), 0);
    fflush(stdout);
    cr_expect_stdout_eq_str(help);
    cr_expect(strncmp(help, "usage: mech compare ", 20) == 0);
    expect_has(help, "default 1e-9");
    expect_has(help, "default 1e-12");
    expect_has(help, "exit status:");
    free(help);
}
