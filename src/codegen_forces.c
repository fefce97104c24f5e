/* src/codegen_forces.c: the kinetostatics of `mech codegen` (codegen.h,
 * docs/codegen.md section "Forces"): the joint reactions, the gear pairs'
 * tooth forces and their separating part, each driver's torque or force,
 * joint friction, springs, the loads that depend on the motion
 * (codegen_state_loads.c) and the power balance, written as C that mirrors
 * src/forces.c, src/gears.c and src/springs.c operation for operation.
 *
 * The force system's pattern, columns and block triangular form are the
 * interpreter's own (forces_plan_init, its linsys plan's blocklu analysis):
 * the generated code assembles each column's entries straight into their
 * slots of the dense diagonal blocks (or above them), factors the blocks
 * with the same dense LU as the kinematics and solves, so the results are
 * those of `mech solve --forces` to the last bit when the interpreter
 * factors the force system dense (every block of at most 16 equations; a
 * larger block is refused here, the interpreter would use KLU). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "codegen.h"
#include "drivers.h"

static const double PI = 3.14159265358979323846;

/* ---- analysis ------------------------------------------------------------- */

int codegen_forces_plan(codegen *g, mech_diag *d)
{
    const mech_model *m = g->m;
    int rc = forces_plan_init(&g->fp, &g->sp, g->opt.friction, d);
    g->fp_ready = 1;
    if (rc != MECH_OK)
        return rc;
    rc = codegen_sl_check(g, d);
    if (rc != MECH_OK)
        return rc;
    if (g->fp.lp.use_klu)
        return diag_error(d, m->file, m->driver.mark,
                          "codegen: the force system has a diagonal block of more than %d "
                          "equations, which mech solve factors with KLU: not supported by the "
                          "code generator", BLOCKLU_MAX_BLOCK);
    return MECH_OK;
}

/* ---- helpers --------------------------------------------------------------- */

static void num(char *buf, size_t size, double v) { codegen_number(buf, size, v); }

void codegen_point_xy(const mech_model *m, int l, int i, char *buf, size_t size)
{
    char x[40], y[40];
    num(x, sizeof x, m->links[l].points[i].x);
    num(y, sizeof y, m->links[l].points[i].y);
    snprintf(buf, size, "%s, %s", x, y);
}

/* Receiving link (a) and the other (b) of joint j (forces.c joint_links). */
static void joint_links(const mech_joint *jt, int *a, int *b)
{
    if (jt->kind == MECH_JOINT_SLIDER) {
        *a = jt->link[0];
        *b = jt->link[1];
    } else {
        *a = jt->link[0] > jt->link[1] ? jt->link[0] : jt->link[1];
        *b = jt->link[0] > jt->link[1] ? jt->link[1] : jt->link[0];
    }
}

/* u[0], u[1] = the guide direction of slider jt (forces.c guide_dir). */
static void emit_guide(FILE *f, const mech_joint *jt, const char *indent)
{
    char ang[40];
    num(ang, sizeof ang, jt->angle);
    fprintf(f, "%sdouble u[2];\n%s{\n%s    double ang = F[%d].th + %s;\n"
               "%s    u[0] = cos(ang);\n%s    u[1] = sin(ang);\n%s}\n",
            indent, indent, indent, jt->link[1], ang, indent, indent, indent);
}

/* ---- the declarations ------------------------------------------------------ */

void codegen_forces_enums(const codegen *g, FILE *f)
{
    if (!g->want_forces)
        return;
    fprintf(f, "/* The force system: its unknowns (joint reactions, the gear pairs' tooth\n"
               " * forces, then each driver's torque or force, the last), and what %s_solve\n"
               " * returns when the forces fail. */\n"
               "enum { %s_NF = %d, %s_FORCE_SINGULAR = 4, %s_FRICTION_STUCK = 5 };\n\n",
            g->lower, g->upper, g->fp.ncols, g->upper, g->upper);
}

void codegen_forces_state(const codegen *g, FILE *f)
{
    if (!g->want_forces)
        return;
    const forces_plan *fp = &g->fp;
    const blocklu_plan *b = &fp->lp.blu;
    int n = fp->ncols, nl = g->m->nlinks, ns = g->m->nsprings > 0 ? g->m->nsprings : 1;
    fprintf(f,
            "    /* forces (docs/forces.md): the force system's unknowns in the order of\n"
            "       src/forces.c (Fx, Fy per revolute, N (M) per slider, the tooth force\n"
            "       per gear pair, the drivers last) */\n"
            "    double fy[%d];    /* with friction (when the file has it) */\n"
            "    double fy0[%d];   /* frictionless (with --friction both, or at the first\n"
            "                         position of a friction iteration) */\n"
            "    double power_residual, power_residual0; /* power balance, relative */\n"
            "    double friction_power; /* W dissipated in the joints */\n"
            "    double drive_power;    /* W from the driver */\n"
            "    double force_rcond;    /* reciprocal condition of the force system, when checked */\n"
            "    int friction_iterations; /* fixed-point iterations (-1: no convergence) */\n"
            "    int force_status;      /* 0, %s_FORCE_SINGULAR or %s_FRICTION_STUCK */\n"
            "    /* forces work (private) */\n"
            "    double fv[%d], fcs[%d], fb[%d], fw[%d], fe[%d], fcolnorm[%d], fanorm[%d];\n"
            "    double ffric[%d], fg[%d], fr[%d], fag[%d], fdg[%d], fdr[%d];\n"
            "    double cg[%d], cvg[%d], cag[%d], spr[%d], fqd;\n"
            "    int fpiv[%d], fswap, fcond_known, fprev;\n",
            n, n, g->upper, g->upper, b->nv > 0 ? b->nv : 1, n, n, n, n, n,
            b->nblocks > 0 ? b->nblocks : 1, n, n, n, n, 3 * n, 3 * n, 2 * nl, 2 * nl, 2 * nl,
            9 * ns, n);
    codegen_sl_state(g, f);
}

