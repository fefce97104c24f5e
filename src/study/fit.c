/* src/study/fit.c: the least-squares problem of `mech fit` (docs/synthesis.md):
 * the residuals r = w (y(p) - y*) of solved output columns against targets
 * at given driver positions, and their exact Jacobian dr/dp from the
 * sensitivities (sens_table_at: the implicit-function theorem). The
 * minimiser itself (MINPACK lmder) is fit_lm.c's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "load.h"
#include "study.h"

/* Which of the solve's columns a fit may target: positions only. */
static int position_suffix(const char *s)
{
    return strcmp(s, "x") == 0 || strcmp(s, "y") == 0 || strcmp(s, "angle") == 0 ||
           strcmp(s, "s") == 0;
}

/* fp->outputs: the objects of the target columns ("P.x,P.y,rocker.angle"
 * -> "P,rocker"), each once; an error for a column that is not OBJ.SUFFIX
 * with a position suffix. */
static int outputs_list(fit_problem *fp, mech_diag *d)
{
    size_t len = 0;
    for (int j = 0; j < fp->ncols; j++)
        len += strlen(fp->cols[j]) + 1;
    fp->outputs = xcalloc(len + 1, 1);
    if (!fp->outputs)
        return diag_nomem(d, fp->path, (mech_mark){0, 0});
    char *o = fp->outputs;
    for (int j = 0; j < fp->ncols; j++) {
        const char *c = fp->cols[j], *dot = strrchr(c, '.');
        if (!dot || dot == c || !position_suffix(dot + 1))
            return diag_error(d, fp->path, (mech_mark){0, 0}, "target column '%s': mech fit "
                              "fits a point's x or y, a link's angle or a slider's s (NAME.x, "
                              "NAME.y, NAME.angle, NAME.s)", c);
        size_t n = (size_t)(dot - c);
        int seen = 0;
        for (const char *s = fp->outputs; *s && !seen; s += strcspn(s, ","), s += *s == ',')
            seen = strcspn(s, ",") == n && strncmp(s, c, n) == 0;
        if (seen)
            continue;
        if (o != fp->outputs)
            *o++ = ',';
        memcpy(o, c, n);
        o += n;
        *o = '\0';
    }
    return MECH_OK;
}

/* The constraints of the file's fit: section: their count and sizes; the
 * transmission, the caller's or else the file's, its two links added to
 * the outputs (their angles solved). */
static int constraints_of(fit_problem *fp, const mech_model *m, mech_diag *d)
{
    const model_fit *mf = m->fit;
    fp->ncons = mf ? mf->ncons : 0;
    if (!fp->trans_a[0] && mf && mf->trans_a) {
        snprintf(fp->trans_a, sizeof fp->trans_a, "%s", mf->trans_a);
        snprintf(fp->trans_b, sizeof fp->trans_b, "%s", mf->trans_b);
        fp->trans_min = mf->trans_min;
    }
    fp->trans = fp->trans_a[0] != '\0';
    free(fp->con_scale);
    fp->con_scale = xcalloc((size_t)fp->ncons + 1, sizeof *fp->con_scale);
    if (!fp->con_scale)
        return diag_nomem(d, fp->path, (mech_mark){0, 0});
    for (int c = 0; c < fp->ncons; c++)
        fp->con_scale[c] = mf->cons[c].scale;
    if (!fp->trans)
        return MECH_OK;
    for (int w = 0; w < 2; w++) {
        const char *name = w ? fp->trans_b : fp->trans_a;
        int found = 0;
        for (int i = 1; i < m->nlinks; i++)
            found |= strcmp(m->links[i].name, name) == 0;
        if (!found)
            return diag_error(d, m->file, (mech_mark){0, 0}, "transmission: '%s' is not a "
                              "moving link of the file", name);
    }
    for (int w = 0; w < 2; w++) {  /* each once */
        const char *name = w ? fp->trans_b : fp->trans_a;
        size_t n = strlen(name);
        int seen = 0;
        for (const char *x = fp->outputs; *x && !seen; x += strcspn(x, ","), x += *x == ',')
            seen = strcspn(x, ",") == n && strncmp(x, name, n) == 0;
        if (seen)
            continue;
        size_t len = strlen(fp->outputs) + n + 2;
        char *o = xcalloc(len, 1);
        if (!o)
            return diag_nomem(d, fp->path, (mech_mark){0, 0});
        snprintf(o, len, "%s%s%s", fp->outputs, fp->outputs[0] ? "," : "", name);
        free(fp->outputs);
        fp->outputs = o;
    }
    return MECH_OK;
}

