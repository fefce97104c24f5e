/* src/commands.h: the `mech` subcommands (src/main.c dispatches; each
 * cmd_*.c holds one command's option parsing and output). */
#ifndef MECH_COMMANDS_H
#define MECH_COMMANDS_H

#include "mech.h"

#if defined(__GNUC__)
#define CMD_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define CMD_PRINTF(f, a)
#endif

/* cmd_common.c: "-h" or "--help" */
int cmd_wants_help(const char *arg);
/* Load and check one file, printing diagnostics; returns an exit status
 * (MECH_EXIT_OK with *m set, else *m is NULL). */
int cmd_load_checked(const char *path, mech_model **m);
/* The same with some of the file's parameters replaced (--set). */
int cmd_load_checked_with(const char *path, const mech_override *ov, int nov, mech_model **m);

/* The exit status of a library status: MECH_OK 0, MECH_ESOLVE 1, MECH_EINPUT
 * 2, MECH_EIO and MECH_ENOMEM 3 (the system failed the run, not the input;
 * the message says which: docs/cli.md, "Exit status"). */
static inline int cmd_exit_status(int rc)
{
    return rc == MECH_OK ? MECH_EXIT_OK
           : rc == MECH_ESOLVE ? MECH_EXIT_SOLVE
           : rc == MECH_EIO || rc == MECH_ENOMEM ? MECH_EXIT_IO : MECH_EXIT_INPUT;
}

/* cmd_common.c: "mech COMMAND: MESSAGE (see 'mech COMMAND --help')" on
 * stderr; returns MECH_EXIT_INPUT. fmt has one %s for arg. */
int cmd_usage_error(const char *command, const char *fmt, const char *arg);
/* *v = the whole number text (strtod syntax: 100, 1e3) when lo <= it <= hi;
 * returns 1, or 0 (NaN, out of range, not whole, not a number). */
int cmd_parse_int(const char *text, int lo, int hi, int *v);
/* An output that is one of the n input files (the same st_dev and st_ino,
 * through any link) would destroy it: prints "mech COMMAND: the output OUT
 * is the input file IN; ..." and returns MECH_EXIT_INPUT; else -1. NULL
 * inputs are skipped; out NULL, "-" or not an existing regular file: -1. */
int cmd_refuse_input(const char *command, const char *out, const char *const *inputs, int n);
/* mkdir -p: 0, or -1 with errno set. */
int cmd_make_dir(const char *dir);
/* "K/M" with 0 <= K < M: 0, or -1 when malformed. */
int cmd_parse_shard(const char *s, int *k, int *mod);
int cmd_default_jobs(void);  /* the CPUs of the affinity mask (else those online) */
/* job(ctx, i) for i = 0 .. njobs-1 on up to nthreads threads (each i once). */
void cmd_run_parallel(int njobs, int nthreads, void (*job)(void *ctx, int i), void *ctx);

/* cmd_common.c: the options `mech solve`, `mech plot` and `mech animate`
 * share, with the same meaning and messages (docs/cli.md).
 * --set NAME=VALUE (repeatable): the parameters replaced when loading. */
enum { CMD_MAX_SET = 64 };
typedef struct cmd_sets {
    mech_override set[CMD_MAX_SET];  /* [n] name and text point into copies below */
    char *copy[CMD_MAX_SET];         /* [n] owned "NAME\0VALUE" */
    int n;
} cmd_sets;
/* One --set value into s; returns -1 to go on, else the exit status (the
 * problem printed as "mech COMMAND: ..."). */
int cmd_parse_set(const char *command, const char *val, cmd_sets *s);
void cmd_sets_free(cmd_sets *s);
/* --from A --to B [--steps N]: "--from and --to go together" unless both
 * or neither are given (returns -1 to go on, else the exit status). */
int cmd_check_range_pair(const char *command, const char *from, const char *to);
/* The driver range into o: --from/--to (each a finite position within
 * +-1e6 rad or m, units allowed, bare numbers deg or mm) with `steps`
 * intervals (default 360), or only --steps: the file's range re-spaced.
 * Returns -1 to go on, else the exit status (the problem printed). */
int cmd_apply_range(const char *command, const char *from, const char *to, int steps,
                    const mech_model *m, mech_solve_options *o);

extern const char cmd_check_help[];
int cmd_check(int argc, char **argv);

extern const char cmd_equations_help[];
int cmd_equations(int argc, char **argv);

extern const char cmd_solve_help[];
int cmd_solve(int argc, char **argv);

extern const char cmd_batch_help[];
int cmd_batch(int argc, char **argv);

extern const char cmd_sweep_help[];
int cmd_sweep(int argc, char **argv);

/* `mech report FILE -o OUT.html` (cmd_report.c, docs/report.md). */
extern const char cmd_report_help[];
int cmd_report(int argc, char **argv);
extern const char cmd_codegen_help[];
int cmd_codegen(int argc, char **argv);
/* `mech solve --jit` (cmd_codegen_jit.c): mech_solve through the generated
 * code, compiled and loaded; the interpreter, with a note, where it cannot. */
int cmd_jit_solve(const mech_model *m, const mech_solve_options *o, mech_table *t,
                  mech_solve_stats *st, mech_diag *d);
/* `mech merge -o OUT SHARD...` (cmd_merge.c): shards of a sweep or batch. */
extern const char cmd_merge_help[];
int cmd_merge(int argc, char **argv);

/* Outputs of the animation (mech animate, mech report): every point name and
 * every moving link, no forces; *all is freed with mech_outputs_free.
 * Returns 0, or -1 when out of memory. */
int cmd_select_everything(const mech_model *m, mech_outputs *all);

/* Gap i of a partial sweep t, as `mech solve` and `mech report` print it
 * ("rows 3 to 9 of 361 (driver at ...) not solved: why; limits found: ...");
 * o are the options the sweep was solved with (cmd_gaps.c). */
void cmd_gap_line(const mech_model *m, const mech_solve_options *o, const mech_table *t, int i,
                  char *line, size_t size);

/* `mech compare [options] OUT.csv GOLDEN.csv` (cmd_compare.c): argv[0] is
 * "compare"; returns the exit code. */
extern const char cmd_compare_help[];
int cmd_compare(int argc, char **argv);

/* cmd_common.c: progress of a long run on standard error: on a terminal a
 * bar redrawn at most ten times a second, otherwise a line every few
 * seconds (MECH_PROGRESS_SECONDS overrides: 0 prints every update); quiet
 * prints nothing. Thread safe (the batch and sweep workers call it). */
typedef struct cmd_progress {
    const char *command;  /* "solve" */
    const char *unit;     /* "rows", "files", "variants" */
    int quiet, tty;
    double start, last, interval;
    int drawn;            /* a bar is on the terminal's line */
} cmd_progress;
void cmd_progress_init(cmd_progress *p, const char *command, const char *unit, int quiet);
void cmd_progress_update(cmd_progress *p, int done, int total);
/* After the run: ends the bar's line. */
void cmd_progress_done(cmd_progress *p);
/* The signature of mech_solve_options.progress (ctx: a cmd_progress). */
void cmd_progress_callback(void *ctx, int done, int total);

#endif
