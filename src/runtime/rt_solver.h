/* src/runtime/rt_solver.h: the part of the C that `mech codegen` writes which is
 * the same for every mechanism (docs/codegen.md): one position's Newton
 * solve on the generated state, its rates, the condition where a decision
 * needs it, the predictor and the status. The generator carries this
 * file's text after what it needs, which the generated source defines
 * before it (tests/unit/test_rt_solver.c does the same by hand):
 *
 *   cg_state           the state (P_state): x, xd, xdd, xq, xqq, out, residual,
 *                      rcond, rcond_whole, rcond_exact, iterations, det_sign,
 *                      branch, first, nsolved, q_last, q_prev, xc, xqq_prev and
 *                      the work xe, f, ft, dx, xt, r, cs, w, colnorm, anorm, keep,
 *                      Jv, Ax, lu, piv, swap_parity
 *   CG_OK, CG_NO_ASSEMBLY, CG_SINGULAR, CG_BRANCH, CG_FORCES (0 or 1)
 *   NX, NB, TOL, MIN_RCOND; jac (rt_blocks), col_start (J's CSC columns),
 *                      newton_par (rt_newton_par)
 *   eval_driver, eval_position, eval_velocity, eval_accel (the equations)
 *   NLINKS; kinematics (the frames F[NLINKS], the kinematic output columns,
 *                      the branch conditions: the first that fails, or -1)
 *   with CG_FORCES 1: CG_FORCE_SINGULAR, CG_FRICTION_STUCK; NF, NFDENSE, LREF,
 *                      FORCE_FRICTION, FORCE_BOTH, FORCE_GEARS, DRIVER_SLIDER;
 *                      fjac, fabove_start; the state's force fields (fv, fcs, fb,
 *                      fw, fcolnorm, fanorm, ffric, fg, fr, fag, fdg, fdr, fvel,
 *                      fpiv, fswap, fcond_known, fprev, fy, fy0, force_rcond, ...);
 *                      force_motion, force_state_loads, force_known,
 *                      force_matrix, force_friction, force_gear_separation,
 *                      force_drive_power, force_power, force_columns
 *
 * and rt_blocklu.h, rt_newton.h, rt_frame.h (and rt_forces.h) before it. Names end in none of the
 * public suffixes (_init, _solve, _predict, _rcond, ...): codegen.c checks
 * that a prefix makes no name of this text. */

/* f and J at x, q (after eval_driver at q); returns |f|inf. */
static inline double cg_evaluate(cg_state *s, const double *x, double q, double *f)
{
    for (int i = 0; i < NX; i++)
        s->xe[i] = x[i];
    eval_position(x, q, f, s->Jv, s->keep);
    return rt_norm_inf(f, NX);
}

/* Scale each column of J to unit largest entry, then factor the diagonal
 * blocks of its block triangular form. 0, or -1: a zero pivot or a value
 * that is not finite. */
static inline int cg_factor(cg_state *s)
{
    for (int c = 0; c < NX; c++) {
        int p0 = col_start[c], len = col_start[c + 1] - p0;
        double cs = rt_column_scale(s->Jv + p0, len);
        s->cs[c] = cs;
        for (int p = p0; p < p0 + len; p++)
            s->Ax[p] = s->Jv[p] * cs;
    }
    if (rt_blocks_place(&jac, s->Ax, s->lu) < 0)
        return -1;
    rt_blocks_column_norms(&jac, s->lu, s->colnorm, s->anorm);
    return rt_blocks_factor_placed(&jac, s->lu, s->piv, &s->swap_parity) < 0 ? 0 : -1;
}

/* dx = J^-1 b with the factors, the column scaling undone. */
static inline void cg_linear(cg_state *s, const double *b, double *dx)
{
    for (int i = 0; i < NX; i++)
        dx[i] = b[i];
    rt_blocks_solve(&jac, s->lu, s->piv, s->w, dx);
    for (int i = 0; i < NX; i++)
        dx[i] = dx[i] * s->cs[i];
}

