/* src/codegen/codegen.c: `mech codegen` (codegen.h, docs/codegen.md): the analysis
 * (the interpreter's solver plan, the block triangular form of the solved
 * Jacobian, the output columns and the names of the generated API), and
 * the emission of the header and of the source around the expression code
 * (codegen_expr.c), the kinetostatics (codegen_forces.c) and the text of
 * the runtime libmech shares with it (src/rt_*.h: build/gen/rt_text.c). */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "codegen.h"
#include "load.h"

/* ---- analysis ---------------------------------------------------------------- */

/* NAME in upper case with every other character than a letter or digit
 * made '_', after "PREFIX_"; a copy to free(). */
static char *identifier(const char *upper_prefix, const char *part, const char *name)
{
    size_t len = strlen(upper_prefix) + strlen(part) + strlen(name) + 16;
    char *id = malloc(len);
    if (!id)
        return NULL;
    int at = snprintf(id, len, "%s_%s", upper_prefix, part);
    for (const char *c = name; *c; c++)
        id[at++] = isalnum((unsigned char)*c) ? (char)toupper((unsigned char)*c) : '_';
    id[at] = '\0';
    return id;
}

/* Make ids[i] distinct from ids[0..i-1] by appending "_i" (names that
 * differ only in punctuation: "A.x" and "A_x"). */
static int make_distinct(char **ids, int n)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < i; j++)
            if (strcmp(ids[i], ids[j]) == 0) {
                size_t len = strlen(ids[i]) + 16;
                char *more = realloc(ids[i], len);
                if (!more)
                    return -1;
                snprintf(more + strlen(more), 16, "_%d", i);
                ids[i] = more;
                j = -1;  /* again from the start */
            }
    return 0;
}

static int make_identifiers(codegen *g)
{
    const solver_plan *sp = &g->sp;
    g->col_ident = xcalloc((size_t)g->cols.ncols + 1, sizeof *g->col_ident);
    g->unk_ident = xcalloc((size_t)sp->ns + 1, sizeof *g->unk_ident);
    if (!g->col_ident || !g->unk_ident)
        return -1;
    for (int c = 0; c < g->cols.ncols; c++)
        /* the input column is COL_Q whatever its name (q, or t for laws of time) */
        if (!(g->col_ident[c] = identifier(g->upper, "COL_", g->cols.cols[c].src == SRC_DRIVER
                                                                 ? "q" : g->cols.cols[c].name)))
            return -1;
    for (int k = 0; k < sp->ns; k++) {
        int var = sp->col[k], idx = sp->sys->unk_index[var];
        const char *name = sp->sys->unk_kind[var] == UNK_ANGLE ? g->m->links[idx].name
                                                              : g->m->joints[idx].name;
        if (!(g->unk_ident[k] = identifier(g->upper, "X_", name)))
            return -1;
    }
    return make_distinct(g->col_ident, g->cols.ncols) | make_distinct(g->unk_ident, sp->ns);
}

/* The names the prefix P gives the generated API, as P_NAME (lower case)
 * and P_NAME (upper case: the enumerators and macros; P_X_... and
 * P_COL_... are families). */
static const char *const public_lower[] = {"state", "init", "solve", "predict", "rcond",
                                           "column_names", "column_units", "unknown_names",
                                           "numbers"};
static const char *const public_upper[] = {
    "NX", "NOUT", "OK", "NO_ASSEMBLY", "SINGULAR", "BRANCH", "NF", "FORCE_SINGULAR",
    "FRICTION_STUCK", "DRIVER_FROM", "DRIVER_TO", "DRIVER_STEPS", "DRIVER_SPEED",
    "DRIVER_ACCEL", "GENERATED_H", "X_", "COL_"};

/* Is identifier id (len characters) a name the generated API makes from
 * prefix P (lower and upper case)? */
static int public_name(const char *lower, const char *upper, const char *id, size_t len)
{
    size_t n = strlen(lower);
    if (len <= n + 1 || id[n] != '_')
        return 0;
    const char *rest = id + n + 1;
    size_t rlen = len - n - 1;
    if (strncmp(id, lower, n) == 0)
        for (size_t i = 0; i < COUNT_OF(public_lower); i++)
            if (strlen(public_lower[i]) == rlen && strncmp(rest, public_lower[i], rlen) == 0)
                return 1;
    if (strncmp(id, upper, n) == 0)
        for (size_t i = 0; i < COUNT_OF(public_upper); i++) {
            size_t k = strlen(public_upper[i]);
            int family = public_upper[i][k - 1] == '_';
            if (family ? rlen > k && strncmp(rest, public_upper[i], k) == 0
                       : rlen == k && strncmp(rest, public_upper[i], k) == 0)
                return 1;
        }
    return 0;
}

/* The runtime's names of the state and statuses, which the source
 * defines as P_state, P_OK, ...: with prefix cg they are those names. */
