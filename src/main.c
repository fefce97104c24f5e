/* src/main.c: the `mech` command line, a thin layer over libmech.
 * Maps library status to the documented exit codes (docs/cli.md). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmd_plot.h"
#include "commands.h"
#include "compare.h"

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
    const char *help;
} command;

static int cmd_check(int argc, char **argv);
static int cmd_equations(int argc, char **argv);

static const command commands[] = {
    {"check", cmd_check, "validate mechanism files and print their structure",
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
     "exit status: 0 all files valid, 2 some file invalid, 3 a file cannot be read\n"},
    {"equations", cmd_equations, "print the derived loop equations and their derivatives",
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
     "exit status: 0 printed, 2 invalid file or usage, 3 the file cannot be read\n"},
    {"solve", cmd_solve, "solve positions, velocities and accelerations over the driver range",
     cmd_solve_help},
    {"compare", cmd_compare, "compare a result CSV with a golden CSV", compare_help},
    {"batch", cmd_batch, "solve many files on worker threads, with golden comparisons",
     cmd_batch_help},
    {"sweep", cmd_sweep, "solve a grid of variants of one mechanism, one summary row each",
     cmd_sweep_help},
    {"plot", cmd_plot, "draw SVG figures of the sweep (docs/plots.md)", cmd_plot_help},
    {"animate", cmd_animate, "write an animated SVG of the mechanism", cmd_animate_help},
};
#define NCOMMANDS (sizeof commands / sizeof commands[0])

static void print_usage(FILE *out)
{
    fprintf(out,
            "usage: mech [--help] [--version] COMMAND [ARGS]\n"
            "\n"
            "mech analyses planar mechanisms described in YAML files (docs/format.md).\n"
            "\n"
            "commands:\n");
    for (size_t i = 0; i < NCOMMANDS; i++)
        fprintf(out, "  %-10s %s\n", commands[i].name, commands[i].summary);
    fprintf(out,
            "\n"
            "Run 'mech COMMAND --help' for a command's options.\n"
            "\n"
            "exit status:\n"
            "  0  success\n"
            "  1  the input is valid but the mechanism could not be solved\n"
            "  2  bad usage or invalid input (messages say FILE:LINE:COLUMN)\n"
            "  3  a file could not be read or written\n");
}

int cmd_wants_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

static const char *drive_text(const mech_model *m, char *buf, size_t size)
{
    if (!m->has_driver)
        return "none";
    const mech_driver *dr = &m->driver;
    if (dr->kind == MECH_DRIVE_ANGLE)
        snprintf(buf, size, "angle of link '%s', %d position%s", m->links[dr->index].name,
                 dr->nvalues, dr->nvalues == 1 ? "" : "s");
    else
        snprintf(buf, size, "displacement of slider '%s', %d position%s",
                 m->joints[dr->index].name, dr->nvalues, dr->nvalues == 1 ? "" : "s");
    return buf;
}

static void print_summary(const mech_model *m, const mech_summary *s)
{
    char buf[256];
    int nsliders = s->nprismatic + s->npin_in_slot;
    printf("%s: %s\n", m->file, m->name ? m->name : "(unnamed)");
    printf("  links      %d (ground + %d moving)\n", s->nlinks, s->nlinks - 1);
    printf("  joints     %d (%d revolute, %d prismatic slider, %d pin-in-slot slider)\n",
           s->nrevolute + nsliders, s->nrevolute, s->nprismatic, s->npin_in_slot);
    printf("  unknowns   %d (%d link angles + %d slider displacements - 1 driver)\n",
           s->nunknowns, s->nlinks - 1 - s->nprismatic, nsliders);
    printf("  loops      %d independent%s, %d equations\n", s->nloops,
           m->nloops ? " (listed in the file)" : " (found automatically)", s->nequations);
    printf("  mobility   %d = 3*(%d-1) - 2*%d - %d, drivers %d\n", s->mobility, s->nlinks,
           s->nrevolute + s->nprismatic, s->npin_in_slot, s->ndrivers);
    printf("  driver     %s\n", drive_text(m, buf, sizeof buf));
    printf("  outputs    %d points, %d links, %d sliders%s\n", m->outputs.npoints,
           m->outputs.nlinks, m->outputs.nsliders, m->outputs.forces ? ", forces" : "");
}

static int cmd_check(int argc, char **argv)
{
    int quiet = 0, nfiles = 0, status = MECH_EXIT_OK;
    for (int i = 1; i < argc; i++) {
        if (cmd_wants_help(argv[i])) {
            fputs(commands[0].help, stdout);
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

int cmd_load_checked(const char *path, mech_model **m)
{
    return cmd_load_checked_with(path, NULL, 0, m);
}

int cmd_load_checked_with(const char *path, const mech_override *ov, int nov, mech_model **m)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_summary s;
    int rc = mech_load_file_with(path, ov, nov, m, &d);
    if (rc == MECH_OK)
        rc = mech_check(*m, &s, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc == MECH_OK)
        return MECH_EXIT_OK;
    mech_model_free(m);
    return rc == MECH_EIO ? MECH_EXIT_IO : MECH_EXIT_INPUT;
}

static int cmd_equations(int argc, char **argv)
{
    mech_format fmt = MECH_FORMAT_TEXT;
    const char *file = NULL;
    for (int i = 1; i < argc; i++) {
        if (cmd_wants_help(argv[i])) {
            fputs(commands[1].help, stdout);
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
    int rc = mech_system_new(m, &s, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc == MECH_OK)
        mech_system_print(s, fmt, stdout);
    mech_system_free(&s);
    mech_model_free(&m);
    return rc == MECH_OK ? MECH_EXIT_OK : MECH_EXIT_INPUT;
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        print_usage(stderr);
        return MECH_EXIT_INPUT;
    }
    if (cmd_wants_help(argv[1]) || strcmp(argv[1], "help") == 0) {
        if (argc > 2)
            for (size_t i = 0; i < NCOMMANDS; i++)
                if (strcmp(argv[2], commands[i].name) == 0) {
                    fputs(commands[i].help, stdout);
                    return MECH_EXIT_OK;
                }
        print_usage(stdout);
        return MECH_EXIT_OK;
    }
    if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "-V") == 0) {
        printf("mech %s\n", MECH_VERSION);
        return MECH_EXIT_OK;
    }
    for (size_t i = 0; i < NCOMMANDS; i++)
        if (strcmp(argv[1], commands[i].name) == 0)
            return commands[i].run(argc - 1, argv + 1);
    fprintf(stderr, "mech: unknown command '%s' (see 'mech --help')\n", argv[1]);
    return MECH_EXIT_INPUT;
}
