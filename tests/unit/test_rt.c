/* tests/unit/test_rt.c: the runtime libmech and the generated code share
 * (src/rt_*.h, docs/codegen.md), as C, against independent truths: a block
 * LU reconstructed exactly and its zero pivots, the condition bounds above
 * the exact inverse norms, Newton on a four-bar against its closed form
 * (circle intersection), the rates of a point and of a slider against
 * finite differences, the reactions of a crank standing in gravity and of
 * a pinned bar against statics by hand, Anderson's weights against the
 * one-dimensional least squares, and the load program's operations. */
#include <criterion/criterion.h>
#include <math.h>
#include <string.h>

#include "rt_forces.h"
#include "rt_newton.h"

static const double PI = 3.14159265358979323846;

/* ---- rt_blocklu.h ------------------------------------------------------ */

/* P A = L U of a 3 x 3 (the general kernel) rebuilt from the factors, to
 * rounding (entries of A below 10: 1e-14), and A x = b solved for a known
 * x. */
Test(rt, block_lu_rebuilds_the_matrix)
{
    const double A[9] = {1, 4, 7, 2, 5, 8, 3, 6, 10};  /* column major: rows (1 2 3) (4 5 6) (7 8 10) */
    double a[9];
    memcpy(a, A, sizeof a);
    int piv[3], swaps = 0;
    cr_assert_eq(rt_block_factor(a, 3, piv, &swaps), -1);
    cr_assert_eq(piv[0], 2, "the largest of the first column (7) is the first pivot");
    double pa[9];  /* P A: the swaps applied in order */
    memcpy(pa, A, sizeof pa);
    for (int j = 0; j < 3; j++)
        for (int c = 0; c < 3 && piv[j] != j; c++) {
            double t = pa[j + 3 * c];
            pa[j + 3 * c] = pa[piv[j] + 3 * c];
            pa[piv[j] + 3 * c] = t;
        }
    for (int i = 0; i < 3; i++)
        for (int c = 0; c < 3; c++) {
            double s = 0.0;
            for (int k = 0; k <= (i < c ? i : c); k++)
                s += (k == i ? 1.0 : a[i + 3 * k]) * a[k + 3 * c];  /* (L U)_ic */
            cr_assert(fabs(s - pa[i + 3 * c]) <= 1e-15 * 10, "(L U)[%d][%d] = %.17g, P A %g", i,
                      c, s, pa[i + 3 * c]);
        }
    /* A x = b for x = (1, 2, 3): b = (14, 32, 53) */
    double y[3] = {14, 32, 53};
    rt_block_solve(a, 3, piv, y);
    for (int i = 0; i < 3; i++)
        cr_assert(fabs(y[i] - (i + 1)) <= 1e-14, "x[%d] = %.17g", i, y[i]);
}

Test(rt, block_lu_zero_pivots)
{
    double a2[4] = {1, 2, 2, 4};  /* [1 2; 2 4] */
    int piv[3], swaps = 0;
    cr_assert_eq(rt_block_factor(a2, 2, piv, &swaps), 1, "a 2 x 2's second pivot is 0");
    double a3[9] = {1, 2, 1, 2, 4, 1, 3, 6, 1};  /* rows (1 2 3) (2 4 6) (1 1 1) */
    cr_assert_eq(rt_block_factor(a3, 3, piv, &swaps), 2, "rank 2: the third pivot is 0");
}

/* |B^-1|_1 of [4 1; 2 3] is max(3 + 2, 1 + 4) / det = 5 / 10; of a 3 x 3
 * from its inverse written out. The bound of the comparison matrices is at
 * least the exact value (to the proof's rounding). */
