/* src/codegen/codegen_expr.c: the expression DAG and the link frames as C
 * statements for `mech codegen` (codegen.h). Every DAG node the three
 * phases need becomes one `const double tN = ...;` in the function of the
 * first phase that needs it, with the tape's operations (so the generated
 * code computes the interpreter's values bit for bit); what depends on the
 * driver alone is computed once per position (eval_driver, tape_hoist's
 * part); a node a later phase reuses is kept in the state's keep[] array,
 * as the tape keeps it in its registers. The kinematics mirror src/solve/kinematics.c formula for
 * formula. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "codegen.h"

/* The functions the phases become: eval_driver (what depends on the
 * driver position alone, run once per position as tape_hoist does), then
 * eval_position (f, J), eval_velocity, eval_accel. */
enum { PH_DRIVER, PH_POSITION, PH_VELOCITY, PH_ACCELERATION, NPH };

void codegen_number(char *buf, size_t size, double v)
{
    if (isnan(v)) {
        snprintf(buf, size, "NAN");
        return;
    }
    if (isinf(v)) {
        snprintf(buf, size, v > 0 ? "HUGE_VAL" : "(-HUGE_VAL)");
        return;
    }
    char num[40];
    snprintf(num, sizeof num, "%.17g", v);
    const char *dot = strpbrk(num, ".e");
    snprintf(buf, size, v < 0 || (v == 0 && signbit(v)) ? "(%s%s)" : "%s%s", num,
             dot ? "" : ".0");
}

/* ---- planning: which function computes each node ------------------------ */

/* May phase ph read variable var? (The solved unknowns and q always; q'
 * from the velocity phase on; x' and q'' in the acceleration phase.) */
static int var_allowed(const codegen *g, int var, int ph)
{
    int n = g->sp.n;
    if (var < n)
        return g->unk_col[var] >= 0;
    if (var == SYS_VAR_Q(n) || var >= SYS_NVARS(n))  /* q, a sweep's leaves (keep) */
        return 1;
    if (var == SYS_VAR_QDOT(n))
        return ph >= PH_VELOCITY;
    if (var == SYS_VAR_QDDOT(n))
        return ph == PH_ACCELERATION;
    return ph == PH_ACCELERATION && g->unk_col[var - n - 1] >= 0;
}

/* Does e depend on nothing but constants, the driver q and a sweep's
 * leaves (fixed for a variant)? (memo: -1 unknown, 0 no, 1 yes) */
static int driver_only(codegen *g, ex e)
{
    const expr_node *nd = expr_at(&g->sp.sys->ex, e);
    if (nd->op == EX_CONST)
        return 1;
    if (nd->op == EX_VAR)
        return nd->var == SYS_VAR_Q(g->sp.n) || nd->var >= SYS_NVARS(g->sp.n);
    if (g->driver_only[e] < 0)
        g->driver_only[e] = driver_only(g, nd->a) &&
                            (nd->op != EX_ADD && nd->op != EX_MUL ? 1 : driver_only(g, nd->b));
    return g->driver_only[e];
}

/* ---- laws of time beyond the DAG's operations (docs/motion-programs.md) --
 * Each opaque law (an EX_CALL's function, law_expr) becomes its tables for
 * rt_law.h - its nodes, its programs' segments, a segment's own f(u) - and
 * cg_lawK_call(order, t), which the node calls: the interpreter's tape
 * calls the same rt_law_call on the same numbers (law_fn_eval). */
static void law_nodes(FILE *f, const char *name, const rt_law_node *nd, int n)
{
    fprintf(f, "static const rt_law_node %s[%d] = {\n", name, n);
    for (int i = 0; i < n; i++) {
        char k[40];
        codegen_number(k, sizeof k, nd[i].k);
        fprintf(f, "    {%d, %d, %d, %s},\n", nd[i].op, nd[i].a, nd[i].b, k);
    }
    fprintf(f, "};\n");
}

