/* src/codegen_state_loads.c: the loads that depend on the motion
 * (src/state_loads.h, docs/format.md section 10.2) in the force code of
 * `mech codegen` (docs/codegen.md, "Forces"). The model's register program
 * becomes straight-line C, one statement per input and per instruction,
 * run once per position before the force solve (force_state_loads, as
 * forces_solve runs state_loads_eval); the registers that hold constants
 * are written as literals. The loads then enter the right-hand side and
 * the power balance with state_loads_add's and state_loads_power's
 * operations in their order, so the results are the interpreter's bit for
 * bit. */
#include <stdlib.h>

#include "codegen.h"
#include "state_loads.h"

/* Register r as C: a literal for a constant, else the state's slot. */
static void reg_text(const state_loads *sl, int r, char *buf, size_t size)
{
    if (sl_is_const(sl, r))
        codegen_number(buf, size, sl->reg0[r]);
    else
        snprintf(buf, size, "s->slr[%d]", r);
}

static const state_loads *program(const codegen *g)
{
    const state_loads *sl = g->m->state_loads;
    return sl && sl->nloads > 0 ? sl : NULL;
}

void codegen_sl_state(const codegen *g, FILE *f)
{
    const state_loads *sl = program(g);
    if (sl)
        fprintf(f, "    double slr[%d];  /* registers of the loads that depend on the motion */\n",
                sl->nreg > 0 ? sl->nreg : 1);
}

/* The value of input in (state_loads.c input_value) as C. */
static int input_text(const codegen *g, const sl_input *in, char *buf, size_t size)
{
    const kin_tree *t = &g->sp.tree;
    static const char *const xs[] = {"s->x", "s->xd", "s->xdd"};
    static const char *const qs[] = {"q", "qd", "qdd"};
    switch ((sl_input_kind)in->kind) {
    case SLIN_PX: case SLIN_PY: case SLIN_PVX: case SLIN_PVY: case SLIN_PAX: case SLIN_PAY: {
        int l = t->point_link[in->index];
        if (l < 0)
            return -1;
        char r[96];
        codegen_point_xy(g->m, l, t->point_index[in->index], r, sizeof r);
        snprintf(buf, size, "on_link(&F[%d], %s, p, p + 2, p + 4), p[%d]", l, r,
                 in->kind - SLIN_PX);
        return 0;
    }
    case SLIN_ANGLE: snprintf(buf, size, "F[%d].th", in->index); return 0;
    case SLIN_OMEGA: snprintf(buf, size, "F[%d].om", in->index); return 0;
    case SLIN_ALPHA: snprintf(buf, size, "F[%d].al", in->index); return 0;
    case SLIN_S: case SLIN_SV: case SLIN_SA: {
        int var = t->slide_var[in->index], lv = in->kind - SLIN_S;
        if (var == g->sp.n)
            snprintf(buf, size, "%s", qs[lv]);
        else if (var >= 0 && var < g->sp.n && g->unk_col[var] >= 0)
            snprintf(buf, size, "%s[%d]", xs[lv], g->unk_col[var]);
        else
            snprintf(buf, size, "0.0");
        return 0;
    }
    case SLIN_DRIVER: snprintf(buf, size, "q"); return 0;
    case SLIN_DRIVER_SPEED: snprintf(buf, size, "qd"); return 0;
    case SLIN_DRIVER_ACCEL: snprintf(buf, size, "qdd"); return 0;
    }
    return -1;
}

/* One instruction as a C statement (state_loads.c sl_apply); 0, or -1 for
 * an operation this emitter does not know. */
