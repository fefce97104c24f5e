/* src/cli/cli.h: the mech command line's one header: the option tables and
 * their parser, the commands, and the pieces they share (the plots' and
 * the report's steps, manifests, rows streamed and checked, the HTTP server
 * of mech watch). Private to src/cli/ (docs/architecture.md, "Stages"). */
#ifndef MECH_CLI_STAGE_H
#define MECH_CLI_STAGE_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "mech.h"
#include "output.h"

/* ==== cmd_opts ==== */
/* cmd_opts.c: the command line's one option parser (cmd_opts.c).
 *
 * Every command describes itself once, in a cmd_spec: its usage lines, what
 * it does, a table of its options (spellings, kind, target, range or words,
 * the message's wording, the help text) and how many files it takes.
 * cmd_opts_parse reads argv against the table into the command's argument
 * struct, and cmd_opts_help prints the command's --help from it, so an
 * option cannot be parsed one way and documented another (docs/cli.md,
 * "Options"). */
/* What an option's value is, and where it goes (the target: the field at
 * cmd_opt.at of the command's argument struct). Numbers are exact words:
 * a whole number is written with digits only (an optional '-' first), as
 * in a file ("--steps 0x10", "1e3", " 16" are refused); a real number is
 * decimal ("1e-10", "0.02"; not "0x1p-3", "inf", "nan"). */
typedef enum {
    CMD_OPT_FLAG,  /* no value: *(int *)target = flag */
    CMD_OPT_TEXT,  /* *(const char **)target = the value as given */
    CMD_OPT_INT,   /* *(int *)target = a whole number in [lo, hi] */
    CMD_OPT_LONG,  /* *(long *)target = a whole number in [lo, hi] */
    CMD_OPT_U64,   /* *(unsigned long long *)target = 0 .. 2^64-1 */
    CMD_OPT_REAL,  /* *(double *)target = a number in [lo, hi] (or open: flags) */
    CMD_OPT_WORD,  /* *(int *)target = the value of one of words[], exactly */
    CMD_OPT_CALL,  /* call(command, target, value): the command reads it */
    CMD_OPT_HELP   /* -h, --help: the help on standard output, exit 0 */
} cmd_opt_kind;

/* cmd_opt.flags */
enum {
    CMD_OPEN_LO = 1,   /* REAL: lo itself is refused */
    CMD_OPEN_HI = 2,   /* REAL: hi itself is refused */
    CMD_RUN_ONLY = 4   /* does not change the results (-o, -j, -q, --shard...):
                          left out of a manifest's arguments (cmd_opts_each) */
};

typedef struct cmd_word {
    const char *word;  /* NULL ends the list */
    int value;
} cmd_word;

typedef struct cmd_opt {
    const char *names;      /* every spelling, '|' between: "-o|--output"; NULL:
                               a line of help only (label and help) */
    cmd_opt_kind kind;
    size_t at;              /* offsetof the target in the command's argument struct */
    double lo, hi;          /* INT, LONG, REAL: the range */
    unsigned flags;         /* CMD_OPEN_LO, CMD_OPEN_HI, CMD_RUN_ONLY */
    int flag;               /* FLAG: the value stored */
    const cmd_word *words;  /* WORD: the words, ended by {NULL} */
    /* CALL: -1 to go on, else the exit status (the problem printed) */
    int (*call)(const char *command, void *target, const char *value);
    const char *expect;     /* the refusal: "OPTION EXPECT, not 'VALUE'", e.g.
                               "needs a whole number from 1 to 1e8" */
    const char *label;      /* the help's left column ("-o, --output FILE");
                               NULL: not in the help (an alias, or covered by
                               the line before: "--from A --to B") */
    const char *help;       /* the help's right column, '\n' between lines */
} cmd_opt;

typedef struct cmd_spec {
    const char *name;       /* "solve" */
    const char *summary;    /* one line for `mech --help` */
    const char *usage;      /* "usage: mech solve FILE ...\n", its lines */
    const char *about;      /* the paragraph after it, its lines */
    const cmd_opt *opts;    /* the options, in the help's order, ended by {NULL} */
    int column;             /* where the options' help text starts */
    const char *exits;      /* "exit status: ...", its lines */
    int max_files;          /* 1: one FILE (a second is refused), stored as a
                               const char * at file_at; 0: any number, into a
                               cmd_operands at file_at */
    size_t file_at;
    int min_files;          /* fewer: the no_files message */
    const char *no_files;   /* "no file given (usage: ...)" */
} cmd_spec;

/* The files of a command that takes many (max_files 0): v[n] point into
 * argv; v is malloc'ed by cmd_opts_parse and freed by the command. */
typedef struct cmd_operands {
    const char **v;
    int n;
} cmd_operands;

/* Reads argv[1 .. argc-1] against spec into args: each option's value into
 * its target (the last one given wins; CALL options see every one), the
 * files as spec says. An option is one of its spellings exactly, its value
 * the next argument (also when it starts with '-') or, for a long name,
 * after '=' ("--steps=90"); a lone '-' is a file. Returns -1 to go on;
 * MECH_EXIT_OK when it printed the help; else MECH_EXIT_INPUT (or what a
 * CALL returned), the problem printed as "mech COMMAND: MESSAGE (see 'mech
 * COMMAND --help')". */
