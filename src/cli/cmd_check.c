/* src/cli/cmd_check.c: `mech check`, validate mechanism files and print a
 * summary of each one's structure (docs/cli.md, section mech check). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "output.h"
#include "base.h"

typedef struct check_args {
    cmd_operands files;
    int quiet;
    cmd_draw_options draw;  /* --draw OUT.svg: draw.out */
    int strict;
} check_args;

static const cmd_opt options[] = {
    {.names = "-q|--quiet", .kind = CMD_OPT_FLAG, .at = offsetof(check_args, quiet), .flag = 1,
     .label = "-q, --quiet", .help = "print only errors, no summary"},
    {.names = "--draw", .kind = CMD_OPT_TEXT, .at = offsetof(check_args, draw.out),
     .label = "--draw OUT",
     .help = "then draw the assembled first position as mech draw does\n"
             "(names, and the guessed pose beside it when they differ;\n"
             "one FILE only)"},
    CMD_STRICT_ENTRY(offsetof(check_args, strict)),
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_check_spec = {
    .name = "check",
    .summary = "validate mechanism files and print their structure",
    .usage = "usage: mech check [-q] [--strict] FILE...\n"
             "       mech check [-q] [--strict] FILE --draw OUT.svg\n",
    .about = "Load each mechanism file, report every error as\n"
             "FILE:LINE:COLUMN: error: MESSAGE, and print a summary: links, joints,\n"
             "unknowns, independent loops, and the mobility (Gruebler-Kutzbach count)\n"
             "against the number of drivers. The mechanism is then assembled over its\n"
             "sweep (positions of every link, no forces) and a suspect assembly is\n"
             "reported as a warning (docs/solver.md section 9); whether the sweep\n"
             "solves is mech solve's to say.\n",
    .opts = options,
    .column = 16,
    .exits = "exit status: 0 all files valid, 1 a suspect assembly under --strict or the\n"
             "drawing's position does not assemble, 2 some file invalid, 3 a file cannot be\n"
             "read or written\n",
    .file_at = offsetof(check_args, files),
    .min_files = 1,
    .no_files = "no files given (usage: mech check [-q] FILE...)",
};

/* One summary line: "  LABEL      TEXT" (model_describe: mech report shows
 * the same lines). */
static void print_line(void *ctx, const char *label, const char *text)
{
    (void)ctx;
    printf("  %-10s %s\n", label, text);
}

static void print_summary(const mech_model *m, const mech_summary *s)
{
    printf("%s: %s\n", m->file, m->name ? m->name : "(unnamed)");
    model_describe(m, s, print_line, NULL);
}

/* Assemble m over its sweep (every link, positions only) and copy the
 * warnings of a suspect assembly to d; other messages of the solve are
 * mech solve's (a sweep that fails is not an invalid file). */
static void check_assembly(const mech_model *m, mech_diag *d)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.all_blocks = 1;
    o.want = MECH_WANT_POSITION;
    o.forces = -1;
    mech_diag own;
    mech_diag_init(&own);
    mech_solve(m, &o, NULL, NULL, &own);
    for (size_t i = 0; i < own.count; i++)
        if (fail_is_suspect_assembly(own.entries[i].kind))
            diag_copy(d, &own.entries[i]);
    mech_diag_free(&own);
}

int cmd_check(int argc, char **argv)
{
    check_args a;
    memset(&a, 0, sizeof a);
    cmd_draw_options_default(&a.draw);
    int code = cmd_opts_parse(&cmd_check_spec, argc, argv, &a), status = MECH_EXIT_OK;
    if (code < 0 && a.draw.out && a.files.n > 1)
        code = cmd_usage_error("check", "%s", "--draw draws one file (give one FILE)");
    if (code < 0 && a.draw.out)
        code = cmd_refuse_input("check", a.draw.out, a.files.v, a.files.n);
    for (int i = 0; code < 0 && i < a.files.n; i++) {
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_summary s;
        int rc = mech_load_file(a.files.v[i], &m, &d);
        if (rc == MECH_OK)
            rc = mech_check(m, &s, &d);
        if (rc == MECH_OK)
            check_assembly(m, &d);
        int suspect = a.strict ? cmd_strict_assembly(&d) : 0;
        mech_diag_print(&d, stderr);
        if (rc == MECH_OK && !a.quiet)
            print_summary(m, &s);
        if (rc == MECH_OK && a.draw.out) {
            fflush(stdout);  /* the summary before the drawing's notes */
            status = cmd_draw_model("check", m, &a.draw);
        }
        if (rc == MECH_EIO && status == MECH_EXIT_OK)
            status = MECH_EXIT_IO;
        else if (rc != MECH_OK)
            status = MECH_EXIT_INPUT;
        else if (suspect > 0 && status == MECH_EXIT_OK)
            status = MECH_EXIT_SOLVE;
        mech_model_free(&m);
        mech_diag_free(&d);
    }
    free(a.files.v);
    return code >= 0 ? code : status;
}
