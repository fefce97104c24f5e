/* src/codegen/codegen_forces.c: the kinetostatics of `mech codegen` (codegen.h,
 * docs/codegen.md section "Forces"): the joint reactions, the gear pairs'
 * tooth forces, each driver's torque or force, joint friction, springs,
 * the loads that depend on the motion and the power balance.
 *
 * The force system is the interpreter's, structure and numbers: its
 * pattern, columns and block triangular form (forces_plan_init, its linsys
 * plan's blocklu analysis) and its description (forces_numbers_t: what
 * enters each row and column) are written out as constant tables, and the
 * generated functions call rt_forces.h's functions on them, entry by
 * entry, as forces.c does in its loops; the entries of each column go
 * straight into their slots of the dense diagonal blocks (or above them).
 * So the results are those of `mech solve --forces` to the last bit when
 * the interpreter factors the force system dense (every block of at most
 * 16 equations; a larger block is refused here, the interpreter would use
 * KLU). The solve itself, friction and the power balance's sequence are
 * rt_forces_solve's (src/runtime/rt_solver.h, cg_kinetostatics). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "codegen.h"
#include "load.h"

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
            "       src/forces/forces.c (Fx, Fy per revolute, N (M) per slider, the tooth force\n"
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
            "    double fv[%d], fcs[%d], fb[%d], fw[%d], fcolnorm[%d], fanorm[%d];\n"
            "    double ffric[%d], fg[%d], fr[%d], fag[%d], fdg[%d], fdr[%d];\n"
            "    double cg[%d], cvg[%d], cag[%d], spr[%d], fvel[%d];\n"
            "    int fpiv[%d], fswap, fcond_known, fprev;\n",
            n, n, g->upper, g->upper, b->nv > 0 ? b->nv : 1, n, n, n + 3 * b->largest, n,
            b->nblocks > 0 ? b->nblocks : 1, n, n, n, n, 3 * n, 3 * n, 2 * nl, 2 * nl, 2 * nl,
            RT_SPRING_STATE * ns, g->sp.ns + 1, n);
    codegen_sl_state(g, f);
}

/* ---- the description as constant tables --------------------------------------- */

static void num(char *buf, size_t size, double v) { codegen_number(buf, size, v); }

/* "{link, {x, y}}" */
static void point_init(const rt_point *p, char *buf, size_t size)
{
    char x[40], y[40];
    num(x, sizeof x, p->r[0]);
    num(y, sizeof y, p->r[1]);
    snprintf(buf, size, "{%d, {%s, %s}}", p->link, x, y);
}

static void int_table(FILE *f, const char *name, const int *v, int n)
{
    fprintf(f, "static const int %s[%d] = {", name, n > 0 ? n : 1);
    for (int i = 0; i < n; i++)
        fprintf(f, "%s%d", i % 16 ? ", " : (i ? ",\n    " : ""), v[i]);
    fprintf(f, "%s};\n", n ? "" : "0");
}

/* A slide's rate as the generated code holds it: fvel[i] = xd[i] for solved
 * unknown i, fvel[NX] the driver's speed (the interpreter's vel[var], var n
 * the driver); -1 none. */
static int rate_index(const codegen *g, int var)
{
    if (var == g->sp.n)
        return g->sp.ns;
    return var >= 0 && var < g->sp.n ? g->unk_col[var] : -1;
}

/* The block triangular form and the constants of forces_solve. */
static void emit_form(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    const blocklu_plan *b = &fp->lp.blu;
    int n = fp->ncols;
    fprintf(f, "/* ---- forces (src/forces/forces.c): the force system's block triangular form */\n"
               "#define NF %d        /* unknowns = equations, 3 per moving link */\n"
               "#define NFB %d       /* diagonal blocks */\n"
               "#define NFDENSE %d   /* their dense storage; fv holds them, then the entries "
               "above */\n"
               "#define FORCE_FRICTION %d  /* joint friction applied */\n"
               "#define FORCE_BOTH %d      /* the frictionless forces solved too */\n"
               "#define DRIVER_SLIDER %d   /* the driver is a slider (its eps is in m/s) */\n"
               "#define FORCE_GEARS %d     /* gear pairs: their separating forces solved */\n\n",
            n, b->nblocks, b->ndense, fp->friction, fp->want_frictionless,
            g->m->driver.kind == MECH_DRIVE_SLIDER, g->m->ngears > 0);
    int_table(f, "fperm_row", b->P, n);
    int_table(f, "fperm_col", b->Q, n);
    int_table(f, "fblock_start", b->R, b->nblocks + 1);
    int_table(f, "fblock_at", b->at, b->nblocks);
    int_table(f, "fabove_start", b->op, n + 1);
    int_table(f, "fabove_row", b->oi, b->op[n]);
    int_table(f, "fabove_col", b->oj, b->op[n]);
    fprintf(f, "/* the force system's block triangular form (src/runtime/rt_blocklu.h; force_matrix\n"
               "   writes the entries in their slots) */\n"
               "static const rt_blocks fjac = {NF, NFB, NFDENSE, %d, %d, %d, fperm_row, fperm_col,\n"
               "                               fblock_start, fblock_at, NULL, fabove_start, "
               "fabove_row,\n                               fabove_col};\n\n",
            fp->nnz, b->dense_full, b->pq_parity);
}

