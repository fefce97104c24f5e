/* tests/unit/test_params.c: parameters kept symbolic. The printed
 * equations with the user's names against reviewed golden texts
 * (tests/golden/equations/), the LaTeX's structure balanced for every
 * mechanism (pdflatex is not installed everywhere), and the derivatives of
 * the points' coordinates by a parameter (forward mode through the quantity
 * expressions) against hand derivatives. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"
#include "param_grad.h"
#include "system.h"

static const double M_PI_ = 3.14159265358979323846;

static char *printed(const char *path, mech_format fmt)
{
    mech_model *m = load_path(path);
    mech_diag d;
    mech_diag_init(&d);
    mech_system *s = NULL;
    int rc = mech_system_new_named(m, &s, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    cr_assert_eq(rc, MECH_OK, "%s: no named system", path);
    char *buf = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&buf, &len);
    mech_system_print(s, fmt, mem);
    fclose(mem);
    mech_system_free(&s);
    mech_model_free(&m);
    mech_diag_free(&d);
    return buf;
}

static char *slurp(const char *path)
{
    FILE *f = fopen(path, "r");
    cr_assert_not_null(f, "missing %s", path);
    char *text = calloc(1, 1 << 18);
    size_t n = fread(text, 1, (1 << 18) - 1, f);
    fclose(f);
    text[n] = '\0';
    return text;
}

static void check_golden(const char *name, mech_format fmt)
{
    char path[256], golden[256];
    snprintf(path, sizeof path, "mechanisms/%s.yaml", name);
    snprintf(golden, sizeof golden, "tests/golden/equations/%s.%s", name,
             fmt == MECH_FORMAT_LATEX ? "tex" : "txt");
    char *got = printed(path, fmt), *want = slurp(golden);
    cr_assert_str_eq(got, want, "%s differs; printed:\n%s", golden, got);
    free(got);
    free(want);
}

Test(params, offset_slider_crank_prints_r_l_and_e)
{
    char *t = printed("mechanisms/offset-slider-crank.yaml", MECH_FORMAT_TEXT);
    cr_expect(strstr(t, "f1 = l*cos(th_rod) - x_B + r*cos(th_crank)"), "%s", t);
    cr_expect(strstr(t, "f2 = l*sin(th_rod) - e + r*sin(th_crank)"), "%s", t);
    cr_expect(strstr(t, "l*cos(th_rod)*th_rod'^2"), "squares as x^2: %s", t);
    const char *eqs = strstr(t, "position equations");
    cr_assert_not_null(eqs);
    cr_expect(!strstr(eqs, "0.04") && !strstr(eqs, "0.12") && !strstr(eqs, "0.03"),
              "a parameter folded into a number: %s", eqs);
    free(t);
}

Test(params, equations_match_the_reviewed_golden_texts)
{
    static const char *const names[] = {"offset-slider-crank", "conveyor", "stirling"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        check_golden(names[i], MECH_FORMAT_TEXT);
        check_golden(names[i], MECH_FORMAT_LATEX);
    }
}

/* Braces, \left/\right and \begin/\end pair up, and every $ is closed. */
static void check_balanced(const char *name, const char *t)
{
    int brace = 0, left = 0, dollars = 0, env = 0;
    for (const char *p = t; *p; p++) {
        if (*p == '\\' && (p[1] == '{' || p[1] == '}' || p[1] == '$' || p[1] == '_')) {
            p++;  /* an escaped character */
            continue;
        }
        brace += *p == '{' ? 1 : *p == '}' ? -1 : 0;
        dollars += *p == '$';
        cr_assert_geq(brace, 0, "%s: '}' without '{' at offset %td", name, p - t);
        if (strncmp(p, "\\left", 5) == 0)
            left++;
        if (strncmp(p, "\\right", 6) == 0)
            left--;
        if (strncmp(p, "\\begin{", 7) == 0)
            env++;
        if (strncmp(p, "\\end{", 5) == 0)
            env--;
        cr_assert_geq(left, 0, "%s: \\right without \\left", name);
    }
    cr_expect_eq(brace, 0, "%s: %d braces open", name, brace);
    cr_expect_eq(left, 0, "%s: %d \\left open", name, left);
    cr_expect_eq(env, 0, "%s: %d environments open", name, env);
    cr_expect_eq(dollars % 2, 0, "%s: a $ is not closed", name);
}

Test(params, latex_is_balanced_for_every_mechanism)
{
    static const char *const names[] = {"conveyor", "double-crank", "fourbar", "jansen",
                                        "offset-slider-crank", "quick-return", "slider-crank",
                                        "stephenson-six-bar", "stirling", "watt-six-bar"};
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        char path[128];
        snprintf(path, sizeof path, "mechanisms/%s.yaml", names[i]);
        char *t = printed(path, MECH_FORMAT_LATEX);
        check_balanced(names[i], t);
        free(t);
    }
}