/* The solve options of every evaluation: positions, the target columns'
 * objects, no forces. */
static int eval_options(const fit_problem *fp, const mech_model *m, mech_outputs *outs,
                        mech_solve_options *o, mech_diag *d)
{
    char err[256];
    mech_solve_options_default(o);
    o->want = fp->free_timing ? MECH_WANT_POSITION | MECH_WANT_VELOCITY : MECH_WANT_POSITION;
    o->forces = -1;
    if (mech_outputs_parse(m, fp->outputs, outs, err, sizeof err) != MECH_OK)
        return diag_error(d, fp->path, (mech_mark){0, 0}, "a target column names what mech solve does not output: %s", err);
    o->outputs = outs;
    return MECH_OK;
}

int fit_prepare(fit_problem *fp, double *p0, mech_diag *d)
{
    mech_model *m = NULL;
    mech_outputs outs = {0};
    mech_table h = {0};
    mech_analysis *a = NULL;
    mech_summary s;
    int rc = mech_load_file(fp->path, &m, d);
    if (rc == MECH_OK)
        rc = mech_check(m, &s, d);
    if (rc != MECH_OK)
        goto done;
    for (int k = 0; k < fp->nfree && rc == MECH_OK; k++) {
        int found = -1;
        for (int i = 0; i < m->nparams; i++)
            if (strcmp(m->params[i].name, fp->names[k]) == 0)
                found = i;
        if (found < 0) {
            char list[512] = "";
            size_t len = 0;
            for (int i = 0; i < m->nparams && len < sizeof list; i++)
                len += (size_t)snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "",
                                        m->params[i].name);
            rc = diag_error(d, m->file, (mech_mark){0, 0}, "--free: no parameter '%s' in the "
                            "file (its parameters: %s)", fp->names[k], m->nparams ? list
                            : "none; add a 'parameters:' section");
            break;
        }
        p0[k] = m->params[found].value;
        snprintf(fp->unit[k], sizeof fp->unit[k], "%s", m->params[found].unit);
        fp->mark[k] = m->params[found].mark;
    }
    if (rc == MECH_OK)
        rc = outputs_list(fp, d);
    if (rc == MECH_OK)
        rc = constraints_of(fp, m, d);
    if (rc == MECH_OK && fp->free_timing &&
        (m->driver.kind == MECH_DRIVE_TIME || m->ndrivers != 1 || !(m->driver.speed != 0.0)))
        rc = diag_error(d, m->file, (mech_mark){0, 0}, "free timing needs one driver "
                        "('driver:', with a speed other than 0), not laws of time");
    mech_solve_options o;
    if (rc == MECH_OK)
        rc = eval_options(fp, m, &outs, &o, d);
    if (rc == MECH_OK)
        rc = mech_analysis_new(m, &o, &a, d);
    if (rc == MECH_OK)
        rc = mech_analysis_header(a, &h);
    if (rc != MECH_OK)
        goto done;
    snprintf(fp->qunit, sizeof fp->qunit, "%s", h.columns[0].unit);
    for (int j = 0; j < fp->ncols && rc == MECH_OK; j++) {
        int c = mech_table_column(&h, fp->cols[j]);
        if (c < 0)
            rc = diag_error(d, m->file, (mech_mark){0, 0}, "target column '%s': mech solve "
                            "has no such column", fp->cols[j]);
        else
            snprintf(fp->col_unit[j], sizeof fp->col_unit[j], "%s", h.columns[c].unit);
    }
done:
    mech_table_free(&h);
    mech_analysis_free(&a);
    mech_outputs_free(&outs);
    mech_model_free(&m);
    return rc;
}

