/* tests/unit/test_system.c: the symbolic equations against independent
 * truths: derivatives against complex-step differentiation of the residual
 * (exact to rounding, so 1e-10 relative is a real bound), the tape against a
 * direct walk of the DAG (same operations, so bit-for-bit), file loops
 * against automatic loops at a closed-form four-bar pose, and the printed
 * four-bar equations against a reviewed golden text. */
#include <complex.h>
#include <criterion/criterion.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"
#include "equations.h"

/* ---- helpers ----------------------------------------------------------- */



static mech_system *build(const mech_model *m)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_system *s = NULL;
    int rc = mech_system_new(m, &s, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK, "system of %s", m->file);
    return s;
}

/* Complex evaluation of a DAG node (memo-free: test DAGs are small). */
static double complex ceval(const expr_ctx *c, ex e, const double complex *v)
{
    const expr_node *n = &c->nodes[e];
    switch (n->op) {
    case EX_CONST: return n->value;
    case EX_VAR: return v[n->var];
    case EX_ADD: return ceval(c, n->a, v) + ceval(c, n->b, v);
    case EX_MUL: return ceval(c, n->a, v) * ceval(c, n->b, v);
    case EX_NEG: return -ceval(c, n->a, v);
    case EX_SIN: return csin(ceval(c, n->a, v));
    case EX_COS: return ccos(ceval(c, n->a, v));
    case EX_CALL: break;  /* an opaque law: real only (the mechanisms here have none) */
    }
    cr_assert_fail("unknown op");
    return 0;
}

static unsigned rng_state = 12345u;
static double urand(void) /* uniform in [-1, 1), deterministic */
{
    rng_state = rng_state * 1103515245u + 12345u;
    return (double)(rng_state >> 8) / (double)(1u << 23) - 1.0;
}

/* A random state: angles anywhere, displacements of the mechanism's size. */
static void random_state(const mech_system *s, double size, double *vars)
{
    int n = s->n;
    for (int i = 0; i < SYS_NVARS(n); i++)
        vars[i] = 3.0 * urand();
    for (int i = 0; i < n; i++)
        if (s->unk_kind[i] == UNK_SLIDE) {
            vars[i] *= size;
            vars[SYS_VAR_XDOT(n, i)] *= size;
        }
    if (s->model->driver.kind == MECH_DRIVE_SLIDER) {
        vars[SYS_VAR_Q(n)] *= size;
        vars[SYS_VAR_QDOT(n)] *= size;
        vars[SYS_VAR_QDDOT(n)] *= size;
    }
}

static double mechanism_size(const mech_model *m)
{
    double size = 0;
    for (int l = 0; l < m->nlinks; l++)
        for (int p = 0; p < m->links[l].npoints; p++)
            size = fmax(size, hypot(m->links[l].points[p].x, m->links[l].points[p].y));
    return size > 0 ? size : 1.0;
}

/* Complex-step derivative of expression e along direction dir (per var). */
static double cstep(const mech_system *s, ex e, const double *vars, const double *dir)
{
    const double h = 1e-30;
    int nv = SYS_NVARS(s->n);
    double complex *v = malloc((size_t)nv * sizeof *v);
    for (int i = 0; i < nv; i++)
        v[i] = vars[i] + I * h * dir[i];
    double d = cimag(ceval(&s->ex, e, v)) / h;
    free(v);
    return d;
}

/* ---- derivatives of every mechanism ---------------------------------- */

