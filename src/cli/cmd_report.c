/* src/cli/cmd_report.c: `mech report`, one self-contained HTML page of a
 * mechanism (docs/report.md): its option table, the load, the two solves
 * (the outputs for the figures and the values; every point and link for
 * the animation), the equations' text; the page is src/report*.c. The
 * steps `mech watch` runs too (load, solves, animation, gaps) are declared
 * in src/cli/cli.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"

#define AT(field) offsetof(report_args, field)

static const cmd_opt options[] = {
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .label = "-o, --output FILE",
     .help = "write the page to FILE (temporary file renamed when\n"
             "complete; default: standard output)"},
    CMD_SET_ENTRY(AT(set), "replace the file's parameter NAME by VALUE (repeatable)"),
    {.names = "--from", .kind = CMD_OPT_TEXT, .at = AT(from), .label = "--from A --to B",
     .help = "sweep the driver from A to B instead of the file's range\n"
             "(bare numbers: deg or mm; units allowed: --to 0.2m)"},
    {.names = "--to", .kind = CMD_OPT_TEXT, .at = AT(to)},
    {.names = "--steps", .kind = CMD_OPT_INT, .at = AT(steps), .lo = 1, .hi = 1000000,
     .expect = "needs a whole number from 1 to 1000000", .label = "--steps N",
     .help = "N intervals (with --from/--to: default 360; alone: over\n"
             "the file's range)"},
    {.names = "--outputs", .kind = CMD_OPT_TEXT, .at = AT(outputs), .label = "--outputs LIST",
     .help = "comma-separated point, link and slider names to report\n"
             "instead of the file's outputs"},
    {.names = "--forces", .kind = CMD_OPT_FLAG, .at = AT(forces), .flag = 1, .label = "--forces",
     .help = "also the forces (as 'outputs: {forces: true}')"},
    CMD_FRICTION_ENTRY(AT(friction), "on (default), off or both, as mech solve"),
    {.names = "--frames", .kind = CMD_OPT_INT, .at = AT(anim.max_frames), .lo = 2, .hi = 100000,
     .expect = "needs a whole number from 2 to 100000", .label = "--frames N",
     .help = "slider positions (animation frames) at most, evenly\n"
             "spread over the rows (default 1000)"},
    {.names = "--duration", .kind = CMD_OPT_REAL, .at = AT(anim.duration), .lo = 0.01,
     .hi = 86400, .expect = "needs seconds from 0.01 to 86400", .label = "--duration S",
     .help = "seconds for one pass of the animation (default 4)"},
    {.names = "--test-colours|--test-colors", .kind = CMD_OPT_FLAG, .at = AT(anim.test_colours),
     .flag = 1, .label = "--test-colours",
     .help = "draw the animation in grey with every point a disc of its\n"
             "own colour (for tests/browser/report.sh)"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_report_spec = {
    .name = "report",
    .summary = "write one self-contained HTML page of the mechanism (docs/report.md)",
    .usage = "usage: mech report FILE [-o OUT.html] [--set NAME=VALUE] [--from A --to B]\n"
             "                   [--steps N] [--outputs NAME,...] [--forces]\n"
             "                   [--friction on|off|both] [--frames N] [--duration S]\n",
    .about = "Solve the driver sweep and write one self-contained HTML page (inline CSS,\n"
             "SVG and script; nothing is loaded from the network): the animation of the\n"
             "mechanism with a slider over the driver positions and the values of the\n"
             "output columns at the slider's position, the structure (as mech check), the\n"
             "solve's diagnostics (as mech solve --stats, with every warning and note),\n"
             "every figure of mech plot, and the equations (as mech equations).\n",
    .opts = options,
    .column = 22,
    .exits = "exit status: 0 written, 1 the mechanism cannot be solved somewhere in the range\n"
             "(the page shows the positions solved and lists the gaps; none solved: nothing\n"
             "written), 2 invalid file or usage, 3 a file cannot be read or written\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech report FILE -o OUT.html)",
};

void report_run_free(report_run *r)
{
    cmd_sets_free(&r->a.set);
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

int report_run_load(report_run *r)
{
    int rc = mech_load_file_with(r->a.file, r->a.set.set, r->a.set.n, &r->m, &r->d);
    if (rc == MECH_OK)
        rc = mech_check(r->m, &r->summary, &r->d);
    if (rc == MECH_OK)
        return MECH_EXIT_OK;
    mech_diag_print(&r->d, stderr);
    return rc == MECH_EIO ? MECH_EXIT_IO : MECH_EXIT_INPUT;
}

int report_run_solve(report_run *r)
{
    char err[256];
    const mech_model *m = r->m;
    mech_solve_options_default(&r->o);
    int code = cmd_apply_range(r->cmd, r->a.from, r->a.to, r->a.steps, m, &r->o);
    if (code >= 0)
        return code;
    r->view = *m;
    if (r->a.outputs) {
        if (mech_outputs_parse(m, r->a.outputs, &r->selected, err, sizeof err) != MECH_OK)
            return fprintf(stderr, "mech %s: --outputs: %s\n", r->cmd, err), MECH_EXIT_INPUT;
        r->view.outputs = r->selected;
    }
    r->view_all = *m;
    if (cmd_select_everything(m, &r->all) != 0)
        return fprintf(stderr, "mech %s: out of memory\n", r->cmd), MECH_EXIT_IO;
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

int report_run_animation(report_run *r)
{
    int n = r->t.nrows, same = n >= 1 && r->t_all.nrows == n;
    for (int i = 0; i < n && same; i++)  /* the same driver positions, bit for bit */
        same = mech_table_get(&r->t, i, 0) == mech_table_get(&r->t_all, i, 0);
    if (!same) {
        fprintf(stderr, "mech %s: the sweep of every point and link (the animation) "
                "solved other driver positions than the sweep of the outputs (%d and %d "
                "rows); nothing written\n", r->cmd, r->t_all.nrows, n);
        return MECH_EXIT_SOLVE;
    }
    r->frame_rows = malloc((size_t)n * sizeof *r->frame_rows);
    if (!r->frame_rows)
        return fprintf(stderr, "mech %s: out of memory\n", r->cmd), MECH_EXIT_IO;
    r->nframes = plot_anim_frame_rows(n, r->a.anim.max_frames, r->frame_rows);
    /* the traced paths, unless a gap lies in the sweep: the animation's
       polyline would bridge it (the page says so) */
    r->a.anim.trace = r->view.outputs.points;
    r->a.anim.ntrace = r->partial ? 0 : r->view.outputs.npoints;
    return cmd_exit_status(report_animation(&r->view_all, &r->t_all, &r->a.anim,
                                            &r->animation, &r->d));
}

