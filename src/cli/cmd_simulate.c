/* src/cli/cmd_simulate.c: `mech simulate`, forward dynamics on the command
 * line (docs/dynamics.md): the file's free drivers move as their loads make
 * them move; mech_simulate integrates, the CSV is written whole or not at
 * all, as mech solve's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "output.h"

typedef struct simulate_args {
    const char *file, *out, *to, *step;
    int stats, quiet;
    mech_simulate_options opt;
} simulate_args;

static const cmd_word methods[] = {{"bdf", MECH_SIM_BDF}, {"adams", MECH_SIM_ADAMS}, {NULL, 0}};

#define AT(field) offsetof(simulate_args, field)

static const cmd_opt options[] = {
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .label = "-o, --output FILE",
     .help = "write the CSV to FILE (written to a temporary file and\n"
             "renamed when complete; default: standard output)"},
    {.names = "--to", .kind = CMD_OPT_TEXT, .at = AT(to), .label = "--to T",
     .help = "simulate until time T (bare numbers in seconds, or with\n"
             "a unit: --to '500 ms'; default: the sweep's last time)"},
    {.names = "--step", .kind = CMD_OPT_TEXT, .at = AT(step), .label = "--step DT",
     .help = "one row every DT (default: the sweep's spacing); the\n"
             "integrator's own steps are adaptive"},
    {.names = "--rtol", .kind = CMD_OPT_REAL, .at = AT(opt.rtol), .lo = 1e-14, .hi = 1e-1,
     .expect = "needs a number from 1e-14 to 0.1", .label = "--rtol R",
     .help = "relative tolerance of the integration (default 1e-8)"},
    {.names = "--atol", .kind = CMD_OPT_REAL, .at = AT(opt.atol), .lo = 1e-300, .hi = 1,
     .expect = "needs a number from 1e-300 to 1", .label = "--atol A",
     .help = "absolute tolerance, SI units of the coordinates, rates\n"
             "and works (default 1e-10)"},
    {.names = "--method", .kind = CMD_OPT_WORD, .at = AT(opt.method), .words = methods,
     .expect = "is bdf or adams", .label = "--method M",
     .help = "bdf: CVODE's BDF, for stiff motion (stiff springs,\n"
             "dampers, speed controllers; default); adams: Adams-\n"
             "Moulton, cheaper for smooth non-stiff motion"},
    {.names = "--max-steps", .kind = CMD_OPT_LONG, .at = AT(opt.max_steps), .lo = 1,
     .hi = 1000000000L, .expect = "needs a whole number from 1 to 1000000000",
     .label = "--max-steps N",
     .help = "integration steps allowed between two rows (default 1e6)"},
    {.names = "--stop-at-rest", .kind = CMD_OPT_FLAG, .at = AT(opt.stop_at_rest), .flag = 1,
     .label = "--stop-at-rest",
     .help = "end the run where a free driver's rate crosses zero\n"
             "(CVODE's root finding: the last row is at that time)"},
    {.names = "--stop-when", .kind = CMD_OPT_TEXT, .at = AT(opt.stop_when),
     .label = "--stop-when COND",
     .help = "COND is NAME.MEMBER=V: end the run where a point's x or\n"
             "y, a link's angle or a slider's s crosses V (bare\n"
             "numbers mm or deg): --stop-when 'x_C.s=150 mm'"},
    {.names = "--stats", .kind = CMD_OPT_FLAG, .at = AT(stats), .flag = 1, .label = "--stats",
     .help = "print the integrator's steps, evaluations, the worst\n"
             "loop residual, the energy balance and the time to\n"
             "standard error"},
    {.names = "-q|--quiet", .kind = CMD_OPT_FLAG, .at = AT(quiet), .flag = 1,
     .label = "-q, --quiet", .help = "no summary line"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_simulate_spec = {
    .name = "simulate",
    .summary = "forward dynamics: the motion that the loads give the free drivers",
    .usage = "usage: mech simulate FILE [-o OUT.csv] [--to T] [--step DT] [--rtol R]\n"
             "                     [--atol A] [--method bdf|adams] [--max-steps N]\n"
             "                     [--stop-at-rest] [--stop-when NAME.MEMBER=V]\n"
             "                     [--stats] [--quiet]\n",
    .about = "Integrate the equations of motion of a file whose drivers: list has free\n"
             "drivers ('free: true' with 'initial: {value, speed}' and a 'load:';\n"
             "docs/dynamics.md) with SUNDIALS CVODE, and write one CSV row per output\n"
             "time: t, the outputs' positions, velocities and accelerations, reactions,\n"
             "driver loads (a free driver's is 0 to rounding), the power residual, and\n"
             "energy.kinetic, energy.gravity, energy.springs, work.loads, work.drivers,\n"
             "work.dampers, energy.balance [J] (the balance is 0 to the tolerance).\n",
    .opts = options,
    .column = 22,
    .exits = "exit status: 0 simulated to the end, 1 the run stopped early (a limit\n"
             "position, a dead point, an integrator failure: the message gives the time;\n"
             "the rows so far are written), 2 invalid file or usage, 3 a file cannot be\n"
             "read or written\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech simulate FILE [-o OUT.csv] ...)",
};

/* A time from the command line: bare seconds or with a unit. */
static int read_time(const char *opt, const char *text, double *out)
{
    char err[200];
    if (mech_parse_value(text, 2, out, err, sizeof err) != MECH_OK || !isfinite(*out))
        return fprintf(stderr, "mech simulate: %s: %s\n", opt, err), MECH_EXIT_INPUT;
    return -1;
}

