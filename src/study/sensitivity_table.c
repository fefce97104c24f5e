/* src/study/sensitivity_table.c: mech_sensitivity, the sensitivity columns of a
 * solved table: which columns have one (the kinematic ones), the state of
 * every row (a second sweep that solves every unknown), and the new
 * columns d(COL)/d(NAME) [COL's unit / NAME's unit]. The derivatives
 * themselves are sensitivity.c's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "study.h"

/* A kinematic column: what it is the derivative of. */
typedef struct sens_col {
    int col;      /* in the table */
    int root;     /* first output root of its quantity (sens_add_output) */
    int level;    /* 0 position, 1 velocity, 2 acceleration */
} sens_col;

/* "A.vx" -> point A, component x, level 1; 0 when no kinematic column. */
static int parse_column(const mech_model *m, const char *name, int *kind, int *obj, int *comp,
                        int *level)
{
    static const char *const sfx[] = {"x", "y", "vx", "vy", "ax", "ay", "angle", "omega",
                                      "alpha", "s", "v", "a"};
    const char *dot = strrchr(name, '.');
    if (!dot || dot == name || dot - name >= 128)
        return 0;
    char obj_name[128];
    memcpy(obj_name, name, (size_t)(dot - name));
    obj_name[dot - name] = '\0';
    for (int k = 0; k < 12; k++) {
        if (strcmp(dot + 1, sfx[k]) != 0)
            continue;
        *kind = k < 6 ? SENS_POINT : k < 9 ? SENS_LINK : SENS_SLIDER;
        *comp = k < 6 ? k % 2 : 0;
        *level = k < 6 ? k / 2 : (k - 6) % 3;
        *obj = -1;
        if (*kind == SENS_POINT) {
            for (int i = 0; i < m->npoint_names; i++)
                if (strcmp(m->point_names[i], obj_name) == 0)
                    *obj = i;
        } else {
            *obj = *kind == SENS_LINK ? mech_find_link(m, obj_name) : mech_find_joint(m, obj_name);
        }
        return *obj >= 0;
    }
    return 0;
}

/* The kinematic columns of t, each with its output roots in the plan. */
static int plan_columns(sens_plan *sp, const mech_table *t, sens_col *cols, int *ncols)
{
    const mech_model *m = sp->sys->model;
    int nc = 0, *key = xcalloc(3 * (size_t)t->ncolumns + 1, sizeof *key), nkey = 0;
    int *keyroot = xcalloc((size_t)t->ncolumns + 1, sizeof *keyroot);
    if (!key || !keyroot) {
        free(key);
        free(keyroot);
        return -1;
    }
    for (int c = 0; c < t->ncolumns; c++) {
        int kind, obj, comp, level, root = -1;
        if (!parse_column(m, t->columns[c].name, &kind, &obj, &comp, &level))
            continue;
        for (int k = 0; k < nkey && root < 0; k++)
            if (key[3 * k] == kind && key[3 * k + 1] == obj && key[3 * k + 2] == comp)
                root = keyroot[k];
        ex e;
        if (root < 0 && (sens_output_expr(sp, kind, obj, comp, &e) < 0 ||
                         sens_add_output(sp, e, &root) < 0)) {
            free(key);
            free(keyroot);
            return -1;
        }
        key[3 * nkey] = kind;
        key[3 * nkey + 1] = obj;
        key[3 * nkey + 2] = comp;
        keyroot[nkey++] = root;
        cols[nc++] = (sens_col){c, root, level};
    }
    free(key);
    free(keyroot);
    *ncols = nc;
    return 0;
}

/* Every unknown's position and rates, per row: the same sweep with every
 * moving link and slider as outputs and no forces (at the driver positions
 * q[0..nq-1] when q is not NULL, else the options'). */
