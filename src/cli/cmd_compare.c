/* src/cli/cmd_compare.c: `mech compare OUT.csv GOLDEN.csv`, the command line
 * on top of compare_csv_files() (src/output/compare.c): options, the report on
 * standard output, the exit status (docs/cli.md, section mech compare). */
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "output.h"

#define STR_(x) #x
#define STR(x) STR_(x)

enum { GO_ON = -1 };  /* parse_args: the arguments are fine, compare */

typedef struct compare_args {
    compare_options o;
    cmd_operands files;    /* OUT, GOLDEN */
    char *columns_text;    /* the --columns values joined by ',', owned; cut in place */
    size_t columns_len;
    const char **columns;  /* [o.ncolumns] names in columns_text, owned array */
} compare_args;

/* Append one --columns value to a->columns_text (a CMD_OPT_CALL). */
static int add_columns(const char *command, void *args, const char *text)
{
    compare_args *a = args;
    size_t n = strlen(text), old = a->columns_len;
    char *s = realloc(a->columns_text, old + n + 2);
    if (!s)
        return fprintf(stderr, "mech %s: out of memory\n", command), MECH_EXIT_IO;
    if (old > 0)
        s[old++] = ',';
    memcpy(s + old, text, n + 1);
    a->columns_text = s;
    a->columns_len = old + n;
    return GO_ON;
}

/* Cut a->columns_text at its commas into a->columns. */
static int split_columns(compare_args *a)
{
    if (!a->columns_text)
        return GO_ON;
    size_t n = 1;
    for (const char *s = a->columns_text; *s; s++)
        n += *s == ',';
    a->columns = calloc(n, sizeof *a->columns);
    if (!a->columns)
        return fprintf(stderr, "mech compare: out of memory\n"), MECH_EXIT_IO;
    char *s = a->columns_text;
    for (size_t i = 0; i < n; i++) {
        a->columns[i] = s;
        s += strcspn(s, ",");
        if (*s)
            *s++ = '\0';
        if (a->columns[i][0] == '\0')
            return cmd_usage_error("compare", "%s", "--columns: empty column name");
    }
    a->o.columns = a->columns;
    a->o.ncolumns = n;
    return GO_ON;
}

#define AT(field) offsetof(compare_args, field)

static const cmd_opt options[] = {
    {.names = "--rtol", .kind = CMD_OPT_REAL, .at = AT(o.rtol), .lo = 0, .hi = DBL_MAX,
     .expect = "needs a number >= 0", .label = "--rtol R",
     .help = "relative tolerance (default " STR(COMPARE_RTOL) ")"},
    {.names = "--atol", .kind = CMD_OPT_REAL, .at = AT(o.atol), .lo = 0, .hi = DBL_MAX,
     .expect = "needs a number >= 0", .label = "--atol A",
     .help = "absolute tolerance (default " STR(COMPARE_ATOL) ")"},
    {.names = "--columns", .kind = CMD_OPT_CALL, .at = 0 /* the whole compare_args */,
     .call = add_columns, .label = "--columns NAME,NAME...",
     .help = "compare only these columns of GOLDEN"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_compare_spec = {
    .name = "compare",
    .summary = "compare a result CSV with a golden CSV",
    .usage = "usage: mech compare [--rtol R] [--atol A] [--columns NAME,...]\n"
             "                    OUT.csv GOLDEN.csv\n",
    .about = "Compare a solver output CSV (OUT) with a golden CSV, column by column; columns\n"
             "are matched by name and must have the same unit. A value passes when\n"
             "|out - golden| <= atol + rtol*|golden|; NaN matches only NaN, and inf only an\n"
             "inf of the same sign. Prints one line per column of GOLDEN (worst absolute and\n"
             "relative error, first failing row, ok or FAIL) and a one-line verdict.\n"
             "A column missing from OUT, another unit or another number of rows fails;\n"
             "columns only in OUT are listed but do not fail.\n",
    .opts = options,
    .column = 27,
    .exits = "exit status: 0 the files match, 1 they differ, 2 bad usage or a malformed CSV,\n"
             "3 a file cannot be read\n",
    .file_at = AT(files),
};

/* Returns GO_ON, or the exit code when done (help) or on bad usage. */
static int parse_args(int argc, char **argv, compare_args *a)
{
    int code = cmd_opts_parse(&cmd_compare_spec, argc, argv, a);
    if (code != GO_ON)
        return code;
    if (a->files.n > 2)
        return cmd_usage_error("compare", "too many files ('%s'): expected OUT.csv GOLDEN.csv",
                               a->files.v[2]);
    if (a->files.n < 2)
        return cmd_usage_error("compare", "%s", a->files.n == 0
                               ? "no files given (usage: mech compare [--rtol R] [--atol A] "
                                 "[--columns NAME,...] OUT.csv GOLDEN.csv)"
                               : "only one of two files given (usage: mech compare [--rtol R] "
                                 "[--atol A] [--columns NAME,...] OUT.csv GOLDEN.csv)");
    return split_columns(a);
}

int cmd_compare(int argc, char **argv)
{
    compare_args a;
    memset(&a, 0, sizeof a);
    compare_options_default(&a.o);
    int code = parse_args(argc, argv, &a);
    if (code == GO_ON) {
        int rc = compare_csv_files(a.files.v[0], a.files.v[1], &a.o, stdout, stderr);
        code = compare_exit_status(rc);
    }
    free(a.columns_text);
    free(a.columns);
    free(a.files.v);
    return code;
}
