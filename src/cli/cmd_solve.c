/* src/cli/cmd_solve.c: `mech solve`, the driver sweep on the command line.
 * Parses options into mech_solve_options, runs mech_solve, writes the CSV
 * (whole or not at all) and the statistics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "output.h"
#include "study.h"

/* The smallest --tol: a residual is a sum of products of lengths, rounded
 * to about DBL_EPSILON (2.2e-16) times the largest; below a few times that
 * Newton cannot get (docs/solver.md: 4e-15 or better on every file). */
#define MIN_TOL 1e-15

typedef struct solve_args {
    const char *file, *out, *from, *to, *outputs;
    const char *sens;            /* --sensitivity NAME,... */
    int tolerances;              /* --tolerances */
    cmd_sets set;                /* --set NAME=VALUE: parameters replaced */
    int steps, stats, verbose, quiet;
    int strict;                  /* --strict: a suspect assembly is an error */
    int units_file;              /* --units file: results in the file's units */
    double speed_fluctuation;    /* --speed-fluctuation: Cs, 0 when not given */
    int within;                  /* --within-assembly or --range assembly */
    int range_assembly;          /* --range assembly */
    int jit;                     /* --jit: the generated code, compiled and loaded */
    int engine;                  /* --engine: CMD_ENGINE_* */
    mech_outputs selected;       /* --outputs, parsed (opt.outputs points here) */
    mech_solve_options opt;
} solve_args;

enum { MAX_SENS_NAMES = 64 };

/* Split --sensitivity's list in place into names[], at most 64, different,
 * none empty; 0 when it is not such a list. */
static int split_names(char *list, const char **names, int *n)
{
    char *save = NULL;
    size_t len = strlen(list);
    int bad = len == 0 || list[0] == ',' || list[len - 1] == ',' || strstr(list, ",,");
    for (char *tok = strtok_r(list, ",", &save); tok && !bad; tok = strtok_r(NULL, ",", &save)) {
        for (int k = 0; k < *n; k++)
            bad |= strcmp(names[k], tok) == 0;  /* a name twice: the same columns twice */
        if (*n == MAX_SENS_NAMES)
            bad = 1;
        else
            names[(*n)++] = tok;
    }
    return !bad;
}

/* --sensitivity LIST: kept when well formed (split_names on a copy). */
static int read_sensitivity(const char *command, void *target, const char *val)
{
    char *copy = strdup(val);
    const char *names[MAX_SENS_NAMES];
    int n = 0, ok = copy && split_names(copy, names, &n);
    free(copy);
    if (!ok)
        return cmd_usage_error(command, "--sensitivity needs at most 64 different parameter "
                               "names separated by commas, not '%s'", val);
    *(const char **)target = val;
    return -1;
}

static const cmd_word levels[] = {
    {"positions", MECH_WANT_POSITION},
    {"velocities", MECH_WANT_POSITION | MECH_WANT_VELOCITY},
    {"accelerations", MECH_WANT_ALL},
    {NULL, 0}};
static const cmd_word solvers[] = {{"auto", MECH_LINEAR_AUTO}, {"klu", MECH_LINEAR_KLU}, {NULL, 0}};
static const cmd_word ranges[] = {{"assembly", 1}, {NULL, 0}};
static const cmd_word unit_systems[] = {{"si", 0}, {"file", 1}, {NULL, 0}};

#define AT(field) offsetof(solve_args, field)

