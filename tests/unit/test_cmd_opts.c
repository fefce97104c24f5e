/* tests/unit/test_cmd_opts.c: the command line's one option parser
 * (src/cli/cmd_opts.c): every kind of value read exactly (whole numbers in
 * digits, decimal reals, exact words) into its target, --name=value, flags,
 * files, the last value wins, what a manifest sees (cmd_opts_each), the help
 * laid out from the table; and every command's table well formed (each
 * option reachable, its help within 80 columns, no spelling twice). */
#include <criterion/criterion.h>
#include <criterion/redirect.h>
#include <float.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

typedef struct toy {
    const char *file, *out;
    int flag, count, word, calls;
    long big;
    unsigned long long seed;
    double real, open;
    const char *last_call;
} toy;

static int note_call(const char *command, void *target, const char *value)
{
    (void)command;
    toy *t = target;
    t->calls++;
    t->last_call = value;
    return strcmp(value, "stop") == 0 ? MECH_EXIT_INPUT : -1;
}

static const cmd_word words[] = {{"positions", 1}, {"velocities", 2}, {NULL, 0}};

#define AT(f) offsetof(toy, f)
static const cmd_opt toy_opts[] = {
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .flags = CMD_RUN_ONLY,
     .label = "-o, --output FILE", .help = "where\nsecond line"},
    {.names = "--flag", .kind = CMD_OPT_FLAG, .at = AT(flag), .flag = 7, .label = "--flag",
     .help = "a flag"},
    {.names = "--no-flag", .kind = CMD_OPT_FLAG, .at = AT(flag), .flag = -1},
    {.names = "--count", .kind = CMD_OPT_INT, .at = AT(count), .lo = -5, .hi = 100,
     .expect = "needs a whole number from -5 to 100", .label = "--count N", .help = "how many"},
    {.names = "--big", .kind = CMD_OPT_LONG, .at = AT(big), .lo = 0, .hi = 1e12,
     .expect = "needs 0 to 10^12", .label = "--a-very-long-label-here X", .help = "long"},
    {.names = "--seed", .kind = CMD_OPT_U64, .at = AT(seed), .expect = "needs 0 to 2^64-1"},
    {.names = "--real", .kind = CMD_OPT_REAL, .at = AT(real), .lo = 1e-15, .hi = 1,
     .flags = CMD_OPEN_HI, .expect = "needs 1e-15 to below 1"},
    {.names = "--open", .kind = CMD_OPT_REAL, .at = AT(open), .lo = 0, .hi = DBL_MAX,
     .flags = CMD_OPEN_LO, .expect = "needs a number > 0"},
    {.names = "--level", .kind = CMD_OPT_WORD, .at = AT(word), .words = words,
     .expect = "is positions or velocities"},
    {.names = "--call", .kind = CMD_OPT_CALL, .at = 0, .call = note_call},
    {.label = "--help-only LINE", .help = "only in the help"},
    {.names = "-h|--help", .kind = CMD_OPT_HELP, .label = "-h, --help", .help = "show this help"},
    {NULL}};

static const cmd_spec toy_spec = {
    .name = "toy",
    .usage = "usage: mech toy FILE\n",
    .about = "A toy.\n",
    .opts = toy_opts,
    .column = 20,
    .exits = "exit status: 0\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given",
};

/* Parse a NULL-terminated argument list (after "toy") into *t. */
static int parse(toy *t, const char **args)
{
    const char *argv[32] = {"toy"};
    int argc = 1;
    while (*args)
        argv[argc++] = *args++;
    memset(t, 0, sizeof *t);
    return cmd_opts_parse(&toy_spec, argc, (char **)argv, t);
}

#define PARSE(t, ...) parse(t, (const char *[]){__VA_ARGS__, NULL})

