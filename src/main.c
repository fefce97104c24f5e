/* src/main.c: the `mech` command line, a thin layer over libmech.
 * Maps library status to the documented exit codes (docs/cli.md); a
 * command whose standard output was lost exits 3. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmd_plot.h"
#include "commands.h"
#include "output.h"

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
    const char *help;
} command;

static const command commands[] = {
    {"check", cmd_check, "validate mechanism files and print their structure", cmd_check_help},
    {"equations", cmd_equations, "print the derived loop equations and their derivatives",
     cmd_equations_help},
    {"solve", cmd_solve, "solve positions, velocities and accelerations over the driver range",
     cmd_solve_help},
    {"compare", cmd_compare, "compare a result CSV with a golden CSV", cmd_compare_help},
    {"batch", cmd_batch, "solve many files on worker threads, with golden comparisons",
     cmd_batch_help},
    {"sweep", cmd_sweep, "solve a grid of variants of one mechanism, one summary row each",
     cmd_sweep_help},
    {"merge", cmd_merge, "join the shards of a sweep or batch, checking their manifests",
     cmd_merge_help},
    {"plot", cmd_plot, "draw SVG figures of the sweep (docs/plots.md)", cmd_plot_help},
    {"animate", cmd_animate, "write an animated SVG of the mechanism", cmd_animate_help},
    {"report", cmd_report, "write one self-contained HTML page of the mechanism (docs/report.md)",
     cmd_report_help},
    {"codegen", cmd_codegen, "write a standalone C solver for one mechanism (docs/codegen.md)",
     cmd_codegen_help},
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

static int dispatch(int argc, char **argv)
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

/* Standard output is where most commands put their results: a lost write
 * (a full disk, /dev/full, a closed pipe's EIO) is an error, exit 3. */
static int check_stdout(int code)
{
    errno = 0;
    int bad = fflush(stdout) != 0;
    int e = errno;
    if (!bad && !ferror(stdout))
        return code;
    if (output_stdout_reported())
        return MECH_EXIT_IO;
    fprintf(stderr, "mech: cannot write standard output: %s\n", strerror(e ? e : EIO));
    return MECH_EXIT_IO;
}

int main(int argc, char **argv)
{
    output_catch_signals();
    return check_stdout(dispatch(argc, argv));
}