/* ---- the tables and the per-mechanism functions ------------------------------- */

static void table(FILE *f, const char *name, const int *v, int n)
{
    fprintf(f, "static const int %s[%d] = {", name, n > 0 ? n : 1);
    for (int i = 0; i < n; i++)
        fprintf(f, "%s%d", i % 16 ? ", " : (i ? ",\n    " : ""), v[i]);
    fprintf(f, "%s};\n", n ? "" : "0");
}

static int emit_tables(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    const blocklu_plan *b = &fp->lp.blu;
    int n = fp->ncols;
    int *Q = xcalloc((size_t)n + 1, sizeof *Q);
    if (!Q)
        return -1;
    for (int k = 0; k < n; k++)
        Q[k] = b->Q[k] < 0 ? -b->Q[k] - 2 : b->Q[k];
    fprintf(f, "/* ---- forces (src/forces.c): the force system's block triangular form */\n"
               "#define NF %d        /* unknowns = equations, 3 per moving link */\n"
               "#define NFB %d       /* diagonal blocks */\n"
               "#define NFDENSE %d   /* their dense storage; fv holds them, then the entries "
               "above */\n"
               "#define FORCE_FRICTION %d  /* joint friction applied */\n"
               "#define FORCE_BOTH %d      /* the frictionless forces solved too */\n"
               "#define DRIVER_SLIDER %d   /* the driver is a slider (its eps is in m/s) */\n"
               "#define FORCE_GEARS %d     /* gear pairs: their separating forces solved */\n"
               "#define FRICTION_TOL 1e-12\n#define FRICTION_MAX_ITER 100\n"
               "#define ANDERSON_DEPTH 3\n\n",
            n, b->nblocks, b->ndense, fp->friction, fp->want_frictionless,
            g->m->driver.kind == MECH_DRIVE_SLIDER, g->m->ngears > 0);
    table(f, "fperm_row", b->P, n);
    table(f, "fperm_col", Q, n);
    table(f, "fblock_start", b->R, b->nblocks + 1);
    table(f, "fblock_at", b->at, b->nblocks);
    table(f, "fabove_start", b->op, n + 1);
    table(f, "fabove_row", b->oi, b->op[n]);
    fprintf(f, "\n");
    free(Q);
    return 0;
}

/* Centres of mass (frame origins for links without mass) with their
 * rates, and the springs (forces.c update_centres, springs.c springs_eval). */
static void emit_motion(const codegen *g, FILE *f)
{
    const mech_model *m = g->m;
    fprintf(f, "/* Centres of mass and their rates, the springs (src/forces.c update_centres,\n"
               " * src/springs.c springs_eval) */\n"
               "static void force_motion(cg_state *s, const cg_frame *F)\n{\n"
               "    (void)F;\n");
    for (int l = 0; l < m->nlinks; l++) {
        const mech_link *k = &m->links[l];
        char x[40], y[40];
        num(x, sizeof x, k->has_mass ? k->center[0] : 0.0);
        num(y, sizeof y, k->has_mass ? k->center[1] : 0.0);
        fprintf(f, "    on_link(&F[%d], %s, %s, s->cg + %d, s->cvg + %d, s->cag + %d);\n", l, x, y,
                2 * l, 2 * l, 2 * l);
    }
    for (int i = 0; i < m->nsprings; i++) {
        const mech_spring *sp = &m->springs[i];
        char fr[40], k[40], pre[40], c[40], twopi[40];
        num(fr, sizeof fr, sp->free);
        num(k, sizeof k, sp->stiffness);
        num(pre, sizeof pre, sp->preload);
        num(c, sizeof c, sp->damping);
        num(twopi, sizeof twopi, 2 * PI);
        fprintf(f, "    {   /* spring %d: length, rate, force, u, ends */\n"
                   "        double *st = s->spr + %d;\n", i, 9 * i);
        if (sp->kind == MECH_SPRING_TORSION) {
            fprintf(f, "        double dev = remainder(F[%d].th - F[%d].th - %s, %s);\n"
                       "        st[0] = %s + dev;\n"
                       "        st[1] = F[%d].om - F[%d].om;\n"
                       "        st[2] = %s + %s * dev + %s * st[1];\n    }\n",
                    sp->link[0], sp->link[1], fr, twopi, fr, sp->link[0], sp->link[1], pre, k, c);
            continue;
        }
        char p0[96], p1[96];
        codegen_point_xy(m, sp->link[0], sp->point[0], p0, sizeof p0);
        codegen_point_xy(m, sp->link[1], sp->point[1], p1, sizeof p1);
        fprintf(f, "        double v0[2], v1[2], a[2];\n"
                   "        on_link(&F[%d], %s, st + 5, v0, a);\n"
                   "        on_link(&F[%d], %s, st + 7, v1, a);\n"
                   "        double d[2] = {st[7] - st[5], st[8] - st[6]};\n"
                   "        st[0] = hypot(d[0], d[1]);\n"
                   "        st[3] = st[0] > 0.0 ? d[0] / st[0] : 1.0;\n"
                   "        st[4] = st[0] > 0.0 ? d[1] / st[0] : 0.0;\n"
                   "        st[1] = st[3] * (v1[0] - v0[0]) + st[4] * (v1[1] - v0[1]);\n"
                   "        st[2] = %s + %s * (st[0] - %s) + %s * st[1];\n    }\n",
                sp->link[0], p0, sp->link[1], p1, pre, k, fr, c);
    }
    fprintf(f, "}\n\n");
}

