/* src/cli/cmd_codegen.c: `mech codegen`, a standalone C11 solver for one
 * mechanism (docs/codegen.md, docs/cli.md): options, the prefix, and the
 * two files written whole. */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codegen.h"
#include "cli.h"
#include "output.h"

/* Base name of path without its extension, as a C identifier (into buf). */
static void prefix_from(const char *path, char *buf, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t n = 0;
    if (!isalpha((unsigned char)base[0]) && base[0] != '_' && n + 1 < size)
        buf[n++] = 'm';
    for (const char *c = base; *c && *c != '.' && n + 1 < size && n < 40; c++)
        buf[n++] = isalnum((unsigned char)*c) ? *c : '_';
    buf[n] = '\0';
}

typedef struct codegen_args {
    const char *file, *out, *header, *prefix;
    int all, forces, friction;
} codegen_args;

#define AT(field) offsetof(codegen_args, field)

static const cmd_opt options[] = {
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .label = "-o, --output NAME.c",
     .help = "the source (written to a temporary file and renamed when\n"
             "complete; '-' for standard output)"},
    {.names = "--header", .kind = CMD_OPT_TEXT, .at = AT(header), .label = "--header NAME.h",
     .help = "also write the declarations to NAME.h (the source then\n"
             "includes it by its base name); without it the source\n"
             "holds them itself"},
    {.names = "--prefix", .kind = CMD_OPT_TEXT, .at = AT(prefix), .label = "--prefix P",
     .help = "prefix of the generated names (P_solve, P_state, P_OK);\n"
             "default: the base name of NAME.c (of FILE with -o -),\n"
             "letters, digits and '_' kept, other characters made '_'"},
    {.names = "--all", .kind = CMD_OPT_FLAG, .at = AT(all), .flag = 1, .label = "--all",
     .help = "solve every unknown, also those no output needs"},
    {.names = "--forces", .kind = CMD_OPT_FLAG, .at = AT(forces), .flag = 1, .label = "--forces",
     .help = "also the kinetostatics (as 'outputs: {forces: true}');\n"
             "--no-forces: kinematics only (default: as the file says)"},
    {.names = "--no-forces", .kind = CMD_OPT_FLAG, .at = AT(forces), .flag = -1},
    CMD_FRICTION_ENTRY(AT(friction), "on: the joints' friction coefficients (default); off:\n"
             "frictionless; both: also the frictionless columns"),
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_codegen_spec = {
    .name = "codegen",
    .summary = "write a standalone C solver for one mechanism (docs/codegen.md)",
    .usage = "usage: mech codegen FILE -o NAME.c [--header NAME.h] [--prefix P] [--all]\n"
             "                    [--forces | --no-forces] [--friction on|off|both]\n",
    .about = "Write a standalone C11 source that solves this one mechanism: straight-line\n"
             "code for its loop equations, Jacobian and rate right-hand sides, dense LU of\n"
             "the diagonal blocks of the Jacobian's block triangular form, and the Newton,\n"
             "singularity and branch checks of 'mech solve'. It needs only the C library\n"
             "and libm, and allocates nothing. P_solve(&state, q, qd, qdd) solves one driver\n"
             "position from the guess in state.x into positions, velocities and\n"
             "accelerations of the unknowns and the file's output columns (docs/codegen.md);\n"
             "with forces, also the joint reactions, the driver torque or force, joint\n"
             "friction, springs and the power balance, as 'mech solve --forces'.\n",
    .opts = options,
    .column = 23,
    .exits = "exit status: 0 written, 2 invalid file or usage (or a mechanism the generator\n"
             "does not support), 3 a file cannot be read or written\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given",
};

/* The options checked together: -1 to go on, else the exit status. */
static int check_args(const codegen_args *a)
{
    if (!a->out)
        return cmd_usage_error("codegen", "no output given (-o NAME.c)%s", "");
    if (a->header && (strcmp(a->header, "-") == 0 || strcmp(a->header, a->out) == 0))
        return cmd_usage_error("codegen", "the header must be a file other than the source "
                               "('%s')", a->header);
    if (a->header && strpbrk(a->header, "\"\\\n"))
        return cmd_usage_error("codegen", "the header's name cannot be #included: it has a "
                               "quote, a backslash or a line break ('%s')", a->header);
    const char *inputs[] = {a->file};
    int refused = cmd_refuse_input("codegen", a->out, inputs, 1);
    if (refused < 0 && a->header)
        refused = cmd_refuse_input("codegen", a->header, inputs, 1);
    return refused;
}

static int write_both(const codegen *g, const codegen_args *a)
{
    mech_diag d;
    mech_diag_init(&d);
    int rc = MECH_OK;
    if (a->header)
        rc = write_file_whole(a->header, codegen_emit_header, g, &d);
    if (rc == MECH_OK)
        rc = write_file_whole(a->out, codegen_emit_source, g, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    return cmd_exit_status(rc);
}

int cmd_codegen(int argc, char **argv)
{
    codegen_args a = {0};
    int code = cmd_opts_parse(&cmd_codegen_spec, argc, argv, &a);
    if (code < 0)
        code = check_args(&a);
    if (code >= 0)
        return code;
    char prefix[48], include[256];
    if (a.prefix)
        snprintf(prefix, sizeof prefix, "%s", a.prefix);
    else
        prefix_from(strcmp(a.out, "-") == 0 ? a.file : a.out, prefix, sizeof prefix);
    if (a.header) {
        const char *base = strrchr(a.header, '/');
        snprintf(include, sizeof include, "%s", base ? base + 1 : a.header);
    }
    mech_model *m = NULL;
    code = cmd_load_checked(a.file, &m);
    if (code != MECH_EXIT_OK)
        return code;
    codegen_options o = {a.prefix ? a.prefix : prefix, a.header ? include : NULL, a.all,
                         a.forces, a.friction};
    codegen g;
    mech_diag d;
    mech_diag_init(&d);
    int rc = codegen_init(&g, m, &o, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    code = rc == MECH_OK ? write_both(&g, &a) : cmd_exit_status(rc);
    codegen_free(&g);
    mech_model_free(&m);
    return code;
}