int cmd_opts_parse(const cmd_spec *spec, int argc, char **argv, void *args);

/* The command's --help from spec: usage, about, "options:" and the table's
 * labels and help texts (each help at spec->column, or two spaces after a
 * longer label), the exit statuses. */
void cmd_opts_help(const cmd_spec *spec, FILE *out);

/* After a successful cmd_opts_parse: fn(ctx, opt, name, value) for each
 * argument in order, opt NULL for a file (name the file), value NULL for a
 * flag; name is the option's spelling as listed first in its names (the
 * manifest of a sharded run lists the options that are not CMD_RUN_ONLY). */
void cmd_opts_each(const cmd_spec *spec, int argc, char **argv,
                   void (*fn)(void *ctx, const cmd_opt *opt, const char *name, const char *value),
                   void *ctx);

/* ==== commands ==== */
/* the `mech` subcommands (src/cli/main.c dispatches; each
 * cmd_*.c holds one command's option parsing and output). */
#if defined(__GNUC__)
#define CMD_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define CMD_PRINTF(f, a)
#endif

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

/* cmd_manifest.c: a command's table to `out` (NULL or "-": standard output):
 * HDF5 when the name ends in .h5 or .hdf5 (output_h5.c, with the manifest
 * as attributes: mech's version, the command, the input file and its
 * digest), else CSV. MECH_OK or a failure in d. */
int cmd_write_table(const mech_table *t, const char *out, const char *command,
                    const char *input, mech_diag *d);

/* ==== cmd_h5 ==== */
/* cmd_h5.c: HDF5 for the tables that are text first (mech sweep's rows,
 * mech merge's output; docs/cli.md, "HDF5 output"). */
typedef struct h5_head {
    const char *command;   /* "sweep", "merge": for messages, and the attribute */
    const char *manifest;  /* the run's manifest line (no newline), or NULL */
    const char *header;    /* the CSV header line (no newline) */
    const char *input;     /* the input file, or NULL */
    int shard;             /* 1: a shard's (the manifest's fields and lines, and
                              the digest line of the canonical text, for merge) */
} h5_head;
/* The CSV text emit(f, ctx) writes (comment lines skipped), read back and
 * written to OUT as HDF5, whole or not at all, with h's root attributes.
 * Returns the exit status (the problem printed). */
int cmd_h5_write_text(const h5_head *h, const char *out, int (*emit)(FILE *, const void *),
                      const void *ctx);
/* The HDF5 shard at path as the lines of its CSV form (its manifest and
 * header attributes, its rows with each number in the shortest form that
 * reads back as it, its digest attribute): a temporary file at its start,
 * or NULL (the problem printed). */
FILE *cmd_h5_shard_text(const char *path);
/* cmd_common.c: "mech COMMAND: MESSAGE (see 'mech COMMAND --help')" on
 * stderr; returns MECH_EXIT_INPUT. fmt has one %s for arg. */
int cmd_usage_error(const char *command, const char *fmt, const char *arg);
/* An output that is one of the n input files (the same st_dev and st_ino,
 * through any link) would destroy it: prints "mech COMMAND: the output OUT
 * is the input file IN; ..." and returns MECH_EXIT_INPUT; else -1. NULL
 * inputs are skipped; out NULL, "-" or not an existing regular file: -1. */
int cmd_refuse_input(const char *command, const char *out, const char *const *inputs, int n);
/* --strict (solve, check, batch): the warnings of a suspect assembly in d
 * (fail_is_suspect_assembly: docs/solver.md section 9) made errors; how
 * many there were. */
int cmd_strict_assembly(mech_diag *d);
/* The --strict entry of the commands' option tables, at offset `at`. */
#define CMD_STRICT_ENTRY(at_)                                                                  \
    {.names = "--strict", .kind = CMD_OPT_FLAG, .at = (at_), .flag = 1, .label = "--strict",     \
     .help = "a suspect assembly is an error (exit 1), not a warning:\n"                        \
             "the first position far from the guesses, a point on a\n"                          \
             "ground point, a still slider, links folded flat, still\n"                          \
             "outputs (docs/solver.md section 9)"}
/* mkdir -p: 0, or -1 with errno set. */
int cmd_make_dir(const char *dir);
/* --shard K/M (batch, sweep; a CMD_OPT_CALL): K and M in digits, 0 <= K <
 * M <= 10^6, into the cmd_shard at `shard`; -1, or the exit status (the
 * problem printed). */
typedef struct cmd_shard {
    int k, m;   /* this shard: the indices i with i % m == k (default 0, 1) */
    int given;  /* --shard was given: the output is a part of a larger run */
} cmd_shard;
int cmd_read_shard(const char *command, void *shard, const char *value);

/* cmd_common.c: the options `mech solve`, `mech plot` and `mech animate`
 * share, with the same meaning and messages (docs/cli.md).
 * --set NAME=VALUE (repeatable): the parameters replaced when loading. */