static int cg_alias(const char *id, size_t len)
{
    static const char *const alias[] = {"cg_state", "CG_OK", "CG_NO_ASSEMBLY", "CG_SINGULAR",
                                        "CG_BRANCH", "CG_FORCE_SINGULAR", "CG_FRICTION_STUCK"};
    for (size_t i = 0; i < COUNT_OF(alias); i++)
        if (strlen(alias[i]) == len && strncmp(id, alias[i], len) == 0)
            return 1;
    return 0;
}

/* The first identifier of one line of C code (comments, which may go on
 * from the line before, and members after . or ->, which live apart from
 * the functions and types, left out) that the prefix makes a public name
 * of too, into buf; NULL when none. */
static const char *line_clash(const codegen *g, const char *line, int *in_comment, char *buf,
                              size_t size)
{
    for (const char *c = line; *c;) {
        if (*in_comment || (c[0] == '/' && c[1] == '*')) {
            const char *end = strstr(*in_comment ? c : c + 2, "*/");
            *in_comment = !end;
            if (!end)
                return NULL;
            c = end + 2;
            continue;
        }
        if (!(isalpha((unsigned char)*c) || *c == '_')) {
            c++;
            continue;
        }
        const char *id = c, *before = c;
        while (isalnum((unsigned char)*c) || *c == '_')
            c++;
        while (before > line && before[-1] == ' ')
            before--;
        int member = before > line && (before[-1] == '.' || before[-1] == '>');
        if (!member && public_name(g->lower, g->upper, id, (size_t)(c - id)) &&
            !cg_alias(id, (size_t)(c - id))) {
            snprintf(buf, size, "%.*s", (int)(c - id), id);
            return buf;
        }
    }
    return NULL;
}

/* The first identifier of the runtime's code (src/rt_*.h) that the prefix
 * makes a public name of too, or NULL (into buf). */
static const char *prefix_clash(const codegen *g, char *buf, size_t size)
{
    const char *const *texts[] = {codegen_rt_base,   codegen_rt_blocklu, codegen_rt_newton,
                                  codegen_rt_frame,  codegen_rt_forces,  codegen_rt_law,
                                  codegen_rt_solver};
    for (size_t t = 0; t < COUNT_OF(texts); t++) {
        int in_comment = 0;
        for (int l = 0; texts[t][l]; l++)
            if (line_clash(g, texts[t][l], &in_comment, buf, size))
                return buf;
    }
    return NULL;
}

static int valid_prefix(const char *p)
{
    if (!p || !(isalpha((unsigned char)p[0]) || p[0] == '_') || strlen(p) > 40)
        return 0;
    for (const char *c = p; *c; c++)
        if (!isalnum((unsigned char)*c) && *c != '_')
            return 0;
    return 1;
}

/* Every point the columns or branch conditions read has its frame placed
 * (the plan activates them already; this keeps the two in step). */
static int activate_points(codegen *g)
{
    const mech_model *m = g->m;
    unsigned char *need = xcalloc((size_t)g->sp.n + 1, 1);
    if (!need)
        return -1;
    for (int c = 0; c < g->cols.ncols; c++)
        if (g->cols.cols[c].src == SRC_POINT)
            kin_need_point(&g->sp.tree, g->cols.cols[c].obj, need);
    for (int b = 0; b < m->nbranches; b++)
        for (int k = 0; k < 3 && m->branches[b].kind != MECH_BRANCH_SLIDER; k++)
            kin_need_point(&g->sp.tree, m->branches[b].point[k], need);
    free(need);
    return 0;
}

static int plan_solver(codegen *g, mech_diag *d)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.all_blocks = g->opt.all_blocks;
    o.forces = -1;
    g->want_forces = g->opt.forces > 0 || (g->opt.forces == 0 && g->m->outputs.forces);
    if (g->want_forces)  /* reactions need every link's acceleration (sweep.c) */
        o.all_blocks = 1;
    mech_system *sys = NULL;  /* NULL: the plan builds it */
    int rc = g->opt.leaves ? sys_new_with(g->m, g->opt.leaves, &sys, d) : MECH_OK;
    if (rc == MECH_OK)
        rc = solver_plan_init_with(&g->sp, g->m, &o, sys, d);
    if (rc != MECH_OK)
        return rc;
    const solver_plan *sp = &g->sp;
    g->nleaf = sp->sys->nvars - SYS_NVARS(sp->n);
    if (sp->aug)
        return diag_error(d, g->m->file, g->m->driver.mark,
                          "codegen: the loops have redundant constraints (%d equations for %d "
                          "unknowns), solved in the least-squares sense: not supported by the "
                          "code generator", sp->sys->m, sp->n);
    if (sp->ns > CODEGEN_MAX_UNKNOWNS)
        return diag_error(d, g->m->file, g->m->driver.mark,
                          "codegen: %d unknowns to solve, more than the code generator's limit "
                          "of %d", sp->ns, CODEGEN_MAX_UNKNOWNS);
    g->unk_col = xcalloc((size_t)sp->n + 1, sizeof *g->unk_col);
    if (!g->unk_col)
        return MECH_ENOMEM;
    for (int i = 0; i < sp->n; i++)
        g->unk_col[i] = -1;
    for (int k = 0; k < sp->ns; k++)
        g->unk_col[sp->col[k]] = k;
    /* the plan checked the pattern: only memory, or a block too large for the
       runtime's dense LU (the interpreter's KLU), can fail here */
    int rb = sp->ns > 0 ? blocklu_analyze(&g->bp, sp->ns, sp->Ap, sp->Ai, BLOCKLU_MAX_BLOCK) : 0;
    if (rb == 2)
        return diag_error(d, g->m->file, g->m->driver.mark,
                          "codegen: the Jacobian has a diagonal block of %d equations, more than "
                          "%d, which mech solve factors with KLU: not supported by the code "
                          "generator", g->bp.largest, BLOCKLU_MAX_BLOCK);
    return rb == 0 ? MECH_OK : MECH_ENOMEM;
}

