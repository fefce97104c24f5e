/* src/solve/kinematics.c: link frames and point motion from the solved unknowns
 * (see kinematics.h): which links to place, in which order, through which
 * points; the formulas are rt_frame.h's (the generated code's too). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "solve.h"

/* Variable of an angle or slide expression: -1 for the constant zero. */
static int expr_variable(const expr_ctx *c, ex e)
{
    const expr_node *nd = expr_at(c, e);
    return nd->op == EX_VAR ? nd->var : -1;
}

static void nearest_carriers(kin_tree *t)
{
    const mech_model *m = t->model;
    for (int p = 0; p < m->npoint_names; p++)
        t->point_link[p] = -1;
    for (int l = 0; l < m->nlinks; l++) {
        if (t->span->depth[l] < 0)
            continue;
        for (int i = 0; i < m->links[l].npoints; i++) {
            int id = m->links[l].points[i].id, cur = t->point_link[id];
            if (cur < 0 || t->span->depth[l] < t->span->depth[cur]) {
                t->point_link[id] = l;
                t->point_index[id] = i;
            }
        }
    }
}

/* The points through which each link is placed from its parent (place_link),
 * looked up once instead of at every step: the tree's numbers. */
void kin_tree_numbers(kin_tree *t, const mech_model *m)
{
    t->model = m;
    for (int l = 1; l < m->nlinks; l++) {
        int j = t->span->parent_joint[l], pl = t->span->parent_link[l];
        if (j < 0 || pl < 0)
            continue;
        const mech_joint *jt = &m->joints[j];
        int ip, il;  /* the point in the parent, in l */
        if (jt->kind == MECH_JOINT_REVOLUTE) {
            ip = loops_attach(jt, pl);
            il = loops_attach(jt, l);
        } else {
            ip = jt->point[l == jt->link[0] ? 1 : 0];
            il = jt->point[l == jt->link[0] ? 0 : 1];
        }
        double *a = t->attach + 4 * l;
        a[0] = m->links[pl].points[ip].x, a[1] = m->links[pl].points[ip].y;
        a[2] = m->links[l].points[il].x, a[3] = m->links[l].points[il].y;
    }
}

int kin_tree_build(kin_tree *t, const mech_system *s)
{
    const mech_model *m = s->model;
    memset(t, 0, sizeof *t);
    t->model = m;
    t->span = &s->span;
    t->n = s->n;
    size_t nl = (size_t)m->nlinks, nj = (size_t)m->njoints + 1, np = (size_t)m->npoint_names + 1;
    t->angle_var = xcalloc(nl, sizeof *t->angle_var);
    t->slide_var = xcalloc(nj, sizeof *t->slide_var);
    t->point_link = xcalloc(np, sizeof *t->point_link);
    t->point_index = xcalloc(np, sizeof *t->point_index);
    t->active = xcalloc(nl, sizeof *t->active);
    t->keep_cs = xcalloc(nl, sizeof *t->keep_cs);
    if (!t->angle_var || !t->slide_var || !t->point_link || !t->point_index || !t->active ||
        !t->keep_cs) {
        kin_tree_free(t);
        return MECH_ENOMEM;
    }
    for (int l = 0; l < m->nlinks; l++)
        t->angle_var[l] = expr_variable(&s->ex, s->link_angle[l]);
    for (int j = 0; j < m->njoints; j++)
        t->slide_var[j] = m->joints[j].kind == MECH_JOINT_SLIDER
                              ? expr_variable(&s->ex, s->slide[j]) : -1;
    nearest_carriers(t);
    return MECH_OK;
}

void kin_tree_free(kin_tree *t)
{
    free(t->angle_var);
    free(t->slide_var);
    free(t->point_link);
    free(t->point_index);
    free(t->active);
    free(t->keep_cs);
    memset(t, 0, sizeof *t);
}

static void need_var(const kin_tree *t, int var, unsigned char *need)
{
    if (var >= 0 && var < t->n)
        need[var] = 1;
}

void kin_need_link(kin_tree *t, int link, unsigned char *need)
{
    need_var(t, t->angle_var[link], need);
}

/* The frame of `link` needs the angles of every link on its chain to the
 * ground and the displacements of the sliders along it. */
static void need_frame(kin_tree *t, int link, unsigned char *need)
{
    for (int l = link; l > 0 && l < t->model->nlinks; l = t->span->parent_link[l]) {
        t->active[l] = 1;
        need_var(t, t->angle_var[l], need);
        int j = t->span->parent_joint[l];
        if (j < 0)
            break;
        need_var(t, t->slide_var[j], need);
        need_var(t, t->angle_var[t->span->parent_link[l]], need);
    }
}

void kin_need_point(kin_tree *t, int name_id, unsigned char *need)
{
    int l = t->point_link[name_id];
    if (l > 0)
        need_frame(t, l, need);
}

int kin_state_init(kin_state *st, const mech_model *m)
{
    size_t nl = (size_t)m->nlinks;
    st->F = xcalloc(nl, sizeof *st->F);
    st->cth = xcalloc(nl, sizeof *st->cth);
    int nguide = 0;  /* joints up to the last slider: a chain of pins needs none */
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER)
            nguide = j + 1;
    st->guide = xcalloc(3 * (size_t)nguide + 1, sizeof *st->guide);
    if (!st->F || !st->cth || !st->guide) {
        kin_state_free(st);
        return MECH_ENOMEM;
    }
    for (size_t l = 0; l < nl; l++)
        rt_frame_rest(&st->F[l]);  /* angle 0 until updated; the ground stays so */
    for (int j = 0; j < nguide; j++)
        st->guide[3 * j] = NAN;  /* no direction yet */
    return MECH_OK;
}

