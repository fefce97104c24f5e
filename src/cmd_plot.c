/* src/cmd_plot.c: `mech plot` (SVG figures of the sweep) and `mech animate`
 * (an animated SVG of the mechanism). Option parsing and the solve; the
 * drawing is src/plot.c and src/plot_anim.c (docs/plots.md). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmd_plot.h"
#include "commands.h"
#include "plot.h"

const char cmd_plot_help[] =
    "usage: mech plot FILE [--out DIR] [--outputs NAME,...] [--from A --to B]\n"
    "                 [--steps N] [--set NAME=VALUE] [--forces]\n"
    "                 [--friction on|off|both]\n"
    "\n"
    "Solve the driver sweep and draw one SVG figure per group of quantities\n"
    "against the driver (angle in deg, or displacement in mm): point positions,\n"
    "velocities and accelerations (x and y of each point), link angles, angular\n"
    "velocities and accelerations, slider displacements, velocities and\n"
    "accelerations, and with forces the reaction components Fx, Fy of every joint\n"
    "(the legend names the link the force acts on) and the driver torque, with\n"
    "and without friction when the file has friction. Then the path of every\n"
    "output point that moves (path-P: y against x in mm on equal axes, a start\n"
    "marker, arrows in the direction of motion). The figures follow the file's\n"
    "outputs. Units: mm, deg, m/s, m/s^2, rad/s, rad/s^2, N, N*m. Files are\n"
    "DIR/STEM-GROUP.svg, STEM the file's name without .yaml; each written path\n"
    "is printed on standard output. Long sweeps are thinned to within 0.25 px.\n"
    "\n"
    "options:\n"
    "  --out DIR, -d DIR   directory of the figures (created if missing; default .)\n"
    "  --outputs LIST      comma-separated point, link and slider names to plot\n"
    "                      instead of the file's outputs (the points' paths too)\n"
    "  --from A --to B     sweep the driver from A to B instead of the file's range\n"
    "                      (as mech solve: bare numbers deg or mm, units allowed)\n"
    "  --steps N           N intervals (with --from/--to: default 360; alone: over\n"
    "                      the file's range)\n"
    "  --set NAME=VALUE    replace the file's parameter NAME by VALUE (repeatable),\n"
    "                      e.g. --set 'l=150 mm'\n"
    "  --forces            also the forces (as 'outputs: {forces: true}')\n"
    "  --friction MODE     on, off or both (default: both when a joint has friction)\n"
    "  -h, --help          show this help\n"
    "\n"
    "exit status: 0 written, 1 the mechanism cannot be solved somewhere in the range\n"
    "(nothing written), 2 invalid file or usage, 3 a file cannot be read or written\n";

const char cmd_animate_help[] =
    "usage: mech animate FILE [-o OUT.svg] [--outputs POINT,...] [--from A --to B]\n"
    "                    [--steps N] [--set NAME=VALUE] [--duration S] [--frames N]\n"
    "                    [--frame K] [--test-colours] [--pause-at T]\n"
    "\n"
    "Solve the positions over the driver range and write one self-contained\n"
    "animated SVG (SMIL, no script, no network) of the mechanism going through\n"
    "the range: links as bars (2 points) or plates (3 or more), pins as circles,\n"
    "ground pivots hatched, sliders as blocks on their guides, the paths of the\n"
    "file's output points (or of --outputs), and a scale bar in mm. It plays in\n"
    "any web browser.\n"
    "\n"
    "options:\n"
    "  -o, --output FILE   write the SVG to FILE (temporary file renamed when\n"
    "                      complete; default: standard output)\n"
    "  --outputs LIST      comma-separated point names whose paths are drawn\n"
    "                      instead of the file's output points\n"
    "  --from A --to B     sweep the driver from A to B instead of the file's range\n"
    "                      (as mech solve: bare numbers deg or mm, units allowed)\n"
    "  --steps N           N intervals (with --from/--to: default 360; alone: over\n"
    "                      the file's range)\n"
    "  --set NAME=VALUE    replace the file's parameter NAME by VALUE (repeatable)\n"
    "  --duration S        seconds for one pass through the range (default 4)\n"
    "  --frames N          use at most N evenly spread positions (default 1000)\n"
    "  --frame K           a still picture of position K (0 = the first), no animation\n"
    "  --test-colours      draw in grey with every point a disc of its own colour\n"
    "                      (for tests/browser/run.sh)\n"
    "  --pause-at T        add an inline script that stops the animation at T s\n"
    "                      (for tests; the SVG has no script otherwise)\n"
    "  -h, --help          show this help\n"
    "\n"
    "exit status: 0 written, 1 the mechanism cannot be solved somewhere in the range\n"
    "(nothing written), 2 invalid file or usage, 3 a file cannot be read or written\n";

typedef struct plot_args {
    const char *cmd;          /* "plot" or "animate" */
    const char *file, *out, *outputs, *from, *to;
    cmd_sets set;             /* --set NAME=VALUE, as mech solve */
    int steps, forces, friction; /* friction: -1 = default */
    plot_anim_options anim;
} plot_args;