static void segment_row(FILE *f, const prog_segment *sg, const char *user)
{
    char v[6][40];
    const double x[6] = {sg->x0, sg->span, sg->s0, sg->lift, 0, 0};
    for (int i = 0; i < 4; i++)
        codegen_number(v[i], sizeof v[i], x[i]);
    fprintf(f, "    {%d, %d, %s, %s, %s, %s, {", sg->kind, sg->shape, v[0], v[1], v[2], v[3]);
    for (int j = 0; j < 5; j++) {
        const rt_piece *p = &sg->piece[j];
        const double pv[7] = {p->u0, p->f0, p->f1, p->c0, p->c1, p->w, p->phi};
        fprintf(f, "%s{", j ? ", " : "");
        for (int c = 0; c < 7; c++) {
            char num[40];
            codegen_number(num, sizeof num, pv[c]);
            fprintf(f, "%s%s", c ? ", " : "", num);
        }
        fprintf(f, "}");
    }
    if (user)
        fprintf(f, "}, %d, {%s, %d, %d, NULL}, NULL, 0, 0},\n", sg->npieces, user, sg->user.n,
                sg->user.root);
    else
        fprintf(f, "}, %d, {NULL, 0, -1, NULL}, NULL, 0, 0},\n", sg->npieces);
}

static void program_tables(FILE *f, int k, int j, const mech_program *p)
{
    char name[64];
    for (int i = 0; i < p->n; i++)
        if (p->seg[i].shape == SHAPE_USER) {
            snprintf(name, sizeof name, "cg_law%d_p%d_u%d", k, j, i);
            law_nodes(f, name, p->seg[i].user.nodes, p->seg[i].user.n);
        }
    fprintf(f, "static const rt_segment cg_law%d_p%d_seg[%d] = {\n", k, j, p->n);
    for (int i = 0; i < p->n; i++) {
        snprintf(name, sizeof name, "cg_law%d_p%d_u%d", k, j, i);
        segment_row(f, &p->seg[i], p->seg[i].shape == SHAPE_USER ? name : NULL);
    }
    char v[3][40];
    codegen_number(v[0], sizeof v[0], p->start);
    codegen_number(v[1], sizeof v[1], p->period);
    codegen_number(v[2], sizeof v[2], p->net);
    fprintf(f, "};\nstatic const rt_program cg_law%d_p%d = {cg_law%d_p%d_seg, %d, %s, %s, %s};\n",
            k, j, k, j, p->n, v[0], v[1], v[2]);
}

void codegen_laws_emit(const codegen *g, FILE *f)
{
    const expr_ctx *c = &g->sp.sys->ex;
    for (int k = 0; k < c->nfns; k++) {
        const struct mech_law *l = c->fns[k].data;
        char name[64], progs[64] = "NULL";
        fprintf(f, "/* %s: a law of time of the runtime (rt_law.h) */\n", c->fns[k].name);
        for (int j = 0; j < l->nprogs; j++)
            program_tables(f, k, j, l->progs[j]);
        if (l->nprogs > 0) {
            fprintf(f, "static const rt_program *const cg_law%d_progs[%d] = {", k, l->nprogs);
            for (int j = 0; j < l->nprogs; j++)
                fprintf(f, "%s&cg_law%d_p%d", j ? ", " : "", k, j);
            fprintf(f, "};\n");
            snprintf(progs, sizeof progs, "cg_law%d_progs", k);
        }
        snprintf(name, sizeof name, "cg_law%d_nodes", k);
        law_nodes(f, name, l->nodes, l->n);
        fprintf(f, "static const rt_law cg_law%d = {cg_law%d_nodes, %d, %d, %s};\n"
                   "static inline double cg_law%d_call(int order, double t)\n{\n"
                   "    double buf[4 * %d];\n"
                   "    return rt_law_call(&cg_law%d, order, t, buf);\n}\n\n",
                k, k, l->n, l->root, progs, k, l->n, k);
    }
}