void kin_state_free(kin_state *st)
{
    free(st->F);
    free(st->cth);
    free(st->guide);
    memset(st, 0, sizeof *st);
}

static double var_value(const double *v, int var) { return v && var >= 0 ? v[var] : 0.0; }

/* Refresh link l's cos and sin when its angle has changed since they were
 * computed (the same values the cache held when every link was refreshed at
 * every update; a NaN angle is recomputed every time, as before). */
static inline void fresh_cs(kin_state *st, int l)
{
    rt_frame *F = &st->F[l];
    if (F->th != st->cth[l]) {
        st->cth[l] = F->th;
        F->c = cos(F->th);  /* once per link and angle: rt_on_link is hot */
        F->s = sin(F->th);
    }
}

void kin_offer_cs(kin_state *st, int l, double th, double c, double s)
{
    st->cth[l] = th;
    st->F[l].c = c;
    st->F[l].s = s;
}

void kin_on_link(const kin_state *st, int l, const double *r, double *p, double *v, double *a)
{
    rt_on_link(&st->F[l], r[0], r[1], p, v, a);
}

/* Offset of the mover point from the guide point, and its rates, for a
 * slider j with guide g (rt_slide_offset), its direction u at angle th_g +
 * angle kept while the angle holds. */
static void slide_offset(kin_state *st, int j, const mech_joint *jt, double s, double sd,
                         double sdd, double d[3][2])
{
    const rt_frame *G = &st->F[jt->link[1]];
    double ang = G->th + jt->angle;
    double *u = st->guide + 3 * j;  /* angle, cos, sin: the same values while it holds */
    if (!(u[0] == ang)) {
        u[0] = ang;
        u[1] = cos(ang);
        u[2] = sin(ang);
    }
    rt_slide_offset(G, u[1], u[2], s, sd, sdd, d);
}

static void place_link(const kin_tree *t, kin_state *st, int l, const double *pos,
                       const double *vel, const double *acc)
{
    const mech_model *m = t->model;
    int j = t->span->parent_joint[l], pl = t->span->parent_link[l];
    const mech_joint *jt = &m->joints[j];
    const double *at = t->attach + 4 * l;
    if (jt->kind == MECH_JOINT_REVOLUTE) {
        rt_place_across(&st->F[l], &st->F[pl], at[0], at[1], at[2], at[3], NULL, 1.0);
        return;
    }
    int sv = t->slide_var[j];
    double d[3][2];
    slide_offset(st, j, jt, var_value(pos, sv), var_value(vel, sv), var_value(acc, sv), d);
    double sign = l == jt->link[0] ? 1.0 : -1.0;  /* mover = guide point + d */
    rt_place_across(&st->F[l], &st->F[pl], at[0], at[1], at[2], at[3], (const double(*)[2])d,
                    sign);
}

void kin_update(const kin_tree *t, kin_state *st, const double *pos, const double *vel,
                const double *acc)
{
    /* angles first: a guide's angle may be needed before its frame */
    for (int k = 0; k < t->span->norder; k++) {
        int l = t->span->order[k], var = t->angle_var[l];
        st->F[l].th = var_value(pos, var);  /* c, s: only where needed, below */
        st->F[l].om = var_value(vel, var);
        st->F[l].al = var_value(acc, var);
    }
    for (int k = 0; k < t->span->norder; k++) {
        int l = t->span->order[k];
        if (t->keep_cs[l])  /* a parent comes before its children in the order */
            fresh_cs(st, l);
        if (t->active[l])
            place_link(t, st, l, pos, vel, acc);
    }
}

void kin_place_all(const kin_tree *t, kin_state *st, const double *pos)
{
    for (int k = 0; k < t->span->norder; k++) {
        int l = t->span->order[k];
        st->F[l].th = var_value(pos, t->angle_var[l]);
        st->F[l].om = st->F[l].al = 0.0;
    }
    for (int k = 0; k < t->span->norder; k++) {
        int l = t->span->order[k];
        fresh_cs(st, l);
        if (t->span->parent_link[l] >= 0)
            place_link(t, st, l, pos, NULL, NULL);
    }
}

void kin_tree_finish(kin_tree *t)
{
    const mech_model *m = t->model;
    for (int l = 0; l < m->nlinks; l++)
        if (t->active[l]) {
            t->keep_cs[l] = 1;
            if (t->span->parent_link[l] >= 0)
                t->keep_cs[t->span->parent_link[l]] = 1;
        }
    for (int i = 0; i < m->nsprings; i++)
        for (int k = 0; k < 2; k++)
            if (m->springs[i].link[k] >= 0 && m->springs[i].link[k] < m->nlinks)
                t->keep_cs[m->springs[i].link[k]] = 1;
}

void kin_refresh_all(const kin_tree *t, kin_state *st)
{
    for (int l = 0; l < t->model->nlinks; l++)
        fresh_cs(st, l);
}

void kin_point(const kin_tree *t, const kin_state *st, int name_id, double *p, double *v,
               double *a)
{
    int l = t->point_link[name_id];
    if (l < 0) {  /* not reachable from the ground: mech_check rejects this */
        p[0] = p[1] = NAN;
        l = 0;
    }
    const mech_point *pt = &t->model->links[l].points[t->point_index[name_id]];
    rt_on_link(&st->F[l], pt->x, pt->y, p, v, a);  /* v, a NULL: not computed */
}