int codegen_init(codegen *g, const mech_model *m, const codegen_options *o, mech_diag *d)
{
    memset(g, 0, sizeof *g);
    g->m = m;
    g->opt = *o;
    if (!valid_prefix(o->prefix))
        return diag_error(d, m->file, (mech_mark){0, 0},
                          "codegen: the prefix '%s' is not a C identifier of at most 40 "
                          "characters (--prefix)", o->prefix ? o->prefix : "");
    snprintf(g->lower, sizeof g->lower, "%s", o->prefix);
    for (size_t i = 0; g->lower[i]; i++)
        g->upper[i] = (char)toupper((unsigned char)g->lower[i]);
    char clash[64];
    if (prefix_clash(g, clash, sizeof clash))
        return diag_error(d, m->file, (mech_mark){0, 0},
                          "codegen: the prefix '%s' makes the public name '%s', which the "
                          "generated code's runtime uses itself: choose another (--prefix)",
                          o->prefix, clash);
    if (o->leaves && (m->state_loads || model_ncams(m) > 0))  /* variant_regs.c's too */
        return diag_error(d, m->file, (mech_mark){0, 0}, "codegen: one solver for a sweep's "
                          "variants: not with loads that depend on the motion or cams");
    int rc = plan_solver(g, d);
    if (rc != MECH_OK)
        goto fail;
    rc = MECH_ENOMEM;
    if (!(g->point_at = xcalloc((size_t)m->nlinks + 1, sizeof *g->point_at)))
        goto fail;
    for (int l = 1; l <= m->nlinks; l++)
        g->point_at[l] = g->point_at[l - 1] + m->links[l - 1].npoints;
    if (g->want_forces && model_ncams(m) > 0) {  /* the contact's geometry is the loader's */
        rc = diag_error(d, m->file, m->cams->cam[0].mark, "codegen: forces through a cam pair "
                        "('%s') are not generated (docs/cams.md, Limits): the interpreter "
                        "computes them", m->cams->cam[0].name);
        goto fail;
    }
    if (m->outputs.ncams > 0) {  /* the design quantities are the loader's geometry */
        rc = diag_error(d, m->file, m->cams->cam[m->outputs.cams[0]].mark, "codegen: the "
                        "design quantities of cam '%s' are not generated (docs/cams.md, "
                        "Limits): the interpreter computes them",
                        m->cams->cam[m->outputs.cams[0]].name);
        goto fail;
    }
    if (g->want_forces && (rc = codegen_forces_plan(g, d)) != MECH_OK)
        goto fail;
    int friction = !g->want_forces || !g->fp.friction ? 0 : g->fp.want_frictionless ? 2 : 1;
    column_request rq = {&m->outputs, MECH_WANT_ALL, g->want_forces, friction, 0};
    rc = MECH_ENOMEM;
    if (columns_build(&g->cols, m, &rq) != MECH_OK || activate_points(g) < 0 ||
        make_identifiers(g) < 0)
        goto fail;
    rc = codegen_expr_plan(g, d);
    if (rc == MECH_OK)
        return MECH_OK;
fail:
    if (rc == MECH_ENOMEM)
        diag_nomem(d, m->file, (mech_mark){0, 0});
    return rc;
}

void codegen_free(codegen *g)
{
    for (int c = 0; g->col_ident && c < g->cols.ncols; c++)
        free(g->col_ident[c]);
    for (int k = 0; g->unk_ident && k < g->sp.ns; k++)
        free(g->unk_ident[k]);
    free(g->col_ident);
    free(g->unk_ident);
    free(g->phase);
    free(g->keep);
    free(g->driver_only);
    free(g->point_at);
    free(g->unk_col);
    columns_free(&g->cols);
    if (g->fp_ready)
        forces_plan_free(&g->fp);
    blocklu_plan_free(&g->bp);
    solver_plan_free(&g->sp);
    memset(g, 0, sizeof *g);
}

/* ---- the header ------------------------------------------------------------- */

static int at_least_1(int n) { return n > 0 ? n : 1; }