/* Give e (used by a node or root of phase `user`, under a root of phase
 * `root`) its phase, and a keep slot when a later phase uses it. */
static int visit(codegen *g, ex e, int user, int root, mech_diag *d)
{
    const expr_node *nd = expr_at(&g->sp.sys->ex, e);
    switch (nd->op) {
    case EX_CONST:
        return MECH_OK;
    case EX_VAR:
        if (var_allowed(g, nd->var, root))
            return MECH_OK;
        return diag_error(d, g->m->file, g->m->driver.mark,
                          "codegen: an equation uses '%s', which is not solved",
                          g->sp.sys->names[nd->var]);
    case EX_ADD: case EX_MUL: case EX_NEG: case EX_SIN: case EX_COS:
        break;
    case EX_CALL:
        break;
    default:
        return diag_error(d, g->m->file, g->m->driver.mark,
                          "codegen: expression node kind %d is not supported by the "
                          "code generator (src/codegen/codegen_expr.c)", (int)nd->op);
    }
    int rc = MECH_OK;
    if (g->phase[e] < 0) {
        g->phase[e] = root == PH_POSITION && driver_only(g, e) ? PH_DRIVER : root;
        rc = visit(g, nd->a, g->phase[e], root, d);
        if (rc == MECH_OK && (nd->op == EX_ADD || nd->op == EX_MUL))
            rc = visit(g, nd->b, g->phase[e], root, d);
    }
    if (g->phase[e] < user && g->keep[e] < 0)
        g->keep[e] = g->nkeep++;
    return rc;
}

int codegen_expr_plan(codegen *g, mech_diag *d)
{
    const solver_plan *sp = &g->sp;
    size_t count = sp->sys->ex.count;
    g->phase = malloc((count + 1) * sizeof *g->phase);
    g->keep = malloc((count + 1) * sizeof *g->keep);
    g->driver_only = malloc((count + 1) * sizeof *g->driver_only);
    if (!g->phase || !g->keep || !g->driver_only)
        return diag_nomem(d, g->m->file, (mech_mark){0, 0});
    for (size_t i = 0; i < count; i++)
        g->phase[i] = g->keep[i] = g->driver_only[i] = -1;
    const ex *roots[NPH] = {NULL, sp->proot, sp->vroot, sp->aroot};
    int nroots[NPH] = {0, sp->nr + sp->nnzJ, sp->nr, sp->nr};
    int rc = MECH_OK;
    for (int ph = PH_POSITION; ph < NPH && rc == MECH_OK; ph++)
        for (int i = 0; i < nroots[ph] && rc == MECH_OK; i++)
            rc = visit(g, roots[ph][i], ph, ph, d);
    g->leaf0 = g->nkeep;  /* a sweep's leaves: after the kept nodes (P_numbers sets them) */
    return rc;
}

/* ---- emission -------------------------------------------------------------- */

/* The C text of variable var in phase code: x[k], q, xd[k], 1.0 (q' = 1),
 * 0.0 (q'' = 0): the rates are solved for q' = 1, q'' = 0 and scaled; a
 * sweep's leaf k is k[leaf0 + k], which P_numbers sets. */
static void var_text(const codegen *g, int var, char *buf, size_t size)
{
    int n = g->sp.n;
    if (var < n)
        snprintf(buf, size, "x[%d]", g->unk_col[var]);
    else if (var == SYS_VAR_Q(n))
        snprintf(buf, size, "q");
    else if (var == SYS_VAR_QDOT(n))
        snprintf(buf, size, "1.0");
    else if (var == SYS_VAR_QDDOT(n))
        snprintf(buf, size, "0.0");
    else if (var >= SYS_NVARS(n))
        snprintf(buf, size, "k[%d]", g->leaf0 + var - SYS_NVARS(n));
    else
        snprintf(buf, size, "xd[%d]", g->unk_col[var - n - 1]);
}