/* rhs[3 (l - 1) ..] for a force fx, fy at p on link l (forces.c load_force). */
static void emit_load_force(FILE *f, int l, const char *rhs, const char *p, const char *fx,
                            const char *fy, const char *indent)
{
    if (l == 0)
        return;
    int row = 3 * (l - 1);
    fprintf(f, "%s{\n%s    double r0 = %s[0] - s->cg[%d], r1 = %s[1] - s->cg[%d];\n"
               "%s    %s[%d] -= %s;\n%s    %s[%d] -= %s;\n"
               "%s    %s[%d] -= r0 * (%s) - r1 * (%s);\n%s}\n",
            indent, indent, p, 2 * l, p, 2 * l + 1, indent, rhs, row, fx, indent, rhs, row + 1, fy,
            indent, rhs, row + 2, fy, fx, indent);
}

/* double p[2], t[2], r[2] = gear pair i's pitch point, tangent and
 * separating direction at the position of the frames F (gears.c
 * gears_contact, place). */
static void emit_gear_contact(const codegen *g, FILE *f, int i, const char *in)
{
    const mech_model *m = g->m;
    const mech_gear *gr = &m->gears[i];
    char pa[96], rad[40], sep[40];
    codegen_point_xy(m, gr->arm, gr->arm_pivot[0], pa, sizeof pa);
    num(rad, sizeof rad, gr->radius[0]);
    fprintf(f, "%sdouble p[2], t[2], r[2], a[2], n[2], av[2], aa[2];\n"
               "%son_link(&F[%d], %s, a, av, aa);\n", in, in, gr->arm, pa);
    if (gr->kind == MECH_GEAR_RACK) {
        const mech_joint *jt = &m->joints[gr->rack];
        char ang[40], sd[40], msd[40];
        num(ang, sizeof ang, jt->angle);
        num(sd, sizeof sd, (double)gr->side);
        num(msd, sizeof msd, (double)-gr->side);
        fprintf(f, "%s{\n%s    double ang = F[%d].th + %s;\n"
                   "%s    n[0] = %s * sin(ang);\n%s    n[1] = %s * cos(ang);\n%s}\n",
                in, in, jt->link[1], ang, in, sd, in, msd, in);
    } else {
        char pb[96];
        codegen_point_xy(m, gr->arm, gr->arm_pivot[1], pb, sizeof pb);
        fprintf(f, "%s{\n%s    double b[2], bv[2], ba[2];\n"
                   "%s    on_link(&F[%d], %s, b, bv, ba);\n"
                   "%s    double d = hypot(b[0] - a[0], b[1] - a[1]);\n"
                   "%s    n[0] = (b[0] - a[0]) / d;\n%s    n[1] = (b[1] - a[1]) / d;\n",
                in, in, in, gr->arm, pb, in, in, in);
        if (gr->internal && gr->radius[0] < gr->radius[1])  /* a inside the ring b */
            fprintf(f, "%s    n[0] = -n[0];\n%s    n[1] = -n[1];\n", in, in);
        fprintf(f, "%s}\n", in);
    }
    double sg = gr->kind == MECH_GEAR_PAIR && gr->internal && gr->radius[0] > gr->radius[1]
                    ? -1.0 : 1.0;
    num(sep, sizeof sep, sg);
    fprintf(f, "%sp[0] = a[0] + %s * n[0];\n%sp[1] = a[1] + %s * n[1];\n"
               "%st[0] = -n[1];\n%st[1] = n[0];\n"
               "%sr[0] = %s * n[0];\n%sr[1] = %s * n[1];\n"
               "%s(void)t, (void)r;\n",
            in, rad, in, rad, in, in, in, sep, in, sep, in);
}