Test(cmd_opts, every_kind_into_its_target)
{
    toy t;
    cr_assert_eq(PARSE(&t, "f.yaml", "--flag", "--count", "-5", "--big", "1000000000000",
                       "--seed", "18446744073709551615", "--real", "1e-10", "--open", "0.5",
                       "--level", "velocities", "-o", "-x.csv", "--call", "a", "--call", "b"),
                 -1);
    cr_expect_str_eq(t.file, "f.yaml");
    cr_expect_eq(t.flag, 7);
    cr_expect_eq(t.count, -5);
    cr_expect_eq(t.big, 1000000000000L);
    cr_expect_eq(t.seed, 18446744073709551615ULL);
    cr_expect_eq(t.real, 1e-10);
    cr_expect_eq(t.open, 0.5);
    cr_expect_eq(t.word, 2);
    cr_expect_str_eq(t.out, "-x.csv", "a value may start with '-'");
    cr_expect_eq(t.calls, 2, "a CALL sees every occurrence");
    cr_expect_str_eq(t.last_call, "b");
}

Test(cmd_opts, long_names_take_equals_and_the_last_value_wins)
{
    toy t;
    cr_assert_eq(PARSE(&t, "--count=3", "f.yaml", "--count", "9", "--output=o.csv",
                       "--level=positions", "--no-flag"), -1);
    cr_expect_eq(t.count, 9);
    cr_expect_str_eq(t.out, "o.csv");
    cr_expect_eq(t.word, 1);
    cr_expect_eq(t.flag, -1);
    cr_expect_eq(PARSE(&t, "f.yaml", "-o=x"), MECH_EXIT_INPUT, "'=' only after a long name");
}

Test(cmd_opts, numbers_are_exact_words, .init = cr_redirect_stderr)
{
    toy t;
    /* whole numbers: digits only, an optional '-' first (as in a file) */
    static const char *const not_whole[] = {"0x10", "1e3", "16.0", " 16", "+16", "16 ", "",
                                            "-", "1O", "nan", "99999999999999999999"};
    for (size_t i = 0; i < sizeof not_whole / sizeof *not_whole; i++)
        cr_expect_eq(PARSE(&t, "f.yaml", "--count", not_whole[i]), MECH_EXIT_INPUT,
                     "--count '%s' accepted", not_whole[i]);
    cr_expect_eq(PARSE(&t, "f.yaml", "--count", "101"), MECH_EXIT_INPUT, "above the range");
    cr_expect_eq(PARSE(&t, "f.yaml", "--count", "-6"), MECH_EXIT_INPUT, "below the range");
    cr_expect_eq(PARSE(&t, "f.yaml", "--count", "100"), -1);
    cr_expect_eq(PARSE(&t, "f.yaml", "--seed", "-1"), MECH_EXIT_INPUT);
    cr_expect_eq(PARSE(&t, "f.yaml", "--seed", "18446744073709551616"), MECH_EXIT_INPUT);
    /* reals: decimal, within the range, open ends refused */
    static const char *const not_real[] = {"0x1p-30", "inf", "nan", "1e", ".", "1e-10x", " 0.5"};
    for (size_t i = 0; i < sizeof not_real / sizeof *not_real; i++)
        cr_expect_eq(PARSE(&t, "f.yaml", "--real", not_real[i]), MECH_EXIT_INPUT,
                     "--real '%s' accepted", not_real[i]);
    cr_expect_eq(PARSE(&t, "f.yaml", "--real", "1"), MECH_EXIT_INPUT, "the open end");
    cr_expect_eq(PARSE(&t, "f.yaml", "--real", "1e-16"), MECH_EXIT_INPUT);
    cr_expect_eq(PARSE(&t, "f.yaml", "--real", ".5"), -1);
    cr_expect_eq(t.real, 0.5);
    cr_expect_eq(PARSE(&t, "f.yaml", "--open", "0"), MECH_EXIT_INPUT, "the open end");
    cr_expect_eq(PARSE(&t, "f.yaml", "--open", "1E300"), -1);
    /* words: whole words only */
    cr_expect_eq(PARSE(&t, "f.yaml", "--level", "positionsXYZ"), MECH_EXIT_INPUT);
    cr_expect_eq(PARSE(&t, "f.yaml", "--level", "position"), MECH_EXIT_INPUT);
    cr_expect_eq(PARSE(&t, "f.yaml", "--level", "Positions"), MECH_EXIT_INPUT);
}