static int emit_ins(const state_loads *sl, const sl_ins *c, FILE *f)
{
    char a[48], b[48];
    reg_text(sl, c->a, a, sizeof a);
    if (c->b >= 0)
        reg_text(sl, c->b, b, sizeof b);
    else
        snprintf(b, sizeof b, "0.0");
    fprintf(f, "    s->slr[%d] = ", c->d);
    switch ((sl_op)c->op) {
    case SLOP_ADD: fprintf(f, "%s + %s;\n", a, b); return 0;
    case SLOP_SUB: fprintf(f, "%s - %s;\n", a, b); return 0;
    case SLOP_MUL: fprintf(f, "%s * %s;\n", a, b); return 0;
    case SLOP_DIV: fprintf(f, "%s / %s;\n", a, b); return 0;
    case SLOP_NEG: fprintf(f, "-%s;\n", a); return 0;
    case SLOP_POWI: {
        int e = c->k < 0 ? -c->k : c->k;
        fprintf(f, "1.0;\n    {\n        double x = %s%s;\n", c->k < 0 ? "1.0 / " : "", a);
        fprintf(f, "        (void)x;\n        for (int e = %d; e > 0; e--)\n"
                   "            s->slr[%d] *= x;\n    }\n", e, c->d);
        return 0;
    }
    case SLOP_SIN: fprintf(f, "sin(%s);\n", a); return 0;
    case SLOP_COS: fprintf(f, "cos(%s);\n", a); return 0;
    case SLOP_TAN: fprintf(f, "tan(%s);\n", a); return 0;
    case SLOP_ATAN2: fprintf(f, "atan2(%s, %s);\n", a, b); return 0;
    case SLOP_SQRT: fprintf(f, "sqrt(%s);\n", a); return 0;
    case SLOP_ABS: fprintf(f, "fabs(%s);\n", a); return 0;
    case SLOP_MIN: fprintf(f, "%s < %s ? %s : %s;\n", a, b, a, b); return 0;
    case SLOP_MAX: fprintf(f, "%s > %s ? %s : %s;\n", a, b, a, b); return 0;
    case SLOP_EXP: fprintf(f, "exp(%s);\n", a); return 0;
    case SLOP_LOG: fprintf(f, "log(%s);\n", a); return 0;
    case SLOP_TANH: fprintf(f, "tanh(%s);\n", a); return 0;
    case SLOP_STEP: fprintf(f, "%s > 0.0 ? 1.0 : 0.0;\n", a); return 0;
    case SLOP_SIGN: fprintf(f, "%s > 0.0 ? 1.0 : %s < 0.0 ? -1.0 : 0.0;\n", a, a); return 0;
    case SLOP_SMOOTHSIGN: fprintf(f, "%s / sqrt(%s * %s + %s * %s);\n", a, a, a, b, b); return 0;
    }
    fprintf(f, "0.0;\n");
    return -1;
}

int codegen_sl_check(const codegen *g, mech_diag *d)
{
    const state_loads *sl = program(g);
    const mech_model *m = g->m;
    char buf[160];
    for (int i = 0; sl && i < sl->nin; i++)
        if (input_text(g, &sl->in[i], buf, sizeof buf) < 0)
            return diag_error(d, m->file, sl->loads[0].mark,
                              "codegen: a load that depends on the motion reads an input (kind "
                              "%d) the code generator does not know", sl->in[i].kind);
    for (int i = 0; sl && i < sl->nins; i++)
        if (sl->ins[i].op < 0 || sl->ins[i].op > SLOP_SMOOTHSIGN)
            return diag_error(d, m->file, sl->loads[0].mark,
                              "codegen: a load that depends on the motion uses an operation "
                              "(%d) the code generator does not know", sl->ins[i].op);
    return MECH_OK;
}

int codegen_sl_emit(const codegen *g, FILE *f)
{
    const state_loads *sl = program(g);
    fprintf(f, "/* The loads that depend on the motion: their register program, once per\n"
               " * position (src/state_loads.c state_loads_eval) */\n"
               "static void force_state_loads(cg_state *s, const cg_frame *F, double q, double qd,\n"
               "                              double qdd)\n{\n"
               "    (void)s, (void)F, (void)q, (void)qd, (void)qdd;\n");
    if (!sl)
        return fprintf(f, "}\n\n") < 0 ? -1 : 0;
    fprintf(f, "    double p[6];\n    (void)p;\n");
    int rc = 0;
    for (int i = 0; i < sl->nin; i++) {
        char v[160];
        if (input_text(g, &sl->in[i], v, sizeof v) < 0)
            rc = -1;
        fprintf(f, "    s->slr[%d] = (%s);\n", sl->in[i].reg, v);
    }
    for (int i = 0; i < sl->nins; i++)
        if (emit_ins(sl, &sl->ins[i], f) < 0)
            rc = -1;
    fprintf(f, "}\n\n");
    return rc;
}

/* rhs of link l for a force fx, fy at p and a moment t (state_loads.c add_load). */
static void emit_add(FILE *f, int l, const char *p0, const char *p1, const char *fx,
                     const char *fy, const char *t)
{
    if (l == 0)
        return;
    int row = 3 * (l - 1);
    fprintf(f, "        {\n            double r0 = %s - s->cg[%d], r1 = %s - s->cg[%d];\n"
               "            rhs[%d] -= %s;\n            rhs[%d] -= %s;\n"
               "            rhs[%d] -= r0 * %s - r1 * %s + %s;\n        }\n",
            p0, 2 * l, p1, 2 * l + 1, row, fx, row + 1, fy, row + 2, fy, fx, t);
}

/* The ends of line load l (state_loads.c state_loads_line): pe[2][2],
 * ve[2][2], u[2], len, rate. */
