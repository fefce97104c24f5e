/* src/cmd_report.c: `mech report`, one self-contained HTML page of a
 * mechanism (docs/report.md): option parsing, the load, the two solves
 * (the outputs for the figures and the values; every point and link for
 * the animation), the equations' text; the page is src/report*.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "commands.h"
#include "report.h"

const char cmd_report_help[] =
    "usage: mech report FILE [-o OUT.html] [--set NAME=VALUE] [--from A --to B]\n"
    "                   [--steps N] [--outputs NAME,...] [--forces]\n"
    "                   [--friction on|off|both] [--frames N] [--duration S]\n"
    "\n"
    "Solve the driver sweep and write one self-contained HTML page (inline CSS,\n"
    "SVG and script; nothing is loaded from the network): the animation of the\n"
    "mechanism with a slider over the driver positions and the values of the\n"
    "output columns at the slider's position, the structure (as mech check), the\n"
    "solve's diagnostics (as mech solve --stats, with every warning and note),\n"
    "every figure of mech plot, and the equations (as mech equations).\n"
    "\n"
    "options:\n"
    "  -o, --output FILE   write the page to FILE (temporary file renamed when\n"
    "                      complete; default: standard output)\n"
    "  --set NAME=VALUE    replace the file's parameter NAME by VALUE (repeatable)\n"
    "  --from A --to B     sweep the driver from A to B instead of the file's range\n"
    "                      (bare numbers: deg or mm; units allowed: --to 0.2m)\n"
    "  --steps N           N intervals (with --from/--to: default 360; alone: over\n"
    "                      the file's range)\n"
    "  --outputs LIST      comma-separated point, link and slider names to report\n"
    "                      instead of the file's outputs\n"
    "  --forces            also the forces (as 'outputs: {forces: true}')\n"
    "  --friction MODE     on (default), off or both, as mech solve\n"
    "  --frames N          slider positions (animation frames) at most, evenly\n"
    "                      spread over the rows (default 1000)\n"
    "  --duration S        seconds for one pass of the animation (default 4)\n"
    "  --test-colours      draw the animation in grey with every point a disc of its\n"
    "                      own colour (for tests/browser/report.sh)\n"
    "  -h, --help          show this help\n"
    "\n"
    "exit status: 0 written, 1 the mechanism cannot be solved somewhere in the range\n"
    "(the page shows the positions solved and lists the gaps; none solved: nothing\n"
    "written), 2 invalid file or usage, 3 a file cannot be read or written\n";

enum { REPORT_MAX_SET = 64 };
#define REPORT_MAX_DRIVER 1e6  /* rad or m, as mech solve (cmd_solve.c) */

typedef struct report_args {
    const char *file, *out, *from, *to, *outputs;
    mech_override set[REPORT_MAX_SET];
    char *set_text[REPORT_MAX_SET];
    int nset, steps, forces, friction;  /* friction: -1 = mech solve's default */
    plot_anim_options anim;
} report_args;

static const char *const valued[] = {"-o", "--output", "--set", "--from", "--to", "--steps",
                                     "--outputs", "--friction", "--frames", "--duration"};

static int parse_set(report_args *a, const char *val)
{
    const char *eq = strchr(val, '=');
    if (!eq || eq == val || !eq[1] || a->nset == REPORT_MAX_SET)
        return cmd_usage_error("report", "--set needs NAME=VALUE (at most 64), not '%s'", val);
    char *copy = strdup(val);
    if (!copy)
        return fprintf(stderr, "mech report: out of memory\n"), MECH_EXIT_IO;
    copy[eq - val] = '\0';
    a->set_text[a->nset] = copy;
    a->set[a->nset].name = copy;
    a->set[a->nset++].text = copy + (eq - val) + 1;
    return -1;
}

/* One option with its value; returns -1 to go on, else the exit status. */
static int parse_valued(report_args *a, const char *arg, const char *val)
{
    if (strcmp(arg, "-o") == 0 || strcmp(arg, "--output") == 0)
        a->out = val;
    else if (strcmp(arg, "--set") == 0)
        return parse_set(a, val);
    else if (strcmp(arg, "--from") == 0)
        a->from = val;
    else if (strcmp(arg, "--to") == 0)
        a->to = val;
    else if (strcmp(arg, "--outputs") == 0)
        a->outputs = val;
    else if (strcmp(arg, "--steps") == 0) {
        if (!cmd_parse_int(val, 1, 1000000, &a->steps))
            return cmd_usage_error("report", "--steps needs a whole number from 1 to 1000000, "
                                   "not '%s'", val);
    } else if (strcmp(arg, "--frames") == 0) {
        if (!cmd_parse_int(val, 2, 100000, &a->anim.max_frames))
            return cmd_usage_error("report", "--frames needs a whole number from 2 to 100000, "
                                   "not '%s'", val);
    } else if (strcmp(arg, "--duration") == 0) {
        char *end;
        double s = strtod(val, &end);
        if (end == val || *end != '\0' || !(s >= 0.01 && s <= 86400))
            return cmd_usage_error("report", "--duration needs seconds from 0.01 to 86400, "
                                   "not '%s'", val);
        a->anim.duration = s;
    } else if (strcmp(val, "on") == 0) {  /* --friction */
        a->friction = MECH_FRICTION_ON;
    } else if (strcmp(val, "off") == 0) {
        a->friction = MECH_FRICTION_OFF;
    } else if (strcmp(val, "both") == 0) {
        a->friction = MECH_FRICTION_BOTH;
    } else {
        return cmd_usage_error("report", "--friction is on, off or both, not '%s'", val);
    }
    return -1;
}

