/* bench/bench_hand.c: the price of being general. Solvers written by hand
 * for one mechanism each, with the interpreter's outputs (positions,
 * velocities and accelerations of the same points, links and sliders):
 *
 *   fourbar.yaml   closed form (circle intersection, 2x2 Cramer for rates),
 *                  and Newton with a hand-written 2x2 Jacobian
 *   offset-slider-crank.yaml  Newton with a hand-written 2x2 Jacobian
 *   stirling.yaml  Newton with a hand-written 8x8 Jacobian (docs/stirling.md
 *                  section 7, in the file's mirrored frame), inline dense LU
 *   conveyor.yaml  Newton with a hand-written 4x4 Jacobian, inline dense LU
 *
 * The Newton solvers do what the interpreter does per step (quadratic
 * predictor from x_q and x_qq, Newton to |f| <= tol*lref and |dx| <= tol
 * keeping the x whose factors serve the rates, one solve each for x_q and
 * x_qq with those factors), with the same tolerance, but with the
 * equations compiled by the C compiler instead of the tape, and a dense
 * LU instead of KLU. Each runs on the file's driver steps, like
 * `mech_solve` at MECH_WANT_ALL without forces, at the default tolerance
 * 1e-12 and at 1e-15 ("full accuracy"); both are timed as the
 * median of repeated sweeps and their tables compared (they must agree to
 * ~1e-9, or the comparison is void). Prints a table; not a test.
 *
 * bench-hand --count NAME interp|hand STEPS [forces] runs one sweep of
 * STEPS intervals over the file's driver range, interpreter or hand-written
 * (the forces variant: interpreter with joint reactions, friction off), for
 * bench/bench_ratio.sh to count instructions per step under callgrind (the
 * difference of two step counts, inside mech_solve or hand_sweep). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "mech.h"

enum { REPS = 31, MAXN = 8, MAXCOLS = 64 };

/* ---- rotating vectors ---------------------------------------------------- */

/* p, v, a += r e(th) with th' = w, th'' = al. */
static inline void add_arm(double *p, double r, double th, double w, double al)
{
    double c = r * cos(th), s = r * sin(th);
    p[0] += c, p[1] += s;
    p[2] += -s * w, p[3] += c * w;
    p[4] += -s * al - c * w * w, p[5] += c * al - s * w * w;
}

/* ---- the four-bar, closed form ------------------------------------------- */

#define FB_A 0.020
#define FB_B 0.060
#define FB_C 0.050
#define FB_D 0.070
#define FB_PL 0.040
#define FB_PA (30.0 * M_PI / 180.0)

static const char *const FB_COLS[] = {
    "q",  "A.x", "A.y", "A.vx", "A.vy", "A.ax", "A.ay", "B.x", "B.y", "B.vx", "B.vy", "B.ax",
    "B.ay", "P.x", "P.y", "P.vx", "P.vy", "P.ax", "P.ay", "crank.angle", "crank.omega",
    "crank.alpha", "coupler.angle", "coupler.omega", "coupler.alpha", "rocker.angle",
    "rocker.omega", "rocker.alpha", NULL};

static void fourbar_row(double q, double w, double al, double *o)
{
    double c = cos(q), s = sin(q);
    double Ax = FB_A * c, Ay = FB_A * s;
    double dx = FB_D - Ax, dy = -Ay, L2 = dx * dx + dy * dy, L = sqrt(L2);
    double p = (FB_B * FB_B - FB_C * FB_C + L2) / (2 * L), h = sqrt(FB_B * FB_B - p * p);
    double ux = dx / L, uy = dy / L;
    double Bx = Ax + p * ux - h * uy, By = Ay + p * uy + h * ux;  /* B above A->C */
    double bx = Bx - Ax, by = By - Ay, cx = Bx - FB_D, cy = By;
    double th3 = atan2(by, bx), th4 = atan2(cy, cx);
    /* w3 k x b - w4 k x c = -vA, the same matrix for the accelerations */
    double vAx = -FB_A * w * s, vAy = FB_A * w * c;
    double aAx = -FB_A * (al * s + w * w * c), aAy = FB_A * (al * c - w * w * s);
    double det = by * cx - cy * bx; /* of [[-by, cy], [bx, -cx]] */
    double g1 = -vAx, g2 = -vAy;
    double w3 = (g1 * -cx - cy * g2) / det, w4 = (-by * g2 - bx * g1) / det;
    g1 = -aAx + w3 * w3 * bx - w4 * w4 * cx, g2 = -aAy + w3 * w3 * by - w4 * w4 * cy;
    double al3 = (g1 * -cx - cy * g2) / det, al4 = (-by * g2 - bx * g1) / det;
    double A[6] = {0}, B[6] = {FB_D, 0, 0, 0, 0, 0}, P[6] = {0};
    add_arm(A, FB_A, q, w, al);
    add_arm(B, FB_C, th4, w4, al4);
    memcpy(P, A, sizeof P);
    add_arm(P, FB_PL, th3 + FB_PA, w3, al3);
    double *r = o;
    *r++ = q;
    memcpy(r, A, sizeof A), r += 6;
    memcpy(r, B, sizeof B), r += 6;
    memcpy(r, P, sizeof P), r += 6;
    *r++ = q, *r++ = w, *r++ = al;
    *r++ = th3, *r++ = w3, *r++ = al3;
    *r++ = th4, *r++ = w4, *r++ = al4;
}

/* ---- Newton solvers with a hand-written Jacobian -------------------------- */