Test(cmd_opts, the_refusal_names_option_value_and_reason, .init = cr_redirect_stderr)
{
    toy t;
    cr_assert_eq(PARSE(&t, "f.yaml", "--count", "0x10"), MECH_EXIT_INPUT);
    fflush(stderr);
    cr_expect_stderr_eq_str("mech toy: --count needs a whole number from -5 to 100, not '0x10': "
                            "write it with digits only (see 'mech toy --help')\n");
}

Test(cmd_opts, a_word_refused_names_the_nearest, .init = cr_redirect_stderr)
{
    toy t;
    cr_assert_eq(PARSE(&t, "f.yaml", "--level", "positionsXYZ"), MECH_EXIT_INPUT);
    fflush(stderr);
    cr_expect_stderr_eq_str("mech toy: --level is positions or velocities, not 'positionsXYZ' "
                            "(did you mean 'positions'?) (see 'mech toy --help')\n");
}

Test(cmd_opts, usage_errors, .init = cr_redirect_stderr)
{
    toy t;
    cr_expect_eq(PARSE(&t, "f.yaml", "--count"), MECH_EXIT_INPUT, "a value missing");
    cr_expect_eq(PARSE(&t, "f.yaml", "--flag=1"), MECH_EXIT_INPUT, "a flag with a value");
    cr_expect_eq(PARSE(&t, "f.yaml", "--frobnicate"), MECH_EXIT_INPUT, "unknown");
    cr_expect_eq(PARSE(&t, "f.yaml", "g.yaml"), MECH_EXIT_INPUT, "a second file");
    cr_expect_eq(PARSE(&t, "--flag"), MECH_EXIT_INPUT, "no file");
    cr_expect_eq(PARSE(&t, "-"), -1, "a lone '-' is a file");
    cr_expect_str_eq(t.file, "-");
    cr_expect_eq(PARSE(&t, "f.yaml", "--call", "stop", "--count", "x"), MECH_EXIT_INPUT,
                 "a CALL's status stops the parse");
    cr_expect_eq(t.calls, 1);
    cr_expect_eq(PARSE(&t, "--help-only", "f.yaml"), MECH_EXIT_INPUT, "a help line is no option");
}

Test(cmd_opts, an_unknown_option_names_the_nearest, .init = cr_redirect_stderr)
{
    toy t;
    cr_assert_eq(PARSE(&t, "f.yaml", "--levle=positions"), MECH_EXIT_INPUT);
    fflush(stderr);
    cr_expect_stderr_eq_str("mech toy: unknown option '--levle=positions' (did you mean "
                            "'--level'?) (see 'mech toy --help')\n");
}

typedef struct seen {
    char text[512];
} seen;

/* "file NAME;", "NAME;", "run-only NAME=VALUE;" ... */
static void record(void *ctx, const cmd_opt *o, const char *name, const char *value)
{
    seen *s = ctx;
    size_t n = strlen(s->text);
    snprintf(s->text + n, sizeof s->text - n, "%s%s%s%s%s;", o ? "" : "file ",
             o && (o->flags & CMD_RUN_ONLY) ? "run-only " : "", name, value ? "=" : "",
             value ? value : "");
}

Test(cmd_opts, each_argument_as_parsed)
{
    const char *argv[] = {"toy", "--output=o.csv", "f.yaml", "--count", "3", "--flag",
                          "-o", "p.csv", "--level=velocities", NULL};
    toy t = {0};
    cr_assert_eq(cmd_opts_parse(&toy_spec, 9, (char **)argv, &t), -1);
    seen s = {""};
    cmd_opts_each(&toy_spec, 9, (char **)argv, record, &s);
    cr_expect_str_eq(s.text, "run-only -o=o.csv;file f.yaml;--count=3;--flag;run-only -o=p.csv;"
                             "--level=velocities;");
}