static void operand(const codegen *g, ex e, int ph, char *buf, size_t size)
{
    const expr_node *nd = expr_at(&g->sp.sys->ex, e);
    if (nd->op == EX_CONST)
        codegen_number(buf, size, nd->value);
    else if (nd->op == EX_VAR)
        var_text(g, nd->var, buf, size);
    else if (g->phase[e] < ph)
        snprintf(buf, size, "k[%d]", g->keep[e]);
    else
        snprintf(buf, size, "t%d", e);
}

/* The nodes of phase ph, in index order (a node's operands are made
 * before it, so this is an order of evaluation). */
static int emit_nodes(const codegen *g, FILE *f, int ph)
{
    for (size_t i = 0; i < g->sp.sys->ex.count; i++) {
        ex e = (ex)i;
        if (g->phase[e] != ph)
            continue;
        const expr_node *nd = expr_at(&g->sp.sys->ex, e);
        char a[48], b[48] = "";
        operand(g, nd->a, ph, a, sizeof a);
        if (nd->op == EX_ADD || nd->op == EX_MUL)
            operand(g, nd->b, ph, b, sizeof b);
        switch (nd->op) {
        case EX_ADD: fprintf(f, "    const double t%d = %s + %s;\n", e, a, b); break;
        case EX_MUL: fprintf(f, "    const double t%d = %s * %s;\n", e, a, b); break;
        case EX_NEG: fprintf(f, "    const double t%d = -%s;\n", e, a); break;
        case EX_SIN: fprintf(f, "    const double t%d = sin(%s);\n", e, a); break;
        case EX_COS: fprintf(f, "    const double t%d = cos(%s);\n", e, a); break;
        case EX_CALL:
            fprintf(f, "    const double t%d = cg_law%d_call(%d, %s);\n", e, nd->var, (int)nd->value,
                    a);
            break;
        default: return -1;  /* codegen_expr_plan has reported it */
        }
        if (g->keep[e] >= 0)
            fprintf(f, "    k[%d] = t%d;\n", g->keep[e], e);
    }
    return 0;
}

/* The nodes of phase ph, then out[i] = root i, for i < nroots. */
static int emit_phase(const codegen *g, FILE *f, int ph, const ex *roots, int nroots,
                      const char *out)
{
    char a[48];
    if (emit_nodes(g, f, ph) < 0)
        return -1;
    for (int i = 0; i < nroots; i++) {
        operand(g, roots[i], ph, a, sizeof a);
        fprintf(f, "    %s[%d] = %s;\n", out, i, a);
    }
    return 0;
}

int codegen_expr_emit(const codegen *g, FILE *f)
{
    const solver_plan *sp = &g->sp;
    int rc = 0;
    fprintf(f, "/* What depends on the driver position q alone (once per position) */\n"
               "static void eval_driver(double q, double *restrict k)\n{\n    (void)q, (void)k;\n");
    rc |= emit_nodes(g, f, PH_DRIVER);
    fprintf(f, "}\n\n/* f(x, q) and the nonzeros of J = df/dx (CSC order), after eval_driver "
               "at q */\nstatic void eval_position(const double *restrict x, double q, "
               "double *restrict f, double *restrict Jv, double *restrict k)\n{\n    (void)x, (void)q, (void)f, (void)Jv, (void)k;\n");
    rc |= emit_phase(g, f, PH_POSITION, sp->proot, sp->nr, "f");
    for (int i = 0; i < sp->nnzJ; i++) {
        char a[48];
        operand(g, sp->proot[sp->nr + i], PH_POSITION, a, sizeof a);
        fprintf(f, "    Jv[%d] = %s;\n", i, a);
    }
    fprintf(f, "}\n\n/* b = -df/dq, the velocity right-hand side for q' = 1 (after eval_position "
               "at x, q) */\nstatic void eval_velocity(const double *restrict x, double q, "
               "double *restrict k, double *restrict b)\n{\n    (void)x, (void)q, (void)k, (void)b;\n");
    rc |= emit_phase(g, f, PH_VELOCITY, sp->vroot, sp->nr, "b");
    fprintf(f, "}\n\n/* c, the acceleration right-hand side for x' = xd, q' = 1, q'' = 0 (after "
               "eval_velocity) */\nstatic void eval_accel(const double *restrict x, double q, "
               "const double *restrict xd, const double *restrict k, double *restrict c)\n{\n"
               "    (void)x, (void)q, (void)xd, (void)k, (void)c;\n");
    rc |= emit_phase(g, f, PH_ACCELERATION, sp->aroot, sp->nr, "c");
    fprintf(f, "}\n\n");
    return rc;
}
/* ---- kinematics ------------------------------------------------------------ */