/* The rate column of a position column: "P.x" -> "P.vx", "rocker.angle" ->
 * "rocker.omega", "slider.s" -> "slider.v". */
static void rate_name(const char *col, char *buf, size_t size)
{
    const char *dot = strrchr(col, '.');
    const char *sfx = strcmp(dot + 1, "x") == 0 ? "vx" : strcmp(dot + 1, "y") == 0 ? "vy"
                      : strcmp(dot + 1, "angle") == 0 ? "omega" : "v";
    snprintf(buf, size, "%.*s.%s", (int)(dot - col), col, sfx);
}

/* y - y*, an angle's difference taken in (-pi, pi]. */
static double difference(const char *unit, double y, double t)
{
    double e = y - t;
    return strcmp(unit, "rad") == 0 ? remainder(e, 6.283185307179586476925) : e;
}

/* The file loaded and checked with the free parameters at p (as overrides
 * of their values, in their file units). */
static int load_values(const fit_problem *fp, const double *p, mech_model **m, mech_diag *quiet,
                       mech_diag *d)
{
    int n = fp->nfree, rc;
    mech_override *ov = xcalloc((size_t)n + 1, sizeof *ov);
    char (*text)[64] = xcalloc((size_t)n + 1, sizeof *text);
    if (!ov || !text) {
        free(ov);
        free(text);
        return diag_nomem(d, fp->path, (mech_mark){0, 0});
    }
    for (int k = 0; k < n; k++) {
        snprintf(text[k], sizeof text[k], "%.17g%s%s", p[k], fp->unit[k][0] ? " " : "",
                 fp->unit[k]);
        ov[k] = (mech_override){fp->names[k], text[k]};
    }
    rc = mech_load_file_with(fp->path, ov, n, m, quiet);
    mech_summary s;
    if (rc == MECH_OK)
        rc = mech_check(*m, &s, quiet);
    free(ov);
    free(text);
    return rc;
}

/* load_values, counted as a solve. */
static int load_at(fit_problem *fp, const double *p, mech_model **m, mech_diag *quiet,
                   mech_diag *d)
{
    fp->nsolves++;
    return load_values(fp, p, m, quiet, d);
}

/* The constraint values after the target residuals (fit_ncons of them)
 * and their rows of the Jacobian: an expression's g and dg/dp from its
 * recorded tree (exact, param_expr.c); a transmission's g_i = min -
 * asin|sin(a_i - b_i)| from the two links' solved angles and their
 * sensitivities (and rates, with free timing). */
