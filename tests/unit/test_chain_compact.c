/* tests/unit/test_chain_compact.c: a long chain of four-bars solved through
 * mech_solve, whose analysis frees what only its set-up needed
 * (src/solve/plan_compact.c) and whose link frames get cos and sin only for the
 * links placed (src/solve/kinematics.c): angles, points and rates of links far
 * along the chain against the closed form of one four-bar (every odd loop
 * turns its rocker as loop 1, every even loop undoes it), rates against
 * central differences of that closed form. The chain is bench/bench_scale.c's. */
#include <math.h>

#include "helpers.h"

#define DEG (3.14159265358979323846 / 180)
#define CA 0.3
#define CB 1.0
#define CC 0.6
#define CD 1.0

enum { NLOOPS = 41 };

/* Loop 1 at driver angle q (rad), open assembly: rocker phi, coupler psi (rad). */
static void loop1(double q, double *phi, double *psi)
{
    double ax = CA * cos(q), ay = CA * sin(q);
    double dx = CD - ax, dy = -ay, L = hypot(dx, dy);
    double p = (CB * CB - CC * CC + L * L) / (2 * L), h = sqrt(CB * CB - p * p);
    double bx = ax + (p * dx - h * dy) / L, by = ay + (p * dy + h * dx) / L;
    *phi = atan2(by, bx - CD);
    *psi = atan2(by - ay, bx - ax);
}

/* Link L_k's angle in loop k (odd: the rocker; even: the crank again, q + pi). */
static double link_angle(int k, double q)
{
    double phi, psi;
    loop1(q, &phi, &psi);
    return k % 2 ? phi : q + 180 * DEG;
}

static double coupler_angle(double q)
{
    double phi, psi;
    loop1(q, &phi, &psi);
    return psi;
}

static char *chain_text(int n)
{
    size_t cap = 4096 + 400 * (size_t)n, len = 0;
    char *s = malloc(cap);
    cr_assert_not_null(s);
#define PUT(...) (len += (size_t)snprintf(s + len, cap - len, __VA_ARGS__))
    PUT("name: chain\nunits: {angle: deg}\nground:\n");
    for (int k = 0; k <= n; k++)
        PUT("  G%d: [%.17g, 0]\n", k, k * CD);
    PUT("links:\n  L0: {points: {G0: [0, 0], A1: [%.17g, 0]}}\n", CA);
    for (int k = 1; k <= n; k++) {
        double arm = k % 2 ? CC : CA;
        PUT("  L%d: {points: {G%d: [0, 0], B%d: [%.17g, 0]", k, k, k, arm);
        if (k < n)
            PUT(", A%d: [%.17g, 0]", k + 1, -arm);
        PUT("}}\n");
    }
    for (int k = 1; k <= n; k++)
        PUT("  C%d: {points: {A%d: [0, 0], B%d: [%.17g, 0]}}\n", k, k, k, CB);
    PUT("driver: {link: L0, angle: {from: 60, to: 110, steps: 20}}\ninitial:\n");
    double phi, psi;
    loop1(60 * DEG, &phi, &psi);
    for (int k = 1; k <= n; k++)
        PUT("  L%d: %.17g\n  C%d: %.17g\n", k, (k % 2 ? phi : 60 * DEG + 180 * DEG) / DEG, k,
            psi / DEG);
    PUT("outputs: {points: [B%d, B%d], links: [L%d, C%d, L%d]}\n", n, n / 2, n, n, n / 2);
#undef PUT
    cr_assert_lt(len, cap);
    return s;
}

static double angle_diff(double a, double b) { return remainder(a - b, 2 * 3.14159265358979323846); }

Test(chain_compact, far_links_against_closed_form)
{
    char *text = chain_text(NLOOPS);
    mech_model *m = load_text(text);
    free(text);
    mech_table t = must_solve(m, NULL);
    cr_assert_geq(t.nrows, 21);
    char name[64];
    const int ks[2] = {NLOOPS, NLOOPS / 2};  /* odd (a rocker) and even (a crank) */
    double worst_pos = 0, worst_rate = 0;
    for (int r = 0; r < t.nrows; r++) {
        double q = table_at(&t, r, "q"), h = 1e-5;
        for (int i = 0; i < 2; i++) {
            int k = ks[i];
            double th = link_angle(k, q), arm = k % 2 ? CC : CA;
            double w = (link_angle(k, q + h) - link_angle(k, q - h)) / (2 * h);
            snprintf(name, sizeof name, "L%d.angle", k);
            worst_pos = fmax(worst_pos, fabs(angle_diff(table_at(&t, r, name), th)));
            snprintf(name, sizeof name, "L%d.omega", k);
            worst_rate = fmax(worst_rate, fabs(table_at(&t, r, name) - w));
            snprintf(name, sizeof name, "B%d.x", k);
            worst_pos = fmax(worst_pos, fabs(table_at(&t, r, name) - (k * CD + arm * cos(th))));
            snprintf(name, sizeof name, "B%d.y", k);
            worst_pos = fmax(worst_pos, fabs(table_at(&t, r, name) - arm * sin(th)));
            snprintf(name, sizeof name, "B%d.vx", k);
            worst_rate = fmax(worst_rate, fabs(table_at(&t, r, name) + arm * sin(th) * w));
            snprintf(name, sizeof name, "B%d.vy", k);
            worst_rate = fmax(worst_rate, fabs(table_at(&t, r, name) - arm * cos(th) * w));
        }
        double psi = coupler_angle(q);
        double wc = (coupler_angle(q + h) - coupler_angle(q - h)) / (2 * h);
        snprintf(name, sizeof name, "C%d.angle", NLOOPS);
        worst_pos = fmax(worst_pos, fabs(angle_diff(table_at(&t, r, name), psi)));
        snprintf(name, sizeof name, "C%d.omega", NLOOPS);
        worst_rate = fmax(worst_rate, fabs(table_at(&t, r, name) - wc));
    }
    cr_log_info("chain of %d loops: worst position error %.2e, rate error %.2e", NLOOPS,
                worst_pos, worst_rate);
    cr_expect_lt(worst_pos, 1e-12, "positions off the closed form by %g", worst_pos);
    cr_expect_lt(worst_rate, 1e-8, "rates off the closed form's differences by %g", worst_rate);
    mech_table_free(&t);
    mech_model_free(&m);
}