/* The C text of variable var (0..n, n the driver) at derivative level lv
 * (0 position, 1 velocity, 2 acceleration); 0.0 for none (-1) or an
 * unknown that is not solved (mech solve leaves those at 0 too). */
static void kin_var(const codegen *g, int var, int lv, char *buf, size_t size)
{
    static const char *const xs[] = {"s->x", "s->xd", "s->xdd"};
    static const char *const qs[] = {"q", "qd", "qdd"};
    if (var == g->sp.n)
        snprintf(buf, size, "%s", qs[lv]);
    else if (var >= 0 && var < g->sp.n && g->unk_col[var] >= 0)
        snprintf(buf, size, "%s[%d]", xs[lv], g->unk_col[var]);
    else
        snprintf(buf, size, "0.0");
}

/* The keep slot of the node op(q) (EX_COS or EX_SIN of the driver q) that
 * eval_driver computes, or -1. */
static int driver_trig_slot(const codegen *g, int op)
{
    const expr_ctx *pool = &g->sp.sys->ex;
    for (size_t e = 0; e < pool->count; e++) {
        const expr_node *nd = expr_at(pool, (int)e);
        if ((int)nd->op != op || g->phase[e] != PH_DRIVER || g->keep[e] < 0)
            continue;
        const expr_node *a = expr_at(pool, nd->a);
        if (a->op == EX_VAR && a->var == SYS_VAR_Q(g->sp.n))
            return g->keep[e];
    }
    return -1;
}

/* Angle, rates, cosine and sine of link l's frame. The driven link's
 * cosine and sine are eval_driver's cos(q) and sin(q) where it keeps them
 * (the same function of the same argument: the same values), computed
 * again otherwise. */
static void emit_angle(const codegen *g, FILE *f, int l)
{
    int var = g->sp.tree.angle_var[l];
    char v[3][32];
    for (int lv = 0; lv < 3; lv++)
        kin_var(g, var, lv, v[lv], sizeof v[lv]);
    fprintf(f, "    F[%d].th = %s, F[%d].om = %s, F[%d].al = %s;\n", l, v[0], l, v[1], l, v[2]);
    int kc = var == g->sp.n ? driver_trig_slot(g, EX_COS) : -1;
    int ks = var == g->sp.n ? driver_trig_slot(g, EX_SIN) : -1;
    if (kc >= 0 && ks >= 0 && g->sp.ns > 0)
        fprintf(f, "    F[%d].c = s->keep[%d], F[%d].s = s->keep[%d];  /* eval_driver's */\n", l,
                kc, l, ks);
    else if (var >= 0)
        fprintf(f, "    F[%d].c = cos(F[%d].th), F[%d].s = sin(F[%d].th);\n", l, l, l, l);
}

void codegen_point_xy(const codegen *g, int l, int i, char *buf, size_t size)
{
    if (g->opt.leaves) {  /* the variant's, from P_numbers (codegen_numbers_fill) */
        int at = 2 * (g->point_at[l] + i);
        snprintf(buf, size, "s->num->points[%d], s->num->points[%d]", at, at + 1);
        return;
    }
    char x[40], y[40];
    codegen_number(x, sizeof x, g->m->links[l].points[i].x);
    codegen_number(y, sizeof y, g->m->links[l].points[i].y);
    snprintf(buf, size, "%s, %s", x, y);
}