static int run(simulate_args *a, const mech_model *m)
{
    if (a->to && read_time("--to", a->to, &a->opt.to) >= 0)
        return MECH_EXIT_INPUT;
    if (a->step && read_time("--step", a->step, &a->opt.step) >= 0)
        return MECH_EXIT_INPUT;
    if (a->step && !(a->opt.step > 0.0))
        return fprintf(stderr, "mech simulate: --step needs a positive time, not '%s'\n",
                       a->step), MECH_EXIT_INPUT;
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    mech_simulate_stats st;
    int rc = mech_simulate(m, &a->opt, &t, &st, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    int code = cmd_exit_status(rc);
    if (t.nrows > 0) {
        int bal = mech_table_column(&t, "energy.balance");
        double worst = 0.0, scale = 0.0;
        for (int r = 0; r < t.nrows; r++) {
            worst = fmax(worst, fabs(mech_table_get(&t, r, bal)));
            for (int c = bal - 6; c < bal; c++)
                scale = fmax(scale, fabs(mech_table_get(&t, r, c)));
        }
        if (a->stats)
            fprintf(stderr,
                    "%s: simulated to t = %.9g s, %d rows\n"
                    "  integrator         %s, rtol %.3g, atol %.3g: %ld steps, %ld rhs, %ld "
                    "jacobians\n"
                    "  evaluations        %ld states, %ld force solves\n"
                    "  worst residual     %.3g m (loops); free drivers' load at most %.3g\n"
                    "  energy balance     worst %.3g J (%.3g of the largest energy or work)\n"
                    "  time               %.3g s (%.3g us per state)\n",
                    m->file, st.stop_time, st.rows,
                    a->opt.method == MECH_SIM_ADAMS ? "CVODE Adams" : "CVODE BDF",
                    a->opt.rtol, a->opt.atol, st.steps, st.rhs_evals, st.jac_evals,
                    st.evaluations, st.force_solves, st.worst_residual, st.worst_free_load,
                    worst, scale > 0 ? worst / scale : 0.0, st.seconds,
                    st.evaluations ? st.seconds / st.evaluations * 1e6 : 0.0);
        mech_diag w;
        mech_diag_init(&w);
        if (cmd_write_table(&t, a->out, "simulate", a->file, &w) != MECH_OK)
            code = MECH_EXIT_IO;
        mech_diag_print(&w, stderr);
        mech_diag_free(&w);
        if (rc == MECH_ESOLVE)
            fprintf(stderr, "mech simulate: stopped at t = %.9g s; the %d rows before are %s\n",
                    st.stop_time, t.nrows, a->out ? "written" : "written out");
    }
    mech_table_free(&t);
    return code;
}

int cmd_simulate(int argc, char **argv)
{
    simulate_args a = {0};
    mech_simulate_options_default(&a.opt);
    int code = cmd_opts_parse(&cmd_simulate_spec, argc, argv, &a);
    if (code >= 0)
        return code;
    mech_model *m = NULL;
    code = cmd_refuse_input("simulate", a.out, &a.file, 1);
    if (code < 0)
        code = cmd_load_checked_with(a.file, NULL, 0, &m);
    if (code == MECH_EXIT_OK)
        code = run(&a, m);
    mech_model_free(&m);
    return code;
}