static void check_derivatives(const char *path)
{
    mech_model *m = load_path(path);
    mech_system *s = build(m);
    int n = s->n, nv = SYS_NVARS(n);
    double size = mechanism_size(m);
    double *vars = calloc((size_t)nv, sizeof *vars), *dir = calloc((size_t)nv, sizeof *dir);
    double *J = calloc((size_t)n * (size_t)n, sizeof *J);
    for (int trial = 0; trial < 20; trial++) {
        random_state(s, size, vars);
        /* the Jacobian: every (row, col), pattern entries and structural zeros */
        memset(J, 0, (size_t)n * (size_t)n * sizeof *J);
        for (int j = 0; j < n; j++)
            for (int k = s->Jp[j]; k < s->Jp[j + 1]; k++)
                J[(size_t)s->Ji[k] * (size_t)n + (size_t)j] = expr_eval(&s->ex, s->Jx[k], vars);
        for (int j = 0; j <= n; j++) {  /* column n is df/dq */
            memset(dir, 0, (size_t)nv * sizeof *dir);
            dir[j] = 1.0;
            for (int r = 0; r < n; r++) {
                double want = cstep(s, s->f[r], vars, dir);
                double got = j < n ? J[(size_t)r * (size_t)n + (size_t)j]
                                   : expr_eval(&s->ex, s->fq[r], vars);
                /* scale: the row's largest possible term, the mechanism size */
                cr_assert(fabs(got - want) <= 1e-10 * size,
                          "%s: d f%d / d var%d: symbolic %.17g, complex step %.17g", path, r + 1,
                          j, got, want);
            }
        }
        /* velocity rhs = -f_q qdot */
        for (int r = 0; r < n; r++) {
            double want = -expr_eval(&s->ex, s->fq[r], vars) * vars[SYS_VAR_QDOT(n)];
            cr_assert(fabs(expr_eval(&s->ex, s->vel[r], vars) - want) <= 1e-12 * size * 10,
                      "%s: velocity rhs row %d", path, r + 1);
        }
        /* acceleration rhs: c = -d/dt (J xdot + f_q qdot) with xddot = 0,
         * along x(t) = x + xdot t, q(t) = q + qdot t, qdot(t) = qdot + qddot t */
        memset(dir, 0, (size_t)nv * sizeof *dir);
        for (int i = 0; i < n; i++)
            dir[i] = vars[SYS_VAR_XDOT(n, i)];
        dir[SYS_VAR_Q(n)] = vars[SYS_VAR_QDOT(n)];
        dir[SYS_VAR_QDOT(n)] = vars[SYS_VAR_QDDOT(n)];
        for (int r = 0; r < n; r++) {
            double dv = 0;  /* d/dt of row r of J xdot + f_q qdot */
            for (int j = 0; j < n; j++)
                for (int k = s->Jp[j]; k < s->Jp[j + 1]; k++)
                    if (s->Ji[k] == r)
                        dv += cstep(s, s->Jx[k], vars, dir) * vars[SYS_VAR_XDOT(n, j)];
            double complex fq_c;
            {
                const double h = 1e-30;
                double complex *v = malloc((size_t)nv * sizeof *v);
                for (int i = 0; i < nv; i++)
                    v[i] = vars[i] + I * h * dir[i];
                fq_c = ceval(&s->ex, s->fq[r], v) * v[SYS_VAR_QDOT(n)];
                free(v);
                dv += cimag(fq_c) / h;
            }
            double got = expr_eval(&s->ex, s->acc[r], vars);
            double scale = size * 100;  /* |terms| <= size * (3 rad/s)^2 and 3 rad/s^2 */
            cr_assert(fabs(got + dv) <= 1e-10 * scale,
                      "%s: acceleration rhs row %d: symbolic %.17g, complex step %.17g", path,
                      r + 1, got, -dv);
        }
    }
    free(vars);
    free(dir);
    free(J);
    mech_system_free(&s);
    mech_model_free(&m);
}