static int solve_states(const mech_model *m, const mech_solve_options *o, const double *q,
                        int nq, mech_table *x, mech_diag *d)
{
    mech_outputs all = {0};
    all.links = xcalloc((size_t)m->nlinks + 1, sizeof *all.links);
    all.sliders = xcalloc((size_t)m->njoints + 1, sizeof *all.sliders);
    if (!all.links || !all.sliders) {
        free(all.links);
        free(all.sliders);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    for (int l = 1; l < m->nlinks; l++)
        all.links[all.nlinks++] = l;
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER)
            all.sliders[all.nsliders++] = j;
    mech_solve_options o2 = *o;
    o2.outputs = &all;
    o2.forces = -1;
    o2.diagnostics = 0;
    o2.progress = NULL;
    o2.log = NULL;
    mech_diag quiet;
    mech_diag_init(&quiet);
    int rc;
    if (q) {
        mech_analysis *a = NULL;
        rc = mech_analysis_new(m, &o2, &a, &quiet);
        if (rc == MECH_OK)
            rc = mech_analysis_solve(a, q, nq, x, NULL, &quiet);
        mech_analysis_free(&a);
    } else {
        rc = mech_solve(m, &o2, x, NULL, &quiet);
    }
    mech_diag_free(&quiet);
    free(all.links);
    free(all.sliders);
    if (rc == MECH_ESOLVE)
        rc = MECH_OK;  /* the same gaps as the table's: checked row by row */
    if (rc != MECH_OK)
        return diag_fail(d, fail_of_status(rc), m->file, (mech_mark){0, 0}, "the sweep for the "
                         "sensitivities failed");
    return MECH_OK;
}

/* Columns of x holding unknown i's position, rate and acceleration (-1: absent). */
static void state_columns(const mech_system *s, const mech_table *x, int i, int *c)
{
    static const char *const ang[] = {"angle", "omega", "alpha"}, *const sl[] = {"s", "v", "a"};
    const mech_model *m = s->model;
    int is_angle = s->unk_kind[i] == UNK_ANGLE;
    const char *name = is_angle ? m->links[s->unk_index[i]].name : m->joints[s->unk_index[i]].name;
    for (int k = 0; k < 3; k++) {
        char buf[160];
        snprintf(buf, sizeof buf, "%s.%s", name, is_angle ? ang[k] : sl[k]);
        c[k] = mech_table_column(x, buf);
    }
}

static double cell(const mech_table *t, int row, int col)
{
    return col < 0 ? 0.0 : mech_table_get(t, row, col);
}

/* t widened by `extra` columns after its own: the old columns and values
 * kept, the new ones zero with no name yet (the caller names them). Returns
 * the old width, or -1 with t unchanged when out of memory. */
static int table_add_columns(mech_table *t, int extra)
{
    int old = t->ncolumns, wide = old + extra;
    mech_column *cn = xcalloc((size_t)wide, sizeof *cn);
    double *v = xcalloc((size_t)t->nrows * (size_t)wide + 1, sizeof *v);
    if (!cn || !v) {
        free(cn);
        free(v);
        return -1;
    }
    memcpy(cn, t->columns, (size_t)old * sizeof *cn);
    for (int r = 0; r < t->nrows; r++)
        memcpy(v + (size_t)r * wide, t->values + (size_t)r * old, (size_t)old * sizeof *v);
    free(t->columns);
    free(t->values);
    t->columns = cn;
    t->values = v;
    t->ncolumns = wide;
    return old;
}

/* The table t widened by nnames * nc columns, filled from vals[row][k][c]. */
static int widen(mech_table *t, const mech_model *m, const int *which, int nnames,
                 const sens_col *cols, int nc, const double *vals)
{
    int old = table_add_columns(t, nnames * nc), wide = t->ncolumns;
    if (old < 0)
        return -1;
    int failed = 0;
    for (int k = 0; k < nnames; k++)
        for (int c = 0; c < nc; c++) {
            const mech_column *col = &t->columns[cols[c].col];
            const mech_param *p = &m->params[which[k]];
            mech_column *out = &t->columns[old + k * nc + c];
            size_t ln = strlen(col->name) + strlen(p->name) + 16;
            size_t lu = strlen(col->unit) + strlen(p->unit) + 8;
            out->name = malloc(ln);
            out->unit = malloc(lu);
            if (!out->name || !out->unit) {
                failed = 1;
                continue;
            }
            snprintf(out->name, ln, "d(%s)/d(%s)", col->name, p->name);
            if (p->unit[0])
                snprintf(out->unit, lu, "%s/%s", col->unit, p->unit);
            else
                snprintf(out->unit, lu, "%s", col->unit);  /* per 1 of a bare number */
        }
    for (int r = 0; r < t->nrows; r++)
        memcpy(t->values + (size_t)r * wide + old, vals + (size_t)r * nnames * nc,
               (size_t)(nnames * nc) * sizeof *t->values);
    return failed ? -1 : 0;
}