static const cmd_opt options[] = {
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .label = "-o, --output FILE",
     .help = "write the CSV to FILE (written to a temporary file and\n"
             "renamed when complete; default: standard output)"},
    {.names = "--from", .kind = CMD_OPT_TEXT, .at = AT(from), .label = "--from A --to B",
     .help = "sweep the driver from A to B instead of the file's range;"},
    {.names = "--to", .kind = CMD_OPT_TEXT, .at = AT(to)},
    {.names = "--steps", .kind = CMD_OPT_INT, .at = AT(steps), .lo = 1, .hi = 1000000,
     .expect = "needs a whole number from 1 to 1000000 (as in a file)", .label = "--steps N",
     .help = "N intervals (N+1 rows, default 360). Bare numbers are\n"
             "degrees (crank) or millimetres (slider); units are\n"
             "allowed: --from 2.0864rad, --to 0.2m"},
    {.names = "--tol", .kind = CMD_OPT_REAL, .at = AT(opt.tol), .lo = MIN_TOL, .hi = 1,
     .flags = CMD_OPEN_HI,
     .expect = "needs a number from 1e-15 (a smaller residual is below what double precision "
               "can reach) to below 1",
     .label = "--tol T",
     .help = "Newton tolerance relative to the largest length of the\n"
             "mechanism, from 1e-15 to below 1 (default 1e-12)"},
    {.names = "--max-iter", .kind = CMD_OPT_INT, .at = AT(opt.max_iter), .lo = 1, .hi = 10000,
     .expect = "needs a whole number from 1 to 10000", .label = "--max-iter N",
     .help = "Newton iterations per step before giving up (default 50)"},
    {.names = "--min-rcond", .kind = CMD_OPT_REAL, .at = AT(opt.min_rcond), .lo = 0, .hi = 1,
     .flags = CMD_OPEN_LO | CMD_OPEN_HI, .expect = "needs a number between 0 and 1",
     .label = "--min-rcond R",
     .help = "reciprocal condition below which a position is reported\n"
             "singular (default 1e-6)"},
    {.names = "--linear-solver", .kind = CMD_OPT_WORD, .at = AT(opt.linear_solver),
     .words = solvers, .expect = "needs auto or klu", .label = "--linear-solver S",
     .help = "auto: dense LU of each block of the block triangular\n"
             "form when all are at most 16x16, else KLU (default);\n"
             "klu: SuiteSparse KLU always (docs/solver.md)"},
    CMD_SET_ENTRY(AT(set), "replace the file's parameter NAME by VALUE (repeatable),\n"
             "e.g. --set 'l=150 mm'"),
    {.names = "--sensitivity", .kind = CMD_OPT_CALL, .at = AT(sens), .call = read_sensitivity,
     .label = "--sensitivity LIST",
     .help = "for each parameter NAME in the comma-separated LIST, add\n"
             "a column d(COL)/d(NAME) [COL's unit/NAME's unit] after\n"
             "the others for every position, velocity and\n"
             "acceleration column COL: exact derivatives by the\n"
             "implicit-function theorem, not finite differences"},
    {.names = "--tolerances", .kind = CMD_OPT_FLAG, .at = AT(tolerances), .flag = 1,
     .label = "--tolerances",
     .help = "for every position, velocity and acceleration column COL\n"
             "add worst(COL) = sum |d(COL)/dp| tol_p over the parameters\n"
             "with a tolerance ({value: 40 mm, tolerance: 0.05 mm}) and\n"
             "rss(COL) = sqrt(sum (d(COL)/dp tol_p)^2); print the\n"
             "largest of each over the sweep to standard error"},
    {.names = "--outputs", .kind = CMD_OPT_TEXT, .at = AT(outputs), .label = "--outputs LIST",
     .help = "comma-separated point, link, slider and cam names to\n"
             "output instead of the file's outputs"},
    {.names = "--level", .kind = CMD_OPT_WORD, .at = AT(opt.want), .words = levels,
     .expect = "is positions, velocities or accelerations", .label = "--level L",
     .help = "positions, velocities or accelerations (default): the\n"
             "highest derivative computed"},
    {.names = "--forces", .kind = CMD_OPT_FLAG, .at = AT(opt.forces), .flag = 1,
     .label = "--forces",
     .help = "also joint reactions (Fx, Fy, magnitude; sliders: normal\n"
             "force N and moment M), the driver torque or force, and\n"
             "the power-balance residual (as 'outputs: {forces: true}')"},
    CMD_FRICTION_ENTRY(AT(opt.friction), "on: apply the joints' friction coefficients (default);\n"
             "off: frictionless; both: also the frictionless columns,\n"
             "suffixed .nofriction"),
    {.names = "--diagnostics", .kind = CMD_OPT_FLAG, .at = AT(opt.diagnostics), .flag = 1,
     .label = "--diagnostics", .help = "add the columns iterations, residual [m], rcond, substeps"},
    {.names = "--stats", .kind = CMD_OPT_FLAG, .at = AT(stats), .flag = 1, .label = "--stats",
     .help = "print iterations per step, worst residual, smallest\n"
             "rcond and time per step to standard error; with\n"
             "forces, the flywheel figures of the driver torque: its\n"
             "mean, the largest energy fluctuation (over the rows:\n"
             "sweep one full turn)"},
    {.names = "--speed-fluctuation", .kind = CMD_OPT_REAL, .at = AT(speed_fluctuation),
     .lo = 0, .hi = 1, .flags = CMD_OPEN_LO | CMD_OPEN_HI,
     .expect = "needs a number between 0 and 1 (e.g. 0.02)", .label = "--speed-fluctuation CS",
     .help = "the flywheel inertia I = dE / (CS w^2) for the\n"
             "coefficient of speed fluctuation CS (0 < CS < 1, e.g.\n"
             "0.02; w the driver speed) printed with the figures\n"
             "above; implies --forces"},
    CMD_ENGINE_ENTRY(AT(engine)),
    {.names = "--jit", .kind = CMD_OPT_FLAG, .at = AT(jit), .flag = 1, .label = "--jit",
     .help = "the same as --engine compiled"},
    {.names = "-v|--verbose", .kind = CMD_OPT_FLAG, .at = AT(verbose), .flag = 1,
     .label = "--verbose", .help = "say which blocks of equations are solved and why"},
    {.names = "-q|--quiet", .kind = CMD_OPT_FLAG, .at = AT(quiet), .flag = 1,
     .label = "-q, --quiet",
     .help = "no progress report (long runs show one on standard error:\n"
             "a bar on a terminal, else a line every 5 s)"},
    CMD_STRICT_ENTRY(AT(strict)),
    {.names = "--units", .kind = CMD_OPT_WORD, .at = AT(units_file), .words = unit_systems,
     .expect = "is si or file", .label = "--units U",
     .help = "si: results in SI (default); file: in the file's own\n"
             "units: (lengths in mm, angles in deg...), the CSV, the\n"
             "--tolerances summary and --stats, units in the header"},
    {.names = "--all", .kind = CMD_OPT_FLAG, .at = AT(opt.all_blocks), .flag = 1,
     .label = "--all", .help = "solve every unknown, also those no output needs"},
    {.names = "--within-assembly", .kind = CMD_OPT_FLAG, .at = AT(within), .flag = 1,
     .label = "--within-assembly",
     .help = "the request is the part of the range where the mechanism\n"
             "assembles: exit 0 when every row there was solved (gaps\n"
             "past limit positions and dead points are expected)"},
    {.names = "--range", .kind = CMD_OPT_WORD, .at = AT(range_assembly), .words = ranges,
     .expect = "needs 'assembly'", .label = "--range assembly",
     .help = "as --within-assembly, and add a row at each limit of the\n"
             "assembly found (where it is not singular)"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_solve_spec = {
    .name = "solve",
    .summary = "solve positions, velocities and accelerations over the driver range",
    .usage = "usage: mech solve FILE [-o OUT.csv] [--from A --to B --steps N] [--tol T]\n"
             "                  [--outputs NAME,...]\n"
             "                  [--level positions|velocities|accelerations]\n"
             "                  [--sensitivity NAME,...] [--tolerances]\n"
             "                  [--forces] [--friction on|off|both]\n"
             "                  [--diagnostics] [--stats] [--speed-fluctuation CS]\n"
             "                  [--verbose] [--all] [--engine auto|compiled|interpreted]\n"
             "                  [--jit] [--strict] [--units si|file]\n"
             "                  [--within-assembly] [--range assembly]\n",
    .about = "Solve positions, velocities and accelerations of the mechanism at every\n"
             "driver position and write one CSV row per position: the driver position q,\n"
             "then per output point x, y, vx, vy, ax, ay; per link angle, omega, alpha;\n"
             "per slider s, v, a. SI units; each header cell is 'name [unit]'.\n"
             "Only the unknowns the outputs need are solved (see --verbose).\n",
    .opts = options,
    .column = 22,
    .exits = "exit status: 0 solved, 1 the mechanism cannot be solved somewhere in the range\n"
             "(the message gives the driver position, the loop and the unknowns involved;\n"
             "the rows that were solved are written, each gap is listed), 2 invalid file or\n"
             "usage, 3 a file cannot be read or written\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech solve FILE [-o OUT.csv] ...)",
};

/* Returns -1 to go on, else the exit status. */
static int parse_args(int argc, char **argv, solve_args *a)
{
    mech_solve_options_default(&a->opt);
    int code = cmd_opts_parse(&cmd_solve_spec, argc, argv, a);
    if (a->range_assembly)
        a->within = a->opt.limit_rows = 1;
    if (a->speed_fluctuation > 0.0)
        a->opt.forces = 1;
    return code >= 0 ? code : cmd_check_range_pair("solve", a->from, a->to);
}

/* --from/--to/--steps and --outputs into the options (the model is not
 * changed). */
static int apply_overrides(solve_args *a, const mech_model *m)
{
    char err[256];
    int code = cmd_apply_range("solve", a->from, a->to, a->steps, m, &a->opt);
    if (code >= 0)
        return code;
    if (a->outputs) {
        if (mech_outputs_parse(m, a->outputs, &a->selected, err, sizeof err) != MECH_OK)
            return fprintf(stderr, "mech solve: --outputs: %s\n", err), MECH_EXIT_INPUT;
        a->opt.outputs = &a->selected;
    }
    return -1;
}

static void print_stats(const mech_model *m, const mech_solve_stats *st, int units_file,
                        FILE *out)
{
    char ru[64];  /* the residual in the file's length unit with --units file */
    double resid = units_file ? output_in_file_units(m, "m", st->worst_residual, ru, sizeof ru)
                              : (snprintf(ru, sizeof ru, "m"), st->worst_residual);
    int angle = m->driver.kind == MECH_DRIVE_ANGLE;
    double per = st->steps ? st->seconds / st->steps : 0.0;
    fprintf(out, "%s: %d steps, %d of %d unknowns solved (%d of %d blocks)\n", m->file,
            st->steps, st->nsolved, st->nunknowns, st->nblocks_solved, st->nblocks);
    fprintf(out, "  Newton iterations  %.2f per step, at most %d\n",
            st->steps ? (double)st->iterations / st->steps : 0.0, st->max_iterations);
    fprintf(out, "  worst residual     %.3g %s\n", resid, ru);
    if (st->steps)
        fprintf(out, "  smallest rcond     %.3g at %s = %.6g %s\n", st->min_rcond,
                m->driver.kind == MECH_DRIVE_TIME ? "t" : "q",
                angle ? st->worst_rcond_q * 57.29577951308232
                : m->driver.kind == MECH_DRIVE_TIME ? st->worst_rcond_q : st->worst_rcond_q * 1e3,
                angle ? "deg" : m->driver.kind == MECH_DRIVE_TIME ? "s" : "mm");
    if (st->nsolved < st->nunknowns)
        fprintf(out, "  assembly checks    the guesses only: the outputs need %d of %d unknowns "
                "(--all for the checks over the sweep)\n", st->nsolved, st->nunknowns);
    fprintf(out, "  factorizations     %d full, %d refactor\n", st->factorizations,
            st->refactorizations);
    if (st->worst_power_residual > 0.0 || st->max_friction_iterations > 0)
        fprintf(out, "  power balance      worst relative residual %.3g; friction iterations "
                "at most %d\n", st->worst_power_residual, st->max_friction_iterations);
    fprintf(out, "  time               %.3g us per step (sweep %.3g s, set-up %.3g s)\n",
            per * 1e6, st->seconds, st->setup_seconds);
}

/* The flywheel figures of the driver torque, when there is one. */
static void print_flywheel(const solve_args *a, const mech_model *m, const mech_table *t)
{
    flywheel_figures f;
    char why[200];
    if (flywheel_compute(t, m, a->speed_fluctuation, &f, why, sizeof why) == 0)
        flywheel_print(&f, a->speed_fluctuation, stderr);
    else if (a->speed_fluctuation > 0.0 || mech_table_column(t, "driver.torque") >= 0)
        fprintf(stderr, "  flywheel           none: %s\n", why);
}

/* One line per gap: the rows missing, why, and the limits found. */
static void print_gaps(const solve_args *a, const mech_model *m, const mech_table *t)
{
    char line[600];
    for (int i = 0; i < t->ngaps; i++) {
        cmd_gap_line(m, &a->opt, t, i, line, sizeof line);
        fprintf(stderr, "mech solve: gap: %s\n", line);
    }
}

/* --within-assembly: every requested row missing lies in a gap where the
 * mechanism does not assemble or cannot be driven past a dead point. */
static int only_assembly_gaps(const mech_table *t)
{
    int missing = t->nrequested;
    for (int i = 0; i < t->ngaps; i++) {
        if (t->gaps[i].kind != MECH_GAP_NO_ASSEMBLY && t->gaps[i].kind != MECH_GAP_DEAD_POINT)
            return 0;
        missing -= t->gaps[i].last_row - t->gaps[i].first_row + 1;
    }
    return t->nrows >= missing && t->nrows > 0;
}

/* The rows solved (all, or those of a partial sweep) to the output. */
static int write_rows(const solve_args *a, const mech_table *t)
{
    mech_diag d;
    mech_diag_init(&d);
    int code = MECH_EXIT_OK;
    if (cmd_write_table(t, a->out, "solve", a->file, &d) != MECH_OK)
        code = MECH_EXIT_IO;
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    return code;
}

/* --sensitivity: the derivative columns added to t (mech_sensitivity). */
static int add_sensitivity(const solve_args *a, const mech_model *m, mech_table *t)
{
    char *list = strdup(a->sens);
    const char *names[MAX_SENS_NAMES];
    int n = 0;
    if (!list)
        return fprintf(stderr, "mech solve: out of memory\n"), MECH_EXIT_IO;
    split_names(list, names, &n);  /* checked by read_sensitivity */
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_sensitivity(m, a->set.set, a->set.n, &a->opt, names, n, t, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    free(list);
    return rc == MECH_OK ? -1 : cmd_exit_status(rc);
}

/* --tolerances: the summary of the worst(COL) and rss(COL) columns. */
static void print_stackup(const mech_model *m, const mech_table *t, int units_file, FILE *out)
{
    fprintf(out, "mech solve: tolerance stack-up, first order, from");
    for (int i = 0; i < m->nparams; i++)
        if (m->params[i].tol > 0) {
            char u[64];
            double tol = units_file ? output_in_file_units(m, m->params[i].unit,
                                                           m->params[i].tol, u, sizeof u)
                                    : (snprintf(u, sizeof u, "%s", m->params[i].unit),
                                       m->params[i].tol);
            fprintf(out, " %s +-%.6g %s", m->params[i].name, tol, u[0] ? u : "(bare)");
        }
    fprintf(out, "; largest over the %d rows:\n", t->nrows);
    for (int c = 0; c + 1 < t->ncolumns; c++) {
        const char *name = t->columns[c].name;
        if (strncmp(name, "worst(", 6) != 0)
            continue;
        int at = 0;
        double worst = 0, rss = 0;
        for (int r = 0; r < t->nrows; r++) {
            if (mech_table_get(t, r, c) > worst) {
                worst = mech_table_get(t, r, c);
                at = r;
            }
            rss = fmax(rss, mech_table_get(t, r, c + 1));
        }
        fprintf(out, "  %-24.*s worst case %-12.6g RSS %-12.6g [%s] (worst at q = %.6g)\n",
                (int)strlen(name) - 7, name + 6, worst, rss, t->columns[c].unit,
                t->nrows ? mech_table_get(t, at, 0) : 0.0);
    }
}

/* --tolerances: the columns (mech_tolerances) and the summary. */
static int add_tolerances(const solve_args *a, const mech_model *m, mech_table *t)
{
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_tolerances(m, a->set.set, a->set.n, &a->opt, t, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    return rc != MECH_OK ? cmd_exit_status(rc) : -1;
}

static int solve_loaded(solve_args *pa, mech_model *m)
{
    solve_args a = *pa;
    int code;
    if (a.verbose)
        a.opt.log = stderr;
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    mech_solve_stats st;
    cmd_progress pr;
    cmd_progress_init(&pr, "solve", "rows", a.quiet);
    a.opt.progress = cmd_progress_callback;
    a.opt.progress_ctx = &pr;
    int rc = cmd_jit_solve(m, &a.opt, &t, &st, &d, a.jit ? CMD_ENGINE_COMPILED : a.engine,
                           stderr, "mech solve");
    cmd_progress_done(&pr);
    int suspect = a.strict ? cmd_strict_assembly(&d) : 0;
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (suspect > 0) {
        fprintf(stderr, "mech solve: --strict: the assembly is suspect (%d finding%s); %s\n",
                suspect, suspect == 1 ? "" : "s",
                a.out ? "no output file written" : "no output written");
        mech_table_free(&t);
        return MECH_EXIT_SOLVE;
    }
    if (rc == MECH_ESOLVE) {
        print_gaps(&a, m, &t);
        fprintf(stderr, "mech solve: %d rows solved (%d positions requested); %s\n", t.nrows,
                t.nrequested, t.nrows == 0 ? (a.out ? "no output file written" : "no output written")
                : a.out ? "the rows solved are written" : "the rows solved follow");
    }
    if (a.stats) {
        print_stats(m, &st, a.units_file, stderr);
        fprintf(stderr, "  solver             %s\n", cmd_jit_how());
    }
    if (a.stats || a.speed_fluctuation > 0.0)
        print_flywheel(&a, m, &t);
    code = cmd_exit_status(rc);
    if (rc == MECH_ESOLVE && a.within && only_assembly_gaps(&t))
        code = MECH_EXIT_OK;
    if ((a.sens || a.tolerances) && t.nrows > 0 && (rc == MECH_OK || rc == MECH_ESOLVE)) {
        a.opt.progress = NULL;
        int sc = a.sens ? add_sensitivity(&a, m, &t) : -1;
        if (sc < 0 && a.tolerances)
            sc = add_tolerances(&a, m, &t);
        if (sc < 0 && a.units_file && output_file_units(m, &t) != MECH_OK)
            sc = MECH_EXIT_IO;
        if (sc < 0 && a.tolerances)
            print_stackup(m, &t, a.units_file, stderr);
        if (sc >= 0) {
            mech_table_free(&t);
            return sc;
        }
    } else if (a.units_file && output_file_units(m, &t) != MECH_OK) {
        code = MECH_EXIT_IO;
    }
    if (rc == MECH_OK || (rc == MECH_ESOLVE && t.nrows > 0)) {
        int wc = write_rows(&a, &t);
        code = wc != MECH_EXIT_OK ? wc : code;
    }
    mech_table_free(&t);
    return code;
}

int cmd_solve(int argc, char **argv)
{
    solve_args a = {0};
    int code = parse_args(argc, argv, &a);
    if (code >= 0) {
        cmd_sets_free(&a.set);
        return code;
    }
    mech_model *m = NULL;
    code = cmd_refuse_input("solve", a.out, &a.file, 1);
    if (code < 0)
        code = cmd_load_checked_with(a.file, a.set.set, a.set.n, &m);
    if (code == MECH_EXIT_OK && (code = apply_overrides(&a, m)) < 0)
        code = solve_loaded(&a, m);
    cmd_sets_free(&a.set);
    mech_outputs_free(&a.selected);
    mech_model_free(&m);
    return code;
}