Test(rt, inverse_norms_and_bounds)
{
    double b[4] = {4, 2, 1, 3};
    int piv[3], swaps = 0;
    rt_block_factor(b, 2, piv, &swaps);
    cr_assert(fabs(rt_block_inverse_norm_small(b, 2) - 0.5) <= 1e-15);
    /* [2 -1 0; -1 2 -1; 0 -1 2]^-1 = [3 2 1; 2 4 2; 1 2 3] / 4: |.|_1 = 2 */
    double t[9] = {2, -1, 0, -1, 2, -1, 0, -1, 2}, w[9];
    rt_block_factor(t, 3, piv, &swaps);
    double exact = rt_block_inverse_norm_exact(t, 3, piv, w);
    cr_assert(fabs(exact - 2.0) <= 1e-14, "exact %.17g", exact);
    static const int P[3] = {0, 1, 2}, R[2] = {0, 3}, at[1] = {0}, op[4] = {0, 0, 0, 0};
    rt_blocks one = {3, 1, 9, 9, 1, 0, P, P, R, at, NULL, op, NULL, NULL};
    double bound = rt_blocks_inverse_bound(&one, t, piv, 0, w);
    /* at least the exact value up to the rounding the proof allows (1 + 1e-6,
       rt_blocks_rcond_bounds), and not far above it here */
    cr_assert((1.0 + 1e-6) * bound >= exact && bound <= 4 * exact, "bound %.17g, exact %.17g",
              bound, exact);
    double anorm[1] = {4.0}, r, rw;
    cr_assert_eq(rt_blocks_rcond_bounds(&one, t, piv, anorm, w, &r, &rw), 1);
    cr_assert(r <= 1.0 / (4.0 * exact) && r > 0.0, "rcond bound %g", r);
}

/* ---- rt_newton.h: a four-bar ------------------------------------------- */

enum { FB_A, FB_B, FB_C, FB_D };
static const double FB[4] = {0.02, 0.07, 0.05, 0.06};  /* crank, coupler, rocker, ground */

/* th3, th4 from the circle through B about A (radius b) and about D (c) */
static void fourbar_closed(double q, double *th3, double *th4)
{
    double ax = FB[FB_A] * cos(q), ay = FB[FB_A] * sin(q), dx = FB[FB_D] - ax, dy = -ay;
    double dist = hypot(dx, dy), along = (FB[FB_B] * FB[FB_B] - FB[FB_C] * FB[FB_C] + dist * dist) /
                                         (2.0 * dist);
    double h = sqrt(FB[FB_B] * FB[FB_B] - along * along);
    double bx = ax + along * dx / dist - h * dy / dist, by = ay + along * dy / dist + h * dx / dist;
    *th3 = atan2(by - ay, bx - ax);
    *th4 = atan2(by, bx - FB[FB_D]);
}

typedef struct fb_ctx {
    double q, Jv[4], Ax[4], cs[2], v[4], colnorm[2], anorm[1], w[16];
    int piv[2], swaps;
    double rcond, rcond_whole;
} fb_ctx;

static const int FB_P[2] = {0, 1}, FB_R[2] = {0, 2}, FB_AT[1] = {0}, FB_WHERE[4] = {0, 1, 2, 3},
                 FB_OP[3] = {0, 0, 0};
static const rt_blocks fb_blocks = {2, 1, 4, 4, 1, 0, FB_P, FB_P, FB_R, FB_AT,
                                    FB_WHERE, FB_OP, NULL, NULL};

static double fb_evaluate(void *c, const double *x, double *f)
{
    fb_ctx *s = c;
    f[0] = FB[FB_A] * cos(s->q) + FB[FB_B] * cos(x[0]) - FB[FB_D] - FB[FB_C] * cos(x[1]);
    f[1] = FB[FB_A] * sin(s->q) + FB[FB_B] * sin(x[0]) - FB[FB_C] * sin(x[1]);
    s->Jv[0] = -FB[FB_B] * sin(x[0]), s->Jv[1] = FB[FB_B] * cos(x[0]);
    s->Jv[2] = FB[FB_C] * sin(x[1]), s->Jv[3] = -FB[FB_C] * cos(x[1]);
    return rt_norm_inf(f, 2);
}

