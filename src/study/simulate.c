/* src/study/simulate.c: forward dynamics, `mech simulate` (docs/dynamics.md).
 *
 * The free coordinates X (the drivers of `drivers:` marked `free: true`)
 * and their rates W are the state; the dependent coordinates are solved
 * from them at every evaluation by the sweep's own Newton (the driver rows
 * shifted to hold X), so the loops close to Newton's tolerance at every
 * step whatever the integrator does. The equations of motion come from
 * the force analysis (inverse dynamics): with free accelerations A the
 * loads the free drivers would have to apply are tau(A) = M A + tau0
 * (tau0 at A = 0: gravity, springs, dampers, velocity products and every
 * load, the free drivers' own included); the motion of free coordinates
 * needs no driver load, so M A = -tau0, column j of M being tau(e_j) -
 * tau0. SUNDIALS CVODE integrates [X, W] and the work of the loads, the
 * prescribed drivers and the dampers. Every workspace is allocated once
 * before the integration. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_dense.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "base.h"
#include "study.h"
#include "solve.h"

/* the energy columns after the layout's */
static const char *const energy_names[] = {"energy.kinetic", "energy.gravity", "energy.springs",
                                           "work.loads",     "work.drivers",   "work.dampers",
                                           "energy.balance"};
enum { NENERGY = 7 };

typedef struct sim {
    const mech_model *m;
    mech_diag *d;
    solver_plan sp;
    forces_plan fp;
    solver sv;
    forces fc;
    column_layout cl;
    int have_sp, have_fp, have_sv, have_fc, have_cl;
    int nf;                /* free coordinates */
    int *fdrv, *frow;      /* [nf] their driver and its solved row */
    double *shift, *vshift, *ashift; /* [nr] */
    double *M, *tau0, *A;  /* [nf nf], [nf], [nf] */
    double **Mcol;         /* [nf] M's columns, for SUNDIALS' dense LU */
    sunindextype *piv;
    double p_loads, p_drivers, p_dampers; /* powers at the last evaluation */
    double kinetic, gravity, springs;
    double worst_load;     /* largest |free driver load| at the output rows, N*m or N */
    double worst_resid;    /* largest Newton residual */
    int det_sign;
    long evals, force_solves;
    int nroots;            /* root functions: nf rates (stop_at_rest), then the condition */
    int rates_watched;     /* stop_at_rest */
    int cond_kind;         /* stop_when: 0 none, 1 point x, 2 point y, 3 link angle,
                              4 slider s */
    int cond_obj;          /* its point name id, link or joint */
    double cond_value;     /* SI */
    int cond_failed;       /* the root function could not evaluate a state */
    double end_time;       /* where a stop at rest ended the run, else NAN */
    int rest_driver;       /* and the driver whose rate crossed zero, else -1 */
    int failed;            /* MECH_ESOLVE reported */
    double fail_t;
} sim;

static int fail_at(sim *s, double t, const char *fmt, const char *what)
{
    if (!s->failed) {
        char buf[600];
        snprintf(buf, sizeof buf, fmt, what);
        diag_error(s->d, s->m->file, s->m->driver.mark, "at t = %.9g s: %s", t, buf);
        s->failed = 1;
        s->fail_t = t;
    }
    return -1;
}

/* ---- one evaluation: positions, rates, the mass matrix, the accelerations ---- */

/* The driver loads of the free coordinates at the published state. */
static int free_loads(sim *s, double *tau)
{
    s->force_solves++;
    if (forces_solve(&s->fc, &s->sv) != 0)
        return -1;
    for (int k = 0; k < s->nf; k++)
        tau[k] = forces_drive_of(&s->fc, 1, s->fdrv[k]);
    return 0;
}

/* Solve M A = b in place (b := A) by SUNDIALS' dense LU with partial
 * pivoting (M column-major, factored in its own storage); -1 when a pivot
 * is below 1e-13 of M's largest entry: the mass matrix is singular there
 * (a dead point of the free coordinates). */
static int solve_small(sim *s, double *b)
{
    int n = s->nf;
    double big = 0.0;
    for (int i = 0; i < n * n; i++)
        big = fmax(big, fabs(s->M[i]));
    if (SUNDlsMat_denseGETRF(s->Mcol, n, n, s->piv) != 0)
        return -1;
    for (int k = 0; k < n; k++)
        if (!(fabs(s->Mcol[k][k]) > 1e-13 * big))
            return -1;
    SUNDlsMat_denseGETRS(s->Mcol, n, s->piv, b);
    return 0;
}

