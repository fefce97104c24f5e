/* src/load/state_loads.c: the register program of the loads that depend on the
 * motion (src/load/load.h): building it (constants folded as they are
 * made; state_loads_eval.c runs it once per step); the loads
 * enter the force rows and the power balance as forces.c describes them
 * (rt_forces.h, RT_LOAD_SL_*). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

state_loads *state_loads_new(void) { return xcalloc(1, sizeof(state_loads)); }

void state_loads_free(state_loads *s)
{
    if (!s)
        return;
    free(s->reg0);
    free(s->fixed);
    free(s->ins);
    free(s->in);
    free(s->loads);
    free(s);
}

/* Room for one more item of an array of *cap (doubling); 0, or -1. */
static int grow(void **p, int n, int *cap, size_t size)
{
    if (n < *cap)
        return 0;
    int nc = *cap ? 2 * *cap : 16;
    void *q = xrealloc_array(*p, (size_t)nc, size);
    if (!q)
        return -1;
    *p = q;
    *cap = nc;
    return 0;
}

static int new_reg(state_loads *s, double v, int fixed)
{
    if (s->nreg == s->capreg) {
        int nc = s->capreg ? 2 * s->capreg : 16;
        double *r = xrealloc_array(s->reg0, (size_t)nc, sizeof *r);
        if (!r)
            return -1;
        s->reg0 = r;
        unsigned char *f = xrealloc_array(s->fixed, (size_t)nc, 1);
        if (!f)
            return -1;
        s->fixed = f;
        s->capreg = nc;
    }
    s->reg0[s->nreg] = v;
    s->fixed[s->nreg] = (unsigned char)fixed;
    return s->nreg++;
}

int sl_const(state_loads *s, double v) { return new_reg(s, v, 1); }

int sl_is_const(const state_loads *s, int reg) { return reg >= 0 && s->fixed[reg]; }

int sl_input_reg(state_loads *s, int kind, int index)
{
    for (int i = 0; i < s->nin; i++)
        if (s->in[i].kind == kind && s->in[i].index == index)
            return s->in[i].reg;
    if (grow((void **)&s->in, s->nin, &s->capin, sizeof *s->in) < 0)
        return -1;
    int r = new_reg(s, 0.0, 0);
    if (r < 0)
        return -1;
    s->in[s->nin++] = (sl_input){kind, index, r};
    return r;
}

double sl_apply(int op, double a, double b, int k) { return rt_sl_apply(op, a, b, k); }

int sl_emit(state_loads *s, int op, int a, int b, int k)
{
    if (a < 0 || (b < -1))
        return -1;
    if (sl_is_const(s, a) && (b < 0 || sl_is_const(s, b)))
        return sl_const(s, sl_apply(op, s->reg0[a], b >= 0 ? s->reg0[b] : 0.0, k));
    if (grow((void **)&s->ins, s->nins, &s->capins, sizeof *s->ins) < 0)
        return -1;
    int d = new_reg(s, 0.0, 0);
    if (d < 0)
        return -1;
    s->ins[s->nins++] = (sl_ins){op, d, a, b, k};
    return d;
}

int sl_add_load(state_loads *s, const sl_load *l)
{
    if (grow((void **)&s->loads, s->nloads, &s->caploads, sizeof *s->loads) < 0)
        return -1;
    s->loads[s->nloads++] = *l;
    return 0;
}

double *state_loads_registers(const state_loads *s)
{
    double *r = xcalloc((size_t)(s->nreg > 0 ? s->nreg : 1), sizeof *r);
    if (r && s->nreg > 0)
        memcpy(r, s->reg0, (size_t)s->nreg * sizeof *r);
    return r;
}

void state_loads_describe(const mech_model *m, int i, char *buf, size_t size)
{
    const sl_load *l = &m->state_loads->loads[i];
    const mech_link *k = &m->links[l->link];
    if (l->torque == 1)
        snprintf(buf, size, "torque on link '%s', depends on the motion", k->name);
    else if (l->torque == 2)
        snprintf(buf, size, "force along %s-%s (%s, %s), tension positive, depends on the motion",
                 k->points[l->point].name, m->links[l->link2].points[l->point2].name, k->name,
                 m->links[l->link2].name);
    else
        snprintf(buf, size, "force at %s on link '%s', depends on the motion",
                 k->points[l->point].name, k->name);
}