static int fb_factor(void *c)
{
    fb_ctx *s = c;
    for (int k = 0; k < 2; k++) {
        s->cs[k] = rt_column_scale(s->Jv + 2 * k, 2);
        s->Ax[2 * k] = s->Jv[2 * k] * s->cs[k], s->Ax[2 * k + 1] = s->Jv[2 * k + 1] * s->cs[k];
    }
    if (rt_blocks_place(&fb_blocks, s->Ax, s->v) < 0)
        return -1;
    rt_blocks_column_norms(&fb_blocks, s->v, s->colnorm, s->anorm);
    return rt_blocks_factor_placed(&fb_blocks, s->v, s->piv, &s->swaps) < 0 ? 0 : -1;
}

static double fb_rcond_whole(void *c)
{
    fb_ctx *s = c;
    if (!(s->rcond > 0.0))
        s->rcond = s->rcond_whole = rt_blocks_rcond(&fb_blocks, s->v, s->piv, s->anorm, s->w + 8);
    return s->rcond_whole;
}

static void fb_solve(void *c, const double *b, double *dx)
{
    fb_ctx *s = c;
    dx[0] = b[0], dx[1] = b[1];
    rt_blocks_solve(&fb_blocks, s->v, s->piv, s->w, dx);
    dx[0] *= s->cs[0], dx[1] *= s->cs[1];
}

static double fb_rcond_at_solution(void *c)
{
    fb_ctx *s = c;
    return s->rcond = s->rcond_whole = rt_blocks_rcond(&fb_blocks, s->v, s->piv, s->anorm, s->w + 8);
}

/* From a guess 0.05 rad off, at 36 crank angles: the closed form's angles
 * to 1e-13 rad (the tolerance is 1e-12 of the largest length, the
 * correction below its hundredth). */
Test(rt, newton_fourbar_closed_form)
{
    static const rt_newton_ops ops = {fb_evaluate, fb_factor, fb_rcond_whole, fb_solve,
                                      fb_rcond_at_solution};
    static const double unit[2] = {1.0, 1.0};
    rt_newton_par par = {2, 2, unit, 1e-12, 1e-12 * 0.07, 1e-6, 50, 0};
    for (int k = 0; k < 36; k++) {
        double q = 2.0 * PI * k / 36, th3, th4, x[2], f[2], ft[2], dx[2], xt[2], res = -1.0;
        fourbar_closed(q, &th3, &th4);
        x[0] = th3 + 0.05, x[1] = th4 - 0.05;
        fb_ctx s = {.q = q};
        rt_newton_vec v = {x, f, ft, dx, xt};
        int it = -1, st = rt_newton(&ops, &s, &par, &v, &res, &it);
        cr_assert_eq(st, RT_NEWTON_CONVERGED, "q %g: status %d", q, st);
        cr_assert(fabs(remainder(x[0] - th3, 2 * PI)) <= 1e-13 &&
                      fabs(remainder(x[1] - th4, 2 * PI)) <= 1e-13,
                  "q %g: (%.17g, %.17g) against (%.17g, %.17g)", q, x[0], x[1], th3, th4);
        cr_assert(it >= 2 && it <= 8 && res <= par.ftol, "q %g: %d iterations, |f| %g", q, it, res);
        cr_assert_eq(rt_blocks_det_sign(&fb_blocks, s.v, s.swaps),
                     (FB[FB_B] * FB[FB_C] * sin(th3 - th4) > 0) ? 1 : -1,
                     "det J = b c sin(th3 - th4)");
    }
}

/* ---- rt_frame.h -------------------------------------------------------- */

/* A link turning as th = 0.3 + 2 t + 1.5 t^2 about an origin moving as
 * o = (t^2, 0.5 t^3): a point's velocity and acceleration from rt_on_link
 * against central differences of its position; and rt_place_at puts the
 * point back where it was. */
static void frame_at(double t, rt_frame *F)
{
    rt_frame_rest(F);
    F->th = 0.3 + 2 * t + 1.5 * t * t, F->om = 2 + 3 * t, F->al = 3;
    F->c = cos(F->th), F->s = sin(F->th);
    F->o[0] = t * t, F->o[1] = 0.5 * t * t * t;
    F->vo[0] = 2 * t, F->vo[1] = 1.5 * t * t;
    F->ao[0] = 2, F->ao[1] = 3 * t;
}

