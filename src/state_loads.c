/* src/state_loads.c: the register program of the loads that depend on the
 * motion (src/state_loads.h): building it (constants folded as they are
 * made), running it once per step from the solved motion, and applying the
 * loads to the force rows and to the power balance. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "springs.h"
#include "state_loads.h"

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

double sl_apply(int op, double a, double b, int k)
{
    switch ((sl_op)op) {
    case SLOP_ADD: return a + b;
    case SLOP_SUB: return a - b;
    case SLOP_MUL: return a * b;
    case SLOP_DIV: return a / b;
    case SLOP_NEG: return -a;
    case SLOP_POWI: {
        double r = 1.0, x = k < 0 ? 1.0 / a : a;
        for (int e = k < 0 ? -k : k; e > 0; e--)
            r *= x;
        return r;
    }
    case SLOP_SIN: return sin(a);
    case SLOP_COS: return cos(a);
    case SLOP_TAN: return tan(a);
    case SLOP_ATAN2: return atan2(a, b);
    case SLOP_SQRT: return sqrt(a);
    case SLOP_ABS: return fabs(a);
    case SLOP_MIN: return a < b ? a : b;
    case SLOP_MAX: return a > b ? a : b;
    case SLOP_EXP: return exp(a);
    case SLOP_LOG: return log(a);
    case SLOP_TANH: return tanh(a);
    case SLOP_STEP: return a > 0.0 ? 1.0 : 0.0;
    case SLOP_SIGN: return a > 0.0 ? 1.0 : a < 0.0 ? -1.0 : 0.0;
    case SLOP_SMOOTHSIGN: return a / sqrt(a * a + b * b);
    }
    return 0.0;
}

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

/* ---- per step ------------------------------------------------------ */

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
    case SLIN_ANGLE: return ks->th[in->index];
    case SLIN_OMEGA: return ks->om[in->index];
    case SLIN_ALPHA: return ks->al[in->index];
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

/* A line load's ends, unit vector u from end 0 to end 1 (x when they
 * coincide), length and its rate. */
static void state_loads_line(const sl_load *l, const solver *sv, double p[2][2], double v[2][2],
                             double u[2], double *length, double *rate)
{
    const int link[2] = {l->link, l->link2}, point[2] = {l->point, l->point2};
    springs_line(sv, link, point, p, v, u, length, rate);
}

void state_loads_add(const state_loads *s, const solver *sv, const double *reg, const double *g,
                     double *rhs)
{
    if (!s)
        return;
    static const double none[2] = {0.0, 0.0};
    for (int i = 0; i < s->nloads; i++) {
        const sl_load *l = &s->loads[i];
        if (l->torque == 1) {
            springs_add_known_load(rhs, g, l->link, none, none, reg[l->reg[0]]);
        } else if (l->torque == 2) {
            double p[2][2], v[2][2], u[2], len, rate, t = reg[l->reg[0]];
            state_loads_line(l, sv, p, v, u, &len, &rate);
            double f[2] = {t * u[0], t * u[1]}, fb[2] = {-f[0], -f[1]};
            springs_add_known_load(rhs, g, l->link, p[0], f, 0.0);
            springs_add_known_load(rhs, g, l->link2, p[1], fb, 0.0);
        } else {
            double f[2] = {reg[l->reg[0]], reg[l->reg[1]]}, p[2], v[2];
            springs_point_motion(sv, l->link, l->point, p, v);
            springs_add_known_load(rhs, g, l->link, p, f, 0.0);
        }
    }
}

/* The scale of a load in the power balance is its size times the
 * mechanism's speed, as for springs (springs_power): at a dead point every
 * power vanishes while the driver torque still carries the rounding. */
double state_loads_power(const state_loads *s, const solver *sv, const double *reg,
                         double *scale)
{
    if (!s)
        return 0.0;
    const mech_model *m = sv->p->m;
    double total = 0.0, linear, turning;
    springs_power_scales(m, sv, &linear, &turning);
    for (int i = 0; i < s->nloads; i++) {
        const sl_load *l = &s->loads[i];
        double pw;
        if (l->torque == 1) {
            double t = reg[l->reg[0]];
            pw = t * sv->ks.om[l->link];
            *scale += fabs(t) * turning;
        } else if (l->torque == 2) {
            double p[2][2], v[2][2], u[2], len, rate, t = reg[l->reg[0]];
            state_loads_line(l, sv, p, v, u, &len, &rate);
            pw = -t * rate;
            *scale += fabs(t) * linear;
        } else {
            double f[2] = {reg[l->reg[0]], reg[l->reg[1]]}, p[2], v[2];
            springs_point_motion(sv, l->link, l->point, p, v);
            pw = f[0] * v[0] + f[1] * v[1];
            *scale += hypot(f[0], f[1]) * linear;
        }
        total += pw;
        *scale += fabs(pw);
    }
    return total;
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
