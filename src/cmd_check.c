/* src/cmd_check.c: `mech check`, validate mechanism files and print a
 * summary of each one's structure (docs/cli.md, section mech check). */
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "describe.h"

const char cmd_check_help[] =
    "usage: mech check [-q] FILE...\n"
    "\n"
    "Load each mechanism file, report every error as FILE:LINE:COLUMN: error: MESSAGE,\n"
    "and print a summary: links, joints, unknowns, independent loops, and the\n"
    "mobility (Gruebler-Kutzbach count) against the number of drivers.\n"
    "\n"
    "options:\n"
    "  -q, --quiet   print only errors, no summary\n"
    "  -h, --help    show this help\n"
    "\n"
    "exit status: 0 all files valid, 2 some file invalid, 3 a file cannot be read\n";

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

int cmd_check(int argc, char **argv)
{
    int quiet = 0, nfiles = 0, status = MECH_EXIT_OK;
    for (int i = 1; i < argc; i++) {
        if (cmd_wants_help(argv[i])) {
            fputs(cmd_check_help, stdout);
            return MECH_EXIT_OK;
        }
        if (strcmp(argv[i], "-q") == 0 || strcmp(argv[i], "--quiet") == 0)
            quiet = 1;
        else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            fprintf(stderr, "mech check: unknown option '%s' (see 'mech check --help')\n", argv[i]);
            return MECH_EXIT_INPUT;
        } else
            nfiles++;
    }
    if (nfiles == 0) {
        fprintf(stderr, "mech check: no files given (usage: mech check [-q] FILE...)\n");
        return MECH_EXIT_INPUT;
    }
    for (int i = 1; i < argc; i++) {
        if (argv[i][0] == '-' && argv[i][1] != '\0')
            continue;
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_summary s;
        int rc = mech_load_file(argv[i], &m, &d);
        if (rc == MECH_OK)
            rc = mech_check(m, &s, &d);
        mech_diag_print(&d, stderr);
        if (rc == MECH_OK && !quiet)
            print_summary(m, &s);
        if (rc == MECH_EIO && status == MECH_EXIT_OK)
            status = MECH_EXIT_IO;
        else if (rc != MECH_OK)
            status = MECH_EXIT_INPUT;
        mech_model_free(&m);
        mech_diag_free(&d);
    }
    return status;
}
