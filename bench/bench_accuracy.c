/* bench/bench_accuracy.c: speed against error. For one crank revolution of
 * each mechanism, sweeps the Newton tolerance (mech_solve_options.tol, 1e-6
 * ... 1e-15, 360 steps) and the number of steps per revolution (36 ...
 * 36 000, default tolerance), and reports the time per revolution (median of
 * repeated sweeps, set-up excluded) against the worst error of the
 * positions, velocities and accelerations, measured against references
 * computed independently of the library:
 *
 *   fourbar.yaml, slider-crank.yaml  the closed forms of tests/unit/closed_forms.h
 *   stirling.yaml, conveyor.yaml     the loop equations written out by hand
 *                                    below (docs/stirling.md section 7, in the
 *                                    file's mirrored frame; docs/conveyor.md),
 *                                    solved in __float128 by Newton to 1e-30,
 *                                    rates from the same equations
 *                                    differentiated by hand
 *
 * Errors are relative to the largest value of their kind over the sweep
 * (lengths in m, velocities, accelerations; angles relative to pi, angular
 * rates to their largest value); "pos" is the worst over lengths and angles,
 * "vel" over velocities and angular velocities, "acc" over accelerations and
 * angular accelerations. Compared columns: every point, link and slider
 * output of the file (the conveyor's forces are switched off).
 * Usage: bench-accuracy MECHDIR [SVGDIR]. Not a test. */
#include <math.h>
#include <quadmath.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "closed_forms.h"
#include "mech.h"

typedef __float128 Q;
enum { MAXN = 8, MAXT = 48, MAXC = 64 };

/* ---- high-precision references: loop equations as sums of terms ---------- */

/* A term of row `row`: c cos(v + off), c sin(v + off), c v or c, where v is
 * unknown `var` or the driver q (var = -1). */
typedef enum { TCOS, TSIN, TLIN, TCONST } term_kind;
typedef struct term {
    int row, var;
    term_kind kind;
    Q c, off;
} term;

typedef struct refmech {
    const char *file;
    int n, nt;
    term t[MAXT];
    const char *unknown_col[MAXN]; /* table column holding each unknown */
    /* reference values of the file's output columns, from x, x', x'' */
    void (*out)(const struct refmech *r, const Q *x, const Q *xd, const Q *xdd, Q q, Q qd,
                Q qdd, const mech_table *t, double *row);
} refmech;

static Q tval(const term *t, Q v)
{
    switch (t->kind) {
    case TCOS: return t->c * cosq(v + t->off);
    case TSIN: return t->c * sinq(v + t->off);
    case TLIN: return t->c * v;
    default: return t->c;
    }
}

static Q tder(const term *t, Q v)
{
    switch (t->kind) {
    case TCOS: return -t->c * sinq(v + t->off);
    case TSIN: return t->c * cosq(v + t->off);
    case TLIN: return t->c;
    default: return 0;
    }
}

/* second derivative of the term with respect to its variable */
static Q tder2(const term *t, Q v)
{
    switch (t->kind) {
    case TCOS: return -t->c * cosq(v + t->off);
    case TSIN: return -t->c * sinq(v + t->off);
    default: return 0;
    }
}

/* Solve A b (n x n, row-major, destroyed) in place; partial pivoting. */
static int qsolve(int n, Q *A, Q *b)
{
    for (int k = 0; k < n; k++) {
        int p = k;
        for (int i = k + 1; i < n; i++)
            if (fabsq(A[i * n + k]) > fabsq(A[p * n + k]))
                p = i;
        if (A[p * n + k] == 0)
            return -1;
        for (int j = 0; j < n; j++) {
            Q t = A[k * n + j];
            A[k * n + j] = A[p * n + j], A[p * n + j] = t;
        }
        Q t = b[k];
        b[k] = b[p], b[p] = t;
        for (int i = k + 1; i < n; i++) {
            Q l = A[i * n + k] / A[k * n + k];
            for (int j = k; j < n; j++)
                A[i * n + j] -= l * A[k * n + j];
            b[i] -= l * b[k];
        }
    }
    for (int k = n - 1; k >= 0; k--) {
        for (int j = k + 1; j < n; j++)
            b[k] -= A[k * n + j] * b[j];
        b[k] /= A[k * n + k];
    }
    return 0;
}