static int takes_value(const char *arg)
{
    for (size_t k = 0; k < sizeof valued / sizeof valued[0]; k++)
        if (strcmp(arg, valued[k]) == 0)
            return 1;
    return 0;
}

/* Returns -1 to go on, else the exit status. */
static int parse_args(int argc, char **argv, report_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *arg = argv[i];
        int code = -1;
        if (cmd_wants_help(arg)) {
            fputs(cmd_report_help, stdout);
            return MECH_EXIT_OK;
        }
        if (takes_value(arg)) {
            if (i + 1 >= argc)
                return cmd_usage_error("report", "option '%s' needs a value", arg);
            code = parse_valued(a, arg, argv[++i]);
        } else if (strcmp(arg, "--forces") == 0)
            a->forces = 1;
        else if (strcmp(arg, "--test-colours") == 0 || strcmp(arg, "--test-colors") == 0)
            a->anim.test_colours = 1;
        else if (arg[0] == '-' && arg[1] != '\0')
            return cmd_usage_error("report", "unknown option '%s'", arg);
        else if (a->file)
            return cmd_usage_error("report", "one file at a time ('%s' is a second file)", arg);
        else
            a->file = arg;
        if (code >= 0)
            return code;
    }
    if (!a->file)
        return cmd_usage_error("report", "%s", "no file given (usage: mech report FILE -o OUT.html)");
    if ((a->from != NULL) != (a->to != NULL))
        return cmd_usage_error("report", "%s", "--from and --to go together");
    return -1;
}

/* One end of --from/--to into *si (as mech solve). -1, or the exit status. */
static int parse_end(const char *opt, const char *text, int is_angle, double *si)
{
    char err[256];
    if (mech_parse_value(text, is_angle, si, err, sizeof err) != MECH_OK)
        return fprintf(stderr, "mech report: %s '%s': %s\n", opt, text, err), MECH_EXIT_INPUT;
    if (!(fabs(*si) <= REPORT_MAX_DRIVER)) {
        snprintf(err, sizeof err, "%s '%.40s': a driver position must be within +-1e6 %s",
                 opt, text, is_angle ? "rad" : "m");
        return cmd_usage_error("report", "%s", err);
    }
    return -1;
}

/* --from/--to/--steps into o. -1, or the exit status. */
static int apply_range(const report_args *a, const mech_model *m, mech_solve_options *o)
{
    int is_angle = m->driver.kind == MECH_DRIVE_TIME ? 2 : m->driver.kind == MECH_DRIVE_ANGLE, code;
    if (a->from) {
        if ((code = parse_end("--from", a->from, is_angle, &o->from)) >= 0 ||
            (code = parse_end("--to", a->to, is_angle, &o->to)) >= 0)
            return code;
        o->has_range = 1;
        o->steps = a->steps > 0 ? a->steps : 360;
    } else if (a->steps > 0 && m->has_driver && m->driver.nvalues > 0) {
        o->has_range = 1;
        o->from = m->driver.values[0];
        o->to = m->driver.values[m->driver.nvalues - 1];
        o->steps = a->steps;
    }
    return -1;
}