static int eval_constraints(fit_problem *fp, const mech_model *m, const mech_table *t,
                            double *r, double *jac)
{
    int n = fp->nfree, mrows = fit_nres(fp), base = fp->nq * fp->ncols;
    const model_fit *mf = m->fit;
    for (int c = 0; c < fp->ncons; c++)
        r[base + c] = mf->cons[c].g;
    if (jac && fp->ncons) {
        const param_exprs *pe = m->pexpr;
        double *dv = xcalloc((size_t)(pe ? pe->n : 0) + 1, sizeof *dv);
        if (!dv)
            return MECH_ENOMEM;
        for (int k = 0; k < fit_nvars(fp); k++) {
            int pi = -1;
            for (int i = 0; k < n && i < m->nparams; i++)
                if (strcmp(m->params[i].name, fp->names[k]) == 0)
                    pi = i;
            if (pe && pi >= 0)
                pexpr_derivatives(pe, pi, dv);
            for (int c = 0; c < fp->ncons; c++)
                jac[(size_t)k * mrows + base + c] =
                    pe && pi >= 0 ? pexpr_deriv_of(dv, mf->cons[c].h) : 0.0;
        }
        free(dv);
    }
    if (!fp->trans)
        return MECH_OK;
    char name[300];
    int ca, cb, base2 = base + fp->ncons;
    snprintf(name, sizeof name, "%s.angle", fp->trans_a);
    ca = mech_table_column(t, name);
    snprintf(name, sizeof name, "%s.angle", fp->trans_b);
    cb = mech_table_column(t, name);
    if (ca < 0 || cb < 0)
        return MECH_ESOLVE;
    for (int i = 0; i < fp->nq; i++) {
        double da = mech_table_get(t, i, ca) - mech_table_get(t, i, cb);
        double s = sin(da), c = cos(da);
        r[base2 + i] = fp->trans_min - asin(fabs(s) < 1.0 ? fabs(s) : 1.0);
        if (!jac)
            continue;
        double f = -((s < 0) ? -1.0 : 1.0) * ((c < 0) ? -1.0 : 1.0);  /* dg/d(da) */
        for (int k = 0; k < fit_nvars(fp); k++) {
            double dd = 0.0;
            if (k < n) {
                int x[2];
                for (int w = 0; w < 2; w++) {
                    snprintf(name, sizeof name, "d(%s.angle)/d(%s)", w ? fp->trans_b : fp->trans_a,
                             fp->names[k]);
                    x[w] = mech_table_column(t, name);
                }
                dd = (x[0] < 0 ? 0.0 : mech_table_get(t, i, x[0])) -
                     (x[1] < 0 ? 0.0 : mech_table_get(t, i, x[1]));
            } else if (k - n == i) {  /* free timing: d(da)/dq_i from the rates */
                int x[2];
                for (int w = 0; w < 2; w++) {
                    snprintf(name, sizeof name, "%s.omega", w ? fp->trans_b : fp->trans_a);
                    x[w] = mech_table_column(t, name);
                }
                dd = ((x[0] < 0 ? 0.0 : mech_table_get(t, i, x[0])) -
                      (x[1] < 0 ? 0.0 : mech_table_get(t, i, x[1]))) / m->driver.speed;
            }
            jac[(size_t)k * mrows + base2 + i] = f * dd;
        }
    }
    return MECH_OK;
}

int fit_feasible(const fit_problem *fp, const double *r)
{
    int base = fp->nq * fp->ncols;
    for (int c = 0; c < fit_ncons(fp); c++)
        if (!(r[base + c] <= fit_con_tolerance(fp, c)))
            return MECH_ESOLVE;
    return MECH_OK;
}

int fit_eval(fit_problem *fp, const double *p, double *r, double *jac, mech_diag *d)
{
    int n = fp->nfree, mrows = fit_nres(fp);
    mech_model *m = NULL;
    mech_outputs outs = {0};
    mech_table t = {0};
    mech_diag quiet;
    mech_diag_init(&quiet);
    int rc = load_at(fp, p, &m, &quiet, d);
    mech_solve_options o;
    if (rc == MECH_OK)
        rc = eval_options(fp, m, &outs, &o, &quiet);
    if (rc == MECH_OK)
        rc = sens_table_at(m, &o, fp->free_timing ? p + n : fp->q, fp->nq, fp->names,
                           jac ? n : 0, &t, &quiet);
    if (rc == MECH_OK && t.nrows != fp->nq)
        rc = MECH_ESOLVE;
    if (rc != MECH_OK) {
        /* a start or a trial step where the mechanism does not assemble
         * at every target: the caller's to reject */
        if (rc != MECH_ESOLVE && rc != MECH_EINPUT)
            mech_diag_print(&quiet, stderr);
        rc = rc == MECH_ENOMEM ? diag_nomem(d, fp->path, (mech_mark){0, 0}) : MECH_ESOLVE;
        goto done;
    }
    for (int j = 0; j < fp->ncols; j++) {
        int c = mech_table_column(&t, fp->cols[j]);
        double w = fp->weight ? fp->weight[j] : 1.0;
        for (int i = 0; i < fp->nq; i++) {
            double y = mech_table_get(&t, i, c), y0 = fp->target[(size_t)i * fp->ncols + j];
            r[i * fp->ncols + j] = isnan(y0) ? 0.0 : w * difference(fp->col_unit[j], y, y0);
        }
        if (jac && fp->free_timing) {
            /* dr/dq_i = w dy/dq = w (dy/dt) / (dq/dt), on row i only */
            char name[300];
            rate_name(fp->cols[j], name, sizeof name);
            int vc = mech_table_column(&t, name);
            for (int i = 0; i < fp->nq; i++) {
                double y0 = fp->target[(size_t)i * fp->ncols + j];
                for (int i2 = 0; i2 < fp->nq; i2++)
                    jac[(size_t)(n + i2) * mrows + i * fp->ncols + j] =
                        i2 != i || isnan(y0) || vc < 0
                            ? 0.0 : w * mech_table_get(&t, i, vc) / m->driver.speed;
            }
        }
        for (int k = 0; jac && k < n; k++) {
            char name[300];
            snprintf(name, sizeof name, "d(%s)/d(%s)", fp->cols[j], fp->names[k]);
            int dc = mech_table_column(&t, name);
            for (int i = 0; i < fp->nq; i++) {
                double y0 = fp->target[(size_t)i * fp->ncols + j];
                jac[(size_t)k * mrows + i * fp->ncols + j] =  /* column-major, m rows */
                    isnan(y0) || dc < 0 ? 0.0 : w * mech_table_get(&t, i, dc);
            }
        }
    }
    rc = eval_constraints(fp, m, &t, r, jac);
    if (rc == MECH_ENOMEM)
        rc = diag_nomem(d, fp->path, (mech_mark){0, 0});
    if (rc == MECH_OK && fp->observe) {
        double f = 0.0;
        for (int k = 0; k < fp->nq * fp->ncols; k++)
            f += r[k] * r[k];
        fp->observe(fp->observe_ctx, fp->nsolves, f);
    }
done:
    mech_diag_free(&quiet);
    mech_table_free(&t);
    mech_outputs_free(&outs);
    mech_model_free(&m);
    return rc;
}