static Q var(const Q *x, Q q, int v) { return v < 0 ? q : x[v]; }

/* F, J (and dF/dq) at x, q. */
static void qeval(const refmech *r, const Q *x, Q q, Q *F, Q *J, Q *fq)
{
    memset(F, 0, sizeof(Q) * (size_t)r->n);
    memset(J, 0, sizeof(Q) * (size_t)(r->n * r->n));
    memset(fq, 0, sizeof(Q) * (size_t)r->n);
    for (int k = 0; k < r->nt; k++) {
        const term *t = &r->t[k];
        Q v = var(x, q, t->var);
        F[t->row] += tval(t, v);
        if (t->var < 0)
            fq[t->row] += tder(t, v);
        else if (t->kind != TCONST)
            J[t->row * r->n + t->var] += tder(t, v);
    }
}

/* Positions by Newton from x (to 1e-30), then x' and x''. Returns the size
 * of the correction made to the starting x (how far the table was off). */
static double qsolve_row(const refmech *r, Q *x, Q q, Q qd, Q qdd, Q *xd, Q *xdd)
{
    int n = r->n;
    Q F[MAXN], J[MAXN * MAXN], fq[MAXN], x0[MAXN];
    memcpy(x0, x, sizeof(Q) * (size_t)n);
    for (int it = 0;; it++) {
        qeval(r, x, q, F, J, fq);
        if (qsolve(n, J, F) || it == 40) {
            fprintf(stderr, "bench-accuracy: %s: the reference Newton failed\n", r->file);
            exit(1);
        }
        Q dmax = 0;
        for (int i = 0; i < n; i++)
            x[i] -= F[i], dmax = fmaxq(dmax, fabsq(F[i]));
        if (dmax < 1e-30Q)
            break;
    }
    /* J x_q = -f_q;  J x_qq = -sum_t f_t''(v) v_q^2  (q_qq = 0) */
    Q xq[MAXN], xqq[MAXN];
    qeval(r, x, q, F, J, fq);
    for (int i = 0; i < n; i++)
        xq[i] = -fq[i];
    qsolve(n, J, xq);
    memset(xqq, 0, sizeof xqq);
    for (int k = 0; k < r->nt; k++) {
        const term *t = &r->t[k];
        Q vq = t->var < 0 ? 1 : xq[t->var];
        xqq[t->row] -= tder2(t, var(x, q, t->var)) * vq * vq;
    }
    qeval(r, x, q, F, J, fq);
    qsolve(n, J, xqq);
    double moved = 0;
    for (int i = 0; i < n; i++) {
        xd[i] = xq[i] * qd;
        xdd[i] = xqq[i] * qd * qd + xq[i] * qdd;
        moved = fmax(moved, (double)fabsq(x[i] - x0[i]));
    }
    return moved;
}

/* rotating vector r e(th) into (p, v, a), th' = w, th'' = al */
static void qarm(Q *p, Q r, Q th, Q w, Q al)
{
    Q c = r * cosq(th), s = r * sinq(th);
    p[0] += c, p[1] += s;
    p[2] += -s * w, p[3] += c * w;
    p[4] += -s * al - c * w * w, p[5] += c * al - s * w * w;
}

static void put_point(const mech_table *t, double *row, const char *name, const Q *p)
{
    static const char *const sfx[] = {".x", ".y", ".vx", ".vy", ".ax", ".ay"};
    char col[80];
    for (int k = 0; k < 6; k++) {
        snprintf(col, sizeof col, "%s%s", name, sfx[k]);
        int c = mech_table_column(t, col);
        if (c >= 0)
            row[c] = (double)p[k];
    }
}

