/* src/cmd_codegen.c: `mech codegen`, a standalone C11 solver for one
 * mechanism (docs/codegen.md, docs/cli.md): options, the prefix, and the
 * two files written whole. */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "codegen.h"
#include "commands.h"
#include "output.h"

const char cmd_codegen_help[] =
    "usage: mech codegen FILE -o NAME.c [--header NAME.h] [--prefix P] [--all]\n"
    "                    [--forces | --no-forces] [--friction on|off|both]\n"
    "\n"
    "Write a standalone C11 source that solves this one mechanism: straight-line\n"
    "code for its loop equations, Jacobian and rate right-hand sides, dense LU of\n"
    "the diagonal blocks of the Jacobian's block triangular form, and the Newton,\n"
    "singularity and branch checks of 'mech solve'. It needs only the C library\n"
    "and libm, and allocates nothing. P_solve(&state, q, qd, qdd) solves one driver\n"
    "position from the guess in state.x into positions, velocities and\n"
    "accelerations of the unknowns and the file's output columns (docs/codegen.md);\n"
    "with forces, also the joint reactions, the driver torque or force, joint\n"
    "friction, springs and the power balance, as 'mech solve --forces'.\n"
    "\n"
    "options:\n"
    "  -o, --output NAME.c  the source (written to a temporary file and renamed when\n"
    "                       complete; '-' for standard output)\n"
    "  --header NAME.h      also write the declarations to NAME.h (the source then\n"
    "                       includes it by its base name); without it the source\n"
    "                       holds them itself\n"
    "  --prefix P           prefix of the generated names (P_solve, P_state, P_OK);\n"
    "                       default: the base name of NAME.c (of FILE with -o -),\n"
    "                       letters, digits and '_' kept, other characters made '_'\n"
    "  --all                solve every unknown, also those no output needs\n"
    "  --forces             also the kinetostatics (as 'outputs: {forces: true}');\n"
    "                       --no-forces: kinematics only (default: as the file says)\n"
    "  --friction MODE      on: the joints' friction coefficients (default); off:\n"
    "                       frictionless; both: also the frictionless columns\n"
    "  -h, --help           show this help\n"
    "\n"
    "exit status: 0 written, 2 invalid file or usage (or a mechanism the generator\n"
    "does not support), 3 a file cannot be read or written\n";

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

static int parse(int argc, char **argv, codegen_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        int has_value = i + 1 < argc;
        if ((strcmp(arg, "-o") == 0 || strcmp(arg, "--output") == 0) && has_value)
            a->out = argv[++i];
        else if (strcmp(arg, "--header") == 0 && has_value)
            a->header = argv[++i];
        else if (strcmp(arg, "--prefix") == 0 && has_value)
            a->prefix = argv[++i];
        else if (strcmp(arg, "--all") == 0)
            a->all = 1;
        else if (strcmp(arg, "--forces") == 0)
            a->forces = 1;
        else if (strcmp(arg, "--no-forces") == 0)
            a->forces = -1;
        else if (strcmp(arg, "--friction") == 0 && has_value) {
            const char *v = argv[++i];
            if (strcmp(v, "on") == 0)
                a->friction = MECH_FRICTION_ON;
            else if (strcmp(v, "off") == 0)
                a->friction = MECH_FRICTION_OFF;
            else if (strcmp(v, "both") == 0)
                a->friction = MECH_FRICTION_BOTH;
            else
                return cmd_usage_error("codegen", "--friction is on, off or both, not '%s'", v);
        }
        else if (arg[0] == '-' && arg[1] != '\0')
            return cmd_usage_error("codegen", "unknown option or missing value '%s'", arg);
        else if (a->file)
            return cmd_usage_error("codegen", "one file at a time ('%s')", arg);
        else
            a->file = arg;
    }
    if (!a->file)
        return cmd_usage_error("codegen", "no file given%s", "");
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
    return refused < 0 ? MECH_EXIT_OK : refused;
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
    for (int i = 1; i < argc; i++)
        if (cmd_wants_help(argv[i])) {
            fputs(cmd_codegen_help, stdout);
            return MECH_EXIT_OK;
        }
    codegen_args a = {0};
    int code = parse(argc, argv, &a);
    if (code != MECH_EXIT_OK)
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