/* Powers of the loads, prescribed drivers and dampers, and the energies,
 * at the published state with its forces. */
static void powers(sim *s)
{
    const forces_numbers_t *fn = &s->fp.num;
    const rt_frame *F = s->sv.ks.F;
    rt_power pw;
    rt_power_start(&pw, 0.0, 0.0, 0.0, 0.0);
    for (int i = 0; i < fn->nloads; i++)
        rt_power_load(&pw, &fn->loads[i], F, s->fc.sl_reg);
    s->p_loads = pw.ext + pw.sloads;
    double pd = 0.0;
    for (int k = 0; k < s->m->ndrivers; k++) {
        const rt_drive *dr = &fn->drive[k];
        if (drivers_free_of(s->m, k))
            continue;  /* its load is 0 but for rounding: no work (docs/dynamics.md) */
        double rate = dr->link > 0 ? F[dr->link].om : dr->var >= 0 ? s->sv.vel[dr->var] : 0.0;
        pd += forces_drive_of(&s->fc, 1, k) * rate;
    }
    s->p_drivers = pd;
    double pdamp = 0.0, vs = 0.0;
    for (int i = 0; i < fn->nsprings; i++) {
        const rt_spring *sp = &fn->springs[i];
        const double *st = s->fc.spr + RT_SPRING_STATE * i;
        double dev = st[0] - sp->rest;
        pdamp -= sp->damping * st[1] * st[1];
        vs += sp->preload * dev + 0.5 * sp->stiffness * dev * dev;
    }
    s->p_dampers = pdamp;
    s->springs = vs;
    double kin = 0.0, grav = 0.0;
    for (int l = 1; l < s->m->nlinks; l++) {
        const rt_body *b = &fn->body[l];
        if (!b->has_mass)
            continue;
        double g[2], vg[2], ag[2];
        rt_centre(b, &F[l], g, vg, ag);
        kin += 0.5 * b->mass * (vg[0] * vg[0] + vg[1] * vg[1]) + 0.5 * b->inertia * F[l].om * F[l].om;
        grav -= b->mass * (fn->grav[0] * g[0] + fn->grav[1] * g[1]);
    }
    s->kinetic = kin;
    s->gravity = grav;
}

/* Everything at time t for free coordinates X and rates W: the accelerations
 * into A (s->A when A is NULL), the state published with its forces. 0, 1
 * when the position cannot be solved (CVODE may retry with a shorter step),
 * -1 when the mass matrix is singular or the forces fail. */
static int evaluate_state(sim *s, double t, const double *X, const double *W)
{
    const mech_model *m = s->m;
    s->evals++;
    for (int k = 0; k < s->nf; k++) {
        double dp, ddp, p = law_eval(m->drivers[s->fdrv[k]].law, t, &dp, &ddp);
        int r = s->frow[k];
        s->shift[r] = X[k] - p;
        s->vshift[r] = W[k] - dp;
        s->ashift[r] = -ddp;
    }
    step_status st = solver_newton_shifted(&s->sv, t, s->shift);
    if (st != STEP_OK)
        return 1;
    s->worst_resid = fmax(s->worst_resid, s->sv.resid);
    solver_rates_shifted(&s->sv, s->vshift, s->ashift);
    solver_publish(&s->sv, t, 1.0, 0.0);
    if (free_loads(s, s->tau0) != 0)
        return -1;
    for (int j = 0; j < s->nf; j++) {
        int r = s->frow[j];
        s->ashift[r] += 1.0;
        solver_accel_shifted(&s->sv, s->ashift);
        solver_publish(&s->sv, t, 1.0, 0.0);
        double *col = s->A;  /* work: tau(e_j) */
        if (free_loads(s, col) != 0)
            return -1;
        for (int i = 0; i < s->nf; i++)
            s->M[j * s->nf + i] = col[i] - s->tau0[i];  /* column-major */
        s->ashift[r] -= 1.0;
    }
    for (int i = 0; i < s->nf; i++)
        s->A[i] = -s->tau0[i];
    if (solve_small(s, s->A) != 0)
        return -1;
    for (int k = 0; k < s->nf; k++)
        s->ashift[s->frow[k]] += s->A[k];
    solver_accel_shifted(&s->sv, s->ashift);
    solver_publish(&s->sv, t, 1.0, 0.0);
    s->force_solves++;
    if (forces_solve(&s->fc, &s->sv) != 0)
        return -1;
    powers(s);
    return 0;
}