/* "x, y": attachment point k of the kinematic tree (kin_tree.attach[2k],
 * [2k + 1]) as literals, or a variant's from P_numbers. */
static void attach_text(const codegen *g, int k, char *buf, size_t size)
{
    if (g->opt.leaves) {
        snprintf(buf, size, "s->num->attach[%d], s->num->attach[%d]", 2 * k, 2 * k + 1);
        return;
    }
    char x[40], y[40];
    codegen_number(x, sizeof x, g->sp.tree.attach[2 * k]);
    codegen_number(y, sizeof y, g->sp.tree.attach[2 * k + 1]);
    snprintf(buf, size, "%s, %s", x, y);
}

/* Frame of link l from its parent's across their joint, through the points
 * of the kinematic tree (kin_tree.attach: kinematics.c place_link's). */
static void emit_place(const codegen *g, FILE *f, int l)
{
    const mech_model *m = g->m;
    const span_tree *t = g->sp.tree.span;
    int j = t->parent_joint[l], pl = t->parent_link[l];
    const mech_joint *jt = &m->joints[j];
    char rp[96], rl[96];
    attach_text(g, 2 * l, rp, sizeof rp);
    attach_text(g, 2 * l + 1, rl, sizeof rl);
    if (jt->kind == MECH_JOINT_REVOLUTE) {
        fprintf(f, "    rt_place_across(&F[%d], &F[%d], %s, %s, NULL, 1.0);\n", l, pl, rp, rl);
        return;
    }
    int sv = g->sp.tree.slide_var[j];
    char s[3][32], ang[40];
    for (int lv = 0; lv < 3; lv++)
        kin_var(g, sv, lv, s[lv], sizeof s[lv]);
    codegen_number(ang, sizeof ang, jt->angle);
    fprintf(f, "    {\n        double u[2], d[3][2];\n"
               "        rt_guide_dir(&F[%d], %s, u);\n"
               "        rt_slide_offset(&F[%d], u[0], u[1], %s, %s, %s, d);\n"
               "        rt_place_across(&F[%d], &F[%d], %s, %s, (const double(*)[2])d, %s);\n"
               "    }\n",
            jt->link[1], ang, jt->link[1], s[0], s[1], s[2], l, pl, rp, rl,
            l == jt->link[0] ? "1.0" : "(-1.0)");
}

/* p[6]: position, velocity, acceleration of point name id. */
static void emit_point(const codegen *g, FILE *f, int id)
{
    int l = g->sp.tree.point_link[id];
    char r[96];
    codegen_point_xy(g, l, g->sp.tree.point_index[id], r, sizeof r);
    fprintf(f, "        rt_on_link(&F[%d], %s, p, p + 2, p + 4);\n", l, r);
}

static void emit_columns(const codegen *g, FILE *f)
{
    const column_layout *cl = &g->cols;
    for (int c = 0; c < cl->ncols; c++) {
        const column_desc *cd = &cl->cols[c];
        char v[32];
        switch (cd->src) {
        case SRC_DRIVER:
            fprintf(f, "    s->out[%d] = q;\n", c);
            break;
        case SRC_POINT:
            if (c == 0 || cl->cols[c - 1].src != SRC_POINT || cl->cols[c - 1].obj != cd->obj) {
                fprintf(f, "    {\n        double p[6];\n");
                emit_point(g, f, cd->obj);
            }
            fprintf(f, "        s->out[%d] = p[%d];\n", c, cd->comp);
            if (c + 1 == cl->ncols || cl->cols[c + 1].src != SRC_POINT ||
                cl->cols[c + 1].obj != cd->obj)
                fprintf(f, "    }\n");
            break;
        case SRC_LINK: {
            static const char *const part[] = {"th", "om", "al"};
            fprintf(f, "    s->out[%d] = F[%d].%s;\n", c, cd->obj, part[cd->comp]);
            break;
        }
        case SRC_SLIDER:
            kin_var(g, g->sp.tree.slide_var[cd->obj], cd->comp, v, sizeof v);
            fprintf(f, "    s->out[%d] = %s;\n", c, v);
            break;
        default:  /* the forces' columns: after the branch conditions */
            break;
        }
    }
}