/* Fill vals[row][k][c] for every row of t (states from x). */
static int fill_rows(sens_plan *sp, const mech_table *t, const mech_table *x, int nnames,
                     const sens_col *cols, int nc, double *vals, mech_diag *d)
{
    const mech_system *s = sp->sys;
    const mech_model *m = s->model;
    int n = sp->n, rc = MECH_OK;
    int *sc = xcalloc(3 * (size_t)n + 1, sizeof *sc);
    double *state = xcalloc((size_t)SYS_NVARS(n) + (size_t)n, sizeof *state);
    double *out = xcalloc((size_t)sp->nout + 1, sizeof *out);
    if (!sc || !state || !out) {
        rc = diag_nomem(d, m->file, (mech_mark){0, 0});
        goto done;
    }
    for (int i = 0; i < n; i++)
        state_columns(s, x, i, sc + 3 * i);
    for (int r = 0; r < t->nrows && rc == MECH_OK; r++) {
        if (r >= x->nrows || mech_table_get(x, r, 0) != mech_table_get(t, r, 0)) {
            rc = diag_fail(d, MECH_FAIL_NO_ASSEMBLY, m->file, (mech_mark){0, 0}, "the sweep for "
                           "the sensitivities did not reach row %d (q = %.10g)", r + 1,
                           mech_table_get(t, r, 0));
            break;
        }
        for (int i = 0; i < n; i++) {
            state[i] = cell(x, r, sc[3 * i]);
            state[SYS_VAR_XDOT(n, i)] = cell(x, r, sc[3 * i + 1]);
            state[SYS_NVARS(n) + i] = cell(x, r, sc[3 * i + 2]);
        }
        state[SYS_VAR_Q(n)] = mech_table_get(t, r, 0);
        state[SYS_VAR_QDOT(n)] = m->driver.speed;
        state[SYS_VAR_QDDOT(n)] = m->driver.accel;
        for (int k = 0; k < nnames && rc == MECH_OK; k++) {
            if (sens_row(sp, state, k, out) < 0) {
                rc = diag_fail(d, MECH_FAIL_DEAD_POINT, m->file, (mech_mark){0, 0}, "sensitivity "
                               "at q = %.10g: the Jacobian is singular there",
                               state[SYS_VAR_Q(n)]);
                break;
            }
            for (int c = 0; c < nc; c++)
                vals[((size_t)r * nnames + k) * nc + c] = out[cols[c].root + cols[c].level];
        }
    }
done:
    free(sc);
    free(state);
    free(out);
    return rc;
}

/* Indices of the named parameters, or an error naming the ones there are. */
static int find_params(const mech_model *m, const char *const *names, int nnames, int *which,
                       mech_diag *d)
{
    for (int k = 0; k < nnames; k++) {
        which[k] = -1;
        for (int i = 0; i < m->nparams; i++)
            if (strcmp(m->params[i].name, names[k]) == 0)
                which[k] = i;
        if (which[k] < 0) {
            char list[512] = "";
            size_t len = 0;
            for (int i = 0; i < m->nparams && len < sizeof list; i++)
                len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "",
                                        m->params[i].name);
            return diag_error(d, m->file, (mech_mark){0, 0}, "--sensitivity: no parameter '%s' "
                              "in the file (its parameters: %s)", names[k],
                              m->nparams ? list : "none");
        }
    }
    return MECH_OK;
}