enum { CMD_MAX_SET = 64 };
typedef struct cmd_sets {
    mech_override set[CMD_MAX_SET];  /* [n] name and text point into copies below */
    char *copy[CMD_MAX_SET];         /* [n] owned "NAME\0VALUE" */
    int n;
} cmd_sets;
/* One --set value into the cmd_sets at `sets` (a CMD_OPT_CALL of the option
 * tables); returns -1 to go on, else the exit status (the problem printed
 * as "mech COMMAND: ..."). */
int cmd_parse_set(const char *command, void *sets, const char *val);
void cmd_sets_free(cmd_sets *s);
/* --friction on|off|both (solve, plot, report, codegen): the words of its
 * CMD_OPT_WORD entry and its refusal. */
extern const cmd_word cmd_friction_words[];

/* The entries several option tables share (at: offsetof the target). */
#define CMD_HELP_ENTRY                                                                   \
    {.names = "-h|--help", .kind = CMD_OPT_HELP, .label = "-h, --help", .help = "show this help"}
#define CMD_FRICTION_ENTRY(at_, help_)                                                   \
    {.names = "--friction", .kind = CMD_OPT_WORD, .at = (at_), .words = cmd_friction_words, \
     .expect = "is on, off or both", .label = "--friction MODE", .help = help_}
#define CMD_SET_ENTRY(at_, help_)                                                        \
    {.names = "--set", .kind = CMD_OPT_CALL, .at = (at_), .call = cmd_parse_set,          \
     .label = "--set NAME=VALUE", .help = help_}
#define CMD_JOBS_ENTRY(at_)                                                              \
    {.names = "-j|--jobs", .kind = CMD_OPT_INT, .at = (at_), .lo = 1, .hi = 1024,         \
     .flags = CMD_RUN_ONLY, .expect = "needs a number of workers from 1 to 1024",        \
     .label = "-j, --jobs N",                                                            \
     .help = "worker threads (default: the processors this process may\n"                 \
             "run on: its CPU affinity, as set by taskset or Slurm)"}
/* --engine auto|compiled|interpreted (solve, batch, sweep; a CMD_OPT_WORD into an
 * int, cmd_jit_solve's engine). */
enum { CMD_ENGINE_AUTO, CMD_ENGINE_COMPILED, CMD_ENGINE_INTERPRETED };
extern const cmd_word cmd_engine_words[];
#define CMD_ENGINE_ENTRY(at_)                                                            \
    {.names = "--engine", .kind = CMD_OPT_WORD, .at = (at_), .words = cmd_engine_words,   \
     .flags = CMD_RUN_ONLY, /* the same table either way: shards of both merge */       \
     .expect = "is auto, compiled or interpreted", .label = "--engine E",                \
     .help = "compiled: solve with the code 'mech codegen' writes,\n"                     \
             "compiled by $CC (else cc) and loaded, the same table;\n"                    \
             "without a compiler, or where it cannot, the interpreter\n"                  \
             "solves (a note says why; docs/codegen.md); interpreted:\n"                  \
             "the interpreter; auto (default): compiled from 2 000 000\n"                 \
             "rows ($MECH_JIT_AUTO_ROWS), or from 20 000 when the cache\n"                \
             "holds the solver; else interpreted (solve's --stats,\n"                     \
             "batch's messages and sweep's summary say which; a sweep\n"                  \
             "counts the rows of all its variants and compiles once)"}
/* --from A --to B [--steps N]: "--from and --to go together" unless both
 * or neither are given (returns -1 to go on, else the exit status). */
int cmd_check_range_pair(const char *command, const char *from, const char *to);
/* A driver position on the command line (--from, --to, mech draw's --at)
 * into *si, SI: units allowed, bare numbers deg, mm or s as the driver's
 * kind says; finite and within +-1e6 rad, m or s (beyond, a step of a sweep
 * is lost in the rounding of the position; docs/limits.md). Returns -1 to
 * go on, else the exit status (the problem printed as "mech COMMAND: OPT
 * 'TEXT': ..."). */
int cmd_parse_driver(const char *command, const char *opt, const char *text,
                     const mech_model *m, double *si);
/* The driver range into o: --from/--to (each a finite position within
 * +-1e6 rad or m, units allowed, bare numbers deg or mm) with `steps`
 * intervals (default 360), or only --steps: the file's range re-spaced.
 * Returns -1 to go on, else the exit status (the problem printed). */
int cmd_apply_range(const char *command, const char *from, const char *to, int steps,
                    const mech_model *m, mech_solve_options *o);

extern const cmd_spec cmd_check_spec;
int cmd_check(int argc, char **argv);

extern const cmd_spec cmd_convert_spec;
int cmd_convert(int argc, char **argv);

/* `mech fit FILE --free ... --target CSV` (cmd_fit.c, docs/synthesis.md). */
extern const cmd_spec cmd_fit_spec;
int cmd_fit(int argc, char **argv);

/* `mech draw FILE -o OUT.svg` (cmd_draw.c, docs/plots.md): the assembled
 * position with names, and the stated pose beside it when they differ;
 * cmd_draw_model draws a checked model (mech check --draw too). */