/* One option of either command; *i advances past its value.
 * Returns -1 to go on, else the exit status. */
static int parse_option(plot_args *a, int argc, char **argv, int *i)
{
    const char *arg = argv[*i];
    int animate = strcmp(a->cmd, "animate") == 0;
    static const char *const valued[] = {"--out", "-d", "-o", "--output", "--outputs", "--steps",
                                         "--friction", "--duration", "--frame", "--frames",
                                         "--pause-at", "--set", "--from", "--to"};
    int has_value = 0;
    for (size_t k = 0; k < sizeof valued / sizeof valued[0]; k++)
        has_value |= strcmp(arg, valued[k]) == 0;
    if (!has_value) {
        if (!animate && strcmp(arg, "--forces") == 0)
            a->forces = 1;
        else if (animate && (strcmp(arg, "--test-colours") == 0 ||
                             strcmp(arg, "--test-colors") == 0))
            a->anim.test_colours = 1;
        else
            return cmd_usage_error(a->cmd, "unknown option '%s'", arg);
        return -1;
    }
    if (*i + 1 >= argc)
        return cmd_usage_error(a->cmd, "option '%s' needs a value", arg);
    const char *val = argv[++*i];
    if (strcmp(arg, "--steps") == 0) {
        if (!cmd_parse_int(val, 1, 100000000, &a->steps))
            return cmd_usage_error(a->cmd, "--steps needs a whole number from 1 to 1e8, not '%s'", val);
    } else if (strcmp(arg, "--set") == 0) {
        return cmd_parse_set(a->cmd, val, &a->set);
    } else if (strcmp(arg, "--from") == 0) {
        a->from = val;
    } else if (strcmp(arg, "--to") == 0) {
        a->to = val;
    } else if (strcmp(arg, "--outputs") == 0) {
        a->outputs = val;
    } else if (!animate && (strcmp(arg, "--out") == 0 || strcmp(arg, "-d") == 0)) {
        a->out = val;
    } else if (!animate && strcmp(arg, "--friction") == 0) {
        if (strcmp(val, "on") == 0)
            a->friction = MECH_FRICTION_ON;
        else if (strcmp(val, "off") == 0)
            a->friction = MECH_FRICTION_OFF;
        else if (strcmp(val, "both") == 0)
            a->friction = MECH_FRICTION_BOTH;
        else
            return cmd_usage_error(a->cmd, "--friction is on, off or both, not '%s'", val);
    } else if (animate && (strcmp(arg, "-o") == 0 || strcmp(arg, "--output") == 0)) {
        a->out = val;
    } else if (animate && strcmp(arg, "--duration") == 0) {
        char *end;
        double s = strtod(val, &end);
        if (end == val || *end != '\0' || !(s >= 0.01 && s <= 86400))
            return cmd_usage_error(a->cmd, "--duration needs seconds from 0.01 to 86400, not '%s'", val);
        a->anim.duration = s;
    } else if (animate && strcmp(arg, "--frame") == 0) {
        if (!cmd_parse_int(val, 0, 100000000, &a->anim.frame))
            return cmd_usage_error(a->cmd, "--frame needs a position number from 0, not '%s'", val);
    } else if (animate && strcmp(arg, "--pause-at") == 0) {
        char *end;
        double s = strtod(val, &end);
        if (end == val || *end != '\0' || !(s >= 0 && s <= 86400))
            return cmd_usage_error(a->cmd, "--pause-at needs seconds from 0 to 86400, not '%s'", val);
        a->anim.pause_at = s;
    } else if (animate && strcmp(arg, "--frames") == 0) {
        if (!cmd_parse_int(val, 2, 1000000, &a->anim.max_frames))
            return cmd_usage_error(a->cmd, "--frames needs a whole number from 2 to 1e6, not '%s'", val);
    } else {
        return cmd_usage_error(a->cmd, "unknown option '%s'", arg);
    }
    return -1;
}

