/* src/codegen/codegen_state_loads.c: the loads that depend on the motion
 * (src/load/load.h, docs/format.md section 10.2) in the force code of
 * `mech codegen` (docs/codegen.md, "Forces"). The model's register program
 * becomes straight-line C, one statement per input and per instruction,
 * run once per position before the force solve (force_state_loads, as
 * forces_solve runs state_loads_eval), each instruction rt_sl_apply's (the
 * interpreter's operations); the registers that hold constants are
 * written as literals. The loads then enter the right-hand side and the
 * power balance as the force system's description says (rt_load entries
 * reading the registers: codegen_forces.c), so the results are the
 * interpreter's bit for bit. */
#include <stdlib.h>

#include "codegen.h"
#include "load.h"

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
        codegen_point_xy(g, l, t->point_index[in->index], r, sizeof r);
        snprintf(buf, size, "rt_on_link(&F[%d], %s, p, p + 2, p + 4), p[%d]", l, r,
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

/* One instruction as a C statement: rt_sl_apply (state_loads.c's sl_apply)
 * on registers or their constants. */
static void emit_ins(const state_loads *sl, const sl_ins *c, FILE *f)
{
    char a[48], b[48];
    reg_text(sl, c->a, a, sizeof a);
    if (c->b >= 0)
        reg_text(sl, c->b, b, sizeof b);
    else
        snprintf(b, sizeof b, "0.0");
    fprintf(f, "    s->slr[%d] = rt_sl_apply(%d, %s, %s, %d);\n", c->d, c->op, a, b, c->k);
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
        if (sl->ins[i].op < 0 || sl->ins[i].op >= RT_SL_COUNT)
            return diag_error(d, m->file, sl->loads[0].mark,
                              "codegen: a load that depends on the motion uses an operation "
                              "(%d) the code generator does not know", sl->ins[i].op);
    return MECH_OK;
}

int codegen_sl_emit(const codegen *g, FILE *f)
{
    const state_loads *sl = program(g);
    fprintf(f, "/* The loads that depend on the motion: their register program, once per\n"
               " * position (src/load/state_loads.c state_loads_eval) */\n"
               "static void force_state_loads(cg_state *s, const rt_frame *F, double q, double qd,\n"
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
        emit_ins(sl, &sl->ins[i], f);
    for (int i = 0; i < sl->nloads; i++)  /* the constants the loads read (rt_load.reg) */
        for (int k = 0; k < 2 && (k == 0 || sl->loads[i].torque == 0); k++)
            if (sl_is_const(sl, sl->loads[i].reg[k])) {
                char v[48];
                reg_text(sl, sl->loads[i].reg[k], v, sizeof v);
                fprintf(f, "    s->slr[%d] = %s;\n", sl->loads[i].reg[k], v);
            }
    fprintf(f, "}\n\n");
    return rc;
}