/* The sensitivities of t's kinematic columns by the parameters which[]:
 * *vals[(row * nnames + k) * nc + c] for column cols[c]. */
static int sensitivities(const mech_model *m, const mech_solve_options *o, const double *q,
                         int nq, const int *which, int nnames, const mech_table *table,
                         sens_col *cols, int *nc, double **vals, mech_diag *d)
{
    sens_plan sp;
    mech_table x = {0};
    *vals = NULL;
    int rc = sens_plan_new(&sp, m, which, nnames, d);
    if (rc != MECH_OK)
        return rc;
    if (plan_columns(&sp, table, cols, nc) < 0)
        rc = diag_nomem(d, m->file, (mech_mark){0, 0});
    if (rc == MECH_OK)
        rc = sens_plan_compile(&sp, d);
    if (rc == MECH_OK)
        rc = solve_states(m, o, q, nq, &x, d);
    if (rc == MECH_OK &&
        !(*vals = xcalloc((size_t)table->nrows * nnames * *nc + 1, sizeof **vals)))
        rc = diag_nomem(d, m->file, (mech_mark){0, 0});
    if (rc == MECH_OK)
        rc = fill_rows(&sp, table, &x, nnames, cols, *nc, *vals, d);
    sens_plan_free(&sp);
    mech_table_free(&x);
    if (rc != MECH_OK) {
        free(*vals);
        *vals = NULL;
    }
    return rc;
}

static int sensitivity_columns(const mech_model *m, const mech_override *ov, int nov,
                               const mech_solve_options *o, const double *q, int nq,
                               const char *const *names, int nnames, mech_table *table,
                               mech_diag *d)
{
    int nc = 0, *which = xcalloc((size_t)nnames + 1, sizeof *which);
    sens_col *cols = xcalloc((size_t)table->ncolumns + 1, sizeof *cols);
    double *vals = NULL;
    (void)ov, (void)nov;  /* the model holds its replacements' expressions already */
    int rc = which && cols ? find_params(m, names, nnames, which, d)
                           : diag_nomem(d, m->file, (mech_mark){0, 0});
    if (rc == MECH_OK)
        rc = sensitivities(m, o, q, nq, which, nnames, table, cols, &nc, &vals, d);
    if (rc == MECH_OK && widen(table, m, which, nnames, cols, nc, vals) < 0)
        rc = diag_nomem(d, m->file, (mech_mark){0, 0});
    free(vals);
    free(which);
    free(cols);
    return rc;
}

/* The worst-case and RSS columns of the kinematic columns cols[0..nc-1]. */
static int add_stackup(mech_table *t, const mech_model *m, const int *which, int np,
                       const sens_col *cols, int nc, const double *vals)
{
    int old = table_add_columns(t, 2 * nc), wide = t->ncolumns;
    if (old < 0)
        return -1;
    int failed = 0;
    for (int c = 0; c < nc; c++)
        for (int k = 0; k < 2; k++) {
            const mech_column *col = &t->columns[cols[c].col];
            size_t ln = strlen(col->name) + 8;
            mech_column *out = &t->columns[old + 2 * c + k];
            out->name = malloc(ln);
            out->unit = xstrdup(col->unit);
            if (!out->name || !out->unit)
                failed = 1;
            else
                snprintf(out->name, ln, "%s(%s)", k ? "rss" : "worst", col->name);
        }
    for (int r = 0; r < t->nrows; r++) {
        double *row = t->values + (size_t)r * wide;
        for (int c = 0; c < nc; c++) {
            double worst = 0, sq = 0;
            for (int k = 0; k < np; k++) {
                double dev = vals[((size_t)r * np + k) * nc + c] * m->params[which[k]].tol;
                worst += fabs(dev);  /* sum |dCOL/dp| tol_p */
                sq += dev * dev;
            }
            row[old + 2 * c] = worst;
            row[old + 2 * c + 1] = sqrt(sq);  /* root-sum-square */
        }
    }
    return failed ? -1 : 0;
}