int fit_check_range(fit_problem *fp, const double *p, mech_diag *d)
{
    mech_model *m = NULL;
    mech_table t = {0};
    mech_diag quiet;
    mech_diag_init(&quiet);
    int rc = load_at(fp, p, &m, &quiet, d);
    if (rc == MECH_OK) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.want = MECH_WANT_POSITION;
        o.forces = -1;
        rc = mech_solve(m, &o, &t, NULL, &quiet);
    }
    if (rc != MECH_OK)
        rc = rc == MECH_ENOMEM ? diag_nomem(d, fp->path, (mech_mark){0, 0}) : MECH_ESOLVE;
    mech_diag_free(&quiet);
    mech_table_free(&t);
    mech_model_free(&m);
    return rc;
}

int fit_objective(fit_problem *fp, const double *p, double *r, double *objective, mech_diag *d)
{
    int rc = fit_eval(fp, p, r, NULL, d);
    double f = 0.0;
    for (int i = 0; rc == MECH_OK && i < fp->nq * fp->ncols; i++)
        f += r[i] * r[i];
    *objective = rc == MECH_OK ? f : INFINITY;
    return rc;
}

int fit_sweep_model(const fit_problem *fp, const mech_model *m, mech_table *t, mech_diag *d)
{
    mech_outputs outs = {0};
    mech_solve_options o;
    int rc = eval_options(fp, m, &outs, &o, d);
    if (rc == MECH_OK) {
        o.want = MECH_WANT_POSITION;
        mech_diag quiet;  /* the gaps are in t->gaps */
        mech_diag_init(&quiet);
        rc = mech_solve(m, &o, t, NULL, &quiet);
        if (rc != MECH_OK && rc != MECH_ESOLVE)
            mech_diag_print(&quiet, stderr);
        mech_diag_free(&quiet);
    }
    mech_outputs_free(&outs);
    return rc;
}

int fit_sweep(const fit_problem *fp, const double *p, mech_table *t, mech_diag *d)
{
    mech_model *m = NULL;
    int rc = load_values(fp, p, &m, d, d);
    if (rc == MECH_OK)
        rc = fit_sweep_model(fp, m, t, d);
    mech_model_free(&m);
    return rc;
}

void fit_problem_free(fit_problem *fp)
{
    free(fp->outputs);
    fp->outputs = NULL;
    free(fp->con_scale);
    fp->con_scale = NULL;
}