/* Branch condition b's signed quantity into bv (continuation.c branch_value). */
static void emit_branch(const codegen *g, FILE *f, int b)
{
    const mech_branch *br = &g->m->branches[b];
    if (br->kind == MECH_BRANCH_SLIDER) {
        char v[32];
        kin_var(g, g->sp.tree.slide_var[br->slider], 0, v, sizeof v);
        fprintf(f, "    bv = %s;\n", v);
    } else {
        fprintf(f, "    {\n        double P[3][6], *p;\n");
        for (int k = 0; k < 3; k++) {
            fprintf(f, "        p = P[%d];\n", k);
            emit_point(g, f, br->point[k]);
        }
        if (br->kind == MECH_BRANCH_X)
            fprintf(f, "        bv = P[0][0] - P[1][0];\n");
        else if (br->kind == MECH_BRANCH_Y)
            fprintf(f, "        bv = P[0][1] - P[1][1];\n");
        else
            fprintf(f, "        bv = (P[1][0] - P[0][0]) * (P[2][1] - P[1][1]) - "
                       "(P[1][1] - P[0][1]) * (P[2][0] - P[1][0]);\n");
        fprintf(f, "    }\n");
    }
    fprintf(f, "    if (%s(bv * %d.0 <= 0.0))\n        return %d;\n",
            br->first_only ? "first && " : "", br->sign, b);
}

int codegen_kin_emit(const codegen *g, FILE *f)
{
    const mech_model *m = g->m;
    const kin_tree *t = &g->sp.tree;
    unsigned char *angle = calloc((size_t)m->nlinks + 1, 1);
    if (!angle)
        return -1;
    for (int l = 1; l < m->nlinks; l++)  /* the frames placed, and the guides they slide on */
        if (t->active[l]) {
            angle[l] = angle[t->span->parent_link[l]] = 1;
            const mech_joint *jt = &m->joints[t->span->parent_joint[l]];
            if (jt->kind == MECH_JOINT_SLIDER)
                angle[jt->link[1]] = 1;
        }
    for (int c = 0; c < g->cols.ncols; c++)
        if (g->cols.cols[c].src == SRC_LINK)
            angle[g->cols.cols[c].obj] = 1;
    fprintf(f, "/* The link frames F[NLINKS] (src/solve/kinematics.c), the output columns, and the\n"
               " * branch conditions: the first that fails, or -1. */\n"
               "static int kinematics(cg_state *s, rt_frame *F, double q, double qd, double qdd,\n"
               "                      int first)\n{\n"
               "    double bv = 0.0;\n"
               "    (void)q, (void)qd, (void)qdd, (void)first, (void)bv;\n");
    for (int l = 0; l < m->nlinks; l++)  /* the frames below do not set in full */
        if (!(l > 0 && angle[l] && t->active[l] && t->angle_var[l] >= 0))
            fprintf(f, "    rt_frame_rest(&F[%d]);\n", l);
    for (int k = 0; k < t->span->norder; k++)
        if (angle[t->span->order[k]])
            emit_angle(g, f, t->span->order[k]);
    for (int k = 0; k < t->span->norder; k++)
        if (t->active[t->span->order[k]])
            emit_place(g, f, t->span->order[k]);
    emit_columns(g, f);
    for (int b = 0; b < m->nbranches; b++)
        emit_branch(g, f, b);
    fprintf(f, "    return -1;\n}\n\n");
    free(angle);
    return 0;
}