Test(rt, frame_rates_against_differences)
{
    const double t = 0.4, h = 1e-5, r0 = 0.12, r1 = -0.05;
    rt_frame F, Fm, Fp;
    frame_at(t, &F), frame_at(t - h, &Fm), frame_at(t + h, &Fp);
    double p[2], v[2], a[2], pm[2], vm[2], pp[2], vp[2];
    rt_on_link(&F, r0, r1, p, v, a);
    rt_on_link(&Fm, r0, r1, pm, vm, NULL);
    rt_on_link(&Fp, r0, r1, pp, vp, NULL);
    for (int k = 0; k < 2; k++) {
        cr_assert(fabs((pp[k] - pm[k]) / (2 * h) - v[k]) <= 1e-8, "v[%d]", k);
        cr_assert(fabs((vp[k] - vm[k]) / (2 * h) - a[k]) <= 1e-8, "a[%d]", k);
    }
    rt_frame G = F;
    G.o[0] = G.o[1] = G.vo[0] = G.vo[1] = G.ao[0] = G.ao[1] = 99.0;
    rt_place_at(&G, r0, r1, p, v, a);
    for (int k = 0; k < 2; k++)
        cr_assert(fabs(G.o[k] - F.o[k]) <= 1e-15 && fabs(G.vo[k] - F.vo[k]) <= 1e-14 &&
                      fabs(G.ao[k] - F.ao[k]) <= 1e-13, "placed origin %d", k);
}

/* A slider's offset s u on the moving guide of frame_at, s = 0.2 + t^2:
 * its rates against differences of s u(t). */
Test(rt, slider_offset_against_differences)
{
    const double t = 0.7, h = 1e-5, angle = 0.25;
    double d[3][2], dm[3][2], dp[3][2], u[2];
    rt_frame F, Fm, Fp;
    frame_at(t, &F), frame_at(t - h, &Fm), frame_at(t + h, &Fp);
    const rt_frame *G[3] = {&Fm, &F, &Fp};
    double (*D[3])[2] = {dm, d, dp};
    for (int i = 0; i < 3; i++) {
        double ti = t + (i - 1) * h;
        rt_guide_dir(G[i], angle, u);
        rt_slide_offset(G[i], u[0], u[1], 0.2 + ti * ti, 2 * ti, 2.0, D[i]);
    }
    for (int k = 0; k < 2; k++) {
        cr_assert(fabs((dp[0][k] - dm[0][k]) / (2 * h) - d[1][k]) <= 1e-8, "velocity %d", k);
        cr_assert(fabs((dp[1][k] - dm[1][k]) / (2 * h) - d[2][k]) <= 1e-7, "acceleration %d", k);
    }
}

/* ---- rt_forces.h ------------------------------------------------------- */

/* A crank (link 1, length L, mass m at L/2, pinned to the ground at the
 * origin) held still at angle q in gravity g by its driver's torque: the
 * pin carries (0, m g), the torque is m g (L/2) cos q. Columns: the pin's
 * Fx, Fy on the crank, the driver's couple. */