static void put3(const mech_table *t, double *row, const char *name, const char *const *sfx,
                 Q a, Q b, Q c)
{
    char col[80];
    Q v[3] = {a, b, c};
    for (int k = 0; k < 3; k++) {
        snprintf(col, sizeof col, "%s%s", name, sfx[k]);
        int i = mech_table_column(t, col);
        if (i >= 0)
            row[i] = (double)v[k];
    }
}

static const char *const LSFX[] = {".angle", ".omega", ".alpha"};
static const char *const SSFX[] = {".s", ".v", ".a"};

/* Stirling engine: x = [Theta2, r3, Theta4, Theta5, Theta6, r7, Theta8, r9]. */
#define QCM(v) ((Q)(v) / 100)
static const Q Sa1 = QCM(24) / 10, Sa21 = QCM(5), Sa22 = QCM(1), Sb = QCM(4) / 10,
               Sa4 = QCM(51) / 10, Sa51 = QCM(6), Sa52 = QCM(5), Sa6 = QCM(24) / 10,
               Sa8 = QCM(48) / 10, SL1 = QCM(94) / 10, SL2 = QCM(68) / 10, SL3 = QCM(19) / 10,
               SL4 = QCM(7), SL5 = QCM(7), SL6 = QCM(6), Sal = 0.4907Q, Sbe = 0.6338Q,
               Sga = 1.6258Q, Sde = 0.1411Q;

static void stirling_out(const refmech *r, const Q *x, const Q *xd, const Q *xdd, Q q, Q qd,
                         Q qdd, const mech_table *t, double *row)
{
    (void)r;
    Q D[6] = {-Sb, x[1], 0, xd[1], 0, xdd[1]};
    Q L[6] = {SL3 - SL1 + SL5, SL6 + SL4 - x[7], 0, -xd[7], 0, -xdd[7]};
    Q ca = cosq(Sal), sa = sinq(Sal);
    Q Jp[6] = {-SL1 + x[5] * ca, SL6 - SL2 + x[5] * sa, xd[5] * ca, xd[5] * sa,
               xdd[5] * ca, xdd[5] * sa};
    put_point(t, row, "D", D);
    put_point(t, row, "L", L);
    put_point(t, row, "J", Jp);
    put3(t, row, "crank", LSFX, q, qd, qdd);
    static const char *const links[] = {"link2", "link4", "link5", "link6", "link8"};
    static const int li[] = {0, 2, 3, 4, 6};
    for (int k = 0; k < 5; k++)
        put3(t, row, links[k], LSFX, x[li[k]], xd[li[k]], xdd[li[k]]);
    put3(t, row, "r3", SSFX, x[1], xd[1], xdd[1]);
    put3(t, row, "r7", SSFX, x[5], xd[5], xdd[5]);
    put3(t, row, "r9", SSFX, x[7], xd[7], xdd[7]);
}