/* CVODE's right-hand side: y = [X, W, work of loads, drivers, dampers]. */
static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void *user)
{
    sim *s = user;
    const double *Y = N_VGetArrayPointer(y);
    double *D = N_VGetArrayPointer(ydot);
    int rc = evaluate_state(s, t, Y, Y + s->nf);
    if (rc != 0)
        return rc;  /* 1: recoverable (a shorter step), -1: stop */
    for (int k = 0; k < s->nf; k++) {
        D[k] = Y[s->nf + k];
        D[s->nf + k] = s->A[k];
    }
    D[2 * s->nf] = s->p_loads;
    D[2 * s->nf + 1] = s->p_drivers;
    D[2 * s->nf + 2] = s->p_dampers;
    return 0;
}

/* The Jacobian of rhs by forward differences, for CVODE's Newton. Not
 * CVODE's own difference quotients: those step a component by about
 * atol x h x |f| where it is 0 (the works at the start), far below the
 * rounding of a right-hand side that a Newton solve computes, so its
 * columns were noise times 1e20 and BDF accepted wrong steps (a crank held
 * at constant speed drifted 1e-3 at rtol 1e-8, atol 1e-14). Here a free
 * coordinate or rate steps by sqrt(eps) of its size (at least 1 SI unit:
 * the Newton solve's rounding is far below), and the works' columns are 0
 * exactly: no right-hand side reads them. */
static int jacobian(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J, void *user,
                    N_Vector tmp1, N_Vector tmp2, N_Vector tmp3)
{
    (void)tmp3;
    sim *s = user;
    int n = (int)N_VGetLength(y), nx = 2 * s->nf;
    const double *F = N_VGetArrayPointer(fy);
    double *Yp = N_VGetArrayPointer(tmp1), *Fp = N_VGetArrayPointer(tmp2);
    memcpy(Yp, N_VGetArrayPointer(y), (size_t)n * sizeof *Yp);
    SUNMatZero(J);
    for (int j = 0; j < nx; j++) {
        double keep = Yp[j], inc = sqrt(DBL_EPSILON) * fmax(fabs(keep), 1.0);
        Yp[j] = keep + inc;
        inc = Yp[j] - keep;  /* the step the rounding made */
        int rc = rhs(t, tmp1, tmp2, user);
        Yp[j] = keep;
        if (rc != 0)
            return rc;
        double *col = SUNDenseMatrix_Column(J, j);
        for (int i = 0; i < n; i++)
            col[i] = (Fp[i] - F[i]) / inc;
    }
    return 0;
}

/* ---- set-up ---------------------------------------------------------------- */

static int refuse(const mech_model *m, mech_diag *d)
{
    if (!m->free_drivers || m->free_drivers->n == 0)
        return diag_error(d, m->file, m->driver.mark,
                          "nothing to simulate: no driver is free (in 'drivers:', give one "
                          "'free: true' with 'initial: {value: ..., speed: ...}'; "
                          "docs/dynamics.md)");
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].friction > 0.0)
            return diag_error(d, m->file, m->joints[j].mark,
                              "joint '%s' has Coulomb friction, which mech simulate does not "
                              "model (the driver loads are then not linear in the "
                              "accelerations): remove 'friction' to simulate without it",
                              m->joints[j].name);
    for (int i = 0; i < model_ncams(m); i++)
        if (m->cams->cam[i].friction > 0.0)
            return diag_error(d, m->file, m->cams->cam[i].mark,
                              "cam '%s' has Coulomb friction at its contact, which mech "
                              "simulate does not model (as a joint's): remove 'friction' to "
                              "simulate without it", m->cams->cam[i].name);
    const state_loads *sl = m->state_loads;
    for (int i = 0; sl && i < sl->nin; i++)
        if (sl->in[i].kind == SLIN_PAX || sl->in[i].kind == SLIN_PAY ||
            sl->in[i].kind == SLIN_ALPHA || sl->in[i].kind == SLIN_SA ||
            sl->in[i].kind == SLIN_DRIVER_ACCEL)
            return diag_error(d, m->file, m->driver.mark,
                              "a load depends on an acceleration (ax, ay, alpha or a): "
                              "mech simulate needs loads of positions, velocities and time");
    return MECH_OK;
}