typedef struct hand_mech {
    int n;
    double lref;
    /* F(x, q), J (row-major n x n) and dF/dq */
    void (*eval)(const double *x, double q, double *F, double *J, double *fq);
    /* right-hand side of J x_qq = r (driver at unit speed, no acceleration) */
    void (*acc)(const double *x, const double *xq, double q, double *r);
    /* the output row from positions, velocities and accelerations */
    void (*out)(const double *x, const double *xd, const double *xdd, double q, double qd,
                double qdd, double *row);
    const char *const *cols;
    double guess[MAXN];
} hand_mech;

/* In-place LU with partial pivoting of the row-major n x n matrix. */
static int lu(int n, double *A, int *piv)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabs(A[i * n + k]) > fabs(A[p * n + k]))
                p = i;
        piv[k] = p;
        if (A[p * n + k] == 0)
            return -1;
        if (p != k)
            for (int j = 0; j < n; j++) {
                double t = A[k * n + j];
                A[k * n + j] = A[p * n + j], A[p * n + j] = t;
            }
        double inv = 1 / A[k * n + k];
        for (int i = k + 1; i < n; i++) {
            double l = A[i * n + k] *= inv;
            for (int j = k + 1; j < n; j++)
                A[i * n + j] -= l * A[k * n + j];
        }
    }
    return 0;
}

static void lu_solve(int n, const double *A, const int *piv, double *b)
{
    for (int k = 0; k < n; k++) { /* whole rows were swapped: permute first */
        double t = b[k];
        b[k] = b[piv[k]], b[piv[k]] = t;
    }
    for (int k = 0; k < n; k++)
        for (int i = k + 1; i < n; i++)
            b[i] -= A[i * n + k] * b[k];
    for (int k = n - 1; k >= 0; k--) {
        for (int j = k + 1; j < n; j++)
            b[k] -= A[k * n + j] * b[j];
        b[k] /= A[k * n + k];
    }
}

/* One sweep over qs[nq]; rows into out (ncols each). Returns total Newton
 * iterations, or -1 when a step does not converge. */
static long hand_sweep(const hand_mech *h, const double *qs, int nq, double qd, double qdd,
                       double tol, double *out, int ncols)
{
    int n = h->n, piv[MAXN];
    double x[MAXN], xq[MAXN], xqq[MAXN], F[MAXN], J[MAXN * MAXN], fq[MAXN], xd[MAXN],
        xdd[MAXN];
    long iters = 0;
    memcpy(x, h->guess, sizeof x);
    for (int r = 0; r < nq; r++) {
        double q = qs[r];
        if (r > 0) {
            double dq = q - qs[r - 1];
            for (int i = 0; i < n; i++)
                x[i] += dq * xq[i] + 0.5 * dq * dq * xqq[i];
        }
        int it = 0;
        double prev = INFINITY;
        for (;; it++) {
            if (it == 50)
                return -1;
            h->eval(x, q, F, J, fq);
            if (lu(n, J, piv))
                return -1;
            double fn = 0, dmax = 0;
            for (int i = 0; i < n; i++)
                fn = fmax(fn, fabs(F[i]));
            lu_solve(n, J, piv, F);
            for (int i = 0; i < n; i++)
                dmax = fmax(dmax, fabs(F[i]));
            /* converged as in src/solve/solve.c: x is kept (not x - dx), so that the
               factors used for the rates belong to the position returned */
            if (fn <= tol * h->lref && (dmax <= tol || dmax >= 0.9 * prev))
                break; /* (or no longer shrinking: the rounding floor) */
            prev = dmax;
            double lam = dmax > 0.5 ? 0.5 / dmax : 1; /* damped far from the solution */
            for (int i = 0; i < n; i++)
                x[i] -= lam * F[i];
        }
        iters += it + 1;
        /* rates with the factors of the last iterate (dx <= tol away) */
        for (int i = 0; i < n; i++)
            xq[i] = -fq[i];
        lu_solve(n, J, piv, xq);
        h->acc(x, xq, q, xqq);
        lu_solve(n, J, piv, xqq);
        for (int i = 0; i < n; i++)
            xd[i] = xq[i] * qd, xdd[i] = xqq[i] * qd * qd + xq[i] * qdd;
        h->out(x, xd, xdd, q, qd, qdd, out + (size_t)r * (size_t)ncols);
    }
    return iters;
}

/* ---- Stirling engine (mechanisms/stirling.yaml; x = -x_paper) ------------- */

#define CM 0.01
static const double S_a1 = 2.4 * CM, S_a21 = 5.0 * CM, S_a22 = 1.0 * CM, S_b = 0.4 * CM,
                    S_a4 = 5.1 * CM, S_a51 = 6.0 * CM, S_a52 = 5.0 * CM, S_a6 = 2.4 * CM,
                    S_a8 = 4.8 * CM, S_L1 = 9.4 * CM, S_L2 = 6.8 * CM, S_L3 = 1.9 * CM,
                    S_L4 = 7.0 * CM, S_L5 = 7.0 * CM, S_L6 = 6.0 * CM, S_al = 0.4907,
                    S_be = 0.6338, S_ga = 1.6258, S_de = 0.1411;