/* ---- A partial sweep: the gaps said as mech solve says them
 * (src/cli/cmd_solve.c, print_gaps), and figures whose curves break there. */

int report_run_gaps(report_run *r)
{
    const mech_table *t = &r->t;
    if (t->ngaps == 0)
        return MECH_EXIT_OK;
    if (!(r->gap_lines = calloc((size_t)t->ngaps, sizeof *r->gap_lines)))
        return fprintf(stderr, "mech %s: out of memory\n", r->cmd), MECH_EXIT_IO;
    for (int i = 0; i < t->ngaps; i++) {
        char line[600];
        cmd_gap_line(r->m, &r->o, t, i, line, sizeof line);
        fprintf(stderr, "mech %s: gap: %s\n", r->cmd, line);
        if (!(r->gap_lines[i] = strdup(line)))
            return fprintf(stderr, "mech %s: out of memory\n", r->cmd), MECH_EXIT_IO;
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
    for (size_t i = 0; rc == MECH_OK && i < wd.count; i++)
        diag_copy(&r->d, &wd.entries[i]);  /* a figure left out: said on the page too */
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
    r.cmd = "report";
    r.a.friction = -1;
    plot_anim_options_default(&r.a.anim);
    mech_diag_init(&r.d);
    int code = cmd_opts_parse(&cmd_report_spec, argc, argv, &r.a);
    if (code < 0)
        code = cmd_check_range_pair("report", r.a.from, r.a.to);
    if (code < 0 && (code = cmd_refuse_input("report", r.a.out, &r.a.file, 1)) < 0 &&
        (code = report_run_load(&r)) == MECH_EXIT_OK) {
        code = report_run_solve(&r);
        if (code == MECH_EXIT_OK)
            code = equations(&r);
        if (code == MECH_EXIT_OK)
            code = report_run_animation(&r);
        mech_diag_print(&r.d, stderr);
        if (code == MECH_EXIT_OK)
            code = report_run_gaps(&r);
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
    report_run_free(&r);
    return code < 0 ? MECH_EXIT_OK : code;
}