typedef struct cmd_draw_options {
    const char *out;  /* the SVG; NULL or "-": standard output */
    int frame;        /* >= 0: position `frame` of the sweep (default -1: the first) */
    const char *at;   /* or the driver at this value (text, as --from), or NULL */
} cmd_draw_options;
void cmd_draw_options_default(cmd_draw_options *o);
extern const cmd_spec cmd_draw_spec;
/* `mech cam FILE` (cmd_cam.c, docs/cams.md): a cam's profile and design. */
extern const cmd_spec cmd_cam_spec;
int cmd_cam(int argc, char **argv);
int cmd_draw(int argc, char **argv);
/* Returns an exit status; cmd names the command in messages. */
int cmd_draw_model(const char *cmd, const mech_model *m, const cmd_draw_options *o);

extern const cmd_spec cmd_equations_spec;
int cmd_equations(int argc, char **argv);

extern const cmd_spec cmd_solve_spec;
int cmd_solve(int argc, char **argv);

/* `mech simulate FILE` (cmd_simulate.c, docs/dynamics.md): forward dynamics. */
extern const cmd_spec cmd_simulate_spec;
int cmd_simulate(int argc, char **argv);

extern const cmd_spec cmd_batch_spec;
int cmd_batch(int argc, char **argv);

extern const cmd_spec cmd_sweep_spec;
int cmd_sweep(int argc, char **argv);

/* `mech watch FILE` (cmd_watch.c, docs/cli.md): a live page on 127.0.0.1. */
extern const cmd_spec cmd_watch_spec;
int cmd_watch(int argc, char **argv);

/* `mech report FILE -o OUT.html` (cmd_report.c, docs/report.md). */
extern const cmd_spec cmd_report_spec;
int cmd_report(int argc, char **argv);
extern const cmd_spec cmd_codegen_spec;
int cmd_codegen(int argc, char **argv);
/* mech_solve by the engine --engine chose (cmd_codegen_jit.c, for mech solve
 * and mech batch). CMD_ENGINE_COMPILED (--jit): through the generated code,
 * compiled and loaded; the interpreter, with a note ("WHO: note: ..." on
 * notes), where it cannot. CMD_ENGINE_AUTO (the default): compiled only
 * where it pays off: at least cmd_jit_auto_rows() rows, or a hundredth of
 * them and a cached solver of the structure; the interpreter otherwise,
 * silently. CMD_ENGINE_INTERPRETED: mech_solve. cmd_jit_how says which.
 * Threads may call it at once (mech batch): one compiles at a time, the
 * others wait and may then find its solver in the cache. */
int cmd_jit_solve(const mech_model *m, const mech_solve_options *o, mech_table *t,
                  mech_solve_stats *st, mech_diag *d, int engine, FILE *notes,
                  const char *who);
/* mech sweep's variants by one compiled solver (cmd_codegen_jit.c): those
 * solved through the sweep's one analysis (variant_regs.c) go to
 * cmd_jit_variants_engine's sweep_engine (sweep_set_engine). engine:
 * CMD_ENGINE_AUTO (compiled when the variants' rows in all pay for it, as
 * cmd_jit_solve) or CMD_ENGINE_COMPILED; variants: this run's count;
 * notes: where a note goes when --engine compiled cannot. NULL out of
 * memory. cmd_jit_variants_how says which solver, and for how many
 * variants each (after the run). */
typedef struct cmd_jit_variants cmd_jit_variants;
cmd_jit_variants *cmd_jit_variants_new(int engine, long variants, FILE *notes);
struct sweep_engine;
const struct sweep_engine *cmd_jit_variants_engine(cmd_jit_variants *v);
const char *cmd_jit_variants_how(cmd_jit_variants *v, long *compiled, long *interpreted);
void cmd_jit_variants_free(cmd_jit_variants **v);
/* The rows from which --engine auto compiles: $MECH_JIT_AUTO_ROWS, else
 * 2 000 000; -1 when MECH_JIT_AUTO=off (never by itself). */
long cmd_jit_auto_rows(void);
/* How this thread's last cmd_jit_solve ran, for --stats: "compiled (...)",
 * or why the interpreter did ("" before any). */
const char *cmd_jit_how(void);

/* The cache of compiled solvers (jit_cache.c, docs/codegen.md): a
 * directory of this user's alone, $MECH_CACHE_DIR/jit, else
 * $XDG_CACHE_HOME/mech/jit, else ~/.cache/mech/jit; MECH_JIT_CACHE=off
 * turns it off, MECH_JIT_CACHE_MB bounds it (256 by default, 0: nothing
 * stored). */
typedef struct jit_cache {
    int usable;           /* 0: not used, why says why */
    int fd;               /* the directory, opened */
    long long max_bytes;  /* the bound */
    char dir[512];
    char why[600];
} jit_cache;
void jit_cache_open(jit_cache *c);
void jit_cache_close(jit_cache *c);
/* 1 with the path of the object compiled for key (klen bytes) in so_path,
 * when the cache holds it whole and unchanged; 0 otherwise. */
