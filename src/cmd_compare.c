/* src/cmd_compare.c: `mech compare OUT.csv GOLDEN.csv`, the command line
 * on top of compare_csv_files() (src/compare.c): options, the report on
 * standard output, the exit status (docs/cli.md, section mech compare). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "compare.h"

#define STR_(x) #x
#define STR(x) STR_(x)

const char cmd_compare_help[] =
    "usage: mech compare [--rtol R] [--atol A] [--columns NAME,...] OUT.csv GOLDEN.csv\n"
    "\n"
    "Compare a solver output CSV (OUT) with a golden CSV, column by column; columns\n"
    "are matched by name and must have the same unit. A value passes when\n"
    "|out - golden| <= atol + rtol*|golden|; NaN matches only NaN, and inf only an\n"
    "inf of the same sign. Prints one line per column of GOLDEN (worst absolute and\n"
    "relative error, first failing row, ok or FAIL) and a one-line verdict.\n"
    "A column missing from OUT, another unit or another number of rows fails;\n"
    "columns only in OUT are listed but do not fail.\n"
    "\n"
    "options:\n"
    "  --rtol R                 relative tolerance (default " STR(COMPARE_RTOL) ")\n"
    "  --atol A                 absolute tolerance (default " STR(COMPARE_ATOL) ")\n"
    "  --columns NAME,NAME...   compare only these columns of GOLDEN\n"
    "  -h, --help               show this help\n"
    "\n"
    "exit status: 0 the files match, 1 they differ, 2 bad usage or a malformed CSV,\n"
    "3 a file cannot be read\n";

enum { GO_ON = -1 };  /* parse_args: the arguments are fine, compare */

typedef struct compare_args {
    compare_options o;
    const char *files[2];  /* OUT, GOLDEN */
    int nfiles;
    char *columns_text;    /* the --columns values joined by ',', owned; cut in place */
    size_t columns_len;
    const char **columns;  /* [o.ncolumns] names in columns_text, owned array */
} compare_args;

/* Print "mech compare: MESSAGE" on stderr; returns the exit code of bad usage. */
static int usage_error(const char *fmt, ...) CMD_PRINTF(1, 2);

static int usage_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("mech compare: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    return MECH_EXIT_INPUT;
}

/* When argv[*i] is option `name`, as "--name V" or "--name=V": sets *value
 * (NULL when missing), steps *i over a separate value and returns 1. */
static int take_option(int argc, char **argv, int *i, const char *name, const char **value)
{
    size_t n = strlen(name);
    const char *arg = argv[*i];
    if (strncmp(arg, name, n) != 0 || (arg[n] != '\0' && arg[n] != '='))
        return 0;
    if (arg[n] == '=')
        *value = arg + n + 1;
    else
        *value = *i + 1 < argc ? argv[++*i] : NULL;
    return 1;
}

/* *v = the number in s when strtod reads all of s. */
static int parse_number(const char *s, double *v)
{
    char *end;
    *v = strtod(s, &end);
    return end != s && *end == '\0';
}

static int parse_tolerance(const char *opt, const char *text, double *out)
{
    double v;
    if (!text)
        return usage_error("%s needs a value (see 'mech compare --help')", opt);
    if (!parse_number(text, &v) || !isfinite(v) || v < 0)
        return usage_error("%s wants a number >= 0, got '%s'", opt, text);
    *out = v;
    return GO_ON;
}

/* Append one --columns value to a->columns_text. */
static int add_columns(compare_args *a, const char *text)
{
    if (!text)
        return usage_error("%s needs a value (see 'mech compare --help')", "--columns");
    size_t n = strlen(text), old = a->columns_len;
    char *s = realloc(a->columns_text, old + n + 2);
    if (!s)
        return usage_error("out of memory");
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
        return usage_error("out of memory");
    char *s = a->columns_text;
    for (size_t i = 0; i < n; i++) {
        a->columns[i] = s;
        s += strcspn(s, ",");
        if (*s)
            *s++ = '\0';
        if (a->columns[i][0] == '\0')
            return usage_error("--columns: empty column name");
    }
    a->o.columns = a->columns;
    a->o.ncolumns = n;
    return GO_ON;
}

static int add_file(compare_args *a, const char *path)
{
    if (a->nfiles == 2)
        return usage_error("too many files ('%s'): expected OUT.csv GOLDEN.csv", path);
    a->files[a->nfiles++] = path;
    return GO_ON;
}

/* One argument at argv[*i]: an option (with its value) or a file. */
static int parse_arg(int argc, char **argv, int *i, compare_args *a)
{
    const char *arg = argv[*i], *value;
    if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
        fputs(cmd_compare_help, stdout);
        return MECH_EXIT_OK;
    }
    if (take_option(argc, argv, i, "--rtol", &value))
        return parse_tolerance("--rtol", value, &a->o.rtol);
    if (take_option(argc, argv, i, "--atol", &value))
        return parse_tolerance("--atol", value, &a->o.atol);
    if (take_option(argc, argv, i, "--columns", &value))
        return add_columns(a, value);
    if (arg[0] == '-' && arg[1] != '\0')  /* a lone '-' is a file name */
        return usage_error("unknown option '%s' (see 'mech compare --help')", arg);
    return add_file(a, arg);
}

/* Returns GO_ON, or the exit code when done (help) or on bad usage. */
static int parse_args(int argc, char **argv, compare_args *a)
{
    for (int i = 1; i < argc; i++) {
        int code = parse_arg(argc, argv, &i, a);
        if (code != GO_ON)
            return code;
    }
    if (a->nfiles < 2)
        return usage_error("%s files given (usage: mech compare [--rtol R] [--atol A] "
                           "[--columns NAME,...] OUT.csv GOLDEN.csv)",
                           a->nfiles == 0 ? "no" : "only one of two");
    return split_columns(a);
}

int cmd_compare(int argc, char **argv)
{
    compare_args a;
    memset(&a, 0, sizeof a);
    compare_options_default(&a.o);
    int code = parse_args(argc, argv, &a);
    if (code == GO_ON) {
        int rc = compare_csv_files(a.files[0], a.files[1], &a.o, stdout, stderr);
        code = compare_exit_status(rc);
    }
    free(a.columns_text);
    free(a.columns);
    return code;
}
