/* src/kinematics.c: link frames and point motion from the solved unknowns
 * (see kinematics.h). A point r (link frame) of link l is at
 *   p = o_l + R(th_l) r,  v = v_o + w x (R r),  a = a_o + al x (R r) - w^2 R r;
 * a slider's mover point M = T + s u (T the guide's `through` point, u the
 * guide direction) moves with
 *   v_M = v_T + s' u + s w_g u_perp,
 *   a_M = a_T + s'' u + (2 s' w_g + s al_g) u_perp - s w_g^2 u. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "kinematics.h"

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
 * looked up once instead of at every step. */
static void attach_points(kin_tree *t)
{
    const mech_model *m = t->model;
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
    t->attach = xcalloc(4 * nl, sizeof *t->attach);
    if (!t->angle_var || !t->slide_var || !t->point_link || !t->point_index || !t->active || !t->keep_cs ||
        !t->attach) {
        kin_tree_free(t);
        return MECH_ENOMEM;
    }
    for (int l = 0; l < m->nlinks; l++)
        t->angle_var[l] = expr_variable(&s->ex, s->link_angle[l]);
    for (int j = 0; j < m->njoints; j++)
        t->slide_var[j] = m->joints[j].kind == MECH_JOINT_SLIDER
                              ? expr_variable(&s->ex, s->slide[j]) : -1;
    nearest_carriers(t);
    attach_points(t);
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
    free(t->attach);
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
    st->th = xcalloc(nl, sizeof *st->th);
    st->om = xcalloc(nl, sizeof *st->om);
    st->al = xcalloc(nl, sizeof *st->al);
    st->c = xcalloc(nl, sizeof *st->c);
    st->s = xcalloc(nl, sizeof *st->s);
    st->cth = xcalloc(nl, sizeof *st->cth);
    st->o = xcalloc(2 * nl, sizeof *st->o);
    st->vo = xcalloc(2 * nl, sizeof *st->vo);
    st->ao = xcalloc(2 * nl, sizeof *st->ao);
    int nguide = 0;  /* joints up to the last slider: a chain of pins needs none */
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER)
            nguide = j + 1;
    st->guide = xcalloc(3 * (size_t)nguide + 1, sizeof *st->guide);
    if (!st->th || !st->om || !st->al || !st->c || !st->s || !st->cth || !st->o || !st->vo || !st->ao ||
        !st->guide) {
        kin_state_free(st);
        return MECH_ENOMEM;
    }
    for (size_t l = 0; l < nl; l++)
        st->c[l] = 1.0;  /* angle 0 until updated; the ground stays so */
    for (int j = 0; j < nguide; j++)
        st->guide[3 * j] = NAN;  /* no direction yet */
    return MECH_OK;
}

void kin_state_free(kin_state *st)
{
    free(st->th);
    free(st->om);
    free(st->al);
    free(st->c);
    free(st->s);
    free(st->cth);
    free(st->o);
    free(st->vo);
    free(st->ao);
    free(st->guide);
    memset(st, 0, sizeof *st);
}

static double var_value(const double *v, int var) { return v && var >= 0 ? v[var] : 0.0; }

/* Point r of link l (cos c, sin s of its angle): position, and rates when
 * the link's rates are known. */
static inline void on_link_cs(const kin_state *st, int l, double c, double s, const double *r,
                              double *p, double *v, double *a)
{
    double rx = c * r[0] - s * r[1], ry = s * r[0] + c * r[1];  /* R r */
    double w = st->om[l], al = st->al[l];
    p[0] = st->o[2 * l] + rx;
    p[1] = st->o[2 * l + 1] + ry;
    if (v) {
        v[0] = st->vo[2 * l] - w * ry;
        v[1] = st->vo[2 * l + 1] + w * rx;
    }
    if (a) {
        a[0] = st->ao[2 * l] - al * ry - w * w * rx;
        a[1] = st->ao[2 * l + 1] + al * rx - w * w * ry;
    }
}

/* ... with the cached cos and sin (links placed by kin_update: fresh) */
static inline void on_link(const kin_state *st, int l, const double *r, double *p, double *v,
                           double *a)
{
    on_link_cs(st, l, st->c[l], st->s[l], r, p, v, a);
}

/* Refresh link l's cos and sin when its angle has changed since they were
 * computed (the same values the cache held when every link was refreshed at
 * every update; a NaN angle is recomputed every time, as before). */
static inline void fresh_cs(kin_state *st, int l)
{
    double th = st->th[l];
    if (th != st->cth[l]) {
        st->cth[l] = th;
        st->c[l] = cos(th);  /* once per link and angle: on_link is hot */
        st->s[l] = sin(th);
    }
}