Test(rt, crank_standing_in_gravity)
{
    const double L = 0.3, m = 2.0, g = 9.81, q = 0.7;
    rt_frame F[2];
    rt_frame_rest(&F[0]), rt_frame_rest(&F[1]);
    F[1].th = q, F[1].c = cos(q), F[1].s = sin(q);
    const rt_body body[2] = {{0, 0, 0, {0, 0}}, {1, m, m * L * L / 12, {L / 2, 0}}};
    const rt_fcol col[3] = {{RT_COL_FORCE, {1, 0}, {1, {0, 0}}, RT_DIR_X, 0, 0.0, 0},
                            {RT_COL_FORCE, {1, 0}, {1, {0, 0}}, RT_DIR_Y, 0, 0.0, 0},
                            {RT_COL_MOMENT, {1, 0}, {0, {0, 0}}, 0, 0, 0.0, 0}};
    const double grav[2] = {0.0, -g};
    double cg[4], vg[4], ag[4], a[9] = {0}, rhs[3], e[6];
    int rows[6], piv[3], swaps = 0;
    for (int l = 0; l < 2; l++)
        rt_centre(&body[l], &F[l], cg + 2 * l, vg + 2 * l, ag + 2 * l);
    cr_assert(fabs(cg[2] - L / 2 * cos(q)) <= 1e-16 && fabs(cg[3] - L / 2 * sin(q)) <= 1e-16);
    for (int c = 0; c < 3; c++) {
        int n = rt_fcol_entries(&col[c], NULL, NULL, F, cg, e);
        cr_assert_eq(rt_fcol_rows(&col[c], rows), n);
        for (int k = 0; k < n; k++)
            a[rows[k] + 3 * c] = e[k];
    }
    rt_body_load(&body[1], &F[1], ag + 2, grav, rhs);
    cr_assert_eq(rt_block_factor(a, 3, piv, &swaps), -1);
    rt_block_solve(a, 3, piv, rhs);
    cr_assert(fabs(rhs[0]) <= 1e-14 && fabs(rhs[1] - m * g) <= 1e-13, "pin (%g, %g)", rhs[0],
              rhs[1]);
    cr_assert(fabs(rhs[2] - m * g * L / 2 * cos(q)) <= 1e-13, "torque %.17g", rhs[2]);
    /* the power balance at rest: every term zero, the residual 0 */
    rt_power pw;
    rt_power_start(&pw, 0.0, 0.0, 1.0, 1.0);
    rt_power_body(&pw, &body[1], &F[1], vg + 2, ag + 2, grav);
    cr_assert_eq(rt_power_end(&pw, 0.0, 0.0), 0.0);
}

/* A linear spring between the ground's (0, 0) and a bar's end (1, 0) at
 * rest length 0.5, stiffness 100: length 1, tension 50, on the bar -50 x
 * at its end; torsional: -T on the first link. */
Test(rt, spring_loads)
{
    rt_frame F[2];
    rt_frame_rest(&F[0]), rt_frame_rest(&F[1]);
    F[1].th = 0.0;
    const rt_spring lin = {0, {{0, {0, 0}}, {1, {1, 0}}}, 0.5, 100.0, 0.0, 0.0};
    double st[RT_SPRING_STATE], rhs[3] = {0, 0, 0}, g[4] = {0, 0, 0.5, 0};
    rt_spring_eval(&lin, F, st);
    cr_assert(st[0] == 1.0 && st[2] == 50.0 && st[3] == 1.0 && st[4] == 0.0);
    rt_spring_load(&lin, st, g, rhs);
    cr_assert(rhs[0] == 50.0 && rhs[1] == 0.0 && rhs[2] == 0.0, "on the bar: -(-50, 0) moved");
    const rt_spring tor = {1, {{1, {0, 0}}, {0, {0, 0}}}, 0.0, 2.0, 0.0, 0.0};
    F[1].th = 0.25;
    rt_spring_eval(&tor, F, st);
    cr_assert(st[0] == 0.25 && st[2] == 0.5);
}

/* One difference dr and residual r: gamma = (dr . r) / (dr . dr). */
Test(rt, anderson_one_difference)
{
    const double dr[3 * 2] = {0, 0, 0, 0, 1.0, 2.0}, r[2] = {3.0, 1.0};
    double gamma[3];
    cr_assert_eq(rt_anderson_weights(dr, 2, 1, 2, r, gamma), 1);
    cr_assert(fabs(gamma[0] - 5.0 / 5.0) <= 1e-15, "gamma %.17g", gamma[0]);
}

Test(rt, load_program_operations)
{
    cr_assert_eq(rt_sl_apply(RT_SL_POWI, 2.0, 0.0, -3), 0.125);
    cr_assert_eq(rt_sl_apply(RT_SL_SIGN, -0.0, 0.0, 0), 0.0);
    cr_assert_eq(rt_sl_apply(RT_SL_MIN, 1.0, -2.0, 0), -2.0);
    cr_assert(fabs(rt_sl_apply(RT_SL_SMOOTHSIGN, 3.0, 4.0, 0) - 0.6) <= 1e-16);
    cr_assert(fabs(rt_smooth_sign(1e-9, 1e-6)) < 1e-2 && rt_smooth_sign(1.0, 1e-6) > 0.999999);
}