/* Reciprocal 1-norm conditions of the equilibrated Jacobian (docs/solver.md
 * section 2): s->rcond, the worst diagonal block's against its whole
 * columns; s->rcond_whole, the whole matrix's (Hager, two iterations; the
 * blocks' when there is one block). */
static inline void cg_condition(cg_state *s)
{
    s->rcond = rt_blocks_rcond(&jac, s->lu, s->piv, s->anorm, s->w + 4 * NX);
    s->rcond_exact = 1;
    s->rcond_whole = NB == 1 ? s->rcond
                             : rt_blocks_rcond_whole(&jac, s->lu, s->piv, s->colnorm, s->w);
}

/* The condition at a converged position, computed only where a decision
 * depends on it (docs/codegen.md "The condition at a solution"). It
 * decides two things: the status (rcond < MIN_RCOND: singular) and the
 * next position's rounding floor xtol = fmax(1e-2 TOL, DBL_EPSILON /
 * fmax(rcond_whole, 1e-300)), which is 1e-2 TOL whenever the division
 * gives at most that. If the lower bounds of rt_blocks_rcond_bounds say
 * rcond >= MIN_RCOND and fl(DBL_EPSILON / whole bound) <= 1e-2 TOL
 * (division rounds monotonically), the exact values give the same status
 * and the same next xtol: s->rcond and s->rcond_whole keep the bounds
 * (s->rcond_exact = 0; P_rcond gives the exact values from the factors,
 * kept until the next solve) and nothing else reads them. Otherwise the
 * exact values, as the interpreter. */
static inline void cg_condition_at_solution(cg_state *s)
{
    double worst, whole;
    if (rt_blocks_rcond_bounds(&jac, s->lu, s->piv, s->anorm, s->w, &worst, &whole) &&
        worst >= MIN_RCOND && whole > 0.0 && DBL_EPSILON / fmax(whole, 1e-300) <= 1e-2 * TOL) {
        s->rcond = worst;
        s->rcond_whole = whole;
        s->rcond_exact = 0;
        return;
    }
    cg_condition(s);
}

/* ---- Newton (rt_newton.h) on the generated equations ------------------- */

typedef struct cg_newton_ctx {
    cg_state *s;
    double q;
} cg_newton_ctx;

static inline double cg_newton_evaluate(void *c, const double *x, double *f)
{
    cg_newton_ctx *n = (cg_newton_ctx *)c;
    return cg_evaluate(n->s, x, n->q, f);
}

static inline int cg_newton_factor(void *c) { return cg_factor(((cg_newton_ctx *)c)->s); }

/* The last position's condition: Newton's rounding floor (computed at the
 * first factorisation of all). */
static inline double cg_newton_rcond_whole(void *c)
{
    cg_state *s = ((cg_newton_ctx *)c)->s;
    if (!(s->rcond > 0.0))
        cg_condition(s);
    return s->rcond_whole;
}

static inline void cg_newton_linear(void *c, const double *b, double *dx)
{
    cg_linear(((cg_newton_ctx *)c)->s, b, dx);
}

static inline double cg_newton_rcond_at_solution(void *c)
{
    cg_state *s = ((cg_newton_ctx *)c)->s;
    cg_condition_at_solution(s);
    return s->rcond;
}

/* Newton from s->x at driver position q (src/solve/solve.c solver_newton): CG_OK,
 * CG_NO_ASSEMBLY or CG_SINGULAR. */