/* x = [Theta2, r3, Theta4, Theta5, Theta6, r7, Theta8, r9] */
static void stirling_eval(const double *x, double q, double *F, double *J, double *fq)
{
    double cq = cos(q), sq = sin(q);
    double c2 = cos(x[0] + S_de), s2 = sin(x[0] + S_de);
    double c2b = cos(x[0] + S_de + S_be), s2b = sin(x[0] + S_de + S_be);
    double c4 = cos(x[2]), s4 = sin(x[2]);
    double c5g = cos(x[3] + S_ga), s5g = sin(x[3] + S_ga);
    double c5 = cos(x[3]), s5 = sin(x[3]);
    double c6 = cos(x[4]), s6 = sin(x[4]), c8 = cos(x[6]), s8 = sin(x[6]);
    double ca = cos(S_al), sa = sin(S_al);
    F[0] = S_b + S_a21 * c2 + S_a1 * cq;
    F[1] = S_a21 * s2 + S_a1 * sq - x[1];
    F[2] = S_a1 * cq + S_a22 * c2b - S_a4 * c4 + S_a51 * c5g - S_L3 + S_L1;
    F[3] = S_a1 * sq + S_a22 * s2b - S_a4 * s4 + S_a51 * s5g - S_L6;
    F[4] = x[5] * ca + S_a6 * c6 + S_a51 * c5g - S_L3;
    F[5] = x[5] * sa + S_a6 * s6 + S_a51 * s5g - S_L2;
    F[6] = S_a52 * c5 + S_a8 * c8 - S_L5;
    F[7] = S_a52 * s5 + S_a8 * s8 + x[7] - S_L4;
    memset(J, 0, 64 * sizeof *J);
#define SJ(i, j) J[(i) * 8 + (j)]
    SJ(0, 0) = -S_a21 * s2;
    SJ(1, 0) = S_a21 * c2, SJ(1, 1) = -1;
    SJ(2, 0) = -S_a22 * s2b, SJ(2, 2) = S_a4 * s4, SJ(2, 3) = -S_a51 * s5g;
    SJ(3, 0) = S_a22 * c2b, SJ(3, 2) = -S_a4 * c4, SJ(3, 3) = S_a51 * c5g;
    SJ(4, 3) = -S_a51 * s5g, SJ(4, 4) = -S_a6 * s6, SJ(4, 5) = ca;
    SJ(5, 3) = S_a51 * c5g, SJ(5, 4) = S_a6 * c6, SJ(5, 5) = sa;
    SJ(6, 3) = -S_a52 * s5, SJ(6, 6) = -S_a8 * s8;
    SJ(7, 3) = S_a52 * c5, SJ(7, 6) = S_a8 * c8, SJ(7, 7) = 1;
#undef SJ
    fq[0] = -S_a1 * sq, fq[1] = S_a1 * cq, fq[2] = -S_a1 * sq, fq[3] = S_a1 * cq;
    fq[4] = fq[5] = fq[6] = fq[7] = 0;
}

static void stirling_acc(const double *x, const double *xq, double q, double *r)
{
    double w2 = xq[0] * xq[0], w4 = xq[2] * xq[2], w5 = xq[3] * xq[3], w6 = xq[4] * xq[4],
           w8 = xq[6] * xq[6];
    double cq = cos(q), sq = sin(q);
    double c2 = cos(x[0] + S_de), s2 = sin(x[0] + S_de);
    double c2b = cos(x[0] + S_de + S_be), s2b = sin(x[0] + S_de + S_be);
    double c5g = cos(x[3] + S_ga), s5g = sin(x[3] + S_ga);
    r[0] = S_a21 * c2 * w2 + S_a1 * cq;
    r[1] = S_a21 * s2 * w2 + S_a1 * sq;
    r[2] = S_a22 * c2b * w2 - S_a4 * cos(x[2]) * w4 + S_a51 * c5g * w5 + S_a1 * cq;
    r[3] = S_a22 * s2b * w2 - S_a4 * sin(x[2]) * w4 + S_a51 * s5g * w5 + S_a1 * sq;
    r[4] = S_a6 * cos(x[4]) * w6 + S_a51 * c5g * w5;
    r[5] = S_a6 * sin(x[4]) * w6 + S_a51 * s5g * w5;
    r[6] = S_a52 * cos(x[3]) * w5 + S_a8 * cos(x[6]) * w8;
    r[7] = S_a52 * sin(x[3]) * w5 + S_a8 * sin(x[6]) * w8;
}

static const char *const ST_COLS[] = {
    "q", "D.x", "D.y", "D.vx", "D.vy", "D.ax", "D.ay", "L.x", "L.y", "L.vx", "L.vy", "L.ax",
    "L.ay", "J.x", "J.y", "J.vx", "J.vy", "J.ax", "J.ay", "crank.angle", "crank.omega",
    "crank.alpha", "link2.angle", "link2.omega", "link2.alpha", "link4.angle", "link4.omega",
    "link4.alpha", "link5.angle", "link5.omega", "link5.alpha", "link6.angle", "link6.omega",
    "link6.alpha", "link8.angle", "link8.omega", "link8.alpha", "r3.s", "r3.v", "r3.a", "r7.s",
    "r7.v", "r7.a", "r9.s", "r9.v", "r9.a", NULL};

static void stirling_out(const double *x, const double *xd, const double *xdd, double q,
                         double qd, double qdd, double *o)
{
    double ca = cos(S_al), sa = sin(S_al);
    *o++ = q;
    *o++ = -S_b, *o++ = x[1], *o++ = 0, *o++ = xd[1], *o++ = 0, *o++ = xdd[1];
    *o++ = S_L3 - S_L1 + S_L5, *o++ = S_L6 + S_L4 - x[7], *o++ = 0, *o++ = -xd[7], *o++ = 0,
    *o++ = -xdd[7];
    *o++ = -S_L1 + x[5] * ca, *o++ = S_L6 - S_L2 + x[5] * sa, *o++ = xd[5] * ca,
    *o++ = xd[5] * sa, *o++ = xdd[5] * ca, *o++ = xdd[5] * sa;
    *o++ = q, *o++ = qd, *o++ = qdd;
    static const int links[] = {0, 2, 3, 4, 6}, sliders[] = {1, 5, 7};
    for (int k = 0; k < 5; k++)
        *o++ = x[links[k]], *o++ = xd[links[k]], *o++ = xdd[links[k]];
    for (int k = 0; k < 3; k++)
        *o++ = x[sliders[k]], *o++ = xd[sliders[k]], *o++ = xdd[sliders[k]];
}