/* The tape computes the same operations as the DAG, in the same order. */
static void check_tape(const char *path)
{
    mech_model *m = load_path(path);
    mech_system *s = build(m);
    int n = s->n, nv = SYS_NVARS(n);
    double *vars = calloc((size_t)nv, sizeof *vars);
    double *f = calloc((size_t)n, sizeof *f), *Jx = calloc((size_t)s->nnz + 1, sizeof *Jx);
    double *b = calloc((size_t)n, sizeof *b), *c = calloc((size_t)n, sizeof *c);
    for (int trial = 0; trial < 10; trial++) {
        random_state(s, mechanism_size(m), vars);
        sys_eval_position(s, vars, vars[SYS_VAR_Q(n)], f, Jx);
        sys_eval_velocity_rhs(s, vars[SYS_VAR_QDOT(n)], b);
        sys_eval_accel_rhs(s, vars + SYS_VAR_XDOT(n, 0), vars[SYS_VAR_QDOT(n)],
                           vars[SYS_VAR_QDDOT(n)], c);
        for (int r = 0; r < n; r++) {
            cr_assert_eq(f[r], expr_eval(&s->ex, s->f[r], vars), "%s f%d", path, r + 1);
            cr_assert_eq(b[r], expr_eval(&s->ex, s->vel[r], vars), "%s b%d", path, r + 1);
            cr_assert_eq(c[r], expr_eval(&s->ex, s->acc[r], vars), "%s c%d", path, r + 1);
        }
        for (int k = 0; k < s->nnz; k++)
            cr_assert_eq(Jx[k], expr_eval(&s->ex, s->Jx[k], vars), "%s J[%d]", path, k);
    }
    free(vars);
    free(f);
    free(Jx);
    free(b);
    free(c);
    mech_system_free(&s);
    mech_model_free(&m);
}

/* The position phase with its driver-only part hoisted (tape_hoist, as the
 * solver runs it: the invariant part once per driver position, the rest per
 * Newton iteration) gives the same registers, bit for bit, as the whole
 * phase run each time; and the hoisted part is not empty (cos and sin of
 * the driver at least) but not everything. */
static void check_hoisted(const char *path)
{
    mech_model *m = load_path(path);
    mech_system *s = build(m);
    cr_assert_eq(sys_compile_tape(s), 0);
    int n = s->n, nv = SYS_NVARS(n);
    tape *t = &s->tp;
    double *reg = s->reg;
    double *vars = calloc((size_t)nv, sizeof *vars);
    double *whole = calloc((size_t)t->nreg + 1, sizeof *whole);
    unsigned char *inv = calloc((size_t)nv, 1);
    inv[SYS_VAR_Q(n)] = 1;
    tape_hoist(t, 0, inv);
    int hoisted = t->phase_split[0] - t->phase_start[0];
    cr_assert(hoisted > 0 && t->phase_split[0] < t->phase_start[1],
              "%s: %d of %d instructions hoisted", path, hoisted,
              t->phase_start[1] - t->phase_start[0]);
    for (int trial = 0; trial < 5; trial++) {
        random_state(s, mechanism_size(m), vars);
        for (int v = 0; v < nv; v++)
            tape_set_var(t, reg, v, vars[v]);
        tape_run_invariant(t, reg, 0);
        for (int it = 0; it < 3; it++) {  /* Newton iterations: x changes, q does not */
            for (int v = 0; v < n; v++) {
                vars[v] += 0.01 * (it + 1);
                tape_set_var(t, reg, v, vars[v]);
            }
            tape_run_variant(t, reg, 0);
            memcpy(whole, reg, (size_t)t->nreg * sizeof *whole);
            tape_run(t, reg, 0);
            for (int r = 0; r < t->nreg; r++)
                cr_assert(whole[r] == reg[r] || (whole[r] != whole[r] && reg[r] != reg[r]),
                          "%s: register %d %.17g hoisted, %.17g whole", path, r, whole[r],
                          reg[r]);
        }
    }
    free(vars);
    free(whole);
    free(inv);
    mech_system_free(&s);
    mech_model_free(&m);
}

/* Superinstructions (tape_fuse, after hoisting, as the solver compiles its
 * tape): fewer instructions, and every root still equal, bit for bit, to
 * the DAG's value, run whole or hoisted part then the rest. */