static int tolerance_columns(const mech_model *m, const mech_override *ov, int nov,
                             const mech_solve_options *o, mech_table *table, mech_diag *d)
{
    int np = 0, nc = 0, *which = xcalloc((size_t)m->nparams + 1, sizeof *which);
    sens_col *cols = xcalloc((size_t)table->ncolumns + 1, sizeof *cols);
    double *vals = NULL;
    if (!which || !cols) {
        free(which);
        free(cols);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    for (int i = 0; i < m->nparams; i++)
        if (m->params[i].tol > 0)
            which[np++] = i;
    int rc = np ? MECH_OK
                : diag_error(d, m->file, (mech_mark){0, 0}, "--tolerances: no parameter has a "
                             "tolerance (write one as r: {value: 40 mm, tolerance: 0.05 mm})");
    (void)ov, (void)nov;  /* the model holds its replacements' expressions already */
    if (rc == MECH_OK)
        rc = sensitivities(m, o, NULL, 0, which, np, table, cols, &nc, &vals, d);
    if (rc == MECH_OK && add_stackup(table, m, which, np, cols, nc, vals) < 0)
        rc = diag_nomem(d, m->file, (mech_mark){0, 0});
    free(vals);
    free(which);
    free(cols);
    return rc;
}

/* ---- the public entries: their arguments (mech.h, "NULL arguments") ----- */

/* m, table, the replacements and the names (names[0..nnames-1]) checked, o
 * read by its size into *full. */
static int check_arguments(const char *func, const mech_model *m, const mech_override *ov,
                           int nov, const mech_solve_options *o, mech_solve_options *full,
                           const char *const *names, int nnames, const mech_table *table,
                           mech_diag *d)
{
    if (!m || !table)
        return api_null(d, func, m ? "table" : "m");
    if (nnames < 0 || (nnames > 0 && !names))
        return diag_error(d, func, (mech_mark){0, 0}, "names is NULL or nnames (%d) is "
                          "negative: give nnames parameter names", nnames);
    for (int i = 0; i < nnames; i++)
        if (!names[i])
            return diag_error(d, func, (mech_mark){0, 0}, "names[%d] is NULL", i);
    int rc = api_overrides(func, ov, nov, d);
    return rc == MECH_OK ? api_options(o, full, func, d) : rc;
}

int mech_sensitivity(const mech_model *m, const mech_override *ov, int nov,
                     const mech_solve_options *o, const char *const *names, int nnames,
                     mech_table *table, mech_diag *d)
{
    mech_solve_options full;
    mech_diag own, *dd = api_diag(d, &own);
    int rc = check_arguments("mech_sensitivity", m, ov, nov, o, &full, names, nnames, table, dd);
    if (rc == MECH_OK)
        rc = sensitivity_columns(m, ov, nov, &full, NULL, 0, names, nnames, table, dd);
    api_diag_end(d, &own);
    return rc;
}

int mech_tolerances(const mech_model *m, const mech_override *ov, int nov,
                    const mech_solve_options *o, mech_table *table, mech_diag *d)
{
    mech_solve_options full;
    mech_diag own, *dd = api_diag(d, &own);
    int rc = check_arguments("mech_tolerances", m, ov, nov, o, &full, NULL, 0, table, dd);
    if (rc == MECH_OK)
        rc = tolerance_columns(m, ov, nov, &full, table, dd);
    api_diag_end(d, &own);
    return rc;
}

int sens_table_at(const mech_model *m, const mech_solve_options *o, const double *q, int nq,
                  const char *const *names, int nnames, mech_table *table, mech_diag *d)
{
    mech_analysis *a = NULL;
    int rc = mech_analysis_new(m, o, &a, d);
    if (rc == MECH_OK)
        rc = mech_analysis_solve(a, q, nq, table, NULL, d);
    mech_analysis_free(&a);
    if (rc != MECH_OK)
        return rc;
    return sensitivity_columns(m, NULL, 0, o, q, nq, names, nnames, table, d);
}