void kin_on_link(const kin_state *st, int l, const double *r, double *p, double *v, double *a)
{
    on_link(st, l, r, p, v, a);
}

/* Place link l so that its point r is at p (with rates v, a). */
static void place_at(kin_state *st, int l, const double *r, const double *p, const double *v,
                     const double *a)
{
    double c = st->c[l], s = st->s[l];
    double rx = c * r[0] - s * r[1], ry = s * r[0] + c * r[1];
    double w = st->om[l], al = st->al[l];
    st->o[2 * l] = p[0] - rx;
    st->o[2 * l + 1] = p[1] - ry;
    st->vo[2 * l] = v[0] + w * ry;
    st->vo[2 * l + 1] = v[1] - w * rx;
    st->ao[2 * l] = a[0] + al * ry + w * w * rx;
    st->ao[2 * l + 1] = a[1] - al * rx + w * w * ry;
}

static const double *point_xy(const mech_model *m, int l, int i, double *buf)
{
    buf[0] = m->links[l].points[i].x;
    buf[1] = m->links[l].points[i].y;
    return buf;
}

/* Offset of the mover point from the guide point, and its rates, for a
 * slider with guide g: d = s u, with u at angle th_g + angle. */
static void slide_offset(kin_state *st, int j, const mech_joint *jt, double s, double sd,
                         double sdd, double *d, double *dv, double *da)
{
    int g = jt->link[1];
    double ang = st->th[g] + jt->angle, w = st->om[g], al = st->al[g];
    double *u = st->guide + 3 * j;  /* angle, cos, sin: the same values while it holds */
    if (!(u[0] == ang)) {
        u[0] = ang;
        u[1] = cos(ang);
        u[2] = sin(ang);
    }
    double ux = u[1], uy = u[2];  /* u; u_perp = (-uy, ux) */
    d[0] = s * ux;
    d[1] = s * uy;
    double tang = sd, norm = s * w;                          /* along u, along u_perp */
    dv[0] = tang * ux - norm * uy;
    dv[1] = tang * uy + norm * ux;
    double ta = sdd - s * w * w, na = 2.0 * sd * w + s * al;
    da[0] = ta * ux - na * uy;
    da[1] = ta * uy + na * ux;
}

static void place_link(const kin_tree *t, kin_state *st, int l, const double *pos,
                       const double *vel, const double *acc)
{
    const mech_model *m = t->model;
    int j = t->span->parent_joint[l], pl = t->span->parent_link[l];
    const mech_joint *jt = &m->joints[j];
    const double *at = t->attach + 4 * l;
    double p[2], v[2], a[2];
    if (jt->kind == MECH_JOINT_REVOLUTE) {
        on_link(st, pl, at, p, v, a);
        place_at(st, l, at + 2, p, v, a);
        return;
    }
    int sv = t->slide_var[j];
    double d[3][2];
    slide_offset(st, j, jt, var_value(pos, sv), var_value(vel, sv), var_value(acc, sv), d[0],
                 d[1], d[2]);
    double sign = l == jt->link[0] ? 1.0 : -1.0;  /* mover = guide point + d */
    on_link(st, pl, at, p, v, a);
    for (int k = 0; k < 2; k++) {
        p[k] += sign * d[0][k];
        v[k] += sign * d[1][k];
        a[k] += sign * d[2][k];
    }
    place_at(st, l, at + 2, p, v, a);
}

void kin_update(const kin_tree *t, kin_state *st, const double *pos, const double *vel,
                const double *acc)
{
    /* angles first: a guide's angle may be needed before its frame */
    for (int k = 0; k < t->span->norder; k++) {
        int l = t->span->order[k], var = t->angle_var[l];
        st->th[l] = var_value(pos, var);  /* c, s: only where needed, below */
        st->om[l] = var_value(vel, var);
        st->al[l] = var_value(acc, var);
    }
    for (int k = 0; k < t->span->norder; k++) {
        int l = t->span->order[k];
        if (t->keep_cs[l])  /* a parent comes before its children in the order */
            fresh_cs(st, l);
        if (t->active[l])
            place_link(t, st, l, pos, vel, acc);
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
    double vb[2], ab[2], rbuf[2];
    int l = t->point_link[name_id];
    if (l < 0) {  /* not reachable from the ground: mech_check rejects this */
        p[0] = p[1] = NAN;
        l = 0;
    }
    on_link(st, l, point_xy(t->model, l, t->point_index[name_id], rbuf), p, v ? v : vb,
            a ? a : ab);
}