/* Each column's description (rt_fcol) as literals. */
static void emit_fcols(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    char a[128], x[40];
    fprintf(f, "static const rt_fcol fcols[NF] = {\n");
    for (int c = 0; c < fp->ncols; c++) {
        const rt_fcol *d = &fp->num.cols[c];
        point_init(&d->at, a, sizeof a);
        num(x, sizeof x, d->angle);
        fprintf(f, "    {%d, {%d, %d}, %s, %d, %d, %s, %d},\n", d->kind, d->on[0], d->on[1], a,
                d->dir, d->guide, x, d->gear);
    }
    fprintf(f, "};\n");
}

/* The bodies, gravity, gears, loads, springs and friction as literals. */
static void emit_number_tables(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    const forces_numbers_t *fn = &fp->num;
    char a[128], b[128], x[40], y[40], z[40], w[40];
    fprintf(f, "static const rt_body fbody[NLINKS] = {\n");
    for (int l = 0; l < g->m->nlinks; l++) {
        const rt_body *d = &fn->body[l];
        num(x, sizeof x, d->mass);
        num(y, sizeof y, d->inertia);
        num(z, sizeof z, d->centre[0]);
        num(w, sizeof w, d->centre[1]);
        fprintf(f, "    {%d, %s, %s, {%s, %s}},\n", d->has_mass, x, y, z, w);
    }
    num(x, sizeof x, fn->grav[0]);
    num(y, sizeof y, fn->grav[1]);
    fprintf(f, "};\nstatic const double fgrav[2] = {%s, %s};\n", x, y);
    if (g->m->ngears > 0)
        fprintf(f, "static const rt_gear fgears[%d] = {\n", g->m->ngears);
    for (int i = 0; i < g->m->ngears; i++) {
        const rt_gear *d = &fn->gears[i];
        char r[40], sep[40], tn[40], cs[40];
        point_init(&d->a, a, sizeof a);
        point_init(&d->b, b, sizeof b);
        num(x, sizeof x, d->angle);
        num(y, sizeof y, d->side);
        num(r, sizeof r, d->radius);
        num(sep, sizeof sep, d->sep);
        num(tn, sizeof tn, d->tan_pa);
        num(cs, sizeof cs, d->cos_pa);
        fprintf(f, "    {%d, %s, %s, %d, %d, %s, %s, %s, %s, %s, %s, {%d, %d}},\n", d->rack, a, b,
                d->inside, d->guide, x, y, r, sep, tn, cs, d->on[0], d->on[1]);
    }
    if (g->m->ngears > 0)
        fprintf(f, "};\n");
    if (fn->nloads > 0)
        fprintf(f, "static const rt_load floads[%d] = {\n", fn->nloads);
    for (int i = 0; i < fn->nloads; i++) {
        const rt_load *d = &fn->loads[i];
        point_init(&d->at, a, sizeof a);
        point_init(&d->to, b, sizeof b);
        num(x, sizeof x, d->v[0]);
        num(y, sizeof y, d->v[1]);
        fprintf(f, "    {%d, %s, %s, {%s, %s}, {%d, %d}},\n", d->kind, a, b, x, y, d->reg[0],
                d->reg[1]);
    }
    if (fn->nloads > 0)
        fprintf(f, "};\n");
    if (fn->nsprings > 0)
        fprintf(f, "static const rt_spring fsprings[%d] = {\n", fn->nsprings);
    for (int i = 0; i < fn->nsprings; i++) {
        const rt_spring *d = &fn->springs[i];
        point_init(&d->end[0], a, sizeof a);
        point_init(&d->end[1], b, sizeof b);
        num(x, sizeof x, d->rest);
        num(y, sizeof y, d->stiffness);
        num(z, sizeof z, d->preload);
        num(w, sizeof w, d->damping);
        fprintf(f, "    {%d, {%s, %s}, %s, %s, %s, %s},\n", d->torsion, a, b, x, y, z, w);
    }
    if (fn->nsprings > 0)
        fprintf(f, "};\n");
    if (fp->friction && fn->nfric > 0)
        fprintf(f, "static const rt_friction ffriction[%d] = {\n", fn->nfric);
    for (int k = 0; fp->friction && k < fn->nfric; k++) {
        const rt_friction *d = &fn->fric[k];
        point_init(&d->at, a, sizeof a);
        num(x, sizeof x, d->mu);
        num(y, sizeof y, d->radius);
        num(z, sizeof z, d->angle);
        fprintf(f, "    {%d, %d, %d, %d, %s, %s, %s, %d, %s, %d},\n", d->slider, d->a, d->b,
                d->col, x, y, a, d->guide, z, rate_index(g, d->var));
    }
    if (fp->friction && fn->nfric > 0)
        fprintf(f, "};\n");
}