int jit_cache_find(const jit_cache *c, const char *key, size_t klen, char *so_path, size_t size);
/* 1 when the cache holds no entry (or is not used). */
int jit_cache_empty(const jit_cache *c);
/* The object at so_path stored for key: 0, or -1 (nothing stored). */
int jit_cache_put(const jit_cache *c, const char *key, size_t klen, const char *so_path);
/* `mech merge -o OUT SHARD...` (cmd_merge.c): shards of a sweep or batch. */
extern const cmd_spec cmd_merge_spec;
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
extern const cmd_spec cmd_compare_spec;
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

/* ==== cmd_plot ==== */
/* cmd_plot.c: the `mech plot` and `mech animate` commands (src/cli/cmd_plot.c;
 * the drawing itself is src/output/plot.c and src/output/plot_anim.c, docs/plots.md). */
extern const cmd_spec cmd_plot_spec, cmd_animate_spec;
/* argv[0] is the command name; returns a MECH_EXIT_* status. */
int cmd_plot(int argc, char **argv);
int cmd_animate(int argc, char **argv);

/* ==== cmd_manifest ==== */
/* cmd_manifest.c: the manifest line of a sharded run's output (mech
 * sweep --shard CSVs, mech batch --shard summaries), which mech merge reads
 * to prove that the shards it joins are the pieces of one run
 * (docs/batch.md, section "Manifests and mech merge"). */
/* The line, one per file, the first line:
 *   # mech-manifest version=V command=C shard=K/M rows=R total=T offset=O
 *     input=H grid=H tol=L args=A...
 * (on one line). rows: the data rows this shard must hold; total: the
 * indices of the run, offset .. offset+total-1; input, grid: FNV-1a 64-bit
 * hashes (16 hex digits) of the input files and of the grid; tol: for
 * `sweep --random`, each sampled parameter's value and tolerance (SI, C99
 * hexadecimal floats, "V~T" joined by commas), so that mech merge can
 * recompute the samples; "-" otherwise; args: the arguments that decide the
 * results (not -o, -j, -q, --shard, ...), escaped, to the end of the line. */
typedef struct manifest {
    char version[32];
    char command[16];
    int shard_k, shard_m;
    long rows, total, offset;
    uint64_t input, grid;
    char tol[2048];
    char args[4096];
} manifest;

#define MANIFEST_PREFIX "# mech-manifest "
/* The largest total and offset a manifest may state (a forged one larger
 * is not a manifest). */
#define MANIFEST_MAX_TOTAL 1000000000000L

/* FNV-1a 64 of n bytes, continuing from h (start with MANIFEST_HASH0). */
#define MANIFEST_HASH0 UINT64_C(0xcbf29ce484222325)
uint64_t manifest_hash(uint64_t h, const void *data, size_t n);
/* The hash of a file's bytes continued from h; 0 with *h set, -1 (errno)
 * when it cannot be read. */
int manifest_hash_file(uint64_t *h, const char *path);
/* Appends arg to m->args (a space before all but the first), with a
 * backslash before a space or a backslash and \xNN for a control byte, so
 * the line stays one line and the arguments can be told apart. */
void manifest_add_arg(manifest *m, const char *arg);
/* Writes m as its line (with the newline). */
void manifest_write(const manifest *m, FILE *f);
/* Reads the line (without its newline) into m: 0, or -1 when it is not a
 * manifest line. */
int manifest_parse(const char *line, manifest *m);
/* 1 when a and b are shards of the same run (all but shard and rows agree). */
int manifest_same_run(const manifest *a, const manifest *b);
/* The rows shard K/M of a run of total indices holds (i % M == K). */
long manifest_shard_rows(long total, int k, int m);
/* The arguments of a manifest (m->args) unescaped into a NULL-terminated
 * vector (*argv, malloc'ed in one block: free(*argv) frees all); 0, or -1
 * when out of memory. */
int manifest_args_split(const char *args, char ***argv, int *argc);

/* ---- digests: what ties a shard's rows to their content ------------------
 * A digest is FNV-1a 64 over lines, each line's bytes and then a newline
 * (a carriage return before the newline is not part of the line, so a file
 * whose ends were turned into CRLF keeps its digest). A shard's file (mech
 * sweep --shard, mech batch --shard) ends with
 *   # mech-digest rows=R fnv1a64=H
 * over every line before it (manifest, header, rows); OUT.partial holds its
 * rows in blocks, each ended by
 *   # mech-block rows=N fnv1a64=H
 * over the head (manifest and header) and the block's rows, so each block
 * can be checked on its own (docs/batch.md, "What merge proves"). */
typedef struct line_digest {
    uint64_t h;
    long lines;
} line_digest;

#define DIGEST_TRAILER "# mech-digest "
#define DIGEST_BLOCK "# mech-block "

void digest_init(line_digest *d);
/* len bytes of line (without its newline) into d. */
void digest_line(line_digest *d, const char *line, size_t len);
/* "PREFIXrows=R fnv1a64=H\n" into buf (size >= 64); its length. */
int digest_format(char *buf, size_t size, const char *prefix, long rows, uint64_t h);
/* A line (without its newline) of that form: 0 with *rows and *h, else -1. */
int digest_parse(const char *line, const char *prefix, long *rows, uint64_t *h);