/* A C string literal of s (names come from the file). */
static void c_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\')
            fprintf(f, "\\%c", c);
        else if (c < 32 || c >= 127)
            fprintf(f, "\\%03o", c);
        else
            fputc(c, f);
    }
    fputc('"', f);
}

/* s for a C comment (into buf): no comment end, no line break. */
static const char *comment_safe(const char *s, char *buf, size_t size)
{
    size_t n = 0;
    for (; *s && n + 1 < size; s++, n++)
        buf[n] = (unsigned char)*s < 32 || (*s == '/' && n > 0 && buf[n - 1] == '*') ? ' ' : *s;
    buf[n] = '\0';
    return buf;
}

/* The file the source is generated from, for its comments ("a file" when
 * anonymous: mech solve --jit's cache). */
static const char *source_file(const codegen *g, char *buf, size_t size)
{
    return g->opt.anonymous ? "a file" : comment_safe(g->m->file, buf, size);
}

static void emit_enums(const codegen *g, FILE *f)
{
    const char *P = g->upper;
    const solver_plan *sp = &g->sp;
    fprintf(f, "/* Sizes: the unknowns solved, the output columns. */\n"
               "enum { %s_NX = %d, %s_NOUT = %d };\n\n", P, sp->ns, P, g->cols.ncols);
    fprintf(f, "/* What %s_solve returns. */\nenum {\n"
               "    %s_OK = 0,          /* solved: x, xd, xdd, out are set */\n"
               "    %s_NO_ASSEMBLY = 1, /* Newton did not converge: the loops do not close "
               "(or the guess is too far) */\n"
               "    %s_SINGULAR = 2,    /* converged (or stuck) where the Jacobian is "
               "singular: rcond < %g */\n"
               "    %s_BRANCH = 3       /* solved, but branch condition `branch` of the file "
               "does not hold */\n};\n\n", g->lower, P, P, P, sp->opt.min_rcond, P);
    codegen_forces_enums(g, f);
    fprintf(f, "/* The unknowns: indices into x, xd, xdd, xq, xqq (link angles in rad, "
               "slider\n * displacements in m). */\nenum {\n");
    for (int k = 0; k < sp->ns; k++) {
        char item[160];
        snprintf(item, sizeof item, "%s = %d,", g->unk_ident[k], k);
        char name[256];
        fprintf(f, "    %-40s /* %s */\n", item,
                comment_safe(sp->sys->names[sp->col[k]], name, sizeof name));
    }
    if (sp->ns == 0)
        fprintf(f, "    %s_X_NONE = 0\n", P);
    fprintf(f, "};\n\n/* The output columns: indices into out, in the order of `mech solve`'s "
               "CSV\n * (without forces), SI units. */\nenum {\n");
    for (int c = 0; c < g->cols.ncols; c++) {
        char item[160];
        snprintf(item, sizeof item, "%s = %d,", g->col_ident[c], c);
        char name[256];
        fprintf(f, "    %-40s /* %s [%s] */\n", item,
                comment_safe(g->cols.cols[c].name, name, sizeof name), g->cols.cols[c].unit);
    }
    fprintf(f, "};\n\n");
}

static void emit_driver_macros(const codegen *g, FILE *f)
{
    const mech_driver *dr = &g->m->driver;
    const char *P = g->upper;
    char a[40], b[40], s[40], acc[40];
    codegen_number(a, sizeof a, dr->nvalues > 0 ? dr->values[0] : 0.0);
    codegen_number(b, sizeof b, dr->nvalues > 0 ? dr->values[dr->nvalues - 1] : 0.0);
    codegen_number(s, sizeof s, dr->speed);
    codegen_number(acc, sizeof acc, dr->accel);
    fprintf(f, "/* The file's driver (%s): its range in %d steps, its speed and acceleration. */\n"
               "#define %s_DRIVER_FROM %s\n#define %s_DRIVER_TO %s\n#define %s_DRIVER_STEPS %d\n"
               "#define %s_DRIVER_SPEED %s\n#define %s_DRIVER_ACCEL %s\n\n",
            dr->kind == MECH_DRIVE_TIME ? "time, s: the drivers' laws are in the equations"
            : dr->kind == MECH_DRIVE_ANGLE ? "an angle, rad" : "a slider, m",
            dr->nvalues > 0 ? dr->nvalues - 1 : 0, P, a, P, b, P,
            dr->nvalues > 0 ? dr->nvalues - 1 : 0, P, s, P, acc);
}