/* Everything one run holds (freed by run_free). */
typedef struct report_run {
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

static void run_free(report_run *r)
{
    for (int i = 0; i < r->a.nset; i++)
        free(r->a.set_text[i]);
    report_free_strings(r->gap_lines, r->t.ngaps);  /* before t: its ngaps counts them */
    mech_table_free(&r->t);
    mech_table_free(&r->t_all);
    mech_outputs_free(&r->selected);
    mech_outputs_free(&r->all);
    free(r->equations);
    report_free_strings(r->figures, r->nfigures);
    free(r->animation);
    free(r->frame_rows);
    mech_model_free(&r->m);
    mech_diag_free(&r->d);
}

/* Load and check with --set; the messages stay in r->d for the page. */
static int load(report_run *r)
{
    int rc = mech_load_file_with(r->a.file, r->a.set, r->a.nset, &r->m, &r->d);
    if (rc == MECH_OK)
        rc = mech_check(r->m, &r->summary, &r->d);
    if (rc == MECH_OK)
        return MECH_EXIT_OK;
    mech_diag_print(&r->d, stderr);
    return rc == MECH_EIO ? MECH_EXIT_IO : MECH_EXIT_INPUT;
}

/* The options, the views of the model (--outputs; everything) and the two
 * solves. Returns an exit status. */
static int solve_both(report_run *r)
{
    char err[256];
    const mech_model *m = r->m;
    mech_solve_options_default(&r->o);
    int code = apply_range(&r->a, m, &r->o);
    if (code >= 0)
        return code;
    r->view = *m;
    if (r->a.outputs) {
        if (mech_outputs_parse(m, r->a.outputs, &r->selected, err, sizeof err) != MECH_OK)
            return fprintf(stderr, "mech report: --outputs: %s\n", err), MECH_EXIT_INPUT;
        r->view.outputs = r->selected;
    }
    r->view_all = *m;
    if (cmd_select_everything(m, &r->all) != 0)
        return fprintf(stderr, "mech report: out of memory\n"), MECH_EXIT_IO;
    r->view_all.outputs = r->all;
    r->o.forces = r->a.forces;
    if (r->a.friction >= 0)  /* else mech solve's default: the values are its CSV's */
        r->o.friction = r->a.friction;
    int rc = mech_solve(&r->view, &r->o, &r->t, &r->stats, &r->d);
    r->partial = rc == MECH_ESOLVE && r->t.nrows > 0;
    if (rc == MECH_OK || r->partial) {
        mech_solve_options po = r->o;  /* the animation: positions only, as mech animate */
        po.want = MECH_WANT_POSITION;
        po.forces = -1;
        mech_diag ad;  /* its warnings repeat the first solve's */
        mech_diag_init(&ad);
        rc = mech_solve(&r->view_all, &po, &r->t_all, NULL, &ad);
        if (rc == MECH_ESOLVE && r->partial)  /* the same gaps: checked in animation() */
            rc = MECH_OK;
        if (rc != MECH_OK)
            mech_diag_print(&ad, stderr);
        mech_diag_free(&ad);
    }
    return cmd_exit_status(rc);
}

/* mech_system_print's text into r->equations: the named system, as mech equations prints it. */
static int equations(report_run *r)
{
    mech_system *s = NULL;
    if (mech_system_new_named(r->m, &s, &r->d) != MECH_OK)
        return MECH_EXIT_INPUT;
    FILE *f = open_memstream(&r->equations, &r->equations_len);
    if (f) {
        mech_system_print(s, MECH_FORMAT_TEXT, f);
        fclose(f);
    }
    mech_system_free(&s);
    if (!f || !r->equations)
        return fprintf(stderr, "mech report: out of memory\n"), MECH_EXIT_IO;
    return MECH_EXIT_OK;
}

/* The rows behind the slider: the animation's frames (plot_anim_frame_rows,
 * at most --frames evenly spread); the animation drawn with exactly those
 * frames. */
static int animation(report_run *r)
{
    int n = r->t.nrows, same = n >= 1 && r->t_all.nrows == n;
    for (int i = 0; i < n && same; i++)  /* the same driver positions, bit for bit */
        same = mech_table_get(&r->t, i, 0) == mech_table_get(&r->t_all, i, 0);
    if (!same) {
        fprintf(stderr, "mech report: the sweep of every point and link (the animation) "
                "solved other driver positions than the sweep of the outputs (%d and %d "
                "rows); nothing written\n", r->t_all.nrows, n);
        return MECH_EXIT_SOLVE;
    }
    r->frame_rows = malloc((size_t)n * sizeof *r->frame_rows);
    if (!r->frame_rows)
        return fprintf(stderr, "mech report: out of memory\n"), MECH_EXIT_IO;
    r->nframes = plot_anim_frame_rows(n, r->a.anim.max_frames, r->frame_rows);
    /* the traced paths, unless a gap lies in the sweep: the animation's
       polyline would bridge it (the page says so) */
    r->a.anim.trace = r->view.outputs.points;
    r->a.anim.ntrace = r->partial ? 0 : r->view.outputs.npoints;
    return cmd_exit_status(report_animation(&r->view_all, &r->t_all, &r->a.anim,
                                            &r->animation, &r->d));
}

/* ---- A partial sweep: the gaps said as mech solve says them
 * (src/cmd_solve.c, print_gaps), and figures whose curves break there. */

/* One line per gap into r->gap_lines, printed on stderr as mech solve
 * prints them ("mech report: gap: ..."). */
static int gap_lines(report_run *r)
{
    const mech_table *t = &r->t;
    if (t->ngaps == 0)
        return MECH_EXIT_OK;
    if (!(r->gap_lines = calloc((size_t)t->ngaps, sizeof *r->gap_lines)))
        return fprintf(stderr, "mech report: out of memory\n"), MECH_EXIT_IO;
    for (int i = 0; i < t->ngaps; i++) {
        char line[600];
        cmd_gap_line(r->m, &r->o, t, i, line, sizeof line);
        fprintf(stderr, "mech report: gap: %s\n", line);
        if (!(r->gap_lines[i] = strdup(line)))
            return fprintf(stderr, "mech report: out of memory\n"), MECH_EXIT_IO;
    }
    return MECH_EXIT_OK;
}

/* The table of the figures: t with a row of NaN where a gap lies between
 * solved rows, so every curve breaks there instead of bridging it
 * (plot_figure_write starts a new stroke after a value that is not
 * finite). g->values is malloc'ed; the columns are t's (borrowed). */
static int gapped_table(const mech_table *t, mech_table *g)
{
    *g = *t;
    g->gaps = NULL;
    g->ngaps = 0;
    size_t nc = (size_t)t->ncolumns;
    g->values = malloc(((size_t)t->nrows + (size_t)t->ngaps) * nc * sizeof *g->values);
    if (!g->values)
        return -1;
    int k = 0, missing = 0, out = 0;
    for (int i = 0; i <= t->nrows; i++) {
        while (k < t->ngaps && t->gaps[k].first_row - missing == i) {
            if (i > 0 && i < t->nrows)  /* a gap at either end breaks nothing */
                for (size_t c = 0; c < nc; c++)
                    g->values[(size_t)out * nc + c] = NAN;
            out += i > 0 && i < t->nrows;
            missing += t->gaps[k].last_row - t->gaps[k].first_row + 1;
            k++;
        }
        if (i < t->nrows)
            memcpy(g->values + (size_t)out++ * nc, t->values + (size_t)i * nc,
                   nc * sizeof *g->values);
    }
    g->nrows = out;
    return 0;
}

static int write_page(report_run *r)
{
    mech_diag wd;
    mech_diag_init(&wd);
    mech_table gt;
    int rc = gapped_table(&r->t, &gt) == 0 ? MECH_OK : MECH_ENOMEM;
    if (rc == MECH_OK)
        rc = report_figures(&r->view, &gt, &r->figures, &r->nfigures, &wd);
    else
        fprintf(stderr, "mech report: out of memory\n");
    free(gt.values);
    report_input in = {
        .m = r->m, .summary = &r->summary, .equations = r->equations, .t = &r->t,
        .stats = &r->stats, .diag = &r->d, .figures = r->figures, .nfigures = r->nfigures,
        .animation = r->animation, .frame_rows = r->frame_rows, .nframes = r->nframes,
        .duration = r->a.anim.duration, .gaps = r->gap_lines, .ngaps = r->t.ngaps,
    };
    if (rc == MECH_OK)
        rc = report_write(&in, r->a.out ? r->a.out : "-", &wd);
    mech_diag_print(&wd, stderr);
    mech_diag_free(&wd);
    return cmd_exit_status(rc);
}

int cmd_report(int argc, char **argv)
{
    report_run r;
    memset(&r, 0, sizeof r);
    r.a.friction = -1;
    plot_anim_options_default(&r.a.anim);
    mech_diag_init(&r.d);
    int code = parse_args(argc, argv, &r.a);
    if (code < 0 && (code = cmd_refuse_input("report", r.a.out, &r.a.file, 1)) < 0 &&
        (code = load(&r)) == MECH_EXIT_OK) {
        code = solve_both(&r);
        if (code == MECH_EXIT_OK)
            code = equations(&r);
        if (code == MECH_EXIT_OK)
            code = animation(&r);
        mech_diag_print(&r.d, stderr);
        if (code == MECH_EXIT_OK)
            code = gap_lines(&r);
        if (code == MECH_EXIT_SOLVE)
            fprintf(stderr, "mech report: %d of the sweep's %d positions were solved; "
                    "nothing written\n", r.t.nrows, r.t.nrequested);
        if (code == MECH_EXIT_OK)
            code = write_page(&r);
        if (code == MECH_EXIT_OK && r.partial) {
            fprintf(stderr, "mech report: %d of the sweep's %d positions were solved; the "
                    "page shows them and lists the gaps\n", r.t.nrows, r.t.nrequested);
            code = MECH_EXIT_SOLVE;
        }
    }
    run_free(&r);
    return code < 0 ? MECH_EXIT_OK : code;
}