static void stirling_ref(refmech *r)
{
    /* the corrected equations of docs/stirling.md section 7, times -1 for
     * the x rows (the file's x = -x_paper) */
    const term t[] = {
        {0, -1, TCONST, Sb, 0},        {0, 0, TCOS, Sa21, Sde},      {0, -1, TCOS, Sa1, 0},
        {1, 0, TSIN, Sa21, Sde},       {1, -1, TSIN, Sa1, 0},        {1, 1, TLIN, -1, 0},
        {2, -1, TCOS, Sa1, 0},         {2, 0, TCOS, Sa22, Sde + Sbe}, {2, 2, TCOS, -Sa4, 0},
        {2, 3, TCOS, Sa51, Sga},       {2, -1, TCONST, SL1 - SL3, 0},
        {3, -1, TSIN, Sa1, 0},         {3, 0, TSIN, Sa22, Sde + Sbe}, {3, 2, TSIN, -Sa4, 0},
        {3, 3, TSIN, Sa51, Sga},       {3, -1, TCONST, -SL6, 0},
        {4, 5, TLIN, cosq(Sal), 0},    {4, 4, TCOS, Sa6, 0},          {4, 3, TCOS, Sa51, Sga},
        {4, -1, TCONST, -SL3, 0},
        {5, 5, TLIN, sinq(Sal), 0},    {5, 4, TSIN, Sa6, 0},          {5, 3, TSIN, Sa51, Sga},
        {5, -1, TCONST, -SL2, 0},
        {6, 3, TCOS, Sa52, 0},         {6, 6, TCOS, Sa8, 0},          {6, -1, TCONST, -SL5, 0},
        {7, 3, TSIN, Sa52, 0},         {7, 6, TSIN, Sa8, 0},          {7, 7, TLIN, 1, 0},
        {7, -1, TCONST, -SL4, 0},
    };
    memset(r, 0, sizeof *r);
    r->file = "stirling.yaml";
    r->n = 8;
    r->nt = (int)(sizeof t / sizeof t[0]);
    memcpy(r->t, t, sizeof t);
    const char *cols[] = {"link2.angle", "r3.s",        "link4.angle", "link5.angle",
                          "link6.angle", "r7.s",        "link8.angle", "r9.s"};
    memcpy(r->unknown_col, cols, sizeof cols);
    r->out = stirling_out;
}

/* Conveyor: x = [phi2 (coupler), theta3 (tray), phi4 (rocker4), phi5 (rocker5)]. */
#define QMM(v) ((Q)(v) / 1000)
static const Q Cl1 = QMM(60), Cl2 = QMM(430), Clk = QMM(75), Cl3a = QMM(560),
               Cl3b = QMM(1140), Cl4 = QMM(440), Cl5 = QMM(440), Ca = QMM(50),
               CxF = QMM(-13246) / 10, CxG = QMM(3738) / 10;

static void conveyor_out(const refmech *r, const Q *x, const Q *xd, const Q *xdd, Q q, Q qd,
                         Q qdd, const mech_table *t, double *row)
{
    (void)r;
    Q A[6] = {0}, B[6], C[6], D[6], E[6];
    qarm(A, Cl1, q, qd, qdd);
    memcpy(B, A, sizeof B);
    qarm(B, Cl2, x[0], xd[0], xdd[0]);
    memcpy(C, B, sizeof C), memcpy(D, B, sizeof D), memcpy(E, B, sizeof E);
    qarm(C, Clk, x[1] + M_PIq / 2, xd[1], xdd[1]);
    qarm(D, hypotq(Cl3b, Clk), x[1] + atan2q(Clk, Cl3b), xd[1], xdd[1]);
    qarm(E, hypotq(Cl3a, Clk), x[1] + atan2q(Clk, -Cl3a), xd[1], xdd[1]);
    put_point(t, row, "A", A);
    put_point(t, row, "B", B);
    put_point(t, row, "C", C);
    put_point(t, row, "D", D);
    put_point(t, row, "E", E);
    put3(t, row, "crank", LSFX, q, qd, qdd);
    static const char *const links[] = {"coupler", "tray", "rocker4", "rocker5"};
    for (int k = 0; k < 4; k++)
        put3(t, row, links[k], LSFX, x[k], xd[k], xdd[k]);
}