/* ==== cmd_rows ==== */
/* cmd_rows.c: the rows of a sweep as they finish, in a file beside the
 * output (OUT.partial) that survives a killed run and that --resume
 * continues; at the end read back, put in index order and written whole to
 * OUT (docs/batch.md, section "Nothing computed is lost").
 *
 * The rows are written in blocks: kept in memory and written with one
 * write(2) when 64 KiB are waiting or a second after the last write (a
 * timer thread), each block ended by a check line (src/cli/cli.h,
 * DIGEST_BLOCK) over the head and its rows. --resume keeps only the rows
 * of blocks whose check line matches and that pass the row checks
 * (src/cli/cli.h); the others are dropped, named, and solved again. */
/* The content of a row (len bytes, no newline) that --resume may keep: 0,
 * else -1 with what is wrong in why. */
typedef int (*rows_check_fn)(const void *ctx, const char *row, size_t len, char *why,
                             size_t size);

typedef struct rowfile {
    FILE *tmp;             /* the anonymous temporary file, when no OUT.partial */
    int fd;                /* OUT.partial or tmp's; written at `end` with pwrite */
    off_t end;
    char *path;            /* OUT.partial (owned), NULL for the temporary file */
    const char *command;   /* "sweep", for messages */
    const char *input;     /* the input file (an HDF5 OUT's attribute), or NULL */
    char *head;            /* the manifest line and the header line, owned */
    size_t head_len;
    line_digest head_digest;  /* of the head: where each block's digest starts */
    int ncells;            /* cells of the header */
    long first, step;      /* row i has the index first + i * step ... */
    long count;            /* ... for i < count */
    unsigned char *done;   /* [count / 8 + 1] bit i: row i is in the file or the block */
    long ndone;
    rows_check_fn check;   /* what --resume checks of each row (NULL: shape only) */
    const void *check_ctx;
    pthread_mutex_t lock;  /* one row (and its messages) at a time; the block */
    char *block;           /* [bcap] rows not yet written (room for the check line) */
    size_t blen, bcap;
    long brows;
    line_digest bd;        /* of the head and the block's rows */
    double last_write;     /* monotonic seconds */
    long saved;            /* rows in the file */
    int write_errno;       /* a write failed: nothing more is written */
    pthread_t timer;
    pthread_cond_t wake;
    int timer_on, stop;
} rowfile;

/* Opens the rows of a run whose file starts with `head` (the manifest line
 * and the CSV header, each with its newline). out NULL, "-" or an existing
 * file that is not a regular one (/dev/null, a FIFO): a temporary file.
 * Else OUT.partial: a new file; one that exists is refused unless resume,
 * which keeps its rows that check (same head, block check lines, shape,
 * check(ctx, row)), dropping the others with a message. Returns -1 when
 * open, else the exit status (the problem printed; nothing left open or
 * allocated). */
int rows_open(rowfile *rf, const char *command, const char *out, int resume, const char *head,
              long first, long step, long count, rows_check_fn check, const void *ctx);
/* 1 when row i is already in the file (resumed). */
int rows_done(const rowfile *rf, long i);
/* Appends row i (line with its newline) to the block (written when full
 * or by the timer); then prints messages (may be NULL) on standard error,
 * under the same lock so the blocks of two rows do not mix. */
void rows_put(rowfile *rf, long i, const char *line, const char *messages);
/* Writes OUT whole: the manifest line when with_manifest, the header, the
 * rows in index order and (with the manifest) the digest line; for an OUT
 * named .h5 or .hdf5 that text as HDF5 (cmd_h5_write_text); then removes
 * OUT.partial. *nok: the rows whose field `status_field` (0-based)
 * is "ok". Returns the exit status. */
int rows_finish(rowfile *rf, const char *out, int with_manifest, int status_field, long *nok);
/* Closes the file and frees rf (OUT.partial stays unless finished). */
void rows_close(rowfile *rf);

/* The rows of a file of blocks (OUT.partial, or a batch's TABLE.partial):
 * calls row(ctx, row, len, line) for each row of buf[from .. len) in a
 * block whose check line matches the digest started at seed, and
 * bad(ctx, first_line, last_line, rows) for each block that does not.
 * Lines are numbered from first_line; a carriage return before a newline
 * is not part of its line. Returns the rows after the last check line
 * (a block cut by a kill), which are neither. */
long rows_scan_blocks(const char *buf, size_t len, size_t from, long first_line,
                      const line_digest *seed,
                      void (*row)(void *ctx, const char *r, size_t n, long line),
                      void (*bad)(void *ctx, long from_line, long to_line, long rows), void *ctx);
/* The rows an earlier run recorded in `table` (a complete file whose
 * digest line matches, src/cli/cli.h) or in `table`.partial (its
 * blocks that check), when the file starts with `head` (its digest
 * head_digest): row(ctx, row, len, line) for each. Files that are not
 * there, not regular or not this run's are skipped. */
void rows_read_recorded(const char *table, const char *head, const line_digest *head_digest,
                        void (*row)(void *ctx, const char *r, size_t n, long line), void *ctx);
/* The check line of a block of `rows` rows whose digest (seeded with the
 * head) is d, into buf (size >= 64); its length. */