/* ---- d(point)/d(parameter) ------------------------------------------- */

static const char polar_yaml[] =
    "name: polar\n"
    "units: {length: mm, angle: deg}\n"
    "parameters:\n"
    "  r: 40 mm\n"
    "  phi: 30 deg\n"
    "  l: 3*r + 10 mm\n"
    "  k: 25\n"                              /* bare: adopts mm where it is used */
    "ground: {O: [0, 0], C: [l, k]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: {length: r, angle: phi}}}\n"
    "  rod: {points: {A: [0, 0], B: [sqrt(l^2 + r^2), r/2], D: {length: 2*r, angle: 90, from: B}}}\n"
    "  rocker: {points: {C: [0, 0], B: [50, 0]}}\n"
    "driver: {link: crank, angle: {from: 0, to: 90, steps: 2}}\n";

/* d(x, y)/dp of point `pt` of link `link` for the parameter at index k. */
static void grad_of(const param_grad *g, const mech_model *m, int k, const char *link,
                    const char *pt, double *dx, double *dy)
{
    int base = 0, l = mech_find_link(m, link);
    cr_assert_geq(l, 0);
    for (int i = 0; i < l; i++)
        base += m->links[i].npoints;
    for (int i = 0; i < m->links[l].npoints; i++)
        if (strcmp(m->links[l].points[i].name, pt) == 0) {
            *dx = g->dxy[k][2 * (base + i)];
            *dy = g->dxy[k][2 * (base + i) + 1];
            return;
        }
    cr_assert_fail("no point %s in %s", pt, link);
}

Test(params, point_derivatives_match_hand_derivatives)
{
    FILE *f = fopen("build/test_params_polar.yaml", "w");
    cr_assert_not_null(f);
    fputs(polar_yaml, f);
    fclose(f);
    mech_model *m = load_path("build/test_params_polar.yaml");
    param_grad g;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(pgrad_build(m, NULL, 0, NULL, 0, 0, &g, &d), MECH_OK);
    const double r = 0.04, phi = M_PI_ / 6, l = 3 * r + 0.01, h = sqrt(l * l + r * r);
    double dx, dy;
    /* A = r (cos phi, sin phi) */
    grad_of(&g, m, 0, "crank", "A", &dx, &dy);
    cr_expect(fabs(dx - cos(phi)) < 1e-15 && fabs(dy - sin(phi)) < 1e-15, "dA/dr %g %g", dx, dy);
    grad_of(&g, m, 1, "crank", "A", &dx, &dy);
    cr_expect(fabs(dx + r * sin(phi)) < 1e-17 && fabs(dy - r * cos(phi)) < 1e-17, "dA/dphi");
    /* C = (l, k mm) with l = 3 r + 10 mm: dC/dr = (3, 0), dC/dl = (1, 0), dC/dk = (0, 1e-3) */
    grad_of(&g, m, 0, "ground", "C", &dx, &dy);
    cr_expect(dx == 3.0 && dy == 0.0, "dC/dr %g %g", dx, dy);
    grad_of(&g, m, 2, "ground", "C", &dx, &dy);
    cr_expect(dx == 1.0 && dy == 0.0, "dC/dl %g %g (l's own derivative is 1)", dx, dy);
    grad_of(&g, m, 3, "ground", "C", &dx, &dy);
    cr_expect(dx == 0.0 && fabs(dy - 1e-3) < 1e-18, "dC/dk %g %g", dx, dy);
    /* B = (sqrt(l^2 + r^2), r/2): dB/dr = (r/h + 3 l/h, 1/2) through l = 3r + 10 mm */
    grad_of(&g, m, 0, "rod", "B", &dx, &dy);
    cr_expect(fabs(dx - (r + 3 * l) / h) < 1e-14 && fabs(dy - 0.5) < 1e-15, "dB/dr %.17g", dx);
    /* D = B + 2 r (cos 90, sin 90): dD/dr = dB/dr + (2 cos 90, 2) */
    double bx = dx;
    grad_of(&g, m, 0, "rod", "D", &dx, &dy);
    cr_expect(fabs(dx - (bx + 2 * cos(M_PI_ / 2))) < 1e-14 && fabs(dy - 2.5) < 1e-14,
              "dD/dr %.17g %.17g", dx, dy);
    pgrad_free(&g);
    mech_diag_free(&d);
    mech_model_free(&m);
}
