/* tests/unit/test_rt_solver.c: src/runtime/rt_solver.h, the part of the generated
 * code that is the same for every mechanism, as C: this file is what `mech
 * codegen` would write for a four-bar, by hand (the equations, their
 * Jacobian and rate right-hand sides, the block table, the frames), then
 * the runtime. A sweep of cg_prediction and cg_step is checked against the
 * four-bar's closed form (circle intersection): the angles, their rates
 * against differences of the closed form, the coupler point, the
 * iterations the predictor leaves and the condition. */
#include <criterion/criterion.h>
#include <float.h>
#include <math.h>
#include <string.h>

#include "rt_forces.h"
#include "rt_newton.h"

static const double PI = 3.14159265358979323846;
static const double LA = 0.02, LB = 0.07, LC = 0.05, LD = 0.06;  /* crank, coupler, rocker, ground */

/* ---- what the generator writes (by hand) ------------------------------- */

enum { CG_OK, CG_NO_ASSEMBLY, CG_SINGULAR, CG_BRANCH };
#define CG_FORCES 0
#define NX 2
#define NB 1
#define TOL 1e-12
#define MIN_RCOND 1e-6
#define NLINKS 4

typedef struct cg_state {
    double x[NX], xd[NX], xdd[NX], xq[NX], xqq[NX], out[1];
    double residual, rcond, rcond_whole;
    int rcond_exact, iterations, det_sign, branch, first, nsolved;
    double q_last, q_prev, xc[NX], xqq_prev[NX];
    double xe[NX], f[NX], ft[NX], dx[NX], xt[NX], r[NX], cs[NX];
    double w[4 * NX + 3 * NX], colnorm[NX], anorm[NB];
    double keep[1], Jv[4], Ax[4], lu[4];
    int piv[NX], swap_parity;
} cg_state;

static const int col_start[3] = {0, 2, 4};
static const int ident[2] = {0, 1}, R[2] = {0, 2}, at[1] = {0}, where[4] = {0, 1, 2, 3};
static const int op[3] = {0, 0, 0};
static const rt_blocks jac = {NX, NB, 4, 4, 1, 0, ident, ident, R, at, where, op, NULL, NULL};
static const double unit[NX] = {1.0, 1.0};
static const rt_newton_par newton_par = {NX, NX, unit, TOL, TOL * 0.07, MIN_RCOND, 50, 0};

static void eval_driver(double q, double *k) { (void)q, (void)k; }

static void eval_position(const double *x, double q, double *f, double *Jv, double *k)
{
    (void)k;
    f[0] = LA * cos(q) + LB * cos(x[0]) - LD - LC * cos(x[1]);
    f[1] = LA * sin(q) + LB * sin(x[0]) - LC * sin(x[1]);
    Jv[0] = -LB * sin(x[0]), Jv[1] = LB * cos(x[0]);
    Jv[2] = LC * sin(x[1]), Jv[3] = -LC * cos(x[1]);
}

/* b = -df/dq for q' = 1 */
static void eval_velocity(const double *x, double q, double *k, double *b)
{
    (void)x, (void)k;
    b[0] = LA * sin(q);
    b[1] = -LA * cos(q);
}

/* c = -(d/dt J) x' - f_qq q'^2 for q' = 1, q'' = 0 */
static void eval_accel(const double *x, double q, const double *xd, const double *k, double *c)
{
    (void)k;
    c[0] = LA * cos(q) + LB * cos(x[0]) * xd[0] * xd[0] - LC * cos(x[1]) * xd[1] * xd[1];
    c[1] = LA * sin(q) + LB * sin(x[0]) * xd[0] * xd[0] - LC * sin(x[1]) * xd[1] * xd[1];
}

/* The frames: crank (1) at q, coupler (2) placed at the crank's end,
 * rocker (3) at D; out[0] = B.x, the coupler's end. */
static int kinematics(cg_state *s, rt_frame *F, double q, double qd, double qdd, int first)
{
    (void)first;
    double p[2], v[2], a[2];
    rt_frame_rest(&F[0]);
    F[1].th = q, F[1].om = qd, F[1].al = qdd, F[1].c = cos(q), F[1].s = sin(q);
    F[2].th = s->x[0], F[2].om = s->xd[0], F[2].al = s->xdd[0];
    F[2].c = cos(F[2].th), F[2].s = sin(F[2].th);
    F[3].th = s->x[1], F[3].om = s->xd[1], F[3].al = s->xdd[1];
    F[3].c = cos(F[3].th), F[3].s = sin(F[3].th);
    rt_place_across(&F[1], &F[0], 0.0, 0.0, 0.0, 0.0, NULL, 1.0);
    rt_place_across(&F[3], &F[0], LD, 0.0, 0.0, 0.0, NULL, 1.0);
    rt_place_across(&F[2], &F[1], LA, 0.0, 0.0, 0.0, NULL, 1.0);
    rt_on_link(&F[2], LB, 0.0, p, v, a);
    s->out[0] = p[0];
    return -1;
}

#include "rt_solver.h"

/* ---- the closed form --------------------------------------------------- */

static void closed(double q, double *th3, double *th4)
{
    double ax = LA * cos(q), ay = LA * sin(q), dx = LD - ax, dy = -ay, dist = hypot(dx, dy);
    double along = (LB * LB - LC * LC + dist * dist) / (2.0 * dist);
    double h = sqrt(LB * LB - along * along);
    double bx = ax + along * dx / dist - h * dy / dist, by = ay + along * dy / dist + h * dx / dist;
    *th3 = atan2(by - ay, bx - ax);
    *th4 = atan2(by, bx - LD);
}

Test(rt_solver, fourbar_sweep_against_closed_form)
{
    static cg_state s;
    memset(&s, 0, sizeof s);
    closed(0.0, &s.x[0], &s.x[1]);
    s.x[0] += 0.02, s.x[1] -= 0.02;  /* a guess near the assembly */
    s.first = 1;
    const double qd = 3.0, qdd = 0.5, h = 1e-6;
    int its = 0;
    for (int k = 0; k <= 72; k++) {
        double q = 2.0 * PI * k / 72, th3, th4, m3, m4, p3, p4;
        cg_prediction(&s, q);
        cr_assert_eq(cg_step(&s, q, qd, qdd), CG_OK, "q %g", q);
        closed(q, &th3, &th4);
        closed(q - h, &m3, &m4);
        closed(q + h, &p3, &p4);
        cr_assert(fabs(remainder(s.x[0] - th3, 2 * PI)) <= 1e-13 &&
                      fabs(remainder(s.x[1] - th4, 2 * PI)) <= 1e-13, "q %g: angles", q);
        double dth3 = remainder(p3 - m3, 2 * PI) / (2 * h), dth4 = remainder(p4 - m4, 2 * PI) / (2 * h);
        cr_assert(fabs(s.xq[0] - dth3) <= 1e-7 && fabs(s.xq[1] - dth4) <= 1e-7, "q %g: xq", q);
        cr_assert(fabs(s.xd[0] - s.xq[0] * qd) <= 1e-15, "xd = xq qd");
        cr_assert(fabs(s.out[0] - (LA * cos(q) + LB * cos(th3))) <= 1e-15, "q %g: B.x", q);
        cr_assert(s.rcond > 0.0 && cg_exact_condition(&s) >= s.rcond, "the exact rcond");
        if (k > 0)
            its += s.iterations;
    }
    /* the predictor leaves about one correction per 5 deg step */
    cr_assert(its <= 2 * 72, "%d iterations for 72 steps", its);
}