/* ---- four-bar by Newton (mechanisms/fourbar.yaml) --------------------------- */

/* x = [theta3 (coupler), theta4 (rocker)]: O A + A B = O C + C B */
static void fourbar_eval(const double *x, double q, double *F, double *J, double *fq)
{
    double cq = cos(q), sq = sin(q), c3 = cos(x[0]), s3 = sin(x[0]), c4 = cos(x[1]),
           s4 = sin(x[1]);
    F[0] = FB_A * cq + FB_B * c3 - FB_D - FB_C * c4;
    F[1] = FB_A * sq + FB_B * s3 - FB_C * s4;
    J[0] = -FB_B * s3, J[1] = FB_C * s4;
    J[2] = FB_B * c3, J[3] = -FB_C * c4;
    fq[0] = -FB_A * sq, fq[1] = FB_A * cq;
}

static void fourbar_acc(const double *x, const double *xq, double q, double *r)
{
    double w3 = xq[0] * xq[0], w4 = xq[1] * xq[1];
    r[0] = FB_A * cos(q) + FB_B * cos(x[0]) * w3 - FB_C * cos(x[1]) * w4;
    r[1] = FB_A * sin(q) + FB_B * sin(x[0]) * w3 - FB_C * sin(x[1]) * w4;
}

static void fourbar_out(const double *x, const double *xd, const double *xdd, double q,
                        double qd, double qdd, double *o)
{
    double A[6] = {0}, B[6], P[6];
    add_arm(A, FB_A, q, qd, qdd);
    memcpy(B, A, sizeof B), memcpy(P, A, sizeof P);
    add_arm(B, FB_B, x[0], xd[0], xdd[0]);
    add_arm(P, FB_PL, x[0] + FB_PA, xd[0], xdd[0]);
    *o++ = q;
    memcpy(o, A, sizeof A), o += 6;
    memcpy(o, B, sizeof B), o += 6;
    memcpy(o, P, sizeof P), o += 6;
    *o++ = q, *o++ = qd, *o++ = qdd;
    for (int k = 0; k < 2; k++)
        *o++ = x[k], *o++ = xd[k], *o++ = xdd[k];
}

/* ---- offset slider-crank (mechanisms/offset-slider-crank.yaml) ------------- */

#define SC_R 0.040
#define SC_L 0.120
#define SC_E 0.030

static const char *const SC_COLS[] = {
    "q", "A.x", "A.y", "A.vx", "A.vy", "A.ax", "A.ay", "B.x", "B.y", "B.vx", "B.vy", "B.ax",
    "B.ay", "rod.angle", "rod.omega", "rod.alpha", "x_B.s", "x_B.v", "x_B.a", NULL};

/* x = [theta (rod), s (slide of B from G = (0, e))]: O A + A B = O G + s e_x */
static void slider_eval(const double *x, double q, double *F, double *J, double *fq)
{
    double cq = cos(q), sq = sin(q), c = cos(x[0]), s = sin(x[0]);
    F[0] = SC_R * cq + SC_L * c - x[1];
    F[1] = SC_R * sq + SC_L * s - SC_E;
    J[0] = -SC_L * s, J[1] = -1;
    J[2] = SC_L * c, J[3] = 0;
    fq[0] = -SC_R * sq, fq[1] = SC_R * cq;
}

static void slider_acc(const double *x, const double *xq, double q, double *r)
{
    double w = xq[0] * xq[0];
    r[0] = SC_R * cos(q) + SC_L * cos(x[0]) * w;
    r[1] = SC_R * sin(q) + SC_L * sin(x[0]) * w;
}

static void slider_out(const double *x, const double *xd, const double *xdd, double q,
                       double qd, double qdd, double *o)
{
    double A[6] = {0}, B[6] = {0, SC_E, 0, 0, 0, 0};
    add_arm(A, SC_R, q, qd, qdd);
    B[0] = x[1], B[2] = xd[1], B[4] = xdd[1];
    *o++ = q;
    memcpy(o, A, sizeof A), o += 6;
    memcpy(o, B, sizeof B), o += 6;
    *o++ = x[0], *o++ = xd[0], *o++ = xdd[0];
    *o++ = x[1], *o++ = xd[1], *o++ = xdd[1];
}

/* ---- six-bar conveyor (mechanisms/conveyor.yaml) --------------------------- */

#define MM 0.001
static const double C_l1 = 60 * MM, C_l2 = 430 * MM, C_lk = 75 * MM, C_l3a = 560 * MM,
                    C_l3b = 1140 * MM, C_l4 = 440 * MM, C_l5 = 440 * MM, C_a = 50 * MM,
                    C_xF = -1324.6 * MM, C_xG = 373.8 * MM;
static double C_rE, C_aE, C_rD, C_aD; /* tray points E, D in polar form (set in main) */