/* The separating part of each tooth force for reactions y, on rhs
 * (forces.c gear_separation): |F| tan(pressure angle) along r. */
static void emit_gear_separation(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    const mech_model *m = g->m;
    fprintf(f, "/* The teeth's separating forces |F| tan(pressure angle) for the reactions y\n"
               " * (src/forces.c gear_separation) */\n"
               "static void force_gear_separation(cg_state *s, const cg_frame *F, const double *y,\n"
               "                                  double *rhs)\n{\n"
               "    (void)s, (void)F, (void)y, (void)rhs;\n");
    for (int i = 0; i < m->ngears; i++) {
        const mech_gear *gr = &m->gears[i];
        char tn[40];
        num(tn, sizeof tn, tan(gr->pressure_angle));  /* the interpreter's libm value */
        fprintf(f, "    {   /* gear pair %d */\n", i);
        emit_gear_contact(g, f, i, "        ");
        fprintf(f, "        double k = fabs(y[%d]) * %s;\n"
                   "        double fb[2] = {k * r[0], k * r[1]}, fa[2] = {-fb[0], -fb[1]};\n"
                   "        (void)fa, (void)fb;\n", fp->gcol + i, tn);
        emit_load_force(f, gr->link[1], "rhs", "p", "fb[0]", "fb[1]", "        ");
        emit_load_force(f, gr->link[0], "rhs", "p", "fa[0]", "fa[1]", "        ");
        fprintf(f, "    }\n");
    }
    fprintf(f, "}\n\n");
}

/* e[] of a force along d at p: on link a (+), its opposite on b (forces.c
 * push_force); the number of entries. */
static int emit_pushes(FILE *f, int a, int b, int *rows)
{
    int n = 0, link[2] = {a, b};
    for (int k = 0; k < 2; k++) {
        if (link[k] == 0)
            continue;
        const char *sg = k ? "(-1.0)" : "1.0";
        int l = link[k];
        fprintf(f, "        {\n            double r0 = p[0] - s->cg[%d], r1 = p[1] - s->cg[%d];\n"
                   "            e[%d] = %s * d[0];\n            e[%d] = %s * d[1];\n"
                   "            e[%d] = %s * (r0 * d[1] - r1 * d[0]);\n        }\n",
                2 * l, 2 * l + 1, n, sg, n + 1, sg, n + 2, sg);
        rows[n] = 3 * (l - 1), rows[n + 1] = rows[n] + 1, rows[n + 2] = rows[n] + 2;
        n += 3;
    }
    return n;
}

/* The entries of force column c as C: e[0..n-1], n returned (forces.c
 * column_entries, push_force, push_moment), and the rows they go to. */
static int emit_column_entries(const codegen *g, FILE *f, int c, int *rows)
{
    const forces_plan *fp = &g->fp;
    const mech_model *m = g->m;
    int n = 0;
    /* driver k's column: joint -1 - k */
    const mech_motion *dr = fp->joint[c] < 0 ? &m->drivers[-1 - fp->joint[c]] : NULL;
    mech_drive_kind dkind = dr ? dr->kind : MECH_DRIVE_SLIDER;
    int dindex = dr ? dr->index : -1;
    if (fp->joint[c] < 0 && dkind == MECH_DRIVE_ANGLE) {
        if (dindex != 0) {
            fprintf(f, "        e[0] = 1.0;\n");
            rows[n++] = 3 * (dindex - 1) + 2;
        }
        return n;
    }
    const mech_joint *jt = &m->joints[fp->joint[c] >= 0 ? fp->joint[c] : dindex];
    int a, b, link[2];
    joint_links(jt, &a, &b);
    link[0] = a, link[1] = b;
    if (fp->kind[c] == FC_GEAR) {  /* the tooth force: on link[1], its opposite on link[0] */
        const mech_gear *gr = &m->gears[fp->joint[c]];
        emit_gear_contact(g, f, fp->joint[c], "        ");
        fprintf(f, "        double d[2] = {t[0], t[1]};\n");
        return emit_pushes(f, gr->link[1], gr->link[0], rows);
    }
    if (fp->kind[c] == FC_MOMENT) {
        for (int k = 0; k < 2; k++)
            if (link[k] != 0) {
                fprintf(f, "        e[%d] = %s;\n", n, k ? "(-1.0)" : "1.0");
                rows[n++] = 3 * (link[k] - 1) + 2;
            }
        return n;
    }
    char pt[96];
    codegen_point_xy(m, jt->link[0], jt->point[0], pt, sizeof pt);
    fprintf(f, "        double p[2], pv[2], pa[2], d[2];\n"
               "        on_link(&F[%d], %s, p, pv, pa);\n", jt->link[0], pt);
    switch (fp->kind[c]) {
    case FC_FX: fprintf(f, "        d[0] = 1.0, d[1] = 0.0;\n"); break;
    case FC_FY: fprintf(f, "        d[0] = 0.0, d[1] = 1.0;\n"); break;
    case FC_NORMAL:
    case FC_DRIVE:
        emit_guide(f, jt, "        ");
        if (fp->kind[c] == FC_NORMAL)
            fprintf(f, "        d[0] = -u[1], d[1] = u[0];\n");
        else
            fprintf(f, "        d[0] = u[0], d[1] = u[1];\n");
        break;
    default: break;
    }
    return emit_pushes(f, a, b, rows);
}