static void emit_state(const codegen *g, FILE *f)
{
    const solver_plan *sp = &g->sp;
    int nx = at_least_1(sp->ns), nz = at_least_1(sp->nnzJ), nk = at_least_1(g->nkeep + g->nleaf);
    int nd = at_least_1(sp->ns > 0 ? g->bp.nv : 0), nb = at_least_1(sp->ns > 0 ? g->bp.nblocks : 0);
    int largest = sp->ns > 0 ? g->bp.largest : 0;
    fprintf(f,
            "/* One solver's state: set it up with %s_init, then call %s_solve for each\n"
            " * driver position; x carries the solution over as the next starting guess. */\n"
            "typedef struct %s_state {\n"
            "    double x[%d];     /* unknowns (%s_X_*): the starting guess in, the solution out */\n"
            "    double xd[%d];    /* their velocities */\n"
            "    double xdd[%d];   /* their accelerations */\n"
            "    double xq[%d];    /* dx/dq, the geometric velocities (for a predictor) */\n"
            "    double xqq[%d];   /* d2x/dq2 */\n"
            "    double out[%d];   /* output columns (%s_COL_*) */\n"
            "    double residual;  /* |f|inf at the solution, m */\n"
            "    double rcond;     /* reciprocal condition of the Jacobian's worst block (a\n"
            "                         lower bound when rcond_exact is 0: %s_rcond) */\n"
            "    double rcond_whole; /* and of the whole Jacobian (Newton's rounding floor) */\n"
            "    int rcond_exact;  /* 1: rcond, rcond_whole are the interpreter's values */\n"
            "    int iterations;   /* Newton iterations of the last solve */\n"
            "    int det_sign;     /* sign of det J at the solution (+1, -1): a change between\n"
            "                         two positions means a singular one was crossed */\n"
            "    int branch;       /* %s_BRANCH: the condition that failed (0-based, in the\n"
            "                         file's order), else -1 */\n"
            "    int first;        /* 1: the next solve is a first position (conditions with\n"
            "                         first_only are checked too); %s_init sets it */\n"
            "    /* the predictor's history (%s_predict) */\n"
            "    int nsolved;      /* positions solved since %s_init */\n"
            "    double q_last, q_prev; /* the last two driver positions solved */\n"
            "    double xc[%d], xqq_prev[%d]; /* x at q_last, xqq at q_prev */\n"
            "    /* work (private) */\n"
            "    double xe[%d], f[%d], ft[%d], dx[%d], xt[%d], r[%d], cs[%d];\n"
            "    double w[%d], colnorm[%d], anorm[%d];\n"
            "    double keep[%d], Jv[%d], Ax[%d], lu[%d];\n"
            "    int piv[%d], swap_parity;\n",
            g->lower, g->lower, g->lower, nx, g->upper, nx, nx, nx, nx, g->cols.ncols, g->upper,
            g->lower, g->upper, g->lower, g->lower, g->lower, nx, nx, nx, nx, nx, nx, nx, nx, nx,
            4 * nx + 3 * largest, nx, nb, nk, nz, nz, nd, nx);
    if (g->opt.leaves)
        fprintf(f, "    const struct rt_numbers *num; /* the variant's numbers (%s_numbers) */\n",
                g->lower);
    codegen_forces_state(g, f);
    fprintf(f, "} %s_state;\n\n", g->lower);
}

static void emit_prototypes(const codegen *g, FILE *f)
{
    const char *p = g->lower, *P = g->upper;
    fprintf(f,
            "/* Names of the output columns (\"B.x\") and their units (\"m\"), of the unknowns. */\n"
            "extern const char *const %s_column_names[%s_NOUT];\n"
            "extern const char *const %s_column_units[%s_NOUT];\n"
            "extern const char *const %s_unknown_names[%d];\n\n"
            "/* The file's starting guesses in x (0 for an unknown without one), first = 1. */\n"
            "void %s_init(%s_state *s);\n"
            "/* Solve the driver position q (rad or m) from the guess in s->x, with driver\n"
            " * speed qd and acceleration qdd: %s_OK, %s_NO_ASSEMBLY, %s_SINGULAR or\n"
            " * %s_BRANCH (then x, xd, xdd and out are set). No allocation. */\n"
            "int %s_solve(%s_state *s, double q, double qd, double qdd);\n"
            "/* Set s->x to the prediction at driver position q from the last position\n"
            " * solved: x + h xq + h^2/2 xqq + h^3/6 xqqq (xqqq from the last two xqq),\n"
            " * the continuation of mech solve; the guesses of %s_init before any. */\n"
            "void %s_predict(%s_state *s, double q);\n"
            "/* The reciprocal condition of the Jacobian's worst block at the position\n"
            " * the last %s_solve converged to, the interpreter's value (s->rcond may\n"
            " * hold a lower bound, when the solve needed no more: docs/codegen.md). */\n"
            "double %s_rcond(%s_state *s);\n\n",
            p, P, p, P, p, at_least_1(g->sp.ns), p, p, P, P, P, P, p, p, p, p, p, p, p, p);
    if (g->opt.leaves)
        fprintf(f, "/* After %s_init: the numbers of the variant to solve (struct rt_numbers,\n"
                   " * src/runtime/rt_base.h), read through s until the next %s_init. */\n"
                   "struct rt_numbers;\n"
                   "void %s_numbers(%s_state *s, const struct rt_numbers *num);\n\n",
                p, p, p, p);
}