static void sim_free(sim *s)
{
    if (s->have_cl)
        columns_free(&s->cl);
    if (s->have_fc)
        forces_free(&s->fc);
    if (s->have_sv)
        solver_free(&s->sv);
    if (s->have_fp)
        forces_plan_free(&s->fp);
    if (s->have_sp)
        solver_plan_free(&s->sp);
    void *blocks[] = {s->fdrv, s->frow, s->shift, s->vshift, s->ashift, s->M, s->tau0, s->A,
                      s->piv, s->Mcol};
    for (size_t i = 0; i < sizeof blocks / sizeof *blocks; i++)
        free(blocks[i]);
}

/* The plans, the states and the free rows. */
static int sim_setup(sim *s, const mech_model *m, mech_diag *d)
{
    s->m = m;
    s->d = d;
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.all_blocks = 1;
    o.want = MECH_WANT_ALL;
    o.forces = 1;
    o.friction = MECH_FRICTION_OFF;
    int rc = solver_plan_init(&s->sp, m, &o, d);
    if (rc != MECH_OK)
        return rc;
    s->have_sp = 1;
    if (s->sp.aug)
        return diag_error(d, m->file, m->driver.mark,
                          "the constraints are redundant: mech simulate needs independent "
                          "loop equations");
    if ((rc = forces_plan_init(&s->fp, &s->sp, MECH_FRICTION_OFF, d)) != MECH_OK)
        return rc;
    s->have_fp = 1;
    if (solver_init(&s->sv, &s->sp) != 0)
        return diag_nomem(d, m->file, m->driver.mark);
    s->have_sv = 1;
    if (forces_init(&s->fc, &s->fp) != 0)
        return diag_nomem(d, m->file, m->driver.mark);
    s->have_fc = 1;
    column_request rq = {&m->outputs, MECH_WANT_ALL, 1, 0, 0};
    if (columns_build(&s->cl, m, &rq) != MECH_OK)
        return diag_nomem(d, m->file, m->driver.mark);
    s->have_cl = 1;
    int nf = s->nf = m->free_drivers->n, nr = s->sp.nr;
    s->fdrv = xcalloc((size_t)nf, sizeof *s->fdrv);
    s->frow = xcalloc((size_t)nf, sizeof *s->frow);
    s->piv = xcalloc((size_t)nf, sizeof *s->piv);
    s->Mcol = xcalloc((size_t)nf, sizeof *s->Mcol);
    double **arrays[] = {&s->shift, &s->vshift, &s->ashift, &s->M, &s->tau0, &s->A};
    size_t sizes[] = {(size_t)nr + 1, (size_t)nr + 1, (size_t)nr + 1, (size_t)(nf * nf),
                      (size_t)nf, (size_t)nf};
    if (!s->fdrv || !s->frow || !s->piv || !s->Mcol || xcalloc_doubles(arrays, sizes, 0, 6) < 0)
        return diag_nomem(d, m->file, m->driver.mark);
    for (int j = 0; j < nf; j++)
        s->Mcol[j] = s->M + (size_t)j * (size_t)nf;
    const mech_system *sys = s->sp.sys;
    for (int k = 0; k < nf; k++) {
        s->fdrv[k] = m->free_drivers->d[k].driver;
        s->frow[k] = -1;
        for (int i = 0; i < nr; i++) {
            const row_desc *rd = &sys->rows[s->sp.row[i]];
            if (rd->kind == ROW_DRIVER && rd->owner == s->fdrv[k])
                s->frow[k] = i;
        }
        if (s->frow[k] < 0)
            return diag_error(d, m->file, m->free_drivers->d[k].mark,
                              "free driver '%s': its equation is not among those solved",
                              drivers_name(m, s->fdrv[k]));
    }
    return MECH_OK;
}

/* Row 0: the assembly at t0 from the file's guesses and branches (the
 * sweep's own start), copied into the simulation's solver. */
static int first_position(sim *s, double t0)
{
    mech_solve_stats st;
    memset(&st, 0, sizeof st);
    cont c;
    if (cont_init(&c, &s->sp, s->d, &st) != 0)
        return diag_nomem(s->d, s->m->file, s->m->driver.mark);
    int rc = cont_start(&c, t0);
    if (rc == MECH_OK)
        memcpy(s->sv.x, c.sv.x, (size_t)s->sp.ns * sizeof *s->sv.x);
    cont_free(&c);
    return rc;
}

/* ---- the run ------------------------------------------------------------------ */

void mech_simulate_options_default(mech_simulate_options *o)
{
    memset(o, 0, sizeof *o);
    o->size = sizeof *o;
    o->to = NAN;
    o->step = 0.0;
    o->rtol = 1e-8;
    o->atol = 1e-10;
    o->method = MECH_SIM_BDF;
    o->max_steps = 1000000;
}

