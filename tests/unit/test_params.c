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
#include "load.h"
#include "equations.h"

static const double M_PI_ = 3.14159265358979323846;

static char *printed(const char *path, mech_format fmt)
{
    mech_model *m = load_path(path);
    char *buf = system_text(m, fmt, 1);
    mech_model_free(&m);
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
static void grad_of(const mech_model *m, int k, const char *link, const char *pt, double *dx,
                    double *dy)
{
    int base = 0, l = mech_find_link(m, link), total = 0;
    cr_assert_geq(l, 0);
    for (int i = 0; i < m->nlinks; i++)
        total += m->links[i].npoints;
    double *g = calloc(2 * (size_t)total, sizeof *g);
    cr_assert_eq(pexpr_point_gradient(m, k, g), 0);
    for (int i = 0; i < l; i++)
        base += m->links[i].npoints;
    for (int i = 0; i < m->links[l].npoints; i++)
        if (strcmp(m->links[l].points[i].name, pt) == 0) {
            *dx = g[2 * (base + i)];
            *dy = g[2 * (base + i) + 1];
            free(g);
            return;
        }
    cr_assert_fail("no point %s in %s", pt, link);
}

Test(params, point_derivatives_match_hand_derivatives)
{
    mech_model *m = load_text(polar_yaml);  /* from memory: no file to read again */
    const double r = 0.04, phi = M_PI_ / 6, l = 3 * r + 0.01, h = sqrt(l * l + r * r);
    double dx, dy;
    /* A = r (cos phi, sin phi) */
    grad_of(m, 0, "crank", "A", &dx, &dy);
    cr_expect(fabs(dx - cos(phi)) < 1e-15 && fabs(dy - sin(phi)) < 1e-15, "dA/dr %g %g", dx, dy);
    grad_of(m, 1, "crank", "A", &dx, &dy);
    cr_expect(fabs(dx + r * sin(phi)) < 1e-17 && fabs(dy - r * cos(phi)) < 1e-17, "dA/dphi");
    /* C = (l, k mm) with l = 3 r + 10 mm: dC/dr = (3, 0), dC/dl = (1, 0), dC/dk = (0, 1e-3) */
    grad_of(m, 0, "ground", "C", &dx, &dy);
    cr_expect(dx == 3.0 && dy == 0.0, "dC/dr %g %g", dx, dy);
    grad_of(m, 2, "ground", "C", &dx, &dy);
    cr_expect(dx == 1.0 && dy == 0.0, "dC/dl %g %g (l's own derivative is 1)", dx, dy);
    grad_of(m, 3, "ground", "C", &dx, &dy);
    cr_expect(dx == 0.0 && fabs(dy - 1e-3) < 1e-18, "dC/dk %g %g", dx, dy);
    /* B = (sqrt(l^2 + r^2), r/2): dB/dr = (r/h + 3 l/h, 1/2) through l = 3r + 10 mm */
    grad_of(m, 0, "rod", "B", &dx, &dy);
    cr_expect(fabs(dx - (r + 3 * l) / h) < 1e-14 && fabs(dy - 0.5) < 1e-15, "dB/dr %.17g", dx);
    /* D = B + 2 r (cos 90, sin 90): dD/dr = dB/dr + (2 cos 90, 2) */
    double bx = dx;
    grad_of(m, 0, "rod", "D", &dx, &dy);
    cr_expect(fabs(dx - (bx + 2 * cos(M_PI_ / 2))) < 1e-14 && fabs(dy - 2.5) < 1e-14,
              "dD/dr %.17g %.17g", dx, dy);
    mech_model_free(&m);
}

/* ---- the model's parameter expressions ------------------------------------ */

/* Every number the loader keeps an expression of, in one order: the points'
 * x and y, the sliders' angles, the gears' radii and phases, the links'
 * mass, inertia and center; into v (the model's numbers) and h (their
 * handles). The count. */
static int tracked(const mech_model *m, double *v, int *h)
{
    const param_exprs *pe = m->pexpr;
    int n = 0;
    for (int l = 0; l < m->nlinks; l++)
        for (int i = 0; i < m->links[l].npoints; i++)
            for (int c = 0; c < 2; c++, n++) {
                v[n] = c ? m->links[l].points[i].y : m->links[l].points[i].x;
                h[n] = pexpr_point(pe, l, i, c);
            }
    for (int j = 0; j < m->njoints; j++, n++) {
        v[n] = m->joints[j].angle;
        h[n] = pexpr_get(pe, PXN_SLIDER_ANGLE, j);
    }
    for (int g = 0; g < m->ngears; g++)
        for (int k = 0; k < 4; k++, n++) {
            v[n] = k < 2 ? m->gears[g].radius[k] : m->gears[g].offset[k - 2];
            h[n] = pexpr_get(pe, PXN_GEAR, 4 * g + k);
        }
    for (int l = 0; l < m->nlinks; l++)
        for (int k = 0; k < 4; k++, n++) {
            const mech_link *lk = &m->links[l];
            v[n] = k == 0 ? lk->mass : k == 1 ? lk->inertia : lk->center[k - 2];
            h[n] = pexpr_get(pe, PXN_MASS, 4 * l + k);
        }
    return n;
}

enum { MAX_TRACKED = 4096 };

/* A model's expressions evaluated again from its parameters' values give
 * every node's value and every tracked number bit for bit (the tree records
 * the operations the loader did); returns the tracked numbers with a tree. */
static int check_faithful(const mech_model *m, const char *what)
{
    const param_exprs *pe = m->pexpr;
    if (!pe)
        return 0;
    double *pv = calloc((size_t)m->nparams + 1, sizeof *pv);
    double *out = calloc((size_t)pe->n + 1, sizeof *out);
    static double v[MAX_TRACKED];
    static int h[MAX_TRACKED];
    for (int k = 0; k < m->nparams; k++)
        pv[k] = m->params[k].value;
    pexpr_eval(pe, pv, out);
    for (int i = 0; i < pe->n; i++)
        cr_assert(memcmp(&out[i], &pe->node[i].value, sizeof out[i]) == 0,
                  "%s: node %d (op %d) re-evaluates to %.17g, recorded %.17g", what, i,
                  pe->node[i].op, out[i], pe->node[i].value);
    int n = tracked(m, v, h), moved = 0;
    for (int k = 0; k < n; k++)
        if (h[k] >= 0) {
            moved++;
            cr_assert(memcmp(&out[h[k]], &v[k], sizeof v[k]) == 0,
                      "%s: tracked number %d is %.17g, its expression %.17g", what, k, v[k],
                      out[h[k]]);
        }
    free(pv);
    free(out);
    return moved;
}

Test(params, expressions_give_every_number_of_every_mechanism_bit_for_bit)
{
    static const char *const names[] = {"conveyor", "double-crank", "jansen", "offset-slider-crank",
                                        "quick-return", "shaper", "slider-crank",
                                        "spring-slider-crank", "stephenson-six-bar", "stirling",
                                        "stirling-gas", "watt-six-bar"};
    int moved = 0;
    for (size_t i = 0; i < sizeof names / sizeof *names; i++) {
        char path[128];
        snprintf(path, sizeof path, "mechanisms/%s.yaml", names[i]);
        mech_model *m = load_path(path);
        cr_assert_not_null(m->pexpr, "%s has parameters", path);
        moved += check_faithful(m, path);
        mech_model_free(&m);
    }
    mech_model *m = load_text(polar_yaml);
    moved += check_faithful(m, "polar");
    mech_model_free(&m);
    cr_assert_gt(moved, 100, "only %d numbers have an expression", moved);
}

/* Parameters in a slider's angle, a gear pair (the module from the pivots'
 * distance, the phase), masses and polar points, through every operation. */
static const char geared_yaml[] =
    "name: geared, with parameters everywhere\n"
    "units: {length: mm, angle: deg}\n"
    "parameters: {d: 60 mm, ph: 90, al: 10, w: 15 mm, rho: 2 kg/m}\n"
    "ground: {O: [0, 0], C: [d, 0], G: [0, -40]}\n"
    "links:\n"
    "  crank1: {points: {O: [0, 0], A: [w, 0]}, mass: rho*w, center: [w/2, 0],"
    " inertia: rho*w^3/12}\n"
    "  crank2: {points: {C: [0, 0], D: {length: w, angle: al}}, mass: 0.3 kg, center: D,"
    " inertia: 2.4e-4 kg*m^2}\n"
    "  coupler: {points: {A: [0, 0], B: [d, 0], P: {length: sqrt(d^2 + w^2)/2,"
    " angle: \"-atan2(w, d)\", from: B}}}\n"
    "  rod: {points: {D: [0, 0], B: [d, 0], Q: [w*d/(w + d), w*cos(al) - w*sin(al)*tan(al)]}}\n"
    "  block: {points: {S: [0, 0], B: [w, 0]}}\n"
    "joints:\n"
    "  - {slider: S, link: block, on: ground, through: G, angle: al + 80}\n"
    "driver: {link: crank1, angle: {from: 0, to: 90, steps: 2}}\n"
    "gears:\n"
    "  - {name: g12, gear: crank1, with: crank2, teeth: [20, 40], offset: [0, ph]}\n";

/* The tracked numbers of geared_yaml with parameter `name` set to `value` (SI). */
static int numbers_with(const char *name, double value, const char *unit, double *v, int *h)
{
    const char *path = "build/test_params_geared.yaml";
    FILE *f = fopen(path, "w");
    cr_assert_not_null(f);
    fputs(geared_yaml, f);
    fclose(f);
    mech_model *m = load_with_value(path, name, value, unit);
    int n = tracked(m, v, h);
    mech_model_free(&m);
    remove(path);
    return n;
}

/* d(number)/d(parameter) of every tracked number against central
 * differences of whole loads with the parameter replaced. */
Test(params, expression_derivatives_match_central_differences)
{
    mech_model *m = NULL;
    mech_diag dg;
    mech_diag_init(&dg);
    int rc = mech_load_string(geared_yaml, strlen(geared_yaml), "<geared>", &m, &dg);
    if (rc != MECH_OK)
        mech_diag_print(&dg, stderr);
    mech_diag_free(&dg);
    cr_assert_eq(rc, MECH_OK);
    cr_assert_geq(check_faithful(m, "geared"), 15, "the geared model's numbers move");
    static double v[MAX_TRACKED], vp[MAX_TRACKED], vm[MAX_TRACKED];
    static int h[MAX_TRACKED], hh[MAX_TRACKED];
    int n = tracked(m, v, h), nonzero = 0;
    double *d = calloc((size_t)m->pexpr->n + 1, sizeof *d);
    for (int p = 0; p < m->nparams; p++) {
        const mech_param *pp = &m->params[p];
        double step = 1e-6 * fabs(pp->value);
        cr_assert_eq(numbers_with(pp->name, pp->value + step, pp->unit, vp, hh), n);
        cr_assert_eq(numbers_with(pp->name, pp->value - step, pp->unit, vm, hh), n);
        pexpr_derivatives(m->pexpr, p, d);
        for (int k = 0; k < n; k++) {
            double exact = pexpr_deriv_of(d, h[k]), fd = (vp[k] - vm[k]) / (2 * step);
            nonzero += exact != 0.0;
            cr_expect(fabs(exact - fd) <= 1e-6 * fmax(1.0, fabs(exact)),
                      "d(number %d)/d(%s): %.12g, central difference %.12g", k, pp->name,
                      exact, fd);
        }
    }
    cr_assert_gt(nonzero, 20, "%d derivatives are not zero", nonzero);
    free(d);
    mech_model_free(&m);
}

/* The expressions of m are those of the reference r: the same nodes and the
 * same handles for every tracked number. */
static void same_expressions(const mech_model *m, const mech_model *r, long k)
{
    static double vm[MAX_TRACKED], vr[MAX_TRACKED];
    static int hm[MAX_TRACKED], hr[MAX_TRACKED];
    cr_assert_not_null(m->pexpr, "allocation %ld failed: no expressions", k);
    cr_assert_eq(m->pexpr->n, r->pexpr->n, "allocation %ld failed: nodes missing", k);
    for (int i = 0; i < r->pexpr->n; i++) {
        const px_node *a = &m->pexpr->node[i], *b = &r->pexpr->node[i];
        cr_assert(a->op == b->op && a->a == b->a && a->b == b->b && a->c == b->c &&
                  memcmp(&a->value, &b->value, sizeof a->value) == 0,
                  "allocation %ld failed: node %d differs", k, i);
    }
    int n = tracked(m, vm, hm);
    cr_assert_eq(n, tracked(r, vr, hr));
    cr_assert(memcmp(hm, hr, (size_t)n * sizeof *hm) == 0, "allocation %ld failed: handles", k);
}

/* Allocation k of a load that records the parameter expressions, and of the
 * named system built from them, fails for k = 1, 2, ...: either an "out of
 * memory" error, or (an allocation the loader can do without, such as a
 * "did you mean" index) the whole expressions, never a model or a system
 * with expressions missing. */
static int load_failing_at(const char *text, long k, int named)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL, *ref = NULL;
    mech_system *s = NULL;
    cr_assert_eq(mech_load_string(text, strlen(text), "<oom>", &ref, &d), MECH_OK);
    xalloc_fail_countdown = named ? 0 : k;
    int rc = mech_load_string(text, strlen(text), "<oom>", &m, &d);
    if (named && rc == MECH_OK) {
        xalloc_fail_countdown = k;
        rc = mech_system_new_named(m, &s, &d);
    }
    int failed = xalloc_fail_countdown == 0;
    xalloc_fail_countdown = 0;
    if (failed && rc != MECH_OK) {
        cr_assert_null(named ? (void *)s : (void *)m);
        int oom = 0;
        for (size_t i = 0; i < d.count; i++)
            oom |= strstr(d.entries[i].message, "out of memory") != NULL;
        cr_assert(oom, "allocation %ld failed: %zu errors, none 'out of memory'", k, d.count);
    } else {
        cr_assert_eq(rc, MECH_OK, "allocation %ld did not fail: status %d", k, rc);
        same_expressions(m, ref, k);
    }
    if (named && failed && rc == MECH_OK)
        cr_assert_fail("allocation %ld of the named system failed, yet it was built", k);
    mech_system_free(&s);
    mech_model_free(&m);
    mech_model_free(&ref);
    mech_diag_free(&d);
    return failed;
}

Test(params, every_failed_allocation_of_the_expressions_is_reported)
{
    for (int named = 0; named < 2; named++) {
        long k = 1;
        while (load_failing_at(polar_yaml, k, named))
            k++;
        cr_assert_gt(k, 50, "only %ld allocations were tried", k);
    }
    long k = 1;
    while (load_failing_at(geared_yaml, k, 0))
        k++;
}