static void emit_declarations(const codegen *g, FILE *f)
{
    char file[512], name[512];
    fprintf(f, "/* Generated by `mech codegen` from %s (%s): a solver of positions,\n"
               " * velocities and accelerations for this mechanism alone (docs/codegen.md). */\n\n",
            source_file(g, file, sizeof file),
            g->opt.anonymous || !g->m->name ? "" : comment_safe(g->m->name, name, sizeof name));
    emit_enums(g, f);
    emit_driver_macros(g, f);
    emit_state(g, f);
    emit_prototypes(g, f);
}

int codegen_emit_header(FILE *f, const void *ctx)
{
    const codegen *g = ctx;
    fprintf(f, "#ifndef %s_GENERATED_H\n#define %s_GENERATED_H\n\n", g->upper, g->upper);
    emit_declarations(g, f);
    fprintf(f, "#endif\n");
    return ferror(f) ? -1 : 0;
}

/* ---- the source ---------------------------------------------------------------- */

static void int_table(FILE *f, const char *name, const int *v, int n)
{
    fprintf(f, "static const int %s[%d] = {", name, at_least_1(n));
    for (int i = 0; i < n; i++)
        fprintf(f, "%s%d", i % 16 ? ", " : (i ? ",\n    " : ""), v[i]);
    fprintf(f, "%s};\n", n ? "" : "0");
}

/* The Jacobian's block triangular form as blocklu_analyze made it (the
 * tables of an rt_blocks, rt_blocklu.h), and the solver's constants. */
static void emit_pattern(const codegen *g, FILE *f)
{
    const solver_plan *sp = &g->sp;
    const blocklu_plan *b = &g->bp;
    int ns = sp->ns, nz = sp->nnzJ, nb = ns > 0 ? b->nblocks : 0;
    int nabove = ns > 0 ? b->op[ns] : 0, none[2] = {0, 0};
    char tol[40], ftol[40], lref[40], minr[40];
    codegen_number(tol, sizeof tol, sp->opt.tol);
    codegen_number(ftol, sizeof ftol, sp->ftol);
    codegen_number(lref, sizeof lref, sp->lref);
    codegen_number(minr, sizeof minr, sp->opt.min_rcond);
    if (g->opt.leaves) {  /* a sweep's variant's (P_numbers) */
        snprintf(ftol, sizeof ftol, "(s->num->ftol)");
        snprintf(lref, sizeof lref, "(s->num->lref)");
    }
    fprintf(f, "#define NX %d      /* unknowns solved */\n#define NZ %d      /* nonzeros of J */\n"
               "#define NB %d      /* diagonal blocks of its block triangular form */\n"
               "#define NDENSE %d  /* their dense storage */\n"
               "#define TOL %s\n#define FTOL %s   /* residual tolerance: TOL * LREF, m */\n"
               "#define LREF %s   /* largest length of the mechanism, m */\n"
               "#define MIN_RCOND %s\n#define MAX_ITER %d\n"
               "#define NLINKS %d  /* links, the ground first (the frames F) */\n\n",
            ns, nz, nb, ns > 0 ? b->ndense : 0, tol, ftol, lref, minr,
            sp->opt.max_iter > 0 ? sp->opt.max_iter : 50, g->m->nlinks);
    int_table(f, "col_start", sp->Ap, ns + 1);   /* J's columns (CSC), as eval_position fills Jv */
    int_table(f, "perm_row", ns > 0 ? b->P : none, ns);
    int_table(f, "perm_col", ns > 0 ? b->Q : none, ns);
    int_table(f, "block_start", ns > 0 ? b->R : none, nb + 1);
    int_table(f, "block_at", ns > 0 ? b->at : none, nb);
    int_table(f, "where", ns > 0 ? b->where : none, nz);
    int_table(f, "above_start", ns > 0 ? b->op : none, ns + 1);
    int_table(f, "above_row", ns > 0 ? b->oi : none, nabove);
    int_table(f, "above_col", ns > 0 ? b->oj : none, nabove);
    fprintf(f, "/* the Jacobian's block triangular form (src/runtime/rt_blocklu.h) */\n"
               "static const rt_blocks jac = {NX, NB, NDENSE, NZ, %d, %d, perm_row, perm_col,\n"
               "                              block_start, block_at, where, above_start, above_row,\n"
               "                              above_col};\n",
            ns > 0 ? b->dense_full : 1, ns > 0 ? b->pq_parity : 0);
    if (g->opt.leaves) {
        fprintf(f, "/* the unit of each unknown's step, Newton's sizes and tolerances: the\n"
                   "   variant's (src/runtime/rt_newton.h) */\n"
                   "#define unit (s->num->unit)\n"
                   "#define newton_par ((rt_newton_par){NX, NX, unit, TOL, FTOL, MIN_RCOND, "
                   "MAX_ITER, 0})\n\n");
        return;
    }
    fprintf(f, "/* the unit of each unknown's step: 1 (angle, rad), LREF (slide) */\n"
               "static const double unit[%d] = {", at_least_1(ns));
    for (int k = 0; k < ns; k++) {
        char u[40];
        codegen_number(u, sizeof u, sp->unit[k]);
        fprintf(f, "%s%s", k ? ", " : "", u);
    }
    fprintf(f, "%s};\n", ns ? "" : "0.0");
    fprintf(f, "/* Newton's sizes and tolerances (src/runtime/rt_newton.h) */\n"
               "static const rt_newton_par newton_par = {NX, NX, unit, TOL, FTOL, MIN_RCOND, "
               "MAX_ITER, 0};\n\n");
}

