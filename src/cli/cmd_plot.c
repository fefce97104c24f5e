/* src/cli/cmd_plot.c: `mech plot` (SVG figures of the sweep) and `mech animate`
 * (an animated SVG of the mechanism). Option parsing and the solve; the
 * drawing is src/output/plot.c and src/output/plot_anim.c (docs/plots.md). */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "output.h"

typedef struct plot_args {
    const char *cmd;          /* "plot" or "animate" */
    const char *file, *out, *outputs, *from, *to;
    cmd_sets set;             /* --set NAME=VALUE, as mech solve */
    int steps, forces, friction; /* friction: -1 = default */
    plot_anim_options anim;
} plot_args;

#define AT(field) offsetof(plot_args, field)

/* The options both commands share, with the same meaning as mech solve's. */
#define OPT_OUTPUTS(what)                                                                   \
    {.names = "--outputs", .kind = CMD_OPT_TEXT, .at = AT(outputs), .label = "--outputs LIST", \
     .help = what}
#define OPT_RANGE                                                                           \
    {.names = "--from", .kind = CMD_OPT_TEXT, .at = AT(from), .label = "--from A --to B",      \
     .help = "sweep the driver from A to B instead of the file's range\n"                    \
             "(as mech solve: bare numbers deg or mm, units allowed)"},                       \
    {.names = "--to", .kind = CMD_OPT_TEXT, .at = AT(to)},                                   \
    {.names = "--steps", .kind = CMD_OPT_INT, .at = AT(steps), .lo = 1, .hi = 100000000,      \
     .expect = "needs a whole number from 1 to 1e8", .label = "--steps N",                  \
     .help = "N intervals (with --from/--to: default 360; alone: over\n"                     \
             "the file's range)"}

#define EXITS                                                                            \
    "exit status: 0 written, 1 the mechanism cannot be solved somewhere in the range\n"  \
    "(nothing written), 2 invalid file or usage, 3 a file cannot be read or written\n"

