/* src/cli/cmd_draw.c: `mech draw`, the assembled mechanism at one driver position
 * as a still SVG with the names of its links, points and joints, and the
 * pose the file states (its `initial:` guesses) beside it when the two
 * differ; `mech check --draw` calls the same drawing (docs/plots.md, "mech
 * draw"). The picture is src/output/plot_anim.c's still frame; the stated pose is
 * mech_pose_guess (src/solve/pose.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "output.h"

typedef struct draw_args {
    const char *file;
    cmd_draw_options o;  /* -o, --frame, --at */
    cmd_sets set;
} draw_args;

#define AT(field) offsetof(draw_args, field)

static const cmd_opt options[] = {
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(o.out), .flags = CMD_RUN_ONLY,
     .label = "-o, --output FILE",
     .help = "write the SVG to FILE (temporary file renamed when\n"
             "complete; default: standard output)"},
    {.names = "--frame", .kind = CMD_OPT_INT, .at = AT(o.frame), .lo = 0, .hi = 100000000,
     .expect = "needs a position number from 0", .label = "--frame K",
     .help = "position K of the sweep (0 = the first, as mech\n"
             "solve's rows)"},
    {.names = "--at", .kind = CMD_OPT_TEXT, .at = AT(o.at), .label = "--at VALUE",
     .help = "the driver at VALUE (bare numbers deg, mm or s; units\n"
             "allowed), solved from the first position in steps no\n"
             "longer than the sweep's"},
    CMD_SET_ENTRY(AT(set), "replace the file's parameter NAME by VALUE (repeatable)"),
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_draw_spec = {
    .name = "draw",
    .summary = "draw the assembled mechanism with its names, and the guessed pose",
    .usage = "usage: mech draw FILE [-o OUT.svg] [--frame K | --at VALUE] [--set NAME=VALUE]\n",
    .about = "Assemble the mechanism at the first position of its sweep (or at position K,\n"
             "or at the driver value VALUE, reached from the first position as the sweep\n"
             "goes) and draw it as one still SVG: links, pins, the ground's hatched pivots,\n"
             "slider guides and blocks, gear pitch circles, with the names of the links,\n"
             "points and joints. When the file gives 'initial:' guesses and the assembly\n"
             "is elsewhere (some point more than 0.25 % of the drawing's size away), the\n"
             "guessed pose (the solver's first iterate: the guesses, 0 for the rest) is\n"
             "drawn behind it, dashed and grey, with a legend, and a note says which point\n"
             "is farthest from it.\n",
    .opts = options,
    .column = 22,
    .exits = "exit status: 0 written, 1 the mechanism does not assemble there (nothing\n"
             "written), 2 invalid file or usage, 3 a file cannot be read or written\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech draw FILE -o OUT.svg)",
};

enum { DRAW_MAX_STEPS = 1000000 };
#define DRAW_TOLERANCE 0.0025  /* of the drawing's larger span: about 2 px of 760 */

void cmd_draw_options_default(cmd_draw_options *o)
{
    memset(o, 0, sizeof *o);
    o->frame = -1;
}

/* The driver positions solved in turn: the sweep's first K + 1, or from
 * the first to --at in steps no longer than the sweep's. *q is malloc'ed.
 * Returns -1 to go on, else the exit status. */
static int positions(const char *cmd, const mech_model *m, const cmd_draw_options *o, double **q,
                     int *nq)
{
    const mech_driver *dr = &m->driver;
    double q0 = dr->values[0], to = q0, step = 0;
    int n = 1;
    if (o->frame < 0 && !o->at && m->has_start)
        q0 = to = m->start_q;  /* a drawn file: the position it was drawn at */
    if (o->frame >= 0) {
        if (o->frame >= dr->nvalues) {
            fprintf(stderr, "mech %s: --frame %d: the sweep has %d positions (frames 0 to %d)\n",
                    cmd, o->frame, dr->nvalues, dr->nvalues - 1);
            return MECH_EXIT_INPUT;
        }
        n = o->frame + 1;
    } else if (o->at) {
        int code = cmd_parse_driver(cmd, "--at", o->at, m, &to);
        if (code >= 0)
            return code;
        step = dr->nvalues > 1 ? fabs(dr->values[1] - dr->values[0]) : 0;
        double need = step > 0 ? ceil(fabs(to - q0) / step) : 1;
        if (!(need <= DRAW_MAX_STEPS)) {
            fprintf(stderr, "mech %s: --at '%s' is more than %d of the sweep's steps from its "
                    "first position\n", cmd, o->at, DRAW_MAX_STEPS);
            return MECH_EXIT_INPUT;
        }
        n = (int)need + 1;
    }
    if (!(*q = malloc((size_t)n * sizeof **q)))
        return fprintf(stderr, "mech %s: out of memory\n", cmd), MECH_EXIT_IO;
    for (int i = 0; i < n; i++)  /* the positions of mech solve --from q0 --to `to` */
        (*q)[i] = o->frame >= 0 ? dr->values[i]
                  : i == n - 1 ? to : q0 + (to - q0) * i / (n - 1);
    *nq = n;
    return -1;
}

