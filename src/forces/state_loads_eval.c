/* src/forces/state_loads_eval.c: the register program of the loads that depend on
 * the motion (state_loads.c builds it at load time) run once per step, from
 * the solved motion, before the force solve. */
#include <math.h>

#include "forces.h"

static double var_at(const double *x, int var) { return var >= 0 && x ? x[var] : 0.0; }

static double input_value(const sl_input *in, const solver *sv)
{
    const kin_tree *t = &sv->p->tree;
    const kin_state *ks = &sv->ks;
    double p[2], v[2], a[2];
    switch ((sl_input_kind)in->kind) {
    case SLIN_PX: case SLIN_PY: case SLIN_PVX: case SLIN_PVY: case SLIN_PAX: case SLIN_PAY:
        kin_point(t, ks, in->index, p, v, a);
        switch (in->kind) {
        case SLIN_PX: return p[0];
        case SLIN_PY: return p[1];
        case SLIN_PVX: return v[0];
        case SLIN_PVY: return v[1];
        case SLIN_PAX: return a[0];
        default: return a[1];
        }
    case SLIN_ANGLE: return ks->F[in->index].th;
    case SLIN_OMEGA: return ks->F[in->index].om;
    case SLIN_ALPHA: return ks->F[in->index].al;
    case SLIN_S: return var_at(sv->pos, t->slide_var[in->index]);
    case SLIN_SV: return var_at(sv->vel, t->slide_var[in->index]);
    case SLIN_SA: return var_at(sv->acc, t->slide_var[in->index]);
    case SLIN_DRIVER: return sv->pub_q;
    case SLIN_DRIVER_SPEED: return sv->pub_qd;
    case SLIN_DRIVER_ACCEL: return sv->pub_qdd;
    }
    return 0.0;
}

void state_loads_eval(const state_loads *s, const solver *sv, double *reg)
{
    if (!s)
        return;
    for (int i = 0; i < s->nin; i++)
        reg[s->in[i].reg] = input_value(&s->in[i], sv);
    for (int i = 0; i < s->nins; i++) {
        const sl_ins *c = &s->ins[i];
        reg[c->d] = sl_apply(c->op, reg[c->a], c->b >= 0 ? reg[c->b] : 0.0, c->k);
    }
}