static int make_table(const sim *s, mech_table *t, int nrows)
{
    const column_layout *cl = &s->cl;
    int nc = cl->ncols + NENERGY;
    memset(t, 0, sizeof *t);
    t->columns = xcalloc((size_t)nc, sizeof *t->columns);
    if (!t->columns)
        return MECH_ENOMEM;
    for (int c = 0; c < nc; c++, t->ncolumns++) {
        int own = c < cl->ncols;
        t->columns[c].name = xstrdup(own ? cl->cols[c].name : energy_names[c - cl->ncols]);
        t->columns[c].unit = xstrdup(own ? cl->cols[c].unit : "J");
        if (!t->columns[c].name || !t->columns[c].unit)
            return MECH_ENOMEM;
    }
    t->values = xcalloc((size_t)nrows * (size_t)nc + 1, sizeof *t->values);
    t->nrequested = nrows;
    return t->values ? MECH_OK : MECH_ENOMEM;
}

/* The output row at the state y (time t). */
static int output_row(sim *s, double t, const double *Y, double e0, mech_table *tab)
{
    int rc = evaluate_state(s, t, Y, Y + s->nf);
    if (rc != 0)
        return rc;
    double *row = tab->values + (size_t)tab->nrows * (size_t)tab->ncolumns;
    row_sources rs = {&s->sv, &s->fc, s->sv.iters, 0};
    columns_fill(&s->cl, &rs, row);
    double *e = row + s->cl.ncols;
    const double *w = Y + 2 * s->nf;
    e[0] = s->kinetic;
    e[1] = s->gravity;
    e[2] = s->springs;
    e[3] = w[0];
    e[4] = w[1];
    e[5] = w[2];
    e[6] = s->kinetic + s->gravity + s->springs - e0 - (w[0] + w[1] + w[2]);
    for (int k = 0; k < s->nf; k++)
        s->worst_load = fmax(s->worst_load, fabs(forces_drive_of(&s->fc, 1, s->fdrv[k])));
    tab->nrows++;
    return 0;
}

static const char *cvode_why(int flag)
{
    switch (flag) {
    case CV_TOO_MUCH_WORK: return "too many integration steps (raise --max-steps)";
    case CV_TOO_MUCH_ACC: return "the accuracy asked for is beyond reach (raise --rtol)";
    case CV_ERR_FAILURE: return "the error test failed repeatedly (a jump in the loads?)";
    case CV_CONV_FAILURE: return "the corrector did not converge";
    case CV_RHSFUNC_FAIL: case CV_REPTD_RHSFUNC_ERR: case CV_UNREC_RHSFUNC_ERR:
    case CV_FIRST_RHSFUNC_ERR:
        return "the mechanism cannot be assembled there (a limit position or dead point)";
    default: return "the integrator failed";
    }
}

/* The value the condition of stop_when watches, at the published state. */
static double cond_now(const sim *s)
{
    double p[2];
    switch (s->cond_kind) {
    case 1: case 2:
        kin_point(&s->sp.tree, &s->sv.ks, s->cond_obj, p, NULL, NULL);
        return p[s->cond_kind - 1];
    case 3: return s->sv.ks.F[s->cond_obj].th;
    default: {
        int var = s->sp.tree.slide_var[s->cond_obj];
        return var >= 0 ? s->sv.pos[var] : 0.0;
    }
    }
}

/* The root functions: the free coordinates' rates (stop_at_rest), then the
 * watched value minus its target (stop_when; the state evaluated at t, y). */
static int roots(sunrealtype t, N_Vector y, sunrealtype *g, void *user)
{
    sim *s = user;
    const double *Y = N_VGetArrayPointer(y);
    int k = 0;
    if (s->rates_watched)
        for (; k < s->nf; k++)
            g[k] = Y[s->nf + k];
    if (s->cond_kind) {
        if (evaluate_state(s, t, Y, Y + s->nf) != 0) {
            s->cond_failed = 1;
            return -1;
        }
        g[k] = cond_now(s) - s->cond_value;
    }
    return 0;
}

/* stop_when "NAME.MEMBER=VALUE" (docs/dynamics.md): a point's x or y, a
 * link's angle or a slider's s, and the value as on the command line
 * (mech_parse_value: bare numbers are mm or deg). */