static void check_fused(const char *path)
{
    mech_model *m = load_path(path);
    mech_system *s = build(m);
    cr_assert_eq(sys_compile_tape(s), 0);
    int n = s->n, nv = SYS_NVARS(n);
    tape *t = &s->tp;
    double *vars = calloc((size_t)nv, sizeof *vars);
    double *f = calloc((size_t)n, sizeof *f), *Jx = calloc((size_t)s->nnz + 1, sizeof *Jx);
    double *b = calloc((size_t)n, sizeof *b), *c = calloc((size_t)n, sizeof *c);
    ex *pos = calloc((size_t)(n + s->nnz), sizeof *pos);
    memcpy(pos, s->f, (size_t)n * sizeof *pos);
    memcpy(pos + n, s->Jx, (size_t)s->nnz * sizeof *pos);
    const ex *roots[3] = {pos, s->vel, s->acc};
    int nroots[3] = {n + s->nnz, n, n};
    unsigned char *inv = calloc((size_t)nv, 1);
    inv[SYS_VAR_Q(n)] = 1;
    tape_hoist(t, 0, inv);
    int before = t->nins, regs_before = t->nreg;
    cr_assert_eq(tape_fuse(t, roots, nroots), 0);
    cr_assert(t->nreg < regs_before, "%s: %d registers before fusing, %d after (renumbered)",
              path, regs_before, t->nreg);
    cr_assert(t->nins < before, "%s: %d instructions before fusing, %d after", path, before,
              t->nins);
    free(s->reg);  /* the registers are renumbered: a register file made before is stale */
    s->reg = tape_registers_new(t);
    cr_assert_not_null(s->reg);
    for (int trial = 0; trial < 10; trial++) {
        random_state(s, mechanism_size(m), vars);
        if (trial % 2) {  /* the solver's way: hoisted part, then the rest */
            for (int v = 0; v < nv; v++)
                tape_set_var(t, s->reg, v, vars[v]);
            tape_run_invariant(t, s->reg, 0);
            tape_run_variant(t, s->reg, 0);
            for (int r = 0; r < n; r++)
                cr_assert_eq(tape_value(t, s->reg, s->f[r]),
                             expr_eval(&s->ex, s->f[r], vars), "%s f%d hoisted", path, r + 1);
        }
        sys_eval_position(s, vars, vars[SYS_VAR_Q(n)], f, Jx);
        sys_eval_velocity_rhs(s, vars[SYS_VAR_QDOT(n)], b);
        sys_eval_accel_rhs(s, vars + SYS_VAR_XDOT(n, 0), vars[SYS_VAR_QDOT(n)],
                           vars[SYS_VAR_QDDOT(n)], c);
        for (int r = 0; r < n; r++) {
            cr_assert_eq(f[r], expr_eval(&s->ex, s->f[r], vars), "%s f%d", path, r + 1);
            cr_assert_eq(b[r], expr_eval(&s->ex, s->vel[r], vars), "%s b%d", path, r + 1);
            cr_assert_eq(c[r], expr_eval(&s->ex, s->acc[r], vars), "%s c%d", path, r + 1);
        }
        for (int k = 0; k < s->nnz; k++)
            cr_assert_eq(Jx[k], expr_eval(&s->ex, s->Jx[k], vars), "%s J[%d]", path, k);
    }
    void *blocks[] = {vars, f, Jx, b, c, pos, inv};
    for (size_t i = 0; i < sizeof blocks / sizeof *blocks; i++)
        free(blocks[i]);
    mech_system_free(&s);
    mech_model_free(&m);
}

static int for_each_mechanism(void (*fn)(const char *))
{
    DIR *dir = opendir("mechanisms");
    cr_assert_not_null(dir, "run the tests from the repository root");
    struct dirent *e;
    int count = 0;
    while ((e = readdir(dir)) != NULL) {
        size_t len = strlen(e->d_name);
        if (len < 6 || strcmp(e->d_name + len - 5, ".yaml") != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, "mechanisms/%s", e->d_name);
        fn(path);
        count++;
    }
    closedir(dir);
    return count;
}

Test(system, derivatives_match_complex_step_for_every_mechanism)
{
    cr_assert_geq(for_each_mechanism(check_derivatives), 2);
}

Test(system, tape_matches_dag_bit_for_bit)
{
    cr_assert_geq(for_each_mechanism(check_tape), 2);
}

Test(system, hoisted_tape_matches_the_whole_phase)
{
    cr_assert_geq(for_each_mechanism(check_hoisted), 2);
}