int rows_block_line(char *buf, size_t size, long rows, const line_digest *d);

/* ==== cmd_rowcheck ==== */
/* cmd_rowcheck.c: what a row of a sweep CSV or of a batch summary may
 * hold, checked where rows are read back: `mech sweep --resume` (its
 * OUT.partial, src/cli/cmd_rows.c) and `mech merge` (src/cli/cmd_merge.c). A row
 * has the header's number of cells, none quoted and no control byte; a
 * sweep row's parameter cells are the grid's values at its index (they are
 * recomputed by the library's grid, src/study/sweep_grid.c), its status a
 * variant status, its rows a count and its metrics numbers;
 * a batch row has its fields in their places (docs/batch.md, "What merge
 * proves"). */
typedef struct mech_sweep mech_sweep;
struct cmd_spec;

/* The arguments of m read by its command's option table (spec: mech
 * sweep's, mech batch's) into that command's argument struct args, as the
 * command read them (with a placeholder for the file, which the manifest
 * hashes by its contents): 0, or -1 when they hold what no manifest does
 * (a file, an unknown option, --help, an option left out of manifests:
 * CMD_RUN_ONLY) or when the table refuses a value (its message printed).
 * The texts args points to are in *words: free(*words) once done. */
int manifest_args_parse(const manifest *m, const struct cmd_spec *spec, void *args,
                        char ***words);

/* The sweep of a shard from its manifest (cmd_sweep.c): its arguments read
 * by mech sweep's own option table into a mech_sweep (the library's grid,
 * sweep_grid.c), its grid hash checked against grid=, the offset from
 * offset= and, for --random, the samples' values and tolerances from tol=
 * (no file is read). Parameter k of variant v is then the library's
 * grid_value, as mech sweep wrote it. 0 with *out (mech_sweep_free), or -1
 * when the manifest does not describe a sweep. */
int sweep_of_manifest(const manifest *m, mech_sweep **out);
/* The --out-dir of a batch shard from its manifest, read by mech batch's
 * option table (cmd_batch.c) into dir ("" when none): 0, or -1 when the
 * manifest's arguments are not mech batch's. */
int batch_out_dir_of_manifest(const manifest *m, char *dir, size_t size);
/* tol=... of a manifest (src/cli/cli.h) from s's --random axes and
 * back into axes of s: "V~T,V~T,..." (C99 hexadecimal floats, exact), ""
 * for a grid; 0, or -1 when it does not fit or parse. */
int sweep_tol_format(const mech_sweep *s, char *buf, size_t size);
int sweep_tol_parse(mech_sweep *s, const char *text);

/* The cells of a CSV line of len bytes (a header: cells may be quoted). */
int csv_cells(const char *line, size_t len);
/* A data row of len bytes has ncells cells, no quote and no control byte:
 * 0, else -1 with what is wrong in why. */
int csv_row_shape(const char *row, size_t len, int ncells, char *why, size_t size);
/* The row's first cell as an index, or -1 when it is not a whole number. */
long csv_row_index(const char *row, size_t len);
/* A sweep row (its shape checked) against the sweep s: its parameter cells
 * the grid's values at its index (grid_value), a status one of
 * mech_variant_status_name's, a count of rows, numbers for the metrics. 0,
 * else -1 with what is wrong in why. */
int sweep_row_content(const mech_sweep *s, const char *row, size_t len, char *why, size_t size);

/* A row of mech batch's summary table: name, status, steps, worst residual,
 * us/step, golden, and in a shard's table the index in the whole list and
 * the hash of the file's CSV ("-": none). Read from the right, so a name
 * may hold spaces. */
typedef struct batch_row {
    const char *name;       /* in the row, name_len bytes */
    int name_len;
    char status[16], golden[16];
    long steps;
    double residual, us_per_step;
    long index;             /* -1 in a table without index */
    int has_csv;
    uint64_t csv;           /* FNV-1a 64 of DIR/NAME.csv's bytes */
} batch_row;

/* Parses the row (len bytes; indexed: a shard's, with index and csv). 0,
 * else -1 with what is wrong in why. */
int batch_row_parse(const char *row, size_t len, int indexed, batch_row *br, char *why,
                    size_t size);

/* ==== cmd_http ==== */
/* cmd_http.c: the small HTTP/1.1 server of `mech watch` (src/cli/cmd_http.c,
 * docs/cli.md "mech watch"): it listens on 127.0.0.1 only, answers GET only,
 * on two fixed routes (`/` the page, `/state` its JSON, long-polled with
 * `/state?since=N`), never touches the file system by URL, bounds every
 * request, and refuses a Host that is not 127.0.0.1 or localhost (DNS
 * rebinding). One thread: poll() over the listening socket and at most
 * HTTP_MAX_CONNS connections, each closed after its one answer. */
enum {
    HTTP_MAX_REQUEST = 8192,  /* bytes of the request line and the headers */
    HTTP_MAX_TARGET = 1024,   /* bytes of the request target */
    HTTP_MAX_HEADERS = 64,    /* header lines */
    HTTP_MAX_CONNS = 16,      /* connections at once; more are turned away (503) */
    HTTP_READ_MS = 10000,     /* a request must arrive within this */
    HTTP_WRITE_MS = 30000,    /* an answer must be taken within this */
    HTTP_HOLD_MS = 20000      /* /state?since=N waits for a newer state this long */
};