static int parse_condition(sim *s, const char *text)
{
    const mech_model *m = s->m;
    const char *eq = strchr(text, '='), *dot = NULL;
    for (const char *c = text; eq && c < eq; c++)
        if (*c == '.')
            dot = c;
    if (!eq || !dot || dot == text)
        return diag_error(s->d, m->file, m->driver.mark,
                          "stop condition '%s': write NAME.MEMBER=VALUE (a point's x or y, a "
                          "link's angle, a slider's s), e.g. 'x_C.s=150 mm'", text);
    char name[128], mem[16];
    snprintf(name, sizeof name, "%.*s", (int)(dot - text), text);
    snprintf(mem, sizeof mem, "%.*s", (int)(eq - dot - 1), dot + 1);
    int is_angle = 0;
    s->cond_kind = 0;
    for (int i = 0; i < m->npoint_names && !s->cond_kind; i++)
        if (strcmp(m->point_names[i], name) == 0 && (!strcmp(mem, "x") || !strcmp(mem, "y"))) {
            s->cond_kind = mem[0] == 'x' ? 1 : 2;
            s->cond_obj = i;
        }
    for (int l = 1; l < m->nlinks && !s->cond_kind; l++)
        if (strcmp(m->links[l].name, name) == 0 && !strcmp(mem, "angle")) {
            s->cond_kind = 3, s->cond_obj = l, is_angle = 1;
        }
    for (int j = 0; j < m->njoints && !s->cond_kind; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER && strcmp(m->joints[j].name, name) == 0 &&
            !strcmp(mem, "s")) {
            s->cond_kind = 4, s->cond_obj = j;
        }
    if (!s->cond_kind)
        return diag_error(s->d, m->file, m->driver.mark,
                          "stop condition '%s': '%s.%s' is not a point's x or y, a moving "
                          "link's angle or a slider's s", text, name, mem);
    char err[200];
    if (mech_parse_value(eq + 1, is_angle, &s->cond_value, err, sizeof err) != MECH_OK) {
        s->cond_kind = 0;
        return diag_error(s->d, m->file, m->driver.mark, "stop condition '%s': %s", text, err);
    }
    return MECH_OK;
}

static void quiet_errors(int code, const char *module, const char *function, char *msg,
                         void *user)
{
    (void)code, (void)module, (void)function, (void)msg, (void)user;
}