static inline int cg_newton(cg_state *s, double q)
{
    static const rt_newton_ops ops = {cg_newton_evaluate, cg_newton_factor, cg_newton_rcond_whole,
                                      cg_newton_linear, cg_newton_rcond_at_solution};
    s->iterations = 0;
    s->rcond_exact = 1;  /* a failure leaves rcond as it is */
    if (NX == 0) {
        s->residual = 0.0;
        s->rcond = s->rcond_whole = 1.0;
        return CG_OK;
    }
    eval_driver(q, s->keep);
    rt_newton_vec v = {s->x, s->f, s->ft, s->dx, s->xt};
    cg_newton_ctx ctx = {s, q};
    int st = rt_newton(&ops, &ctx, &newton_par, &v, &s->residual, &s->iterations);
    return st == RT_NEWTON_CONVERGED ? CG_OK : st == RT_NEWTON_SINGULAR ? CG_SINGULAR
                                                                        : CG_NO_ASSEMBLY;
}

/* dx/dq and d2x/dq2 at the last evaluation, with its factors. */
static inline void cg_rates(cg_state *s, double q)
{
    eval_velocity(s->xe, q, s->keep, s->r);
    cg_linear(s, s->r, s->xq);
    eval_accel(s->xe, q, s->xq, s->keep, s->r);
    cg_linear(s, s->r, s->xqq);
}

/* ---- the kinetostatics (rt_forces.h) on the generated tables ---------- */

#if CG_FORCES
/* y = A^-1 rhs with the force factors, the column scaling undone. */
static inline void cg_force_apply(cg_state *s, const double *rhs, double *y)
{
    for (int i = 0; i < NF; i++)
        y[i] = rhs[i];
    rt_blocks_solve(&fjac, s->fv, s->fpiv, s->fw, y);
    for (int c = 0; c < NF; c++)
        y[c] *= s->fcs[c];
}

typedef struct cg_forces_ctx {
    cg_state *s;
    const rt_frame *F;
    double qd, eps;
} cg_forces_ctx;

static void cg_forces_solve_rhs(void *c, const double *rhs, double *y)
{
    cg_force_apply(((cg_forces_ctx *)c)->s, rhs, y);
}

static double cg_forces_friction(void *c, const double *y, double *fric)
{
    cg_forces_ctx *x = (cg_forces_ctx *)c;
    return force_friction(x->s, x->F, y, x->eps, fric);
}

static void cg_forces_separation(void *c, const double *y, double *rhs)
{
    cg_forces_ctx *x = (cg_forces_ctx *)c;
    force_gear_separation(x->s, x->F, y, rhs);
}

static double cg_forces_drive_power(void *c, const double *y)
{
    cg_forces_ctx *x = (cg_forces_ctx *)c;
    return force_drive_power(x->s, x->F, y, x->qd);
}

static double cg_forces_power(void *c, double pd, double pfric)
{
    cg_forces_ctx *x = (cg_forces_ctx *)c;
    return force_power(x->s, x->F, x->qd, pd, pfric);
}

/* The joint reactions, the drivers' loads, friction and the power balance
 * at the solved position (src/forces/forces.c forces_solve): 0, CG_FORCE_SINGULAR
 * or CG_FRICTION_STUCK. The friction's smoothing eps is 1e-6 of the speed
 * qd given (per LREF for a slider driver). */