/* Solve the positions of every point and link at q[0..nq-1] into t (each
 * row from the one before). Returns an exit status. */
static int assemble(const char *cmd, const mech_model *view, const double *q, int nq,
                    mech_table *t)
{
    mech_solve_options so;
    mech_solve_options_default(&so);
    so.want = MECH_WANT_POSITION;
    so.forces = -1;
    mech_diag d;
    mech_diag_init(&d);
    mech_analysis *a = NULL;
    int rc = mech_analysis_new(view, &so, &a, &d);
    if (rc == MECH_OK)
        rc = mech_analysis_solve(a, q, nq, t, NULL, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    mech_analysis_free(&a);
    if (rc == MECH_OK && t->nrows == nq)
        return MECH_EXIT_OK;
    if (rc == MECH_OK || rc == MECH_ESOLVE) {
        fprintf(stderr, "mech %s: the mechanism does not assemble at the position asked for "
                "(%d of the %d positions on the way solved); nothing written\n", cmd, t->nrows,
                nq);
        return MECH_EXIT_SOLVE;
    }
    return cmd_exit_status(rc);
}

/* Row r of t: where point name p was assembled. */
static void assembled(const mech_model *m, const mech_table *t, int r, int p, double xy[2])
{
    char name[160];
    snprintf(name, sizeof name, "%s.x", m->point_names[p]);
    xy[0] = mech_table_get(t, r, mech_table_column(t, name));
    snprintf(name, sizeof name, "%s.y", m->point_names[p]);
    xy[1] = mech_table_get(t, r, mech_table_column(t, name));
}

/* The larger span of row r's points, m. */
static double span_of(const mech_model *m, const mech_table *t, int r)
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY}, xy[2];
    for (int p = 0; p < m->npoint_names; p++) {
        assembled(m, t, r, p, xy);
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], xy[k]);
            hi[k] = fmax(hi[k], xy[k]);
        }
    }
    return fmax(fmax(hi[0] - lo[0], hi[1] - lo[1]), 1e-9);
}

/* The point of a moving link farthest from where pose puts it: its
 * distance, and the link and point index in *link, *k. */
static double farthest(const mech_model *m, const mech_pose *pose, const mech_table *t, int r,
                       int *link, int *k)
{
    double worst = -1, a[2], g[2];
    for (int l = 1; l < m->nlinks; l++)
        for (int i = 0; i < m->links[l].npoints; i++) {
            assembled(m, t, r, m->links[l].points[i].id, a);
            mech_pose_point(m, pose, l, i, g);
            double dist = hypot(a[0] - g[0], a[1] - g[1]);
            if (!(dist <= worst)) {  /* NaN (a link off the ground) counts as far */
                worst = isfinite(dist) ? dist : INFINITY;
                *link = l;
                *k = i;
            }
        }
    return worst;
}

/* The stated pose at row r when it is not the assembled one (*ghost set,
 * a note printed), else none. Returns an exit status. */