Test(system, fused_tape_matches_dag_bit_for_bit)
{
    cr_assert_geq(for_each_mechanism(check_fused), 2);
}

/* ---- loops from the file against automatic loops --------------------- */

static const char *fourbar_yaml =
    "name: four-bar\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0], C: [70, 0]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [20, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
    "  rocker: {points: {C: [0, 0], B: [50, 0]}}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 4}}\n";

/* Closed-form pose: B is where circles (A, 60 mm) and (C, 50 mm) meet, above AC. */
static void fourbar_pose(double q, double *th_coupler, double *th_rocker)
{
    double ax = 0.02 * cos(q), ay = 0.02 * sin(q), cx = 0.07, cy = 0.0;
    double dx = cx - ax, dy = cy - ay, d = hypot(dx, dy);
    double a = (0.06 * 0.06 - 0.05 * 0.05 + d * d) / (2 * d), h = sqrt(0.06 * 0.06 - a * a);
    double bx = ax + a * dx / d - h * dy / d, by = ay + a * dy / d + h * dx / d;
    *th_coupler = atan2(by - ay, bx - ax);
    *th_rocker = atan2(by - cy, bx - cx);
}

static void residual_at_pose(const char *text, double q, double *f)
{
    mech_model *m = load_text(text);
    mech_system *s = build(m);
    cr_assert_eq(s->n, 2);
    double x[2], J[8];
    fourbar_pose(q, &x[s->link_var[mech_find_link(m, "coupler")]],
                 &x[s->link_var[mech_find_link(m, "rocker")]]);
    sys_eval_position(s, x, q, f, J);
    mech_system_free(&s);
    mech_model_free(&m);
}

Test(system, file_loops_and_automatic_loops_close_at_a_closed_form_pose)
{
    char with_loops[2048];
    snprintf(with_loops, sizeof with_loops, "%sloops: [[O, A, B, C, O]]\n", fourbar_yaml);
    for (int k = 0; k < 12; k++) {
        double q = 0.5 * k, fa[2], fb[2];
        residual_at_pose(fourbar_yaml, q, fa);
        residual_at_pose(with_loops, q, fb);
        for (int r = 0; r < 2; r++) {
            /* 1e-16 m: rounding of sums of a few 0.05 m terms */
            cr_assert(fabs(fa[r]) < 1e-16 && fabs(fb[r]) < 1e-16,
                      "q=%g row %d: automatic %.3g, file %.3g", q, r, fa[r], fb[r]);
        }
    }
}

Test(system, a_loop_step_off_every_link_is_reported)
{
    char text[2048];
    snprintf(text, sizeof text, "%sloops: [[O, A, C, O]]\n", fourbar_yaml);
    mech_model *m = load_text(text);
    mech_diag d;
    mech_diag_init(&d);
    mech_system *s = NULL;
    cr_assert_eq(mech_system_new(m, &s, &d), MECH_EINPUT);
    cr_assert_geq(d.count, 1);
    cr_assert_str_eq(d.entries[0].message,
                     "loop step A -> C lies on no single link and crosses no slider");
    cr_assert_eq(d.entries[0].mark.line, 9);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* ---- the printed equations ------------------------------------------- */

Test(system, printed_fourbar_equations_match_the_reviewed_golden_text)
{
    mech_model *m = load_path("mechanisms/fourbar.yaml");
    mech_system *s = build(m);
    char *buf = NULL;
    size_t len = 0;
    FILE *mem = open_memstream(&buf, &len);
    mech_system_print(s, MECH_FORMAT_TEXT, mem);
    fclose(mem);
    FILE *g = fopen("tests/golden/fourbar.equations.txt", "r");
    cr_assert_not_null(g, "missing tests/golden/fourbar.equations.txt");
    char *want = calloc(1, 1 << 16);
    size_t wlen = fread(want, 1, (1 << 16) - 1, g);
    fclose(g);
    want[wlen] = '\0';
    cr_assert_str_eq(buf, want, "printed equations differ from the golden text:\n%s", buf);
    free(want);
    free(buf);
    mech_system_free(&s);
    mech_model_free(&m);
}