Test(cmd_opts, help_from_the_table)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    cmd_opts_help(&toy_spec, f);
    fclose(f);
    cr_expect_str_eq(text,
                     "usage: mech toy FILE\n"
                     "\n"
                     "A toy.\n"
                     "\n"
                     "options:\n"
                     "  -o, --output FILE  where\n"
                     "                    second line\n"
                     "  --flag            a flag\n"
                     "  --count N         how many\n"
                     "  --a-very-long-label-here X  long\n"
                     "  --help-only LINE  only in the help\n"
                     "  -h, --help        show this help\n"
                     "\n"
                     "exit status: 0\n");
    free(text);
}

/* ---- every command's table ---------------------------------------------- */

static const cmd_spec *const specs[] = {
    &cmd_check_spec, &cmd_equations_spec, &cmd_solve_spec,   &cmd_compare_spec,
    &cmd_batch_spec, &cmd_sweep_spec,     &cmd_merge_spec,   &cmd_plot_spec,
    &cmd_animate_spec, &cmd_draw_spec,    &cmd_report_spec, &cmd_watch_spec,
    &cmd_codegen_spec, &cmd_fit_spec, &cmd_simulate_spec, &cmd_cam_spec};

/* Every spelling of a command's table, in order, into names[]. */
static int spellings(const cmd_spec *spec, char names[][48], int max)
{
    int n = 0;
    for (const cmd_opt *o = spec->opts; o->names || o->label; o++)
        for (const char *s = o->names ? o->names : ""; *s && n < max;) {
            size_t len = strcspn(s, "|");
            snprintf(names[n++], 48, "%.*s", (int)len, s);
            s += len + (s[len] == '|');
        }
    return n;
}

Test(cmd_opts, every_command_table_is_well_formed)
{
    for (size_t c = 0; c < sizeof specs / sizeof *specs; c++) {
        const cmd_spec *spec = specs[c];
        char names[64][48];
        int n = spellings(spec, names, 64), help = 0;
        for (int i = 0; i < n; i++) {
            cr_expect(names[i][0] == '-' && names[i][1] != '\0', "mech %s: spelling '%s'",
                      spec->name, names[i]);
            for (int j = 0; j < i; j++)
                cr_expect_str_neq(names[i], names[j], "mech %s: '%s' twice", spec->name,
                                  names[i]);
        }
        for (const cmd_opt *o = spec->opts; o->names || o->label; o++) {
            help |= o->kind == CMD_OPT_HELP && o->names && strcmp(o->names, "-h|--help") == 0;
            int needs_expect = o->names && (o->kind == CMD_OPT_INT || o->kind == CMD_OPT_LONG ||
                                            o->kind == CMD_OPT_U64 || o->kind == CMD_OPT_REAL ||
                                            o->kind == CMD_OPT_WORD);
            cr_expect(!needs_expect || o->expect, "mech %s %s: no refusal text", spec->name,
                      o->names);
            cr_expect(o->kind != CMD_OPT_WORD || !o->names || o->words, "mech %s %s: no words",
                      spec->name, o->names);
            cr_expect(o->kind != CMD_OPT_CALL || o->call, "mech %s %s: no call", spec->name,
                      o->names);
        }
        cr_expect(help, "mech %s: no -h|--help", spec->name);
        char *text = NULL;
        size_t size = 0;
        FILE *f = open_memstream(&text, &size);
        cmd_opts_help(spec, f);
        fclose(f);
        cr_expect(strncmp(text, "usage: mech ", 12) == 0, "mech %s: the help's first line",
                  spec->name);
        for (const char *line = text; *line;) {
            size_t len = strcspn(line, "\n");
            cr_expect_leq(len, 80, "mech %s --help: a line of %zu columns: %.*s", spec->name,
                          len, (int)len, line);
            line += len + (line[len] == '\n');
        }
        free(text);
    }
}