/* Returns -1 to go on, else the exit status. */
static int parse_args(int argc, char **argv, plot_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        if (cmd_wants_help(arg)) {
            fputs(strcmp(a->cmd, "plot") == 0 ? cmd_plot_help : cmd_animate_help, stdout);
            return MECH_EXIT_OK;
        }
        if (arg[0] == '-' && arg[1] != '\0') {
            int code = parse_option(a, argc, argv, &i);
            if (code >= 0)
                return code;
        } else if (a->file) {
            return cmd_usage_error(a->cmd, "one file at a time ('%s' is a second file)", arg);
        } else {
            a->file = arg;
        }
    }
    if (!a->file)
        return cmd_usage_error(a->cmd, "%s", "no file given");
    return cmd_check_range_pair(a->cmd, a->from, a->to);
}

/* Solve, printing the diagnostics; returns an exit status. */
static int solve(const plot_args *a, const mech_model *m, const mech_solve_options *o,
                 mech_table *t)
{
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_solve(m, o, t, NULL, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc == MECH_ESOLVE)
        fprintf(stderr, "mech %s: %d of the sweep's positions were solved before this; "
                "nothing written\n", a->cmd, t->nrows);
    return cmd_exit_status(rc);
}

/* The file's name without directory and .yaml/.yml. */
static void file_stem(const char *path, char *buf, size_t n)
{
    const char *b = strrchr(path, '/');
    snprintf(buf, n, "%s", b ? b + 1 : path);
    size_t len = strlen(buf);
    if (len > 5 && strcmp(buf + len - 5, ".yaml") == 0)
        buf[len - 5] = '\0';
    else if (len > 4 && strcmp(buf + len - 4, ".yml") == 0)
        buf[len - 4] = '\0';
}

static int any_friction(const mech_model *m)
{
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].friction > 0)
            return 1;
    return 0;
}

/* DIR/STEM-NAME.svg of every figure into paths[n] (each malloc'ed; NULL
 * when out of memory). */
static void figure_paths(const char *dir, const char *stem, const plot_figure *figs, int n,
                         char **paths)
{
    for (int k = 0; k < n; k++) {
        size_t len = strlen(dir) + strlen(stem) + strlen(figs[k].name) + 8;
        if ((paths[k] = malloc(len)))
            snprintf(paths[k], len, "%s/%s-%s.svg", dir, stem, figs[k].name);
    }
}

static int write_figures(const plot_args *a, const mech_model *m, const mech_table *t)
{
    enum { MAXFIG = 4096 };
    const char *dir = a->out ? a->out : ".";
    if (cmd_make_dir(dir) != 0) {
        fprintf(stderr, "%s: error: cannot create the directory: %s\n", dir, strerror(errno));
        return MECH_EXIT_IO;
    }
    plot_figure *figs = calloc(MAXFIG, sizeof *figs);
    char **paths = calloc(MAXFIG, sizeof *paths);
    if (!figs || !paths) {
        fprintf(stderr, "mech plot: out of memory\n");
        free(figs);
        free(paths);
        return MECH_EXIT_IO;
    }
    int n = plot_plan_all(m, t, figs, MAXFIG);
    if (n == 0)
        fprintf(stderr, "mech plot: %s: nothing to plot (no outputs)\n", a->file);
    char stem[256];
    file_stem(a->file, stem, sizeof stem);
    figure_paths(dir, stem, figs, n, paths);
    int code = MECH_EXIT_OK;
    for (int k = 0; k < n && code == MECH_EXIT_OK; k++)  /* every path before any is written */
        code = !paths[k] ? MECH_EXIT_IO
               : cmd_refuse_input("plot", paths[k], &a->file, 1) >= 0 ? MECH_EXIT_INPUT
               : MECH_EXIT_OK;
    for (int k = 0; k < n && code == MECH_EXIT_OK; k++) {
        mech_diag d;
        mech_diag_init(&d);
        if (plot_figure_write(m, t, &figs[k], m->name, paths[k], &d) != MECH_OK)
            code = MECH_EXIT_IO;
        else
            printf("%s\n", paths[k]);
        mech_diag_print(&d, stderr);
        mech_diag_free(&d);
    }
    for (int k = 0; k < n; k++)
        free(paths[k]);
    free(paths);
    free(figs);
    return code;
}

/* What both commands do first: default options, the arguments, the file
 * loaded and checked. Returns -1 to go on, else the exit status. */