static void conveyor_ref(refmech *r)
{
    /* loops O-A-B-C-E-F-O and O-A-B-C-D-G-O; the tray's points E = (-l3a, lk)
     * and D = (l3b, lk) in its frame, in polar form */
    Q rE = hypotq(Cl3a, Clk), aE = atan2q(Clk, -Cl3a), rD = hypotq(Cl3b, Clk),
      aD = atan2q(Clk, Cl3b);
    const term t[] = {
        {0, -1, TCOS, Cl1, 0}, {0, 0, TCOS, Cl2, 0}, {0, 1, TCOS, rE, aE},
        {0, 2, TCOS, -Cl4, 0}, {0, -1, TCONST, -CxF, 0},
        {1, -1, TSIN, Cl1, 0}, {1, 0, TSIN, Cl2, 0}, {1, 1, TSIN, rE, aE},
        {1, 2, TSIN, -Cl4, 0}, {1, -1, TCONST, Ca, 0},
        {2, -1, TCOS, Cl1, 0}, {2, 0, TCOS, Cl2, 0}, {2, 1, TCOS, rD, aD},
        {2, 3, TCOS, -Cl5, 0}, {2, -1, TCONST, -CxG, 0},
        {3, -1, TSIN, Cl1, 0}, {3, 0, TSIN, Cl2, 0}, {3, 1, TSIN, rD, aD},
        {3, 3, TSIN, -Cl5, 0}, {3, -1, TCONST, Ca, 0},
    };
    memset(r, 0, sizeof *r);
    r->file = "conveyor.yaml";
    r->n = 4;
    r->nt = (int)(sizeof t / sizeof t[0]);
    memcpy(r->t, t, sizeof t);
    const char *cols[] = {"coupler.angle", "tray.angle", "rocker4.angle", "rocker5.angle"};
    memcpy(r->unknown_col, cols, sizeof cols);
    r->out = conveyor_out;
}

/* ---- reference tables ------------------------------------------------------ */

/* Fills ref (same shape as t) with reference values; columns the reference
 * does not give are NAN. Returns the largest correction the reference
 * Newton made to the table's positions (0 for the closed forms). */
static double reference(const char *base, const mech_model *m, const mech_table *t, double *ref)
{
    size_t nc = (size_t)t->ncolumns;
    for (size_t i = 0; i < (size_t)t->nrows * nc; i++)
        ref[i] = NAN;
    double qd = m->driver.speed, qdd = m->driver.accel, moved = 0;
    if (strcmp(base, "fourbar.yaml") == 0 || strcmp(base, "slider-crank.yaml") == 0) {
        int fb = base[0] == 'f';
        fourbar g4 = {0.020, 0.060, 0.050, 0.070, 0.040 * cos(M_PI / 6), 0.040 * sin(M_PI / 6), 1};
        slidercrank gs = {0.040, 0.140, 0};
        const char *const *cols = fb ? FOURBAR_COLS : SLIDER_COLS;
        int ncols = fb ? NFOURBAR : NSLIDER;
        double v[64];
        for (int r = 0; r < t->nrows; r++) {
            double q = mech_table_get(t, r, 0);
            if (fb)
                fourbar_ref(&g4, q, qd, qdd, v);
            else
                slider_ref(&gs, q, qd, qdd, v);
            for (int k = 0; k < ncols; k++) {
                int c = mech_table_column(t, cols[k]);
                if (c >= 0)
                    ref[(size_t)r * nc + (size_t)c] = v[k];
            }
        }
        return 0;
    }
    refmech rm;
    if (strcmp(base, "stirling.yaml") == 0)
        stirling_ref(&rm);
    else if (strcmp(base, "conveyor.yaml") == 0)
        conveyor_ref(&rm);
    else
        return NAN;
    int uc[MAXN];
    for (int i = 0; i < rm.n; i++)
        if ((uc[i] = mech_table_column(t, rm.unknown_col[i])) < 0) {
            fprintf(stderr, "bench-accuracy: %s: no column %s\n", base, rm.unknown_col[i]);
            exit(1);
        }
    for (int r = 0; r < t->nrows; r++) {
        Q x[MAXN], xd[MAXN], xdd[MAXN];
        for (int i = 0; i < rm.n; i++)
            x[i] = mech_table_get(t, r, uc[i]);
        Q q = mech_table_get(t, r, 0);
        moved = fmax(moved, qsolve_row(&rm, x, q, qd, qdd, xd, xdd));
        rm.out(&rm, x, xd, xdd, q, qd, qdd, t, ref + (size_t)r * nc);
    }
    return moved;
}