static const cmd_opt plot_options[] = {
    {.names = "--out|-d", .kind = CMD_OPT_TEXT, .at = AT(out), .label = "--out DIR, -d DIR",
     .help = "directory of the figures (created if missing; default .)"},
    OPT_OUTPUTS("comma-separated point, link and slider names to plot\n"
                "instead of the file's outputs (the points' paths too)"),
    OPT_RANGE,
    CMD_SET_ENTRY(AT(set), "replace the file's parameter NAME by VALUE (repeatable),\n"
            "e.g. --set 'l=150 mm'"),
    {.names = "--forces", .kind = CMD_OPT_FLAG, .at = AT(forces), .flag = 1, .label = "--forces",
     .help = "also the forces (as 'outputs: {forces: true}')"},
    CMD_FRICTION_ENTRY(AT(friction), "on, off or both (default: both when a joint has friction)"),
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_plot_spec = {
    .name = "plot",
    .summary = "draw SVG figures of the sweep (docs/plots.md)",
    .usage = "usage: mech plot FILE [--out DIR] [--outputs NAME,...] [--from A --to B]\n"
             "                 [--steps N] [--set NAME=VALUE] [--forces]\n"
             "                 [--friction on|off|both]\n",
    .about = "Solve the driver sweep and draw one SVG figure per group of quantities\n"
             "against the driver (angle in deg, or displacement in mm): point positions,\n"
             "velocities and accelerations (x and y of each point), link angles, angular\n"
             "velocities and accelerations, slider displacements, velocities and\n"
             "accelerations, and with forces the reaction components Fx, Fy of every joint\n"
             "(the legend names the link the force acts on) and the driver torque, with\n"
             "and without friction when the file has friction. Then the path of every\n"
             "output point that moves (path-P: y against x in mm on equal axes, a start\n"
             "marker, arrows in the direction of motion). A file with a fit: section also\n"
             "gets STEM-fit.svg: its curve against the section's targets (mech fit). The\n"
             "figures follow the file's outputs. Units: mm, deg, m/s, m/s^2, rad/s,\n"
             "rad/s^2, N, N*m. Files are DIR/STEM-GROUP.svg, STEM the file's name\n"
             "without .yaml; each written path is printed on standard output. Long sweeps\n"
             "are thinned to within 0.25 px.\n",
    .opts = plot_options,
    .column = 22,
    .exits = EXITS,
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given",
};

static const cmd_opt animate_options[] = {
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .label = "-o, --output FILE",
     .help = "write the SVG to FILE (temporary file renamed when\n"
             "complete; default: standard output)"},
    OPT_OUTPUTS("comma-separated point names whose paths are drawn\n"
                "instead of the file's output points"),
    OPT_RANGE,
    CMD_SET_ENTRY(AT(set), "replace the file's parameter NAME by VALUE (repeatable)"),
    {.names = "--duration", .kind = CMD_OPT_REAL, .at = AT(anim.duration), .lo = 0.01,
     .hi = 86400, .expect = "needs seconds from 0.01 to 86400", .label = "--duration S",
     .help = "seconds for one pass through the range (default 4)"},
    {.names = "--frames", .kind = CMD_OPT_INT, .at = AT(anim.max_frames), .lo = 2, .hi = 1000000,
     .expect = "needs a whole number from 2 to 1e6", .label = "--frames N",
     .help = "use at most N evenly spread positions (default 1000)"},
    {.names = "--frame", .kind = CMD_OPT_INT, .at = AT(anim.frame), .lo = 0, .hi = 100000000,
     .expect = "needs a position number from 0", .label = "--frame K",
     .help = "a still picture of position K (0 = the first), no\n"
             "animation"},
    {.names = "--test-colours|--test-colors", .kind = CMD_OPT_FLAG, .at = AT(anim.test_colours),
     .flag = 1, .label = "--test-colours",
     .help = "draw in grey with every point a disc of its own colour\n"
             "(for tests/browser/run.sh)"},
    {.names = "--pause-at", .kind = CMD_OPT_REAL, .at = AT(anim.pause_at), .lo = 0, .hi = 86400,
     .expect = "needs seconds from 0 to 86400", .label = "--pause-at T",
     .help = "add an inline script that stops the animation at T s\n"
             "(for tests; the SVG has no script otherwise)"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_animate_spec = {
    .name = "animate",
    .summary = "write an animated SVG of the mechanism",
    .usage = "usage: mech animate FILE [-o OUT.svg] [--outputs POINT,...] [--from A --to B]\n"
             "                    [--steps N] [--set NAME=VALUE] [--duration S] [--frames N]\n"
             "                    [--frame K] [--test-colours] [--pause-at T]\n",
    .about = "Solve the positions over the driver range and write one self-contained\n"
             "animated SVG (SMIL, no script, no network) of the mechanism going through\n"
             "the range: links as bars (2 points) or plates (3 or more), pins as circles,\n"
             "ground pivots hatched, sliders as blocks on their guides, the paths of the\n"
             "file's output points (or of --outputs), and a scale bar in mm. It plays in\n"
             "any web browser.\n",
    .opts = animate_options,
    .column = 22,
    .exits = EXITS,
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given",
};

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

/* A file with a fit: section: DIR/STEM-fit.svg, its curve against the
 * section's targets; left out with a warning when the targets cannot be
 * read or the mechanism assembles nowhere. */
static int write_fit_figure(const plot_args *a, const mech_model *m, const char *dir,
                            const char *stem)
{
    size_t len = strlen(dir) + strlen(stem) + 16;
    char *path = malloc(len);
    if (!path) {
        fprintf(stderr, "mech plot: out of memory\n");
        return MECH_EXIT_IO;
    }
    snprintf(path, len, "%s/%s-fit.svg", dir, stem);
    int code = cmd_refuse_input("plot", path, &a->file, 1) >= 0 ? MECH_EXIT_INPUT : MECH_EXIT_OK;
    if (code == MECH_EXIT_OK) {
        mech_diag d;
        mech_diag_init(&d);
        int rc = fit_figure_of_model(m, path, &d);
        mech_diag_print(&d, stderr);
        mech_diag_free(&d);
        if (rc == MECH_OK)
            printf("%s\n", path);
        else if (rc != MECH_EINPUT)
            code = MECH_EXIT_IO;
    }
    free(path);
    return code;
}

/* A file with cams: DIR/STEM-cam-NAME-{lift,velocity,acceleration,jerk,
 * profile}.svg (docs/cams.md 5). */
typedef struct cam_fig_ctx {
    const plot_args *a;
    const mech_model *m;
    const char *dir, *stem;
    mech_diag *d;
} cam_fig_ctx;

static int write_cam_figure(void *vctx, const mech_table *t, const plot_figure *f)
{
    const cam_fig_ctx *c = vctx;
    char path[4096];
    if ((size_t)snprintf(path, sizeof path, "%s/%s-%s.svg", c->dir, c->stem, f->name) >=
        sizeof path)
        return diag_error(c->d, c->m->file, (mech_mark){0, 0}, "the figure's path is too long");
    if (cmd_refuse_input("plot", path, &c->a->file, 1) >= 0)
        return MECH_EINPUT;
    int rc = plot_figure_write(c->m, t, f, c->m->name, path, c->d);
    if (rc == MECH_OK)
        printf("%s\n", path);
    return rc;
}

static int write_cam_figures(const plot_args *a, const mech_model *m, const char *dir,
                             const char *stem)
{
    mech_diag d;
    mech_diag_init(&d);
    cam_fig_ctx c = {a, m, dir, stem, &d};
    int rc = cam_figures_each(m, write_cam_figure, &c, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    return rc == MECH_OK ? MECH_EXIT_OK : cmd_exit_status(rc);
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
    if (code == MECH_EXIT_OK && m->fit)
        code = write_fit_figure(a, m, dir, stem);
    if (code == MECH_EXIT_OK && m->cams)
        code = write_cam_figures(a, m, dir, stem);
    return code;
}

/* What both commands do first: default options, the arguments, the file
 * loaded and checked. Returns -1 to go on, else the exit status. */
static int begin(const char *cmd, int argc, char **argv, plot_args *a, mech_model **m)
{
    *a = (plot_args){.cmd = cmd, .friction = -1};
    plot_anim_options_default(&a->anim);
    int code = cmd_opts_parse(strcmp(cmd, "plot") == 0 ? &cmd_plot_spec : &cmd_animate_spec, argc,
                              argv, a);
    if (code < 0)
        code = cmd_check_range_pair(cmd, a->from, a->to);
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