/* x = [phi2 (coupler), theta3 (tray), phi4 (rocker4), phi5 (rocker5)] */
static void conveyor_eval(const double *x, double q, double *F, double *J, double *fq)
{
    double cq = cos(q), sq = sin(q), c2 = cos(x[0]), s2 = sin(x[0]);
    double cE = cos(x[1] + C_aE), sE = sin(x[1] + C_aE), cD = cos(x[1] + C_aD),
           sD = sin(x[1] + C_aD);
    double c4 = cos(x[2]), s4 = sin(x[2]), c5 = cos(x[3]), s5 = sin(x[3]);
    double ux = C_l1 * cq + C_l2 * c2, uy = C_l1 * sq + C_l2 * s2;
    F[0] = ux + C_rE * cE - C_l4 * c4 - C_xF;
    F[1] = uy + C_rE * sE - C_l4 * s4 + C_a;
    F[2] = ux + C_rD * cD - C_l5 * c5 - C_xG;
    F[3] = uy + C_rD * sD - C_l5 * s5 + C_a;
    J[0] = -C_l2 * s2, J[1] = -C_rE * sE, J[2] = C_l4 * s4, J[3] = 0;
    J[4] = C_l2 * c2, J[5] = C_rE * cE, J[6] = -C_l4 * c4, J[7] = 0;
    J[8] = -C_l2 * s2, J[9] = -C_rD * sD, J[10] = 0, J[11] = C_l5 * s5;
    J[12] = C_l2 * c2, J[13] = C_rD * cD, J[14] = 0, J[15] = -C_l5 * c5;
    fq[0] = fq[2] = -C_l1 * sq, fq[1] = fq[3] = C_l1 * cq;
}

static void conveyor_acc(const double *x, const double *xq, double q, double *r)
{
    double w2 = xq[0] * xq[0], w3 = xq[1] * xq[1], w4 = xq[2] * xq[2], w5 = xq[3] * xq[3];
    double ux = C_l1 * cos(q) + C_l2 * cos(x[0]) * w2, uy = C_l1 * sin(q) + C_l2 * sin(x[0]) * w2;
    r[0] = ux + C_rE * cos(x[1] + C_aE) * w3 - C_l4 * cos(x[2]) * w4;
    r[1] = uy + C_rE * sin(x[1] + C_aE) * w3 - C_l4 * sin(x[2]) * w4;
    r[2] = ux + C_rD * cos(x[1] + C_aD) * w3 - C_l5 * cos(x[3]) * w5;
    r[3] = uy + C_rD * sin(x[1] + C_aD) * w3 - C_l5 * sin(x[3]) * w5;
}

static const char *const CV_COLS[] = {
    "q", "A.x", "A.y", "A.vx", "A.vy", "A.ax", "A.ay", "B.x", "B.y", "B.vx", "B.vy", "B.ax",
    "B.ay", "C.x", "C.y", "C.vx", "C.vy", "C.ax", "C.ay", "D.x", "D.y", "D.vx", "D.vy", "D.ax",
    "D.ay", "E.x", "E.y", "E.vx", "E.vy", "E.ax", "E.ay", "crank.angle", "crank.omega",
    "crank.alpha", "coupler.angle", "coupler.omega", "coupler.alpha", "tray.angle",
    "tray.omega", "tray.alpha", "rocker4.angle", "rocker4.omega", "rocker4.alpha",
    "rocker5.angle", "rocker5.omega", "rocker5.alpha", NULL};

static void conveyor_out(const double *x, const double *xd, const double *xdd, double q,
                         double qd, double qdd, double *o)
{
    double A[6] = {0}, B[6], C[6], D[6], E[6];
    add_arm(A, C_l1, q, qd, qdd);
    memcpy(B, A, sizeof B);
    add_arm(B, C_l2, x[0], xd[0], xdd[0]);
    memcpy(C, B, sizeof C), memcpy(D, B, sizeof D), memcpy(E, B, sizeof E);
    add_arm(C, C_lk, x[1] + M_PI / 2, xd[1], xdd[1]);
    add_arm(D, C_rD, x[1] + C_aD, xd[1], xdd[1]);
    add_arm(E, C_rE, x[1] + C_aE, xd[1], xdd[1]);
    *o++ = q;
    memcpy(o, A, sizeof A), o += 6;
    memcpy(o, B, sizeof B), o += 6;
    memcpy(o, C, sizeof C), o += 6;
    memcpy(o, D, sizeof D), o += 6;
    memcpy(o, E, sizeof E), o += 6;
    *o++ = q, *o++ = qd, *o++ = qdd;
    for (int k = 0; k < 4; k++)
        *o++ = x[k], *o++ = xd[k], *o++ = xdd[k];
}

/* ---- the conveyor's joint reactions by hand (friction off) ----------------- */

/* Newton-Euler for the five moving links (x, y forces and the moment about
 * the centre of mass), unknowns: the reactions at O, A, B, E, D, F, G (each
 * on the later link of the file, its opposite on the earlier) and the
 * driver torque; 15 x 15, dense LU with partial pivoting. The tray's
 * distributed cargo (50 kg over E-D) acts at the tray's centre. */
enum { CF_N = 15 };
static const double C_rho = 7850, C_bw = 0.040, C_bt = 0.020, C_pw = 0.300, C_pt = 0.004,
                    C_cargo = 50, C_g = 9.81;

static const char *const CVF_COLS[] = {
    "q", "A.x", "A.y", "A.vx", "A.vy", "A.ax", "A.ay", "B.x", "B.y", "B.vx", "B.vy", "B.ax",
    "B.ay", "C.x", "C.y", "C.vx", "C.vy", "C.ax", "C.ay", "D.x", "D.y", "D.vx", "D.vy", "D.ax",
    "D.ay", "E.x", "E.y", "E.vx", "E.vy", "E.ax", "E.ay", "crank.angle", "crank.omega",
    "crank.alpha", "coupler.angle", "coupler.omega", "coupler.alpha", "tray.angle",
    "tray.omega", "tray.alpha", "rocker4.angle", "rocker4.omega", "rocker4.alpha",
    "rocker5.angle", "rocker5.omega", "rocker5.alpha", "driver.torque", NULL};