/* A sweep's variants (codegen_options.leaves): the tables of numbers are
 * the variant's, which P_numbers points the state at (codegen_numbers_fill:
 * the view's forces_numbers_t). */
static void emit_tables_from_state(FILE *f)
{
    fprintf(f, "/* the variant's tables (P_numbers) */\n"
               "#define fcols ((const rt_fcol *)s->num->fcols)\n"
               "#define fbody ((const rt_body *)s->num->fbody)\n"
               "#define fgrav (s->num->fgrav)\n"
               "#define fgears ((const rt_gear *)s->num->fgears)\n"
               "#define floads ((const rt_load *)s->num->floads)\n"
               "#define fsprings ((const rt_spring *)s->num->fsprings)\n"
               "#define ffriction ((const rt_friction *)s->num->ffriction)\n");
}

/* What enters each row and column (forces_numbers_t, rt_forces.h): the
 * numbers as literals, or a sweep's variant's; the slots and drivers. */
static void emit_description(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    fprintf(f, "/* ---- what enters each row and column (src/forces/forces.c forces_numbers) */\n");
    if (g->opt.leaves) {
        emit_tables_from_state(f);
    } else {
        emit_fcols(g, f);
        emit_number_tables(g, f);
    }
    fprintf(f, "/* each column's entries' slots in fv, in rt_fcol_entries' order */\n");
    int *dst = xcalloc((size_t)fp->nnz + 1, sizeof *dst);
    for (int p = 0; dst && p < fp->nnz; p++)
        dst[p] = fp->lp.blu.where[fp->slot[p]];
    int_table(f, "fdst", dst, dst ? fp->nnz : 0);
    free(dst);
    if (drivers_rows(g->m) > 0) {
        fprintf(f, "static const rt_drive fdrive[%d] = {", fp->ndrive);
        for (int k = 0; k < fp->ndrive; k++)
            fprintf(f, "%s{%d, %d}", k ? ", " : "", fp->num.drive[k].link,
                    rate_index(g, fp->num.drive[k].var));
        fprintf(f, "};\n");
    }
    fprintf(f, "\n");
}

/* ---- the per-mechanism functions: one call per entry of the tables ------------ */

/* Centres of mass and their rates, the springs (src/forces/forces.c forces_solve). */
static void emit_motion(const codegen *g, FILE *f)
{
    fprintf(f, "/* Centres of mass and their rates, the springs, once per position */\n"
               "static void force_motion(cg_state *s, const rt_frame *F)\n{\n    (void)F;\n");
    for (int l = 0; l < g->m->nlinks; l++)
        fprintf(f, "    rt_centre(&fbody[%d], &F[%d], s->cg + %d, s->cvg + %d, s->cag + %d);\n", l,
                l, 2 * l, 2 * l, 2 * l);
    for (int i = 0; i < g->fp.num.nsprings; i++)
        fprintf(f, "    rt_spring_eval(&fsprings[%d], F, s->spr + %d);\n", i, RT_SPRING_STATE * i);
    fprintf(f, "}\n\n");
}

/* The force matrix, column by column, equilibrated, straight into the
 * slots of the blocks' dense storage or above them (forces.c factor). */
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
               " * entries put where the dense LU of the blocks wants them */\n"
               "static void force_matrix(cg_state *s, const rt_frame *F)\n{\n"
               "    double e[6];\n");
    for (int i = 0; i < b->ndense; i++)
        if (!filled[i])
            fprintf(f, "    s->fv[%d] = 0.0;\n", i);
    free(filled);
    for (int c = 0; c < fp->ncols; c++)
        fprintf(f, "    s->fcs[%d] = rt_scale_into(e, rt_fcol_entries(&fcols[%d], %s, NULL, F, s->cg, e), "
                   "s->fv, fdst + %d);\n",
                c, c, g->m->ngears > 0 ? "fgears" : "NULL", fp->Ap[c]);
    fprintf(f, "}\n\n");
    return 0;
}