typedef enum { HTTP_PAGE, HTTP_STATE } http_route;

/* A request as http_parse reads it. */
typedef struct http_request {
    int status;        /* 0: not complete yet; 200: answer it; else the error status */
    const char *why;   /* the error in words (a static string), else NULL */
    http_route route;
    long long since;   /* /state?since=N: N; else -1 */
} http_request;

/* Read the request in buf[0 .. len-1] (what has arrived so far) of a
 * server listening on `port`: the request line (GET, an origin-form target
 * of at most HTTP_MAX_TARGET bytes, HTTP/1.0 or 1.1), the headers (at most
 * HTTP_MAX_HEADERS, HTTP_MAX_REQUEST bytes in all, no body, exactly one
 * Host: 127.0.0.1 or localhost, with `port` if a port is given), the route.
 * Returns r->status: 0 incomplete, 200, or 400 (malformed), 403 (another
 * Host), 404 (another path), 405 (not GET), 414, 431 (too long), 505. */
int http_parse(const char *buf, size_t len, int port, http_request *r);

/* What the server answers with (borrowed; it may change between calls of
 * http_serve: each answer is copied when it is made). */
typedef struct http_site {
    const char *page;      /* `/`: the HTML page */
    size_t page_len;
    const char *state;     /* `/state`: the JSON of the current state */
    size_t state_len;
    long long version;     /* the state's version: /state?since=N waits while N >= it */
} http_site;

typedef struct http_conn {
    int fd;                /* -1: a free slot */
    int phase;             /* reading, waiting (long poll), writing, closing */
    char in[HTTP_MAX_REQUEST + 1];
    size_t nin;
    long long since;       /* waiting: for a version above this */
    char *out;             /* the answer (owned) */
    size_t nout, sent;
    double deadline;       /* clock_seconds() (src/base/parallel.c) */
} http_conn;

typedef struct http_server {
    int fd;                /* the listening socket, or -1 */
    int port;              /* the port it listens on (a free one when asked for 0) */
    http_conn conn[HTTP_MAX_CONNS];
} http_server;

/* Listen on 127.0.0.1:port (0: a free port, then s->port says which).
 * Returns 0, or -1 with the reason in err. */
int http_open(http_server *s, int port, char *err, size_t errsize);
/* Serve for at most timeout_ms (less when something happens): accept,
 * read, answer, write, end the long polls that a newer version or their
 * time ends. Returns when poll() returns (also on a signal). */
void http_serve(http_server *s, const http_site *site, int timeout_ms);
/* Close every connection and the listening socket; frees the answers. */
void http_close(http_server *s);

/* ==== cmd_report ==== */
/* cmd_report.c: what `mech report` computes before it writes its page
 * (src/cli/cmd_report.c): the file loaded and checked, the two solves (the
 * outputs; every point and link for the animation), the animation and the
 * gaps in words. `mech watch` (src/cli/cmd_watch.c) runs the same steps on
 * every save of its file. Each step returns an exit status (MECH_EXIT_*),
 * the problem printed on stderr as "mech CMD: ..." and, for the load and
 * the solves, kept in run.d. */
/* The options of mech report (its option table, src/cli/cmd_report.c); mech
 * watch fills file, set and anim. */
typedef struct report_args {
    const char *file, *out, *from, *to, *outputs;
    cmd_sets set;                       /* --set NAME=VALUE, as mech solve */
    int steps, forces, friction;        /* friction: -1 = mech solve's default */
    plot_anim_options anim;
} report_args;

/* Everything one run holds (freed by report_run_free). */
typedef struct report_run {
    const char *cmd;             /* "report", "watch": the messages' "mech CMD: " */
    report_args a;
    mech_model *m;
    mech_summary summary;
    mech_diag d;                 /* the load's and the solve's messages */
    mech_outputs selected, all;  /* --outputs; every point and link */
    mech_model view, view_all;   /* the model seen with those outputs */
    mech_solve_options o;
    mech_table t, t_all;         /* the outputs; the animation's positions */
    mech_solve_stats stats;
    char *equations;
    size_t equations_len;
    char **figures;
    int nfigures;
    char *animation;
    int *frame_rows;
    int nframes;
    int partial;                 /* some requested rows are missing (t.gaps) */
    char **gap_lines;            /* [t.ngaps] each gap as mech solve prints it */
} report_run;

/* Load and check with --set; the messages stay in r->d for the page. */
int report_run_load(report_run *r);
/* The options, the views of the model (--outputs; everything) and the two
 * solves. */
int report_run_solve(report_run *r);
/* The rows behind the slider: the animation's frames (plot_anim_frame_rows,
 * at most --frames evenly spread); the animation drawn with exactly those
 * frames, into r->animation. */
int report_run_animation(report_run *r);
/* One line per gap into r->gap_lines, printed on stderr as mech solve
 * prints them ("mech report: gap: ..."). */
int report_run_gaps(report_run *r);
void report_run_free(report_run *r);

#endif