/* One joint: reaction column c at point p, +R on link la (centre ga), -R on lb. */
static void cf_joint(double *A, int c, const double *p, int la, const double *ga, int lb,
                     const double *gb)
{
    const int ls[2] = {la, lb};
    const double *gs[2] = {ga, gb}, sg[2] = {1, -1};
    for (int k = 0; k < 2; k++) {
        if (ls[k] == 0)
            continue;
        int r = 3 * (ls[k] - 1);
        double rx = p[0] - gs[k][0], ry = p[1] - gs[k][1];
        A[r * CF_N + c] += sg[k], A[(r + 1) * CF_N + c + 1] += sg[k];
        A[(r + 2) * CF_N + c] += -sg[k] * ry, A[(r + 2) * CF_N + c + 1] += sg[k] * rx;
    }
}

/* The driver torque at one position from the kinematics (x, xd, xdd). */
static double conveyor_torque(const double *x, const double *xd, const double *xdd, double q,
                              double qd, double qdd)
{
    double l3 = C_l3a + C_l3b, rG3 = hypot((C_l3b - C_l3a) / 2, C_lk),
           aG3 = atan2(C_lk, (C_l3b - C_l3a) / 2);
    double m1 = C_rho * C_bw * C_bt * C_l1, m2 = C_rho * C_bw * C_bt * C_l2,
           m3 = C_rho * C_pw * C_pt * l3, m4 = C_rho * C_bw * C_bt * C_l4, m5 = m4;
    double mass[6] = {0, m1, m2, m3, m4, m5};
    double inertia[6] = {0, m1 * (C_l1 * C_l1 + C_bw * C_bw) / 12,
                         m2 * (C_l2 * C_l2 + C_bw * C_bw) / 12, m3 * (l3 * l3 + C_pw * C_pw) / 12,
                         m4 * (C_l4 * C_l4 + C_bw * C_bw) / 12, m5 * (C_l5 * C_l5 + C_bw * C_bw) / 12};
    double al[6] = {0, qdd, xdd[0], xdd[1], xdd[2], xdd[3]};
    /* points and centres with their accelerations: [x, y, vx, vy, ax, ay] */
    double P_A[6] = {0}, P_B[6], P_E[6], P_D[6], P_F[6] = {C_xF, -C_a, 0, 0, 0, 0},
           P_G[6] = {C_xG, -C_a, 0, 0, 0, 0}, G[6][6] = {{0}};
    add_arm(P_A, C_l1, q, qd, qdd);
    memcpy(P_B, P_A, sizeof P_B);
    add_arm(P_B, C_l2, x[0], xd[0], xdd[0]);
    memcpy(P_E, P_B, sizeof P_E), memcpy(P_D, P_B, sizeof P_D);
    add_arm(P_E, C_rE, x[1] + C_aE, xd[1], xdd[1]);
    add_arm(P_D, C_rD, x[1] + C_aD, xd[1], xdd[1]);
    add_arm(G[1], C_l1 / 2, q, qd, qdd);
    memcpy(G[2], P_A, sizeof G[2]);
    add_arm(G[2], C_l2 / 2, x[0], xd[0], xdd[0]);
    memcpy(G[3], P_B, sizeof G[3]);
    add_arm(G[3], rG3, x[1] + aG3, xd[1], xdd[1]);
    memcpy(G[4], P_F, sizeof G[4]);
    add_arm(G[4], C_l4 / 2, x[2], xd[2], xdd[2]);
    memcpy(G[5], P_G, sizeof G[5]);
    add_arm(G[5], C_l5 / 2, x[3], xd[3], xdd[3]);
    double A[CF_N * CF_N] = {0}, b[CF_N];
    static const double origin[2] = {0, 0};
    cf_joint(A, 0, origin, 1, G[1], 0, NULL);    /* O: ground-crank */
    cf_joint(A, 2, P_A, 2, G[2], 1, G[1]);       /* A: crank-coupler */
    cf_joint(A, 4, P_B, 3, G[3], 2, G[2]);       /* B: coupler-tray */
    cf_joint(A, 6, P_E, 4, G[4], 3, G[3]);       /* E: tray-rocker4 */
    cf_joint(A, 8, P_D, 5, G[5], 3, G[3]);       /* D: tray-rocker5 */
    cf_joint(A, 10, P_F, 4, G[4], 0, NULL);      /* F: ground-rocker4 */
    cf_joint(A, 12, P_G, 5, G[5], 0, NULL);      /* G: ground-rocker5 */
    A[2 * CF_N + 14] = 1;                        /* the driver torque on the crank */
    for (int l = 1; l <= 5; l++) {  /* A y = m a - m g - loads; I al - load moments */
        double fy = -mass[l] * C_g - (l == 3 ? C_cargo * C_g : 0);  /* cargo at the centre */
        b[3 * (l - 1)] = mass[l] * G[l][4];
        b[3 * (l - 1) + 1] = mass[l] * G[l][5] - fy;
        b[3 * (l - 1) + 2] = inertia[l] * al[l];
    }
    int piv[CF_N];
    if (lu(CF_N, A, piv))
        return NAN;
    lu_solve(CF_N, A, piv, b);
    return b[14];
}

static void conveyor_out_forces(const double *x, const double *xd, const double *xdd, double q,
                                double qd, double qdd, double *o)
{
    conveyor_out(x, xd, xdd, q, qd, qdd, o);
    o[46] = conveyor_torque(x, xd, xdd, q, qd, qdd);
}