/* The calls of loads from .. to - 1: onto the right-hand side rhs, or
 * (power 1) into the power balance pw. */
static void emit_loads(const codegen *g, FILE *f, int from, int to, int power)
{
    const forces_numbers_t *fn = &g->fp.num;
    const char *reg = fn->nloads > fn->nconst ? "s->slr" : "NULL";
    for (int i = from; i < to; i++)
        fprintf(f, power ? "    rt_power_load(&pw, &floads[%d], F, %s);\n"
                         : "    rt_load_apply(&floads[%d], F, s->cg, %s, rhs);\n", i, reg);
}

/* One call per load in forces.c's order: the constant loads, the springs,
 * those that depend on the motion. */
static void emit_load_calls(const codegen *g, FILE *f, int power)
{
    const forces_numbers_t *fn = &g->fp.num;
    emit_loads(g, f, 0, fn->nconst, power);
    for (int k = 0; k < fn->nsprings; k++)
        fprintf(f, power ? "    rt_power_spring(&pw, &fsprings[%d], s->spr + %d);\n"
                         : "    rt_spring_load(&fsprings[%d], s->spr + %d, s->cg, rhs);\n",
                k, RT_SPRING_STATE * k);
    emit_loads(g, f, fn->nconst, fn->nloads, power);
}

/* Inertia, gravity, the loads, the springs, those that depend on the
 * motion, in forces.c known_loads' order. */
static void emit_known(const codegen *g, FILE *f)
{
    fprintf(f, "/* The known loads: inertia, gravity, the file's loads, the springs */\n"
               "static void force_known(cg_state *s, const rt_frame *F, double *rhs)\n{\n"
               "    (void)s, (void)F;\n");
    for (int l = 1; l < g->m->nlinks; l++)
        fprintf(f, "    rt_body_load(&fbody[%d], &F[%d], s->cag + %d, fgrav, rhs + %d);\n", l, l,
                2 * l, 3 * (l - 1));
    emit_load_calls(g, f, 0);
    fprintf(f, "}\n\n");
}

/* The drivers' power for reactions y (forces.c ctx_drive_power), the
 * driver's speed qd. */
static void emit_drive_power(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    int laws = drivers_rows(g->m) > 0;
    fprintf(f, "/* The drivers' power for the reactions y */\n"
               "static double force_drive_power(const cg_state *s, const rt_frame *F, "
               "const double *y,\n                                double qd)\n{\n"
               "    (void)s, (void)F;\n"
               "    return rt_drive_power(%s, %d, %d, F, s->fvel, qd, y + %d);\n}\n\n",
            laws ? "fdrive" : "NULL", fp->ndrive, laws, fp->ncols - fp->ndrive);
}

/* The power balance (forces.c ctx_power): the scales from the speed qd. */
static void emit_power(const codegen *g, FILE *f)
{
    const forces_numbers_t *fn = &g->fp.num;
    fprintf(f, "/* P_driver + P_loads + P_gravity - P_friction - dT/dt relative to the sum of\n"
               " * the terms' magnitudes */\n"
               "static double force_power(cg_state *s, const rt_frame *F, double qd, double pd,\n"
               "                          double pfric)\n{\n"
               "    rt_power pw;\n    double linear, turning;\n"
               "    (void)s, (void)F;\n"
               "    rt_power_scales(%d, qd, LREF, &linear, &turning);\n"
               "    rt_power_start(&pw, pd, pfric, linear, turning);\n",
            g->m->driver.kind == MECH_DRIVE_ANGLE);
    for (int l = 1; l < g->m->nlinks; l++)
        if (fn->body[l].has_mass)
            fprintf(f, "    rt_power_body(&pw, &fbody[%d], &F[%d], s->cvg + %d, s->cag + %d, "
                       "fgrav);\n", l, l, 2 * l, 2 * l);
    emit_load_calls(g, f, 1);
    fprintf(f, "    return rt_power_end(&pw, pd, pfric);\n}\n\n");
}

/* Friction loads of reactions y into fr and the power they take
 * (forces.c ctx_friction). */
