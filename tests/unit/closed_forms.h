/* tests/unit/closed_forms.h: closed-form kinematics of a four-bar and an
 * offset slider-crank, written independently of the library, shared by
 * test_solve.c (the solver against them) and test_golden.c (the golden CSV
 * files of mechanisms/fourbar.yaml and mechanisms/slider-crank.yaml against
 * them). Every function here is used by both files. Needs <math.h> and
 * <string.h>. */
#ifndef MECH_TEST_CLOSED_FORMS_H
#define MECH_TEST_CLOSED_FORMS_H

#include <math.h>
#include <string.h>

/* ---- closed forms ------------------------------------------------------ */

/* A four-bar: ground pivots O = (0, 0) and C = (d, 0), crank OA of length
 * a, coupler AB of length b (x axis along AB) carrying P = (px, py) in its
 * frame, rocker CB of length c (x axis along CB). sign = +1: B left of the
 * directed line A -> C (the turn A -> B -> C is clockwise), -1: right. */
typedef struct fourbar {
    double a, b, c, d, px, py;
    int sign;
} fourbar;

/* Solve [m11 m12; m21 m22] x = g by Cramer's rule. */
static void solve2(double m11, double m12, double m21, double m22, double g1, double g2,
                   double *x1, double *x2)
{
    double det = m11 * m22 - m12 * m21;
    *x1 = (g1 * m22 - m12 * g2) / det;
    *x2 = (m11 * g2 - m21 * g1) / det;
}

/* The four-bar's column values, in the order of FOURBAR_COLS. */
static const char *const FOURBAR_COLS[] = {
    "A.x", "A.y", "A.vx", "A.vy", "A.ax", "A.ay",
    "B.x", "B.y", "B.vx", "B.vy", "B.ax", "B.ay",
    "P.x", "P.y", "P.vx", "P.vy", "P.ax", "P.ay",
    "crank.angle", "crank.omega", "crank.alpha",
    "coupler.angle", "coupler.omega", "coupler.alpha",
    "rocker.angle", "rocker.omega", "rocker.alpha"};
#define NFOURBAR ((int)(sizeof FOURBAR_COLS / sizeof *FOURBAR_COLS))

static void fourbar_ref(const void *geom, double q, double w2, double al2, double *out)
{
    const fourbar *g = geom;
    double c2 = cos(q), s2 = sin(q);
    /* positions: B on the circles (A, b) and (C, c) */
    double Ax = g->a * c2, Ay = g->a * s2;
    double Dx = g->d - Ax, Dy = -Ay, L = hypot(Dx, Dy);
    double ux = Dx / L, uy = Dy / L;
    double p = (g->b * g->b - g->c * g->c + L * L) / (2 * L);
    double h = sqrt(g->b * g->b - p * p);
    double Bx = Ax + p * ux - g->sign * h * uy, By = Ay + p * uy + g->sign * h * ux;
    double r3x = Bx - Ax, r3y = By - Ay;      /* A -> B, length b */
    double r4x = Bx - g->d, r4y = By;         /* C -> B, length c */
    double th3 = atan2(r3y, r3x), th4 = atan2(r4y, r4x);
    /* velocities: vA + w3 k x r3 = w4 k x r4 (k x r = (-ry, rx)) */
    double vAx = -g->a * w2 * s2, vAy = g->a * w2 * c2;
    double w3, w4;
    solve2(-r3y, r4y, r3x, -r4x, -vAx, -vAy, &w3, &w4);
    /* accelerations: aA + al3 k x r3 - w3^2 r3 = al4 k x r4 - w4^2 r4 */
    double aAx = -g->a * al2 * s2 - g->a * w2 * w2 * c2;
    double aAy = g->a * al2 * c2 - g->a * w2 * w2 * s2;
    double al3, al4;
    solve2(-r3y, r4y, r3x, -r4x, -aAx + w3 * w3 * r3x - w4 * w4 * r4x,
           -aAy + w3 * w3 * r3y - w4 * w4 * r4y, &al3, &al4);
    /* B from the rocker, P on the coupler */
    double vBx = -w4 * r4y, vBy = w4 * r4x;
    double aBx = -al4 * r4y - w4 * w4 * r4x, aBy = al4 * r4x - w4 * w4 * r4y;
    double rpx = g->px * cos(th3) - g->py * sin(th3), rpy = g->px * sin(th3) + g->py * cos(th3);
    double Px = Ax + rpx, Py = Ay + rpy;
    double vPx = vAx - w3 * rpy, vPy = vAy + w3 * rpx;
    double aPx = aAx - al3 * rpy - w3 * w3 * rpx, aPy = aAy + al3 * rpx - w3 * w3 * rpy;
    double v[] = {Ax,  Ay,  vAx, vAy, aAx, aAy, Bx, By, vBx, vBy, aBx, aBy, Px, Py,
                  vPx, vPy, aPx, aPy, q,   w2,  al2, th3, w3, al3, th4, w4,  al4};
    memcpy(out, v, sizeof v);
}

/* An offset slider-crank: crank OA of length r about O = (0, 0), rod AB of
 * length l (x axis along AB), piston block B sliding (locked) on the ground
 * line through G = (0, e) at 0 deg, on the side x_B > x_A. The slider's
 * displacement is x_B (measured from G along +x). */
typedef struct slidercrank {
    double r, l, e;
} slidercrank;

static const char *const SLIDER_COLS[] = {
    "A.x", "A.y", "A.vx", "A.vy", "A.ax", "A.ay",
    "B.x", "B.y", "B.vx", "B.vy", "B.ax", "B.ay",
    "crank.angle", "crank.omega", "crank.alpha",
    "rod.angle", "rod.omega", "rod.alpha",
    "x_B.s", "x_B.v", "x_B.a"};
#define NSLIDER ((int)(sizeof SLIDER_COLS / sizeof *SLIDER_COLS))

static void slider_ref(const void *geom, double q, double w, double al, double *out)
{
    const slidercrank *g = geom;
    double c = cos(q), s = sin(q);
    /* u = yB - yA and its derivatives; wx = xB - xA = sqrt(l^2 - u^2) */
    double u = g->e - g->r * s;
    double u1 = -g->r * c * w;
    double u2 = g->r * s * w * w - g->r * c * al;
    double wx = sqrt(g->l * g->l - u * u);
    double wx1 = -u * u1 / wx;
    double wx2 = -(u1 * u1 + u * u2) / wx - (u * u1) * (u * u1) / (wx * wx * wx);
    double x = g->r * c + wx;
    double x1 = -g->r * s * w + wx1;
    double x2 = -g->r * c * w * w - g->r * s * al + wx2;
    /* rod angle phi = atan2(u, wx): phi' = u'/wx, phi'' = (u'' wx - u' wx')/wx^2 */
    double phi = atan2(u, wx), phi1 = u1 / wx, phi2 = (u2 * wx - u1 * wx1) / (wx * wx);
    double v[] = {g->r * c, g->r * s, -g->r * s * w, g->r * c * w,
                  -g->r * s * al - g->r * c * w * w, g->r * c * al - g->r * s * w * w,
                  x, g->e, x1, 0, x2, 0,
                  q, w, al,
                  phi, phi1, phi2,
                  x, x1, x2};
    memcpy(out, v, sizeof v);
}

typedef void (*ref_fn)(const void *geom, double q, double w, double al, double *out);

#endif /* MECH_TEST_CLOSED_FORMS_H */