static int begin(const char *cmd, int argc, char **argv, plot_args *a, mech_model **m)
{
    *a = (plot_args){.cmd = cmd, .friction = -1};
    plot_anim_options_default(&a->anim);
    int code = parse_args(argc, argv, a);
    if (code >= 0) {
        cmd_sets_free(&a->set);
        return code;
    }
    code = cmd_load_checked_with(a->file, a->set.set, a->set.n, m);
    cmd_sets_free(&a->set);
    return code == MECH_EXIT_OK ? -1 : code;
}

int cmd_plot(int argc, char **argv)
{
    plot_args a;
    mech_model *m = NULL;
    int code = begin("plot", argc, argv, &a, &m);
    if (code >= 0)
        return code;
    char err[256];
    /* --outputs: the figures and the solve see a view of the model with
       other outputs; the loaded model itself never changes */
    mech_model view = *m;
    mech_outputs selected = {0};
    if (a.outputs && mech_outputs_parse(m, a.outputs, &selected, err, sizeof err) != MECH_OK) {
        fprintf(stderr, "mech plot: --outputs: %s\n", err);
        mech_model_free(&m);
        return MECH_EXIT_INPUT;
    }
    if (a.outputs)
        view.outputs = selected;
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = a.forces;
    if (a.friction >= 0)
        o.friction = a.friction;
    else if ((a.forces || view.outputs.forces) && any_friction(m))
        o.friction = MECH_FRICTION_BOTH;
    mech_table t = {0};
    code = cmd_apply_range("plot", a.from, a.to, a.steps, m, &o);
    if (code < 0)
        code = solve(&a, &view, &o, &t);
    if (code == MECH_EXIT_OK)
        code = write_figures(&a, &view, &t);
    mech_table_free(&t);
    mech_outputs_free(&selected);
    mech_model_free(&m);
    return code;
}

/* --outputs of the animation: the points whose paths are drawn (*traced,
 * owned by the caller); links and sliders have no path and are refused.
 * Returns -1 to go on, else the exit status. */
static int traced_points(const plot_args *a, const mech_model *m, mech_outputs *traced)
{
    char err[256];
    if (!a->outputs)
        return -1;
    if (mech_outputs_parse(m, a->outputs, traced, err, sizeof err) != MECH_OK) {
        fprintf(stderr, "mech animate: --outputs: %s\n", err);
        return MECH_EXIT_INPUT;
    }
    const char *what = traced->nlinks > 0 ? m->links[traced->links[0]].name
                       : traced->nsliders > 0 ? m->joints[traced->sliders[0]].name : NULL;
    if (what) {
        fprintf(stderr, "mech animate: --outputs: '%s' is a %s, not a point: the animation "
                "traces the paths of points\n", what, traced->nlinks > 0 ? "link" : "slider");
        mech_outputs_free(traced);
        return MECH_EXIT_INPUT;
    }
    return -1;
}

int cmd_animate(int argc, char **argv)
{
    plot_args a;
    mech_model *m = NULL;
    int code = begin("animate", argc, argv, &a, &m);
    if (code >= 0)
        return code;
    if ((code = cmd_refuse_input("animate", a.out, &a.file, 1)) >= 0) {
        mech_model_free(&m);
        return code;
    }
    /* the file's output points (or those of --outputs) are traced; every
       point and link is drawn, through a view of the model with those outputs */
    mech_outputs traced = {0};
    if ((code = traced_points(&a, m, &traced)) >= 0) {
        mech_model_free(&m);
        return code;
    }
    mech_model view = *m;
    if (cmd_select_everything(m, &view.outputs) != 0) {
        fprintf(stderr, "mech animate: out of memory\n");
        mech_outputs_free(&traced);
        mech_model_free(&m);
        return MECH_EXIT_IO;
    }
    a.anim.trace = a.outputs ? traced.points : m->outputs.points;
    a.anim.ntrace = a.outputs ? traced.npoints : m->outputs.npoints;
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.want = MECH_WANT_POSITION;
    o.forces = -1;
    mech_table t = {0};
    code = cmd_apply_range("animate", a.from, a.to, a.steps, m, &o);
    if (code < 0)
        code = solve(&a, &view, &o, &t);
    if (code == MECH_EXIT_OK) {
        mech_diag d;
        mech_diag_init(&d);
        int rc = plot_animation_write(&view, &t, &a.anim, a.out ? a.out : "-", &d);
        mech_diag_print(&d, stderr);
        mech_diag_free(&d);
        code = cmd_exit_status(rc);
    }
    mech_outputs_free(&view.outputs);
    mech_outputs_free(&traced);
    mech_table_free(&t);
    mech_model_free(&m);
    return code;
}