static void emit_names(const codegen *g, FILE *f)
{
    const char *p = g->lower;
    fprintf(f, "const char *const %s_column_names[%s_NOUT] = {", p, g->upper);
    for (int c = 0; c < g->cols.ncols; c++) {
        fprintf(f, c ? ", " : "");
        c_string(f, g->cols.cols[c].name);
    }
    fprintf(f, "};\nconst char *const %s_column_units[%s_NOUT] = {", p, g->upper);
    for (int c = 0; c < g->cols.ncols; c++) {
        fprintf(f, c ? ", " : "");
        c_string(f, g->cols.cols[c].unit);
    }
    fprintf(f, "};\nconst char *const %s_unknown_names[%d] = {", p, at_least_1(g->sp.ns));
    for (int k = 0; k < g->sp.ns; k++) {
        fprintf(f, k ? ", " : "");
        c_string(f, g->sp.sys->names[g->sp.col[k]]);
    }
    fprintf(f, "%s};\n\n", g->sp.ns ? "" : "\"\"");
}

/* The guesses of the first position, in x[ns]: the file's guess of each
 * solved unknown, then the driven unknowns at their laws at the file's
 * first position (cont_start: drivers_guess); NaN where none, as emit_init
 * writes them for m. 0, or -1 out of memory. */
static int first_guesses(const codegen *g, const mech_model *m, double *x)
{
    for (int k = 0; k < g->sp.ns; k++)
        x[k] = NAN;
    for (int i = 0; i < m->nguesses; i++) {
        const mech_guess *gs = &m->guesses[i];
        int var = gs->is_slider ? g->sp.sys->joint_var[gs->index] : g->sp.sys->link_var[gs->index];
        if (var >= 0 && var < g->sp.n && g->unk_col[var] >= 0)
            x[g->unk_col[var]] = gs->value;
    }
    if (m->driver.nvalues == 0)
        return 0;
    double *guess = xcalloc((size_t)g->sp.n + 1, sizeof *guess);
    if (!guess)
        return -1;
    for (int v = 0; v < g->sp.n; v++)
        guess[v] = NAN;
    drivers_guess(m, g->sp.sys->link_var, g->sp.sys->joint_var, m->driver.values[0], guess);
    for (int v = 0; v < g->sp.n; v++)
        if (!isnan(guess[v]) && g->unk_col[v] >= 0)
            x[g->unk_col[v]] = guess[v];
    free(guess);
    return 0;
}

/* The file's guess of each solved unknown, else 0 (continuation.c, row 0):
 * literals, or P_numbers's for a sweep's variants. */
static int emit_init(const codegen *g, FILE *f)
{
    fprintf(f, "void %s_init(%s_state *s)\n{\n    memset(s, 0, sizeof *s);\n", g->lower,
            g->lower);
    double *x = g->opt.leaves ? NULL : xcalloc((size_t)g->sp.ns + 1, sizeof *x);
    if (!g->opt.leaves && (!x || first_guesses(g, g->m, x) < 0)) {
        free(x);
        return -1;
    }
    for (int k = 0; x && k < g->sp.ns; k++)
        if (!isnan(x[k])) {
            char v[40];
            codegen_number(v, sizeof v, x[k]);
            fprintf(f, "    s->x[%d] = %s;\n", k, v);
        }
    free(x);
    fprintf(f, "    s->branch = -1;\n    s->first = 1;\n}\n\n");
    return 0;
}

/* P_numbers: the variant's numbers; its leaves into keep[], where the
 * equations read them, and its guesses into x. */
static void emit_numbers(const codegen *g, FILE *f)
{
    if (!g->opt.leaves)
        return;
    fprintf(f, "void %s_numbers(%s_state *s, const struct rt_numbers *num)\n{\n"
               "    s->num = num;\n"
               "    for (int k = 0; k < %d; k++)\n"
               "        s->keep[%d + k] = num->leaf[k];\n"
               "    for (int i = 0; i < NX; i++)\n"
               "        if (!isnan(num->guess[i]))\n"
               "            s->x[i] = num->guess[i];\n}\n\n",
            g->lower, g->lower, g->nleaf, g->leaf0);
}