static void emit_friction(const codegen *g, FILE *f)
{
    const forces_plan *fp = &g->fp;
    fprintf(f, "/* Coulomb friction loads of the reactions y (eps: the smoothing) */\n"
               "static double force_friction(cg_state *s, const rt_frame *F, const double *y,\n"
               "                             double eps, double *fr)\n{\n"
               "    double power = 0.0;\n"
               "    (void)s, (void)F, (void)y, (void)eps;\n"
               "    for (int i = 0; i < NF; i++)\n        fr[i] = 0.0;\n");
    for (int k = 0; fp->friction && k < fp->num.nfric; k++)
        fprintf(f, "    power += rt_friction_load(&ffriction[%d], F, s->cg, s->fvel, y, eps, LREF, "
                   "fr);\n", k);
    fprintf(f, "    return power;\n}\n\n");
}

/* The separating part of each tooth force for reactions y, on rhs. */
static void emit_gear_separation(const codegen *g, FILE *f)
{
    fprintf(f, "/* The teeth's separating forces |F| tan(pressure angle) for the reactions y */\n"
               "static void force_gear_separation(cg_state *s, const rt_frame *F, const double *y,\n"
               "                                  double *rhs)\n{\n"
               "    (void)s, (void)F, (void)y, (void)rhs;\n");
    for (int i = 0; i < g->m->ngears; i++)
        fprintf(f, "    rt_gear_separation(&fgears[%d], F, s->cg, y[%d], rhs);\n", i,
                g->fp.gcol + i);
    fprintf(f, "}\n\n");
}

/* The output column c from the forces; 0 when it is not a force column. */
static int emit_column(const codegen *g, FILE *f, int c)
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
                fprintf(f, "    s->out[%d] = %s[%d];\n", c, y, col + cd->comp);
            else
                fprintf(f, "    s->out[%d] = hypot(%s[%d], %s[%d]);\n", c, y, col, y, col + 1);
        } else if (cd->comp < 2) {
            char ang[40];
            num(ang, sizeof ang, jt->angle);
            fprintf(f, "    {\n        double r[2];\n"
                       "        rt_slider_reaction(&F[%d], %s, %s[%d], r, r + 1);\n"
                       "        s->out[%d] = r[%d];\n    }\n",
                    jt->link[1], ang, y, col, c, cd->comp);
        } else if (cd->comp == 2 || jt->locked) {
            fprintf(f, "    s->out[%d] = %s[%d];\n", c, y, col + cd->comp - 2);
        } else {
            fprintf(f, "    s->out[%d] = 0.0;\n", c);
        }
        return 1;
    }
    case SRC_DRIVE_LOAD:  /* driver obj of the last ndrive columns */
        fprintf(f, "    s->out[%d] = %s[%d];\n", c, y, fp->ncols - fp->ndrive + cd->obj);
        return 1;
    case SRC_GEAR:  /* the tooth force along the line of action (forces.c forces_gear) */
        fprintf(f, "    s->out[%d] = rt_tooth_force(&fgears[%d], s->fy[%d]);\n", c, cd->obj,
                fp->gcol + cd->obj);
        return 1;
    case SRC_POWER_RESIDUAL:
        fprintf(f, "    s->out[%d] = s->power_residual%s;\n", c, cd->set ? "" : "0");
        return 1;
    case SRC_FRICTION_POWER:
        fprintf(f, "    s->out[%d] = s->friction_power;\n", c);
        return 1;
    case SRC_FRICTION_ITERATIONS:
        fprintf(f, "    s->out[%d] = s->friction_iterations;\n", c);
        return 1;
    case SRC_SPRING:
        fprintf(f, "    s->out[%d] = s->spr[%d];\n", c, RT_SPRING_STATE * cd->obj + cd->comp);
        return 1;
    default:
        return 0;
    }
}

static void emit_columns(const codegen *g, FILE *f)
{
    fprintf(f, "/* The force columns of out (forces.c forces_joint, forces_gear, ...) */\n"
               "static void force_columns(cg_state *s, const rt_frame *F)\n{\n    (void)F;\n");
    for (int c = 0; c < g->cols.ncols; c++)
        emit_column(g, f, c);
    fprintf(f, "}\n\n");
}

int codegen_forces_emit(const codegen *g, FILE *f)
{
    if (!g->want_forces)
        return 0;
    emit_form(g, f);
    emit_description(g, f);
    emit_motion(g, f);
    if (emit_matrix(g, f) < 0 || codegen_sl_emit(g, f) < 0)
        return -1;
    emit_known(g, f);
    emit_drive_power(g, f);
    emit_power(g, f);
    emit_friction(g, f);
    emit_gear_separation(g, f);
    emit_columns(g, f);
    return ferror(f) ? -1 : 0;
}
