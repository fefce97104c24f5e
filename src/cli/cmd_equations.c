/* src/cli/cmd_equations.c: `mech equations`, the derived loop equations and
 * their symbolic derivatives as text or LaTeX (docs/cli.md). */
#include <stdio.h>

#include "cli.h"

typedef struct equations_args {
    const char *file;
    int format;  /* mech_format */
} equations_args;

static const cmd_word formats[] = {{"text", MECH_FORMAT_TEXT}, {"latex", MECH_FORMAT_LATEX}, {NULL, 0}};

static const cmd_opt options[] = {
    {.names = "--format", .kind = CMD_OPT_WORD, .at = offsetof(equations_args, format),
     .words = formats, .expect = "is text or latex",
     .label = "--format text", .help = "plain text (default)"},
    {.label = "--format latex", .help = "a standalone LaTeX document (pdflatex compiles it)"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_equations_spec = {
    .name = "equations",
    .summary = "print the derived loop equations and their derivatives",
    .usage = "usage: mech equations [--format text|latex] FILE\n",
    .about = "Derive the vector-loop closure equations of the mechanism and print:\n"
             "the unknowns, the loops, the position equations f(x, q) = 0, the nonzeros\n"
             "of the Jacobian df/dx, and the right-hand sides of the velocity equations\n"
             "J x' = b and acceleration equations J x'' = c. All derivatives are symbolic.\n",
    .opts = options,
    .column = 19,
    .exits = "exit status: 0 printed, 2 invalid file or usage, 3 the file cannot be read\n",
    .max_files = 1,
    .file_at = offsetof(equations_args, file),
    .min_files = 1,
    .no_files = "no file given (usage: mech equations [--format text|latex] FILE)",
};

int cmd_equations(int argc, char **argv)
{
    equations_args a = {NULL, MECH_FORMAT_TEXT};
    int code = cmd_opts_parse(&cmd_equations_spec, argc, argv, &a);
    if (code >= 0)
        return code;
    mech_model *m = NULL;
    code = cmd_load_checked(a.file, &m);
    if (code != MECH_EXIT_OK)
        return code;
    mech_diag d;
    mech_diag_init(&d);
    mech_system *s = NULL;
    int rc = mech_system_new_named(m, &s, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc == MECH_OK)
        mech_system_print(s, (mech_format)a.format, stdout);
    mech_system_free(&s);
    mech_model_free(&m);
    return rc == MECH_OK ? MECH_EXIT_OK : MECH_EXIT_INPUT;
}