static int cg_kinetostatics(cg_state *s, const rt_frame *F, double q, double qd, double qdd)
{
    static const rt_forces_ops ops = {cg_forces_solve_rhs, cg_forces_friction,
                                      cg_forces_separation, cg_forces_drive_power,
                                      cg_forces_power};
    for (int i = 0; i < NX; i++)  /* the slides' rates, the driver's last (rt_friction.var) */
        s->fvel[i] = s->xd[i];
    s->fvel[NX] = qd;
    force_motion(s, F);
    force_state_loads(s, F, q, qd, qdd);
    force_known(s, F, s->fb);
    force_matrix(s, F);
    int finite = 1;
    for (int p = 0; p < NFDENSE + fabove_start[NF]; p++)
        finite &= isfinite(s->fv[p]) != 0;
    if (finite)
        rt_blocks_column_norms(&fjac, s->fv, s->fcolnorm, s->fanorm);
    if (!finite || rt_blocks_factor_placed(&fjac, s->fv, s->fpiv, &s->fswap) >= 0) {
        s->force_rcond = 0.0;
        return CG_FORCE_SINGULAR;
    }
    /* the full condition at the first position, later only when the pivots
       hint at a singular matrix (forces.c factor) */
    if (!s->fcond_known || rt_blocks_pivot_ratio(&fjac, s->fv, s->fanorm) < 1e-10) {
        s->force_rcond = rt_blocks_rcond(&fjac, s->fv, s->fpiv, s->fanorm, s->fw + NF);
        s->fcond_known = 1;
    }
    if (s->force_rcond < 1e-13)
        return CG_FORCE_SINGULAR;
    double w = fabs(qd);
    if (DRIVER_SLIDER)
        w /= LREF;
    cg_forces_ctx ctx = {s, F, qd, 1e-6 * (w > 0.0 ? w : 1.0)};
    rt_forces_vec v = {s->fb, s->fy, s->fy0, s->ffric, s->fg, s->fr, s->fag, s->fdg, s->fdr};
    rt_forces_out out = {s->fprev, 0, 0.0, 0.0, 0.0, 0.0};
    int rc = rt_forces_solve(&ops, &ctx, NF, FORCE_FRICTION, FORCE_BOTH, FORCE_GEARS, &v, &out);
    s->fprev = out.have_previous;
    s->friction_iterations = out.iterations;
    s->power_residual0 = out.residual0;
    s->power_residual = out.residual;
    s->friction_power = out.friction_power;
    s->drive_power = out.drive_power;
    return rc < 0 ? CG_FRICTION_STUCK : 0;
}
#endif

/* ---- the public functions' bodies -------------------------------------- */

/* P_solve: Newton at q, the rates for driver speed qd and acceleration
 * qdd, the output columns, the branch conditions and the forces. */
static int cg_step(cg_state *s, double q, double qd, double qdd)
{
    s->branch = -1;
    int status = cg_newton(s, q);
    if (status != CG_OK)
        return status;
    s->det_sign = rt_blocks_det_sign(&jac, s->lu, s->swap_parity);
    if (s->nsolved++ > 0) {
        s->q_prev = s->q_last;
        for (int i = 0; i < NX; i++)
            s->xqq_prev[i] = s->xqq[i];
    }
    cg_rates(s, q);
    s->q_last = q;
    for (int i = 0; i < NX; i++)
        s->xc[i] = s->x[i];
    for (int i = 0; i < NX; i++) {  /* the equations do not depend on time */
        s->xd[i] = s->xq[i] * qd;
        s->xdd[i] = s->xqq[i] * qd * qd + s->xq[i] * qdd;
    }
    rt_frame F[NLINKS];
    s->branch = kinematics(s, F, q, qd, qdd, s->first);
    if (s->branch >= 0)
        return CG_BRANCH;
    s->first = 0;
#if CG_FORCES
    s->force_status = cg_kinetostatics(s, F, q, qd, qdd);
    if (s->force_status != 0)
        return s->force_status;
    force_columns(s, F);
#endif
    return CG_OK;
}

/* P_predict: x + h x_q + h^2/2 x_qq + h^3/6 x_qqq from the last position
 * solved (x_qqq from the last two x_qq), mech solve's predictor. */
static void cg_prediction(cg_state *s, double q)
{
    if (s->nsolved == 0)
        return;
    double h = q - s->q_last, dq = s->q_last - s->q_prev;
    int prev = s->nsolved > 1 && dq != 0.0;
    for (int i = 0; i < NX; i++) {
        double xqqq = prev ? (s->xqq[i] - s->xqq_prev[i]) / dq : 0.0;
        s->x[i] = s->xc[i] + h * (s->xq[i] + h * (0.5 * s->xqq[i] + h * xqqq / 6.0));
    }
}

/* P_rcond: the exact conditions from the factors of the last solution. */
static double cg_exact_condition(cg_state *s)
{
    if (!s->rcond_exact)
        cg_condition(s);  /* the factors are still those of the solution */
    return s->rcond;
}