/* The force matrix, column by column, equilibrated, straight into the
 * slots of the blocks' dense storage or above them (forces.c factor,
 * blocklu.c blocklu_factor's placement). */
static int emit_matrix(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    const blocklu_plan *b = &fp->lp.blu;
    /* dense slots no entry fills: zero before each factorisation */
    unsigned char *filled = xcalloc((size_t)b->ndense + 1, 1);
    if (!filled)
        return -1;
    for (int p = 0; p < fp->nnz; p++)
        if (b->where[p] < b->ndense)
            filled[b->where[p]] = 1;
    fprintf(f, "/* The force matrix, each column scaled to unit largest entry (s->fcs), its\n"
               " * entries put where the dense LU of the blocks wants them (src/forces.c\n"
               " * factor, src/blocklu.c blocklu_factor) */\n"
               "static void force_matrix(cg_state *s, const cg_frame *F)\n{\n"
               "    double *restrict fv = s->fv;\n    (void)F;\n");
    for (int i = 0; i < b->ndense; i++)
        if (!filled[i])
            fprintf(f, "    fv[%d] = 0.0;\n", i);
    free(filled);
    for (int c = 0; c < fp->ncols; c++) {
        int rows[8];
        fprintf(f, "    {   /* column %d */\n        double e[6], big = 0.0;\n", c);
        int n = emit_column_entries(g, f, c, rows);
        int at = fp->Ap[c];
        if (n != fp->Ap[c + 1] - at) {
            fprintf(stderr, "codegen: force column %d has %d entries, the pattern %d\n", c, n,
                    fp->Ap[c + 1] - at);
            return -1;
        }
        fprintf(f, "        for (int k = 0; k < %d; k++)\n"
                   "            big = fabs(e[k]) > big ? fabs(e[k]) : big;\n"
                   "        double cs = big > 0.0 ? 1.0 / big : 1.0;\n"
                   "        s->fcs[%d] = cs;\n", n, c);
        for (int k = 0; k < n; k++)
            fprintf(f, "        fv[%d] = e[%d] * cs;\n", b->where[fp->slot[at + k]], k);
        fprintf(f, "    }\n");
    }
    fprintf(f, "}\n\n");
    return 0;
}

/* The resultant of load i: double lf[2], lp[2], lv[2] (forces.c
 * load_resultant). */
static void emit_resultant(const codegen *g, FILE *f, int i)
{
    const mech_model *m = g->m;
    const mech_load *ld = &m->loads[i];
    char pt[96], a[40], b[40];
    if (ld->kind == MECH_LOAD_FORCE) {
        codegen_point_xy(m, ld->link, ld->point[0], pt, sizeof pt);
        num(a, sizeof a, ld->force[0]);
        num(b, sizeof b, ld->force[1]);
        fprintf(f, "        double lf[2] = {%s, %s}, lp[2], lv[2], la[2];\n"
                   "        on_link(&F[%d], %s, lp, lv, la);\n"
                   "        (void)lp, (void)lv;\n", a, b, ld->link, pt);
        return;
    }
    char pt1[96], w[40], dir[40];
    codegen_point_xy(m, ld->link, ld->point[0], pt, sizeof pt);
    codegen_point_xy(m, ld->link, ld->point[1], pt1, sizeof pt1);
    num(w, sizeof w, ld->intensity);
    num(dir, sizeof dir, ld->direction);
    fprintf(f, "        double lf[2], lp[2], lv[2], la[2], p0[2], p1[2], v0[2], v1[2];\n"
               "        on_link(&F[%d], %s, p0, v0, la);\n"
               "        on_link(&F[%d], %s, p1, v1, la);\n"
               "        double w = %s * hypot(p1[0] - p0[0], p1[1] - p0[1]);\n"
               "        lf[0] = w * cos(%s);\n        lf[1] = w * sin(%s);\n"
               "        for (int k = 0; k < 2; k++) {\n"
               "            lp[k] = 0.5 * (p0[k] + p1[k]);\n"
               "            lv[k] = 0.5 * (v0[k] + v1[k]);\n        }\n"
               "        (void)lp, (void)lv;\n",
            ld->link, pt, ld->link, pt1, w, dir, dir);
}

/* Inertia, gravity, loads and springs (forces.c known_loads,
 * springs.c springs_add_loads). */
