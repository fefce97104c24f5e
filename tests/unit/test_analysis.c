/* tests/unit/test_analysis.c: the analysed system (mech_analysis) is read
 * only once built: threads that solve on one analysis at the same time get
 * the same tables, bit for bit, as one mech_solve; and a sub-range of the
 * driver positions gives the rows of the whole sweep. */
#include <math.h>
#include <pthread.h>

#include "helpers.h"

enum { REPS = 40 };

typedef struct job {
    const mech_analysis *a;
    const mech_table *ref;     /* what every sweep must give */
    pthread_barrier_t *start;
    int failed;                /* sweeps that failed or differ from ref */
    int rc;
} job;

static int same_values(const mech_table *a, const mech_table *b)
{
    size_t n = (size_t)a->nrows * (size_t)a->ncolumns;
    return a->nrows == b->nrows && a->ncolumns == b->ncolumns &&
           memcmp(a->values, b->values, n * sizeof(double)) == 0;
}

/* Many sweeps in a row, started together, so the threads overlap. */
static void *solve_job(void *arg)
{
    job *j = arg;
    mech_diag d;
    mech_diag_init(&d);
    pthread_barrier_wait(j->start);
    for (int rep = 0; rep < REPS; rep++) {
        mech_table t = {0};
        j->rc = mech_analysis_solve(j->a, NULL, 0, &t, NULL, &d);
        j->failed += j->rc != MECH_OK || !same_values(&t, j->ref);
        mech_table_free(&t);
    }
    mech_diag_free(&d);
    return NULL;
}

static void two_threads(const char *path, int forces)
{
    mech_model *m = load_path(path);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = forces;
    mech_diag d;
    mech_diag_init(&d);
    mech_table ref = {0};
    cr_assert_eq(mech_solve(m, &o, &ref, NULL, &d), MECH_OK, "%s: mech_solve", path);
    mech_analysis *a = NULL;
    cr_assert_eq(mech_analysis_new(m, &o, &a, &d), MECH_OK, "%s: analysis", path);
    cr_assert_eq(mech_analysis_columns(a), ref.ncolumns);
    pthread_barrier_t start;
    pthread_barrier_init(&start, NULL, 2);
    job jobs[2] = {{a, &ref, &start, 0, -1}, {a, &ref, &start, 0, -1}};
    pthread_t tid[2];
    for (int k = 0; k < 2; k++)
        cr_assert_eq(pthread_create(&tid[k], NULL, solve_job, &jobs[k]), 0);
    for (int k = 0; k < 2; k++)
        pthread_join(tid[k], NULL);
    pthread_barrier_destroy(&start);
    for (int k = 0; k < 2; k++) {
        cr_assert_eq(jobs[k].rc, MECH_OK, "%s: thread %d", path, k);
        cr_assert_eq(jobs[k].failed, 0, "%s: thread %d: %d of %d sweeps differ from mech_solve's "
                     "table", path, k, jobs[k].failed, REPS);
    }
    mech_analysis_free(&a);
    cr_assert_null(a, "mech_analysis_free clears the handle");
    mech_table_free(&ref);
    mech_diag_free(&d);
    mech_model_free(&m);
}

Test(analysis, two_threads_one_analysis_fourbar) { two_threads("mechanisms/fourbar.yaml", 0); }
Test(analysis, two_threads_one_analysis_stirling) { two_threads("mechanisms/stirling.yaml", 0); }
Test(analysis, two_threads_one_analysis_conveyor_forces)
{
    two_threads("mechanisms/conveyor.yaml", 1);
}

/* Positions given by the caller: the second half of the sweep, started
 * afresh from the guesses, reaches the same rows (to the Newton tolerance:
 * the first row is found by a different start). */