static int integrate(sim *s, const mech_simulate_options *o, double t0, double t1, int nrows,
                     double h, mech_table *out, mech_simulate_stats *stats)
{
    const mech_model *m = s->m;
    int nf = s->nf, N = 2 * nf + 3, rc = MECH_OK;
    SUNContext ctx = NULL;
    if (SUNContext_Create(NULL, &ctx) != 0)
        return diag_nomem(s->d, m->file, m->driver.mark);
    N_Vector y = N_VNew_Serial(N, ctx);
    SUNMatrix J = SUNDenseMatrix(N, N, ctx);
    SUNLinearSolver LS = y && J ? SUNLinSol_Dense(y, J, ctx) : NULL;
    void *cv = CVodeCreate(o->method == MECH_SIM_ADAMS ? CV_ADAMS : CV_BDF, ctx);
    if (!y || !J || !LS || !cv) {
        rc = diag_nomem(s->d, m->file, m->driver.mark);
        goto done;
    }
    double *Y = N_VGetArrayPointer(y);
    for (int k = 0; k < nf; k++) {
        Y[k] = m->free_drivers->d[k].value;
        Y[nf + k] = m->free_drivers->d[k].speed;
    }
    Y[2 * nf] = Y[2 * nf + 1] = Y[2 * nf + 2] = 0.0;
    if (output_row(s, t0, Y, 0.0, out) != 0) {
        fail_at(s, t0, "%s", "the first position cannot be solved");
        rc = MECH_ESOLVE;
        goto done;
    }
    double e0 = s->kinetic + s->gravity + s->springs;
    out->values[(size_t)(out->ncolumns) - 1] = 0.0;
    s->det_sign = solver_det_sign(&s->sv);
    if (CVodeInit(cv, rhs, t0, y) != CV_SUCCESS || CVodeSStolerances(cv, o->rtol, o->atol) ||
        CVodeSetLinearSolver(cv, LS, J) || CVodeSetJacFn(cv, jacobian) ||
        CVodeSetUserData(cv, s) ||
        CVodeSetMaxNumSteps(cv, o->max_steps) || CVodeSetStopTime(cv, t1)) {
        rc = diag_error(s->d, m->file, m->driver.mark, "CVODE could not be set up");
        goto done;
    }
    CVodeSetErrHandlerFn(cv, quiet_errors, NULL);  /* the failure is reported by fail_at */
    s->rates_watched = o->stop_at_rest != 0;
    s->nroots = (s->rates_watched ? nf : 0) + (s->cond_kind ? 1 : 0);
    if (s->nroots > 0 && CVodeRootInit(cv, s->nroots, roots) != CV_SUCCESS) {
        rc = diag_nomem(s->d, m->file, m->driver.mark);
        goto done;
    }
    if (stats)
        stats->stopped_at_rest = -1;
    for (int i = 1; i < nrows; i++) {
        double tout = i == nrows - 1 ? t1 : t0 + h * i, tret = t0;
        int flag = CVode(cv, tout, y, &tret, CV_NORMAL);
        if (flag < 0) {
            if (s->cond_failed && !s->failed)
                fail_at(s, tret, "%s", "the stop condition's state cannot be solved");
            if (!s->failed) {
                char why[520];
                snprintf(why, sizeof why, "%s", cvode_why(flag));
                if (flag == CV_RHSFUNC_FAIL || flag == CV_REPTD_RHSFUNC_ERR ||
                    flag == CV_UNREC_RHSFUNC_ERR || flag == CV_CONV_FAILURE) {
                    char rows[200], line[160];
                    diagnose_dependent_rows(&s->sv, rows, sizeof rows);
                    diagnose_links_in_line(&s->sv, cos(0.2), line, sizeof line);
                    if (line[0])
                        snprintf(why + strlen(why), sizeof why - strlen(why), ": %s", line);
                    if (rows[0])
                        snprintf(why + strlen(why), sizeof why - strlen(why),
                                 "; the equations that depend there: %s", rows);
                }
                fail_at(s, tret, "%s", why);
            }
            rc = MECH_ESOLVE;
            break;
        }
        if (flag == CV_ROOT_RETURN)
            tout = tret;
        int orc = output_row(s, tout, Y, e0, out);
        if (orc != 0) {
            fail_at(s, tout, "%s", "the position at an output time cannot be solved");
            rc = MECH_ESOLVE;
            break;
        }
        if (flag == CV_ROOT_RETURN) {
            int found[65] = {0}, k = 0;
            if (s->nroots <= 65)
                CVodeGetRootInfo(cv, found);
            int nr = s->rates_watched ? nf : 0;
            while (k < nr && !found[k])
                k++;
            s->end_time = tret;
            if (k < nr) {
                diag_note(s->d, m->file, m->free_drivers->d[k].mark,
                          "stopped at rest: the rate of '%s' crossed zero at t = %.12g s",
                          drivers_name(m, s->fdrv[k]), tret);
                s->rest_driver = s->fdrv[k];
            } else {
                diag_note(s->d, m->file, m->driver.mark,
                          "stopped: the condition %s was met at t = %.12g s", o->stop_when,
                          tret);
            }
            break;
        }
        int sign = solver_det_sign(&s->sv);
        if (sign != s->det_sign) {
            char rows[300];
            diagnose_dependent_rows(&s->sv, rows, sizeof rows);
            fail_at(s, tout, "the motion passed a singular position (a dead point or limit "
                             "position: the loops' Jacobian changed sign%s)", "");
            if (rows[0])
                diag_note(s->d, m->file, m->driver.mark, "the equations involved: %s", rows);
            rc = MECH_ESOLVE;
            break;
        }
    }
    if (stats) {
        long v = 0;
        CVodeGetNumSteps(cv, &v);
        stats->steps = v;
        CVodeGetNumRhsEvals(cv, &v);
        stats->rhs_evals = v;
        CVodeGetNumJacEvals(cv, &v);
        stats->jac_evals = v;
        if (getenv("MECH_SIM_DEBUG")) {
            long a1 = 0, a2 = 0, a3 = 0;
            int q = 0;
            CVodeGetNumErrTestFails(cv, &a1);
            CVodeGetNumNonlinSolvConvFails(cv, &a2);
            CVodeGetNumNonlinSolvIters(cv, &a3);
            CVodeGetLastOrder(cv, &q);
            fprintf(stderr, "cvode: %ld error test fails, %ld conv fails, %ld nl iters, order %d\n", a1, a2, a3, q);
        }
    }
done:
    if (cv)
        CVodeFree(&cv);
    if (LS)
        SUNLinSolFree(LS);
    if (J)
        SUNMatDestroy(J);
    if (y)
        N_VDestroy(y);
    SUNContext_Free(&ctx);
    return rc;
}