/* ---- timing and comparison -------------------------------------------------- */

static int ncols_of(const char *const *cols)
{
    int n = 0;
    while (cols[n])
        n++;
    return n;
}

/* Largest difference between the interpreter's table and the hand table,
 * relative to the largest value of the same unit over the compared columns
 * (angles: absolute, rad). */
static double compare(const mech_table *t, const double *hand, const char *const *cols)
{
    int nc = ncols_of(cols), idx[MAXCOLS];
    double scale[MAXCOLS] = {0}, worst = 0;
    for (int c = 0; c < nc; c++)
        if ((idx[c] = mech_table_column(t, cols[c])) < 0) {
            fprintf(stderr, "bench-hand: no column %s\n", cols[c]);
            return INFINITY;
        }
    for (int c = 0; c < nc; c++)
        for (int r = 0; r < t->nrows; r++)
            for (int u = 0; u < nc; u++)  /* every column of the same unit */
                if (strcmp(t->columns[idx[u]].unit, t->columns[idx[c]].unit) == 0)
                    scale[u] = fmax(scale[u], fabs(mech_table_get(t, r, idx[c])));
    for (int c = 0; c < nc; c++) {
        int is_angle = strcmp(t->columns[idx[c]].unit, "rad") == 0;
        double e = 0;
        for (int r = 0; r < t->nrows; r++) {
            double a = mech_table_get(t, r, idx[c]), b = hand[(size_t)r * (size_t)nc + (size_t)c];
            e = fmax(e, is_angle ? fabs(remainder(a - b, 2 * M_PI)) : fabs(a - b));
        }
        e = is_angle ? e : e / fmax(scale[c], 1e-300);
        if (getenv("BENCH_HAND_DEBUG"))
            fprintf(stderr, "  %-16s %.3g\n", cols[c], e);
        worst = fmax(worst, e);
    }
    return worst;
}

/* 1: the interpreter also solves the joint reactions, friction off (the
 * conveyor's row with forces) */
static int with_forces;

static double time_interpreter(const mech_model *m, double tol, mech_table *keep,
                               mech_solve_stats *st, double *min)
{
    double us[REPS];
    for (int r = 0; r < REPS; r++) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.tol = tol;
        o.forces = with_forces ? 1 : -1; /* kinematics only, like the hand-written solvers */
        o.friction = MECH_FRICTION_OFF;
        mech_table t = {0};
        mech_diag d;
        mech_diag_init(&d);
        if (mech_solve(m, &o, &t, st, &d) != MECH_OK) {
            mech_diag_print(&d, stderr);
            exit(1);
        }
        mech_diag_free(&d);
        us[r] = st->seconds / st->steps * 1e6;
        if (r == 0)
            *keep = t;
        else
            mech_table_free(&t);
    }
    double med = bench_median(us, REPS);
    *min = us[0];
    return med;
}

static void row(const char *name, const char *how, const mech_model *m,
                const hand_mech *h, const char *const *cols, double tol)
{
    mech_solve_stats st;
    mech_table t = {0};
    double timin, ti = time_interpreter(m, tol, &t, &st, &timin);
    int nq = m->driver.nvalues, nc = ncols_of(cols);
    double *out = calloc((size_t)nq * (size_t)nc, sizeof *out), us[REPS];
    long iters = 0;
    for (int r = 0; r < REPS; r++) {
        double t0 = bench_now();
        if (h) {
            iters = hand_sweep(h, m->driver.values, nq, m->driver.speed, m->driver.accel, tol,
                               out, nc);
            if (iters < 0) {
                fprintf(stderr, "bench-hand: %s: the hand-written Newton failed\n", name);
                exit(1);
            }
        } else {
            for (int i = 0; i < nq; i++)
                fourbar_row(m->driver.values[i], m->driver.speed, m->driver.accel,
                            out + (size_t)i * (size_t)nc);
        }
        us[r] = (bench_now() - t0) / nq * 1e6;
    }
    double th = bench_median(us, REPS), thmin = us[0];
    double diff = compare(&t, out, cols);
    printf("%-10s %-24s %6.0e %5d %9.3f %9.3f %8.3f %8.3f %7.1f %7.1f %7.2f %7.2f %9.2e\n", name, how,
           tol, nq, ti, timin, th, thmin, ti / th, timin / thmin, (double)st.iterations / st.steps,
           h ? (double)iters / nq : 0.0, diff);
    free(out);
    mech_table_free(&t);
}

static mech_model *load(const char *dir, const char *file)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, file);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    mech_summary s;
    if (mech_load_file(path, &m, &d) != MECH_OK || mech_check(m, &s, &d) != MECH_OK) {
        mech_diag_print(&d, stderr);
        exit(1);
    }
    mech_diag_free(&d);
    return m;
}

/* The hand-written solvers, by the short name of bench/bench_ratio.sh. */
static hand_mech hand_of(const char *name)
{
    hand_mech fb = {2, FB_D, fourbar_eval, fourbar_acc, fourbar_out, FB_COLS,
                    {40 * M_PI / 180, 100 * M_PI / 180}};
    hand_mech sc = {2, SC_L, slider_eval, slider_acc, slider_out, SC_COLS,
                    {14.5 * M_PI / 180, 0.156}};
    hand_mech st = {8, 0, stirling_eval, stirling_acc, stirling_out, ST_COLS,
                    {1.2745, 0.070, 0.3818, 0.2101, 0.2003, 0.024, 1.0973, 0.017}};
    /* lref: the largest distance between two ground points (H and M) */
    st.lref = hypot(S_L3 + S_L5, S_L4 + S_L2);
    hand_mech cv = {4, C_l3a + C_l3b, conveyor_eval, conveyor_acc, conveyor_out, CV_COLS,
                    {-155 * M_PI / 180, 0, -8 * M_PI / 180, -7 * M_PI / 180}};
    hand_mech cf = cv;  /* with the driver torque (joint reactions, friction off) */
    cf.out = conveyor_out_forces, cf.cols = CVF_COLS;
    return strcmp(name, "fourbar") == 0               ? fb
           : strcmp(name, "offset-slider-crank") == 0 ? sc
           : strcmp(name, "stirling") == 0            ? st
           : strcmp(name, "conveyor-forces") == 0     ? cf
                                                      : cv;
}