Test(analysis, caller_positions_match_the_sweep)
{
    mech_model *m = load_path("mechanisms/fourbar.yaml");
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_diag d;
    mech_diag_init(&d);
    mech_analysis *a = NULL;
    cr_assert_eq(mech_analysis_new(m, &o, &a, &d), MECH_OK);
    mech_table all = {0}, part = {0};
    cr_assert_eq(mech_analysis_solve(a, NULL, 0, &all, NULL, &d), MECH_OK);
    int from = all.nrows / 2, nq = all.nrows - from;
    double *q = calloc((size_t)nq, sizeof *q);
    for (int i = 0; i < nq; i++)
        q[i] = mech_table_get(&all, from + i, 0);
    cr_assert_eq(mech_analysis_solve(a, q, nq, &part, NULL, &d), MECH_OK);
    cr_assert_eq(part.nrows, nq);
    for (int i = 0; i < nq; i++)
        for (int c = 0; c < all.ncolumns; c++) {
            double x = mech_table_get(&all, from + i, c), y = mech_table_get(&part, i, c);
            cr_assert(fabs(x - y) <= 1e-9 * (1.0 + fabs(x)), "row %d column %s: %.17g vs %.17g",
                      i, all.columns[c].name, x, y);
        }
    free(q);
    mech_table_free(&all);
    mech_table_free(&part);
    mech_analysis_free(&a);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* The model does not change after load: --outputs and "no forces" are
 * options; the table follows them and the model's outputs stay the file's. */
Test(analysis, outputs_are_options_not_model_changes)
{
    mech_model *m = load_path("mechanisms/conveyor.yaml");
    mech_outputs before = m->outputs;
    int *points = malloc(((size_t)before.npoints + 1) * sizeof *points);
    memcpy(points, before.points, (size_t)before.npoints * sizeof *points);
    mech_outputs sel = {0};
    char err[256];
    cr_assert_eq(mech_outputs_parse(m, "C, tray", &sel, err, sizeof err), MECH_OK, "%s", err);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.outputs = &sel;
    o.forces = -1;
    mech_diag d;
    mech_diag_init(&d);
    mech_table t = {0};
    cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
    /* q, C: x y vx vy ax ay, tray: angle omega alpha */
    cr_assert_eq(t.ncolumns, 10, "%d columns", t.ncolumns);
    cr_assert_str_eq(t.columns[1].name, "C.x");
    cr_assert_str_eq(t.columns[7].name, "tray.angle");
    cr_assert_eq(mech_table_column(&t, "driver.torque"), -1, "forces: -1 leaves them out");
    cr_assert_eq(m->outputs.npoints, before.npoints);
    cr_assert_eq(m->outputs.points, before.points);
    cr_assert(memcmp(m->outputs.points, points, (size_t)before.npoints * sizeof *points) == 0);
    cr_assert_eq(m->outputs.forces, before.forces);
    mech_table_free(&t);
    o.outputs = NULL;
    o.forces = 0;  /* the file's: conveyor.yaml asks for forces */
    cr_assert_eq(mech_solve(m, &o, &t, NULL, &d), MECH_OK);
    cr_assert_geq(mech_table_column(&t, "driver.torque"), 0);
    mech_table_free(&t);
    mech_outputs_free(&sel);
    free(points);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* Issue 16 item 13: the force columns' names are linear in the number of
 * joints (each joint's name was compared with every other's: 8000 loops
 * with forces spent 80 % of their time there). 200 000 joints, half of
 * them sharing a name with another: quadratic would be 4e10 comparisons,
 * minutes; linear is milliseconds. The timeout is the check. */
#include "study.h"
#include "load.h"

Test(analysis, joint_labels_are_linear, .timeout = 20)
{
    enum { NJ = 200000 };
    mech_link links[2] = {{0}, {0}};
    links[0].name = "ground";
    links[1].name = "bar";
    mech_joint *joints = calloc(NJ, sizeof *joints);
    char (*names)[16] = calloc(NJ, sizeof *names);
    for (int j = 0; j < NJ; j++) {
        snprintf(names[j], sizeof names[j], "J%d", j / 2 * 2 + (j % 4 == 3));  /* pairs */
        joints[j] = (mech_joint){.kind = MECH_JOINT_REVOLUTE, .name = names[j], .link = {0, 1}};
    }
    mech_model m = {0};
    m.links = links;
    m.nlinks = 2;
    m.joints = joints;
    m.njoints = NJ;
    m.driver.kind = MECH_DRIVE_ANGLE;
    m.driver.index = 1;
    cr_assert_eq(drivers_add_sweep(&m), 0);  /* the one driver: bar's angle is q */
    column_request rq = {&m.outputs, MECH_WANT_ALL, 1, 0, 0};
    column_layout cl;
    cr_assert_eq(columns_build(&cl, &m, &rq), MECH_OK);
    cr_assert_eq(cl.ncols, 1 + 3 * NJ + 2);
    /* J0 and J0 share a name (joints 0, 1): both get the links */
    cr_assert_str_eq(cl.cols[1].name, "J0(ground,bar).Fx");
    cr_assert_str_eq(cl.cols[cl.ncols - 2].name, "driver.torque");
    columns_free(&cl);
    drivers_free(&m);
    free(joints);
    free(names);
}