static int simulate_checked(const mech_model *m, const mech_simulate_options *o,
                            mech_table *out, mech_simulate_stats *stats, mech_diag *d)
{
    mech_simulate_options def;
    if (!o) {
        mech_simulate_options_default(&def);
        o = &def;
    }
    if (!m || !out)
        return api_null(d, "mech_simulate", m ? "out" : "m");
    memset(out, 0, sizeof *out);
    if (o->size != sizeof *o)
        return diag_error(d, "mech_simulate", (mech_mark){0, 0},
                          "the simulation options' size is %zu, and this library (%s) knows "
                          "%zu: set them with mech_simulate_options_default", o->size,
                          MECH_VERSION, sizeof *o);
    if (!(o->rtol > 0.0) || !(o->atol > 0.0) || o->max_steps < 1 ||
        (o->method != MECH_SIM_BDF && o->method != MECH_SIM_ADAMS))
        return diag_error(d, "mech_simulate", (mech_mark){0, 0},
                          "the simulation options need rtol > 0, atol > 0, max_steps >= 1 and "
                          "method MECH_SIM_BDF or MECH_SIM_ADAMS");
    if (stats)
        memset(stats, 0, sizeof *stats);
    int rc = refuse(m, d);
    if (rc != MECH_OK)
        return rc;
    if (m->driver.kind != MECH_DRIVE_TIME || m->driver.nvalues < 1)
        return diag_error(d, m->file, m->driver.mark, "mech simulate needs 'sweep: {time: ...}'");
    double t0 = m->driver.values[0];
    double t1 = isnan(o->to) ? m->driver.values[m->driver.nvalues - 1] : o->to;
    double h = o->step > 0.0 ? o->step
               : m->driver.nvalues > 1 ? (m->driver.values[m->driver.nvalues - 1] - t0) /
                                              (m->driver.nvalues - 1)
                                       : t1 - t0;
    if (!(t1 > t0) || !(h > 0.0))
        return diag_error(d, m->file, m->driver.mark,
                          "the simulation needs an end time after its start (%.9g s) and a "
                          "positive output step", t0);
    double nd = ceil((t1 - t0) / h * (1.0 - 1e-12));
    if (nd > 10000000.0)
        return diag_error(d, m->file, m->driver.mark,
                          "%.0f output rows: ask for a longer --step", nd);
    int nrows = (int)nd + 1;
    double start = clock_seconds();
    sim s;
    memset(&s, 0, sizeof s);
    s.end_time = NAN;
    s.rest_driver = -1;
    rc = sim_setup(&s, m, d);
    if (rc == MECH_OK && o->stop_when && o->stop_when[0])
        rc = parse_condition(&s, o->stop_when);
    if (rc == MECH_OK)
        rc = first_position(&s, t0);
    if (rc == MECH_OK && (double)nrows * (s.cl.ncols + NENERGY) * sizeof(double) > 2147483648.0)
        rc = diag_error(d, m->file, m->driver.mark,
                        "the results would take %.3g GB in memory (%d rows of %d columns): ask "
                        "for a longer --step or a shorter --to",
                        (double)nrows * (s.cl.ncols + NENERGY) * 8e-9, nrows,
                        s.cl.ncols + NENERGY);
    if (rc == MECH_OK && make_table(&s, out, nrows) != MECH_OK)
        rc = diag_nomem(d, m->file, m->driver.mark);
    if (rc == MECH_OK)
        rc = integrate(&s, o, t0, t1, nrows, h, out, stats);
    if (stats) {
        stats->seconds = clock_seconds() - start;
        stats->evaluations = s.evals;
        stats->force_solves = s.force_solves;
        stats->worst_residual = s.worst_resid;
        stats->worst_free_load = s.worst_load;
        stats->rows = out->nrows;
        stats->stop_time = s.failed ? s.fail_t : !isnan(s.end_time) ? s.end_time : t1;
        stats->stopped_at_rest = s.rest_driver;
    }
    sim_free(&s);
    if (rc != MECH_OK && out->nrows == 0)
        mech_table_free(out);
    return rc;
}

int mech_simulate(const mech_model *m, const mech_simulate_options *o, mech_table *out,
                  mech_simulate_stats *stats, mech_diag *d)
{
    mech_diag own, *dd = api_diag(d, &own);
    int rc = simulate_checked(m, o, out, stats, dd);
    api_diag_end(d, &own);
    return rc;
}