static void emit_known(const codegen *g, FILE *f)
{
    const mech_model *m = g->m;
    char gx[40], gy[40];
    num(gx, sizeof gx, m->gravity[0]);
    num(gy, sizeof gy, m->gravity[1]);
    fprintf(f, "/* The known loads: inertia, gravity, the file's loads, the springs (src/forces.c\n"
               " * known_loads) */\n"
               "static void force_known(cg_state *s, const cg_frame *F, double *rhs)\n{\n"
               "    (void)s, (void)F;\n");
    for (int l = 1; l < m->nlinks; l++) {
        const mech_link *k = &m->links[l];
        int row = 3 * (l - 1);
        if (!k->has_mass) {
            fprintf(f, "    rhs[%d] = rhs[%d] = rhs[%d] = 0.0;\n", row, row + 1, row + 2);
            continue;
        }
        char mass[40], in[40];
        num(mass, sizeof mass, k->mass);
        num(in, sizeof in, k->inertia);
        fprintf(f, "    rhs[%d] = %s * (s->cag[%d] - %s);\n    rhs[%d] = %s * (s->cag[%d] - %s);\n"
                   "    rhs[%d] = %s * F[%d].al;\n",
                row, mass, 2 * l, gx, row + 1, mass, 2 * l + 1, gy, row + 2, in, l);
    }
    for (int i = 0; i < m->nloads; i++) {
        const mech_load *ld = &m->loads[i];
        if (ld->kind == MECH_LOAD_TORQUE) {
            char t[40];
            num(t, sizeof t, ld->torque);
            if (ld->link != 0)
                fprintf(f, "    rhs[%d] -= %s;\n", 3 * (ld->link - 1) + 2, t);
            continue;
        }
        fprintf(f, "    {   /* load %d */\n", i);
        emit_resultant(g, f, i);
        emit_load_force(f, ld->link, "rhs", "lp", "lf[0]", "lf[1]", "        ");
        fprintf(f, "    }\n");
    }
    for (int i = 0; i < m->nsprings; i++) {  /* springs.c add_load */
        const mech_spring *sp = &m->springs[i];
        fprintf(f, "    {   /* spring %d */\n        const double *st = s->spr + %d;\n", i, 9 * i);
        for (int k = 0; k < 2; k++) {
            int l = sp->link[k];
            if (l == 0)
                continue;
            int row = 3 * (l - 1);
            if (sp->kind == MECH_SPRING_TORSION) {
                fprintf(f, "        {\n            double r0 = 0.0 - s->cg[%d], r1 = 0.0 - s->cg[%d];\n"
                           "            rhs[%d] -= 0.0;\n            rhs[%d] -= 0.0;\n"
                           "            rhs[%d] -= r0 * 0.0 - r1 * 0.0 + %sst[2];\n        }\n",
                        2 * l, 2 * l + 1, row, row + 1, row + 2, k ? "" : "-");
            } else {
                const char *sg = k ? "-" : "";
                fprintf(f, "        {\n            double fx = %s(st[2] * st[3]), fy = %s(st[2] * st[4]);\n"
                           "            double r0 = st[%d] - s->cg[%d], r1 = st[%d] - s->cg[%d];\n"
                           "            rhs[%d] -= fx;\n            rhs[%d] -= fy;\n"
                           "            rhs[%d] -= r0 * fy - r1 * fx + 0.0;\n        }\n",
                        sg, sg, 5 + 2 * k, 2 * l, 6 + 2 * k, 2 * l + 1, row, row + 1, row + 2);
            }
        }
        fprintf(f, "    }\n");
    }
    codegen_sl_known(g, f);
    fprintf(f, "}\n\n");
}

/* The rate of the coordinate slider joint j drives: its unknown's
 * velocity, the driver's speed, or 0 (forces.c drive_power, relative_speed). */
static void slider_rate(const codegen *g, int j, char *buf, size_t size)
{
    int var = g->sp.tree.slide_var[j];
    snprintf(buf, size, "0.0");
    if (var == g->sp.n)  /* the driving slider: its speed */
        snprintf(buf, size, "s->fqd");
    else if (var >= 0 && var < g->sp.n && g->unk_col[var] >= 0)
        snprintf(buf, size, "s->xd[%d]", g->unk_col[var]);
}

/* The drivers' power for reactions y (forces.c drive_power): the sum over
 * the drivers of each load times the rate of its coordinate. */
static void emit_drive_power(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    const mech_model *m = g->m;
    int first = fp->ncols - fp->ndrive;
    fprintf(f, "/* The drivers' power for the reactions y (src/forces.c drive_power) */\n"
               "static double force_drive_power(const cg_state *s, const cg_frame *F, "
               "const double *y,\n                                double qd)\n{\n"
               "    (void)s, (void)F, (void)qd;\n");
    fprintf(f, "    double p = 0.0;\n");
    for (int k = 0; k < fp->ndrive; k++) {
        const mech_motion *mo = &m->drivers[k];
        char rate[48];
        if (mo->kind == MECH_DRIVE_ANGLE)
            snprintf(rate, sizeof rate, "F[%d].om", mo->index);
        else
            slider_rate(g, mo->index, rate, sizeof rate);
        fprintf(f, "    p += y[%d] * %s;\n", first + k, rate);
    }
    fprintf(f, "    return p;\n}\n\n");
}