/* Through a volatile pointer: never inlined, so that callgrind can count
 * inside it (--toggle-collect=hand_sweep). */
static long (*volatile hand_sweep_call)(const hand_mech *, const double *, int, double, double,
                                        double, double *, int) = hand_sweep;

/* One sweep of `steps` intervals over the file's driver range, by the
 * interpreter (kinematics, or forces with friction off) or by hand. */
static int count_one(const char *dir, const char *name, const char *side, int steps, int forces)
{
    char file[256];
    snprintf(file, sizeof file, "%s.yaml", name);
    mech_model *m = load(dir, file);
    double from = m->driver.values[0], to = m->driver.values[m->driver.nvalues - 1];
    int rc = 0;
    if (strcmp(side, "hand") == 0) {
        hand_mech h = hand_of(forces ? "conveyor-forces" : name);
        int nc = ncols_of(h.cols);
        double *qs = calloc((size_t)steps + 1, sizeof *qs);
        double *out = calloc((size_t)(steps + 1) * (size_t)nc, sizeof *out);
        for (int i = 0; i <= steps; i++)
            qs[i] = from + (to - from) * i / steps;
        rc = hand_sweep_call(&h, qs, steps + 1, m->driver.speed, m->driver.accel, 1e-12, out, nc) < 0;
        free(qs);
        free(out);
    } else {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.has_range = 1, o.from = from, o.to = to, o.steps = steps;
        o.forces = forces ? 1 : -1;
        o.friction = MECH_FRICTION_OFF;
        mech_table t = {0};
        mech_solve_stats st;
        mech_diag d;
        mech_diag_init(&d);
        rc = mech_solve(m, &o, &t, &st, &d) != MECH_OK;
        if (rc)
            mech_diag_print(&d, stderr);
        mech_diag_free(&d);
        mech_table_free(&t);
    }
    mech_model_free(&m);
    return rc;
}

int main(int argc, char **argv)
{
    C_rE = hypot(C_l3a, C_lk), C_aE = atan2(C_lk, -C_l3a);
    C_rD = hypot(C_l3b, C_lk), C_aD = atan2(C_lk, C_l3b);
    if (argc >= 5 && strcmp(argv[1], "--count") == 0)
        return count_one(getenv("BENCH_MECHANISMS") ? getenv("BENCH_MECHANISMS") : "mechanisms",
                         argv[2], argv[3], atoi(argv[4]), argc > 5 && strcmp(argv[5], "forces") == 0);
    const char *dir = argc > 1 ? argv[1] : "mechanisms";
    printf("the price of being general: time per driver step, interpreter (mech_solve, positions\n"
           "+ velocities + accelerations, no forces) against a solver written by hand for the\n"
           "mechanism (same steps, same outputs); us per step, median (and min) of %d sweeps;\n"
           "ratio = interpreter / hand-written; it/step = interpreter's Newton iterations, hand LU =\n"
           "hand-written LU factorisations per step; 'differ' = largest difference of the two\n"
           "tables (relative to the largest value of the same unit; angles in rad)\n",
           REPS);
    printf("%-10s %-24s %6s %5s %9s %9s %8s %8s %7s %7s %7s %7s %9s\n", "mechanism",
           "hand-written solver", "tol", "steps", "interp", "(min)", "hand", "(min)", "ratio", "(min)",
           "it/step", "hand LU", "differ");
    mech_model *m = load(dir, "fourbar.yaml");
    row("fourbar", "closed form", m, NULL, FB_COLS, 1e-12);
    row("fourbar", "closed form", m, NULL, FB_COLS, 1e-15);
    hand_mech h = hand_of("fourbar");
    row("fourbar", "Newton, 2x2 J, dense LU", m, &h, FB_COLS, 1e-12);
    mech_model_free(&m);

    m = load(dir, "offset-slider-crank.yaml");
    h = hand_of("offset-slider-crank");
    row("sl-crank", "Newton, 2x2 J, dense LU", m, &h, SC_COLS, 1e-12);
    mech_model_free(&m);

    m = load(dir, "stirling.yaml");
    h = hand_of("stirling");
    row("stirling", "Newton, 8x8 J, dense LU", m, &h, ST_COLS, 1e-12);
    row("stirling", "Newton, 8x8 J, dense LU", m, &h, ST_COLS, 1e-15);
    mech_model_free(&m);

    m = load(dir, "conveyor.yaml");
    h = hand_of("conveyor");
    row("conveyor", "Newton, 4x4 J, dense LU", m, &h, CV_COLS, 1e-12);
    row("conveyor", "Newton, 4x4 J, dense LU", m, &h, CV_COLS, 1e-15);
    h = hand_of("conveyor-forces");
    with_forces = 1;
    row("conv+torq", "+ 15x15 forces, dense LU", m, &h, CVF_COLS, 1e-12);
    with_forces = 0;
    mech_model_free(&m);
    return 0;
}
