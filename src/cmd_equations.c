/* src/cmd_equations.c: `mech equations`, the derived loop equations and
 * their symbolic derivatives as text or LaTeX (docs/cli.md). */
#include <stdio.h>
#include <string.h>

#include "commands.h"

const char cmd_equations_help[] =
    "usage: mech equations [--format text|latex] FILE\n"
    "\n"
    "Derive the vector-loop closure equations of the mechanism and print:\n"
    "the unknowns, the loops, the position equations f(x, q) = 0, the nonzeros\n"
    "of the Jacobian df/dx, and the right-hand sides of the velocity equations\n"
    "J x' = b and acceleration equations J x'' = c. All derivatives are symbolic.\n"
    "\n"
    "options:\n"
    "  --format text    plain text (default)\n"
    "  --format latex   a standalone LaTeX document (pdflatex compiles it)\n"
    "  -h, --help       show this help\n"
    "\n"
    "exit status: 0 printed, 2 invalid file or usage, 3 the file cannot be read\n";

int cmd_equations(int argc, char **argv)
{
    mech_format fmt = MECH_FORMAT_TEXT;
    const char *file = NULL;
    for (int i = 1; i < argc; i++) {
        if (cmd_wants_help(argv[i])) {
            fputs(cmd_equations_help, stdout);
            return MECH_EXIT_OK;
        }
        if (strcmp(argv[i], "--format") == 0 && i + 1 < argc) {
            const char *f = argv[++i];
            if (strcmp(f, "text") == 0)
                fmt = MECH_FORMAT_TEXT;
            else if (strcmp(f, "latex") == 0)
                fmt = MECH_FORMAT_LATEX;
            else {
                fprintf(stderr, "mech equations: unknown format '%s' (text or latex)\n", f);
                return MECH_EXIT_INPUT;
            }
        } else if (argv[i][0] == '-') {
            fprintf(stderr, "mech equations: unknown option '%s' (see 'mech equations --help')\n",
                    argv[i]);
            return MECH_EXIT_INPUT;
        } else if (file) {
            fprintf(stderr, "mech equations: one file at a time\n");
            return MECH_EXIT_INPUT;
        } else {
            file = argv[i];
        }
    }
    if (!file) {
        fprintf(stderr, "mech equations: no file given (usage: mech equations [--format text|latex] FILE)\n");
        return MECH_EXIT_INPUT;
    }
    mech_model *m = NULL;
    int code = cmd_load_checked(file, &m);
    if (code != MECH_EXIT_OK)
        return code;
    mech_diag d;
    mech_diag_init(&d);
    mech_system *s = NULL;
    int rc = mech_system_new_named(m, &s, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc == MECH_OK)
        mech_system_print(s, fmt, stdout);
    mech_system_free(&s);
    mech_model_free(&m);
    return rc == MECH_OK ? MECH_EXIT_OK : MECH_EXIT_INPUT;
}