/* The power balance (forces.c power_residual, springs.c springs_power). */
static void emit_power(const codegen *g, FILE *f)
{
    const mech_model *m = g->m;
    char gx[40], gy[40];
    num(gx, sizeof gx, m->gravity[0]);
    num(gy, sizeof gy, m->gravity[1]);
    fprintf(f, "/* P_driver + P_loads + P_gravity - P_friction - dT/dt relative to the sum of\n"
               " * the terms' magnitudes (src/forces.c power_residual) */\n"
               "static double force_power(cg_state *s, const cg_frame *F, double qd, double pd,\n"
               "                          double pfric)\n{\n"
               "    double kin = 0.0, ext = 0.0, scale = fabs(pd) + fabs(pfric);\n"
               "    (void)s, (void)F, (void)qd;\n");
    for (int l = 1; l < m->nlinks; l++) {
        const mech_link *k = &m->links[l];
        if (!k->has_mass)
            continue;
        char mass[40], in[40];
        num(mass, sizeof mass, k->mass);
        num(in, sizeof in, k->inertia);
        fprintf(f, "    {\n        const double *vg = s->cvg + %d, *ag = s->cag + %d;\n"
                   "        double dk = %s * (vg[0] * ag[0] + vg[1] * ag[1]) + %s * F[%d].om * F[%d].al;\n"
                   "        double pg = %s * (%s * vg[0] + %s * vg[1]);\n"
                   "        kin += dk;\n        ext += pg;\n"
                   "        scale += fabs(%s * vg[0] * ag[0]) + fabs(%s * vg[1] * ag[1]) +\n"
                   "                 fabs(%s * F[%d].om * F[%d].al) + fabs(pg);\n    }\n",
                2 * l, 2 * l, mass, in, l, l, mass, gx, gy, mass, mass, in, l, l);
    }
    for (int i = 0; i < m->nloads; i++) {
        const mech_load *ld = &m->loads[i];
        fprintf(f, "    {   /* load %d */\n        double pw;\n", i);
        if (ld->kind == MECH_LOAD_TORQUE) {
            char t[40];
            num(t, sizeof t, ld->torque);
            fprintf(f, "        pw = %s * F[%d].om;\n", t, ld->link);
        } else {
            emit_resultant(g, f, i);
            fprintf(f, "        pw = lf[0] * lv[0] + lf[1] * lv[1];\n");
        }
        fprintf(f, "        ext += pw;\n        scale += fabs(pw);\n    }\n");
    }
    if (m->nsprings > 0) {
        int angle = m->driver.kind == MECH_DRIVE_ANGLE;
        fprintf(f, "    {   /* the springs (src/springs.c springs_power) */\n"
                   "        double total = 0.0, speed = fabs(qd);\n"
                   "        double linear = %s, turning = %s;\n"
                   "        (void)linear, (void)turning;\n",
                angle ? "speed * LREF" : "speed", angle ? "speed" : "speed / LREF");
        for (int i = 0; i < m->nsprings; i++)
            fprintf(f, "        total -= s->spr[%d] * s->spr[%d];\n"
                       "        scale += fabs(s->spr[%d] * s->spr[%d]) + fabs(s->spr[%d]) * %s;\n",
                    9 * i + 2, 9 * i + 1, 9 * i + 2, 9 * i + 1, 9 * i + 2,
                    m->springs[i].kind == MECH_SPRING_TORSION ? "turning" : "linear");
        fprintf(f, "        ext += total;\n    }\n");
    }
    codegen_sl_power(g, f);
    fprintf(f, "    double r = pd + ext - pfric - kin;\n"
               "    return scale > 0.0 ? r / scale : 0.0;\n}\n\n");
}

/* Friction loads of reactions y into s->ffric and the power they take
 * (forces.c friction_loads). */