/* Worst errors by kind: [0] positions (lengths, angles / pi), [1] velocities,
 * [2] accelerations, each relative to the largest reference value of its
 * unit over the sweep. */
static void errors(const mech_table *t, const double *ref, double err[3])
{
    static const char *const units[6] = {"m", "rad", "m/s", "rad/s", "m/s^2", "rad/s^2"};
    double scale[6] = {0}, e[6] = {0};
    size_t nc = (size_t)t->ncolumns;
    for (int pass = 0; pass < 2; pass++)
        for (int c = 1; c < t->ncolumns; c++) {
            int u = 0;
            while (u < 6 && strcmp(t->columns[c].unit, units[u]) != 0)
                u++;
            if (u == 6)
                continue;
            for (int r = 0; r < t->nrows; r++) {
                double rv = ref[(size_t)r * nc + (size_t)c], v = mech_table_get(t, r, c);
                if (isnan(rv))
                    continue;
                if (pass == 0)
                    scale[u] = u == 1 ? M_PI : fmax(scale[u], fabs(rv));
                else
                    e[u] = fmax(e[u], (u == 1 ? fabs(remainder(v - rv, 2 * M_PI)) : fabs(v - rv)) /
                                          scale[u]);
            }
        }
    for (int k = 0; k < 3; k++)
        err[k] = fmax(e[2 * k], e[2 * k + 1]);
}

/* ---- the sweeps ------------------------------------------------------------- */

typedef struct result {
    double tol;
    int steps;
    double it_per_step, ms_per_rev, us_per_step, err[3], residual, moved;
} result;

static int run(const char *base, const mech_model *m, double tol, int steps, result *res)
{
    int reps = steps <= 360 ? 31 : steps <= 3600 ? 11 : 5;
    double ms[31];
    mech_solve_stats st;
    mech_table keep = {0};
    for (int r = 0; r < reps; r++) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.tol = tol;
        o.forces = -1; /* kinematics only */
        o.has_range = 1;
        o.from = m->driver.values[0];
        o.to = o.from + 2 * M_PI;
        o.steps = steps;
        mech_table t = {0};
        mech_diag d;
        mech_diag_init(&d);
        if (mech_solve(m, &o, &t, &st, &d) != MECH_OK) {
            printf("%-18s %8.0e %6d  FAILED: %s\n", base, tol, steps,
                   d.count ? d.entries[0].message : "?");
            mech_diag_free(&d);
            mech_table_free(&t);
            mech_table_free(&keep);
            return -1;
        }
        mech_diag_free(&d);
        ms[r] = st.seconds * 1e3;
        if (r == 0)
            keep = t;
        else
            mech_table_free(&t);
    }
    double *ref = malloc(sizeof *ref * (size_t)keep.nrows * (size_t)keep.ncolumns);
    res->moved = reference(base, m, &keep, ref);
    errors(&keep, ref, res->err);
    free(ref);
    res->tol = tol;
    res->steps = steps;
    res->ms_per_rev = bench_median(ms, reps);
    res->us_per_step = res->ms_per_rev * 1e3 / st.steps;
    res->it_per_step = (double)st.iterations / st.steps;
    res->residual = st.worst_residual;
    printf("%-18s %8.0e %6d %8.2f %10.3f %9.3f %10.2e %10.2e %10.2e %10.2e\n", base, tol, steps,
           res->it_per_step, res->ms_per_rev, res->us_per_step, res->err[0], res->err[1],
           res->err[2], res->residual);
    mech_table_free(&keep);
    return 0;
}