int codegen_numbers_fill(const codegen *g, const mech_analysis *view, const mech_model *mv,
                         codegen_numbers *out)
{
    memset(out, 0, sizeof *out);
    const solver_plan *sp = analysis_solver_plan(view);
    const forces_plan *fp = analysis_forces_plan(view);
    int npoints = g->point_at[mv->nlinks];
    out->points = xcalloc(2 * (size_t)npoints + 1, sizeof *out->points);
    out->guess = xcalloc((size_t)g->sp.ns + 1, sizeof *out->guess);
    if (!out->points || !out->guess || first_guesses(g, mv, out->guess) < 0) {
        codegen_numbers_free(out);
        return -1;
    }
    for (int l = 0; l < mv->nlinks; l++)
        for (int i = 0; i < mv->links[l].npoints; i++) {
            out->points[2 * (g->point_at[l] + i)] = mv->links[l].points[i].x;
            out->points[2 * (g->point_at[l] + i) + 1] = mv->links[l].points[i].y;
        }
    struct rt_numbers *n = &out->n;
    n->lref = sp->lref;
    n->ftol = sp->ftol;
    n->unit = sp->unit;
    n->leaf = sp->leaf;
    n->attach = sp->tree.attach;
    n->points = out->points;
    n->guess = out->guess;
    if (fp) {
        const forces_numbers_t *fn = &fp->num;
        n->fcols = fn->cols, n->fbody = fn->body, n->fgears = fn->gears;
        n->floads = fn->loads, n->fsprings = fn->springs, n->ffriction = fn->fric;
        n->fgrav = fn->grav;
    }
    return 0;
}

void codegen_numbers_free(codegen_numbers *c)
{
    free(c->points);
    free(c->guess);
    memset(c, 0, sizeof *c);
}

/* The public functions: src/runtime/rt_solver.h's bodies under the prefix's names. */
static void emit_solve(const codegen *g, FILE *f)
{
    const char *p = g->lower;
    fprintf(f, "int %s_solve(%s_state *s, double q, double qd, double qdd)\n{\n"
               "    return cg_step(s, q, qd, qdd);\n}\n\n"
               "void %s_predict(%s_state *s, double q)\n{\n    cg_prediction(s, q);\n}\n\n"
               "double %s_rcond(%s_state *s)\n{\n    return cg_exact_condition(s);\n}\n",
            p, p, p, p, p, p);
}

/* The lines of one of the runtime's files, and a blank line. */
static void emit_text(FILE *f, const char *const *lines)
{
    for (int i = 0; lines[i]; i++)
        fprintf(f, "%s\n", lines[i]);
    fprintf(f, "\n");
}

int codegen_emit_source(FILE *f, const void *ctx)
{
    const codegen *g = ctx;
    char file[512];
    fprintf(f, "/* %s.c: generated by `mech codegen` from %s; standalone C11 (libm only),\n"
               " * no allocation (docs/codegen.md). */\n"
               "#include <float.h>\n#include <math.h>\n#include <string.h>\n\n",
            g->lower, source_file(g, file, sizeof file));
    if (g->opt.header)
        fprintf(f, "#include \"%s\"\n\n", g->opt.header);
    else
        emit_declarations(g, f);
    /* macros and a typedef, not new enumerators: --prefix cg must not redeclare
       CG_OK (the fixed text's static names avoid P_solve, P_init, P_predict too) */
    fprintf(f, "typedef %s_state cg_state;\n"
               "#define CG_OK %s_OK\n#define CG_NO_ASSEMBLY %s_NO_ASSEMBLY\n"
               "#define CG_SINGULAR %s_SINGULAR\n#define CG_BRANCH %s_BRANCH\n\n",
            g->lower, g->upper, g->upper, g->upper, g->upper);
    if (g->want_forces)
        fprintf(f, "#define CG_FORCE_SINGULAR %s_FORCE_SINGULAR\n"
                   "#define CG_FRICTION_STUCK %s_FRICTION_STUCK\n", g->upper, g->upper);
    fprintf(f, "#define CG_FORCES %d\n#define CG_NUMBERS %d\n\n", g->want_forces,
            g->opt.leaves != NULL);
    /* the runtime (src/rt_*.h), its general block kernels unrolled for the
       block sizes of this mechanism (RT_KERNEL) */
    fprintf(f, "#if defined(__GNUC__)\n"
               "#define RT_KERNEL static inline __attribute__((always_inline))\n"
               "#define RT_UNROLL _Pragma(\"GCC unroll 16\")\n"
               "#endif\n");
    emit_text(f, codegen_rt_base);
    emit_text(f, codegen_rt_blocklu);
    emit_text(f, codegen_rt_newton);
    emit_text(f, codegen_rt_frame);
    if (g->want_forces)
        emit_text(f, codegen_rt_forces);
    if (g->sp.sys->ex.nfns > 0) {  /* laws of time beyond the DAG's operations */
        emit_text(f, codegen_rt_law);
        codegen_laws_emit(g, f);
    }
    emit_pattern(g, f);
    if (codegen_expr_emit(g, f) < 0)
        return -1;
    if (codegen_forces_emit(g, f) < 0 || codegen_kin_emit(g, f) < 0)
        return -1;
    emit_text(f, codegen_rt_solver);
    emit_names(g, f);
    if (emit_init(g, f) < 0)
        return -1;
    emit_numbers(g, f);
    emit_solve(g, f);
    return ferror(f) ? -1 : 0;
}
