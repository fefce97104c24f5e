/* src/cli/main.c: the `mech` command line, a thin layer over libmech.
 * Maps library status to the documented exit codes (docs/cli.md); a
 * command whose standard output was lost exits 3. */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "output.h"

typedef struct command {
    const cmd_spec *spec;  /* name, summary, help (src/cli/cli.h) */
    int (*run)(int argc, char **argv);
} command;

static const command commands[] = {
    {&cmd_check_spec, cmd_check},     {&cmd_equations_spec, cmd_equations},
    {&cmd_solve_spec, cmd_solve},     {&cmd_compare_spec, cmd_compare},
    {&cmd_batch_spec, cmd_batch},     {&cmd_sweep_spec, cmd_sweep},
    {&cmd_merge_spec, cmd_merge},     {&cmd_plot_spec, cmd_plot},
    {&cmd_animate_spec, cmd_animate}, {&cmd_draw_spec, cmd_draw},
    {&cmd_report_spec, cmd_report},   {&cmd_watch_spec, cmd_watch},
    {&cmd_codegen_spec, cmd_codegen}, {&cmd_convert_spec, cmd_convert},
    {&cmd_fit_spec, cmd_fit},
    {&cmd_simulate_spec, cmd_simulate}, {&cmd_cam_spec, cmd_cam},
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
        fprintf(out, "  %-10s %s\n", commands[i].spec->name, commands[i].spec->summary);
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

static int wants_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

static int dispatch(int argc, char **argv)
{
    if (argc < 2) {
        print_usage(stderr);
        return MECH_EXIT_INPUT;
    }
    if (wants_help(argv[1]) || strcmp(argv[1], "help") == 0) {
        if (argc > 2)
            for (size_t i = 0; i < NCOMMANDS; i++)
                if (strcmp(argv[2], commands[i].spec->name) == 0) {
                    cmd_opts_help(commands[i].spec, stdout);
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
        if (strcmp(argv[1], commands[i].spec->name) == 0)
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