static int stated_pose(const char *cmd, const mech_model *m, const mech_table *t, int r,
                       mech_pose *pose, const mech_pose **ghost)
{
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_pose_guess(m, mech_table_get(t, r, 0), pose, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    *ghost = NULL;
    if (rc != MECH_OK)
        return cmd_exit_status(rc);
    int l = 0, k = 0;
    double tol = DRAW_TOLERANCE * span_of(m, t, r);
    double off = pose->kind != MECH_POSE_NONE ? farthest(m, pose, t, r, &l, &k) : 0;
    if (off > tol) {
        *ghost = pose;
        fprintf(stderr, "mech %s: note: the mechanism assembled away from its %s pose: "
                "point %s of %s is %.4g mm from it (drawn dashed)\n", cmd,
                pose->kind == MECH_POSE_DRAWN ? "drawn" : "guessed", m->links[l].points[k].name,
                m->links[l].name, off * 1e3);
    }
    return MECH_EXIT_OK;
}

/* "crank at 30 deg (position 0 of the sweep)": the caption's second line. */
static void caption(const mech_model *m, const cmd_draw_options *o, double q, char *buf,
                    size_t n)
{
    const mech_driver *dr = &m->driver;
    int slider = dr->kind == MECH_DRIVE_SLIDER, time = dr->kind == MECH_DRIVE_TIME;
    const char *who = time ? "time" : slider ? m->joints[dr->index].name
                                             : m->links[dr->index].name;
    double shown = time ? q : slider ? q * 1e3 : q * 57.295779513082321;
    char where[64];
    if (o->at)
        snprintf(where, sizeof where, "reached from the first position");
    else if (o->frame < 0 && m->has_start)
        snprintf(where, sizeof where, "the drawing's position");
    else
        snprintf(where, sizeof where, "position %d of the sweep", o->frame > 0 ? o->frame : 0);
    snprintf(buf, n, "%s at %.6g %s (%s), as assembled", who, shown,
             time ? "s" : slider ? "mm" : "deg", where);
}

/* The still picture: the last row of t alone, with names, and the ghost. */
static int picture(const mech_model *view, const mech_table *t,
                   const cmd_draw_options *o, const mech_pose *ghost)
{
    mech_table row = *t;  /* a view of the last row */
    row.values = t->values + (size_t)(t->nrows - 1) * (size_t)t->ncolumns;
    row.nrows = 1;
    row.gaps = NULL;
    row.ngaps = 0;
    char text[200];
    caption(view, o, mech_table_get(t, t->nrows - 1, 0), text, sizeof text);
    plot_anim_options ao;
    plot_anim_options_default(&ao);
    ao.frame = 0;
    ao.labels = 1;
    ao.ghost = ghost;
    ao.ghost_legend = ghost && ghost->kind == MECH_POSE_DRAWN ? "as drawn" : "as guessed (initial:)";
    ao.caption = text;
    ao.trace = NULL;
    mech_diag d;
    mech_diag_init(&d);
    int rc = plot_animation_write(view, &row, &ao, o->out ? o->out : "-", &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    return cmd_exit_status(rc);
}

int cmd_draw_model(const char *cmd, const mech_model *m, const cmd_draw_options *o)
{
    mech_model view = *m;  /* every point and link, no forces */
    if (cmd_select_everything(m, &view.outputs) != 0)
        return fprintf(stderr, "mech %s: out of memory\n", cmd), MECH_EXIT_IO;
    double *q = NULL;
    int nq = 0;
    mech_table t = {0};
    mech_pose pose = {0};
    const mech_pose *ghost = NULL;
    int code = positions(cmd, m, o, &q, &nq);
    if (code < 0)
        code = assemble(cmd, &view, q, nq, &t);
    if (code == MECH_EXIT_OK)
        code = stated_pose(cmd, m, &t, t.nrows - 1, &pose, &ghost);
    if (code == MECH_EXIT_OK)
        code = picture(&view, &t, o, ghost);
    mech_pose_free(&pose);
    mech_table_free(&t);
    free(q);
    mech_outputs_free(&view.outputs);
    return code;
}

int cmd_draw(int argc, char **argv)
{
    draw_args a;
    memset(&a, 0, sizeof a);
    cmd_draw_options_default(&a.o);
    mech_model *m = NULL;
    int code = cmd_opts_parse(&cmd_draw_spec, argc, argv, &a);
    if (code < 0 && a.o.frame >= 0 && a.o.at)
        code = cmd_usage_error("draw", "%s", "--frame and --at cannot go together");
    if (code < 0)
        code = cmd_refuse_input("draw", a.o.out, &a.file, 1);
    if (code < 0)
        code = cmd_load_checked_with(a.file, a.set.set, a.set.n, &m);
    cmd_sets_free(&a.set);
    if (code == MECH_EXIT_OK && m)
        code = cmd_draw_model("draw", m, &a.o);
    mech_model_free(&m);
    return code < 0 ? MECH_EXIT_OK : code;
}