static void emit_line(const mech_model *m, const sl_load *l, FILE *f)
{
    char p0[96], p1[96];
    codegen_point_xy(m, l->link, l->point, p0, sizeof p0);
    codegen_point_xy(m, l->link2, l->point2, p1, sizeof p1);
    fprintf(f, "        double pe[2][2], ve[2][2], ae[2], u[2];\n"
               "        on_link(&F[%d], %s, pe[0], ve[0], ae);\n"
               "        on_link(&F[%d], %s, pe[1], ve[1], ae);\n"
               "        double dd[2] = {pe[1][0] - pe[0][0], pe[1][1] - pe[0][1]};\n"
               "        double len = hypot(dd[0], dd[1]);\n"
               "        u[0] = len > 0.0 ? dd[0] / len : 1.0;\n"
               "        u[1] = len > 0.0 ? dd[1] / len : 0.0;\n"
               "        double rate = u[0] * (ve[1][0] - ve[0][0]) + u[1] * (ve[1][1] - ve[0][1]);\n"
               "        (void)rate;\n",
            l->link, p0, l->link2, p1);
}

void codegen_sl_known(const codegen *g, FILE *f)
{
    const state_loads *sl = program(g);
    const mech_model *m = g->m;
    for (int i = 0; sl && i < sl->nloads; i++) {
        const sl_load *l = &sl->loads[i];
        char r0[48], r1[48], pt[96];
        reg_text(sl, l->reg[0], r0, sizeof r0);
        fprintf(f, "    {   /* load %d that depends on the motion (src/state_loads.c "
                   "state_loads_add) */\n", i);
        if (l->torque == 1) {
            fprintf(f, "        double t = %s;\n", r0);
            emit_add(f, l->link, "0.0", "0.0", "0.0", "0.0", "t");
        } else if (l->torque == 2) {
            emit_line(m, l, f);
            fprintf(f, "        double t = %s;\n"
                       "        double lf[2] = {t * u[0], t * u[1]}, fb[2] = {-lf[0], -lf[1]};\n"
                       "        (void)lf, (void)fb;\n", r0);
            emit_add(f, l->link, "pe[0][0]", "pe[0][1]", "lf[0]", "lf[1]", "0.0");
            emit_add(f, l->link2, "pe[1][0]", "pe[1][1]", "fb[0]", "fb[1]", "0.0");
        } else {
            reg_text(sl, l->reg[1], r1, sizeof r1);
            codegen_point_xy(m, l->link, l->point, pt, sizeof pt);
            fprintf(f, "        double lf[2] = {%s, %s}, lp[2], lv[2], la[2];\n"
                       "        on_link(&F[%d], %s, lp, lv, la);\n"
                       "        (void)lf, (void)lp;\n", r0, r1, l->link, pt);
            emit_add(f, l->link, "lp[0]", "lp[1]", "lf[0]", "lf[1]", "0.0");
        }
        fprintf(f, "    }\n");
    }
}

void codegen_sl_power(const codegen *g, FILE *f)
{
    const state_loads *sl = program(g);
    const mech_model *m = g->m;
    if (!sl)
        return;
    int angle = m->driver.kind == MECH_DRIVE_ANGLE;
    fprintf(f, "    {   /* the loads that depend on the motion (src/state_loads.c "
               "state_loads_power) */\n"
               "        double total = 0.0, speed = fabs(qd);\n"
               "        double linear = %s, turning = %s;\n"
               "        (void)linear, (void)turning;\n",
            angle ? "speed * LREF" : "speed", angle ? "speed" : "speed / LREF");
    for (int i = 0; i < sl->nloads; i++) {
        const sl_load *l = &sl->loads[i];
        char r0[48], r1[48], pt[96];
        reg_text(sl, l->reg[0], r0, sizeof r0);
        fprintf(f, "        {\n        double pw;\n");
        if (l->torque == 1) {
            fprintf(f, "        double t = %s;\n        pw = t * F[%d].om;\n"
                       "        scale += fabs(t) * turning;\n", r0, l->link);
        } else if (l->torque == 2) {
            emit_line(m, l, f);
            fprintf(f, "        double t = %s;\n        pw = -t * rate;\n"
                       "        scale += fabs(t) * linear;\n", r0);
        } else {
            reg_text(sl, l->reg[1], r1, sizeof r1);
            codegen_point_xy(m, l->link, l->point, pt, sizeof pt);
            fprintf(f, "        double lf[2] = {%s, %s}, lp[2], lv[2], la[2];\n"
                       "        on_link(&F[%d], %s, lp, lv, la);\n"
                       "        pw = lf[0] * lv[0] + lf[1] * lv[1];\n"
                       "        scale += hypot(lf[0], lf[1]) * linear;\n", r0, r1, l->link, pt);
        }
        fprintf(f, "        total += pw;\n        scale += fabs(pw);\n        }\n");
    }
    fprintf(f, "        ext += total;\n    }\n");
}