enum { NTOL = 6, NSTEPS = 4, NMECH = 4 };

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : "mechanisms";
    const char *svgdir = argc > 2 ? argv[2] : NULL;
    static const char *const files[NMECH] = {"fourbar.yaml", "slider-crank.yaml", "stirling.yaml",
                                             "conveyor.yaml"};
    static const double tols[NTOL] = {1e-6, 1e-8, 1e-10, 1e-12, 1e-14, 1e-15};
    static const int stepss[NSTEPS] = {36, 360, 3600, 36000};
    static result rt[NMECH][NTOL], rs[NMECH][NSTEPS];
    printf("speed against error over one crank revolution: time per revolution (median, set-up\n"
           "excluded) and the worst error against an independent reference, relative to the\n"
           "largest value of its kind (angles: relative to pi); kinematics only\n");
    printf("%-18s %8s %6s %8s %10s %9s %10s %10s %10s %10s\n", "mechanism", "tol", "steps",
           "it/step", "ms/rev", "us/step", "err pos", "err vel", "err acc", "worst res");
    double worst_moved = 0;
    for (int f = 0; f < NMECH; f++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", dir, files[f]);
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_summary s;
        if (mech_load_file(path, &m, &d) != MECH_OK || mech_check(m, &s, &d) != MECH_OK) {
            mech_diag_print(&d, stderr);
            return 1;
        }
        mech_diag_free(&d);
        for (int k = 0; k < NTOL; k++) {
            if (run(files[f], m, tols[k], 360, &rt[f][k]))
                rt[f][k].ms_per_rev = NAN;
            worst_moved = fmax(worst_moved, rt[f][k].moved);
        }
        for (int k = 0; k < NSTEPS; k++) {
            if (stepss[k] == 360) {
                rs[f][k] = rt[f][3]; /* tol 1e-12, the default: already measured */
                continue;
            }
            if (run(files[f], m, 1e-12, stepss[k], &rs[f][k]))
                rs[f][k].ms_per_rev = NAN;
        }
        mech_model_free(&m);
    }
    printf("(steps 360 at tol 1e-12 is the default; largest correction the __float128 Newton made "
           "to a tabled position: %.2e)\n", worst_moved);
    if (!svgdir)
        return 0;
    char path[600];
    double x[NMECH][NTOL], y[3][NMECH][NTOL], sx[NMECH][NSTEPS], sy[NMECH][NSTEPS];
    svg_series ser[3 * NMECH];
    int ns = 0;
    static const char *const names[NMECH] = {"four-bar", "slider-crank", "Stirling", "conveyor"};
    static char labels[3 * NMECH][64];
    static const char *const kind[3] = {"pos", "vel", "acc"};
    static const char *const dash[3] = {NULL, "6,3", "2,3"};
    for (int f = 0; f < NMECH; f++) {
        for (int k = 0; k < NTOL; k++) {
            x[f][k] = rt[f][k].ms_per_rev;
            for (int e = 0; e < 3; e++)
                y[e][f][k] = fmax(rt[f][k].err[e], 1e-17);
        }
        for (int e = 0; e < 3; e += 2) {
            snprintf(labels[ns], sizeof labels[ns], "%s %s", names[f], kind[e]);
            ser[ns] = (svg_series){labels[ns], x[f], y[e][f], NTOL, SVG_COLORS[f], dash[e]};
            ns++;
        }
    }
    snprintf(path, sizeof path, "%s/accuracy-tolerance.svg", svgdir);
    svg_loglog(path, "Newton tol 1e-6 ... 1e-15, 360 steps: error against time",
               "time per revolution [ms]", "worst relative error", ser, ns);
    ns = 0;
    for (int f = 0; f < NMECH; f++) {
        for (int k = 0; k < NSTEPS; k++)
            sx[f][k] = rs[f][k].steps, sy[f][k] = rs[f][k].ms_per_rev;
        ser[ns++] = (svg_series){names[f], sx[f], sy[f], NSTEPS, SVG_COLORS[f], NULL};
    }
    snprintf(path, sizeof path, "%s/accuracy-steps.svg", svgdir);
    svg_loglog(path, "time per revolution against steps per revolution (tol 1e-12)",
               "steps per revolution", "time per revolution [ms]", ser, ns);
    printf("wrote %s/accuracy-tolerance.svg, %s/accuracy-steps.svg\n", svgdir, svgdir);
    return 0;
}