static void emit_friction(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    const mech_model *m = g->m;
    if (!fp->friction)
        return;
    fprintf(f, "static inline double smooth_sign(double v, double eps) { return v / sqrt(v * v + "
               "eps * eps); }\n\n"
               "/* Coulomb friction loads of the reactions y (src/forces.c friction_loads) */\n"
               "static double force_friction(cg_state *s, const cg_frame *F, const double *y,\n"
               "                             double eps)\n{\n"
               "    double power = 0.0, *fr = s->ffric;\n"
               "    (void)F, (void)y, (void)eps;\n"
               "    for (int i = 0; i < NF; i++)\n        fr[i] = 0.0;\n");
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (!(jt->friction > 0.0))
            continue;
        int a, b, c = fp->jcol[j];
        joint_links(jt, &a, &b);
        char mu[40];
        num(mu, sizeof mu, jt->friction);
        fprintf(f, "    {   /* joint %d */\n", j);
        if (jt->kind == MECH_JOINT_REVOLUTE) {
            char r[40];
            num(r, sizeof r, jt->pin_radius);
            fprintf(f, "        double rel = F[%d].om - F[%d].om;\n"
                       "        double mf = %s * %s * sqrt(y[%d] * y[%d] + y[%d] * y[%d]) * "
                       "smooth_sign(rel, eps);\n", a, b, mu, r, c, c, c + 1, c + 1);
            if (a != 0)
                fprintf(f, "        fr[%d] -= -mf;\n", 3 * (a - 1) + 2);
            if (b != 0)
                fprintf(f, "        fr[%d] -= mf;\n", 3 * (b - 1) + 2);
            fprintf(f, "        power += mf * rel;\n");
        } else {
            char rel[48], pt[96];
            slider_rate(g, j, rel, sizeof rel);
            codegen_point_xy(m, jt->link[0], jt->point[0], pt, sizeof pt);
            fprintf(f, "        double rel = %s;\n"
                       "        double ff = %s * fabs(y[%d]) * smooth_sign(rel, eps * LREF);\n",
                    rel, mu, c);
            emit_guide(f, jt, "        ");
            fprintf(f, "        double p[2], v[2], acc[2];\n"
                       "        on_link(&F[%d], %s, p, v, acc);\n"
                       "        double fa[2] = {-ff * u[0], -ff * u[1]}, fb[2] = {ff * u[0], ff * u[1]};\n"
                       "        (void)fa, (void)fb;\n",
                    jt->link[0], pt);
            emit_load_force(f, a, "fr", "p", "fa[0]", "fa[1]", "        ");
            emit_load_force(f, b, "fr", "p", "fb[0]", "fb[1]", "        ");
            fprintf(f, "        power += ff * rel;\n");
        }
        fprintf(f, "    }\n");
    }
    fprintf(f, "    return power;\n}\n\n");
}

int codegen_forces_emit(const codegen *g, FILE *f)
{
    if (!g->want_forces)
        return 0;
    if (emit_tables(g, f) < 0)
        return -1;
    emit_motion(g, f);
    if (emit_matrix(g, f) < 0)
        return -1;
    if (codegen_sl_emit(g, f) < 0)
        return -1;
    emit_known(g, f);
    emit_drive_power(g, f);
    emit_power(g, f);
    emit_friction(g, f);
    emit_gear_separation(g, f);
    for (int i = 0; codegen_force_runtime[i]; i++)
        fprintf(f, "%s\n", codegen_force_runtime[i]);
    return ferror(f) ? -1 : 0;
}

/* ---- the output columns ---------------------------------------------------------- */

int codegen_forces_column(const codegen *g, FILE *f, int c)
{
    const column_desc *cd = &g->cols.cols[c];
    const forces_plan *fp = &g->fp;
    const mech_model *m = g->m;
    const char *y = cd->set ? "s->fy" : "s->fy0";
    switch (cd->src) {
    case SRC_REACTION: {
        const mech_joint *jt = &m->joints[cd->obj];
        int col = fp->jcol[cd->obj];
        if (jt->kind == MECH_JOINT_REVOLUTE) {
            if (cd->comp < 2)
                fprintf(f, "        s->out[%d] = %s[%d];\n", c, y, col + cd->comp);
            else
                fprintf(f, "        s->out[%d] = hypot(%s[%d], %s[%d]);\n", c, y, col, y, col + 1);
            return 1;
        }
        if (cd->comp == 2)
            fprintf(f, "        s->out[%d] = %s[%d];\n", c, y, col);
        else if (cd->comp == 3 && jt->locked)
            fprintf(f, "        s->out[%d] = %s[%d];\n", c, y, col + 1);
        else if (cd->comp == 3)
            fprintf(f, "        s->out[%d] = 0.0;\n", c);
        if (cd->comp < 2) {
            fprintf(f, "        {\n");
            emit_guide(f, jt, "            ");
            fprintf(f, "            s->out[%d] = %s * %s[%d];\n        }\n", c,
                    cd->comp == 0 ? "-u[1]" : "u[0]", y, col);
        }
        return 1;
    }
    case SRC_DRIVE_LOAD:  /* driver obj of the last ndrive columns */
        fprintf(f, "        s->out[%d] = %s[%d];\n", c, y, fp->ncols - fp->ndrive + cd->obj);
        return 1;
    case SRC_GEAR: {  /* the tooth force along the line of action (forces.c forces_gear) */
        char cs[40];
        num(cs, sizeof cs, cos(m->gears[cd->obj].pressure_angle));  /* the interpreter's libm */
        fprintf(f, "        s->out[%d] = s->fy[%d] / %s;\n", c, fp->gcol + cd->obj, cs);
        return 1;
    }
    case SRC_POWER_RESIDUAL:
        fprintf(f, "        s->out[%d] = s->power_residual%s;\n", c, cd->set ? "" : "0");
        return 1;
    case SRC_FRICTION_POWER:
        fprintf(f, "        s->out[%d] = s->friction_power;\n", c);
        return 1;
    case SRC_FRICTION_ITERATIONS:
        fprintf(f, "        s->out[%d] = s->friction_iterations;\n", c);
        return 1;
    case SRC_SPRING:
        fprintf(f, "        s->out[%d] = s->spr[%d];\n", c, 9 * cd->obj + cd->comp);
        return 1;
    default:
        return 0;
    }
}
