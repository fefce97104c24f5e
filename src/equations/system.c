/* src/equations/system.c: from the model and its loops to the symbolic equations
 *   f(x, q) = 0                    (vector-loop closure, 2 rows per loop)
 *   J = df/dx (CSC pattern), df/dq
 *   J xdot  = -df/dq qdot                                  (velocity)
 *   J xddot = -(d/dx (J xdot + f_q qdot)) xdot
 *             - d/dq (J xdot + f_q qdot) qdot - f_q qddot   (acceleration)
 * all derived symbolically, then compiled to one tape with three phases. */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "equations.h"
#include "load.h"

enum { PHASE_POSITION, PHASE_VELOCITY, PHASE_ACCELERATION, NPHASES };

/* ---- unknowns and names --------------------------------------------- */

/* For each link, the first locked slider that holds it, or -1: one pass over
 * the joints, not one per link (10^5 links and joints). NULL: no memory. */
static int *locking_sliders(const mech_model *m)
{
    int *lock = xcalloc((size_t)m->nlinks, sizeof *lock);
    if (!lock)
        return NULL;
    for (int l = 0; l < m->nlinks; l++)
        lock[l] = -1;
    for (int j = m->njoints - 1; j >= 0; j--)  /* backwards: the first one wins */
        if (m->joints[j].kind == MECH_JOINT_SLIDER && m->joints[j].locked)
            lock[m->joints[j].link[0]] = j;
    return lock;
}

/* The link whose angle each link copies through chains of locked sliders
 * (itself when none holds it), or -1 when the chain ends in a cycle. Each
 * link is visited once (a long chain is linear, not quadratic). */
static int *angle_sources(const mech_model *m)
{
    enum { UNKNOWN = -2, ON_PATH = -3 };
    int *lock = locking_sliders(m);
    int *src = xcalloc((size_t)m->nlinks, sizeof *src);
    int *path = xcalloc((size_t)m->nlinks, sizeof *path);
    if (!lock || !src || !path) {
        free(src);
        src = NULL;
        goto done;
    }
    for (int l = 0; l < m->nlinks; l++)
        src[l] = UNKNOWN;
    for (int l = 0; l < m->nlinks; l++) {
        int np = 0, k = l;
        while (src[k] == UNKNOWN && lock[k] >= 0) {
            src[k] = ON_PATH;
            path[np++] = k;
            k = m->joints[lock[k]].link[1];
        }
        int root = src[k] == ON_PATH ? -1 : src[k] == UNKNOWN ? k : src[k];
        if (src[k] == UNKNOWN)
            src[k] = k;
        while (np > 0)
            src[path[--np]] = root;
    }
done:
    free(lock);
    free(path);
    return src;
}

/* Every link angle and slider displacement is an unknown, but for the ground,
 * the links that locked sliders hold (their angle is their guide's), and the
 * coordinate that is the sweep variable q itself (drivers.h). */
static int assign_unknowns(mech_system *s)
{
    const mech_model *m = s->model;
    int n = 0, qlink = drivers_sweep_link(m), qslider = drivers_sweep_slider(m);
    s->unk_kind = xcalloc((size_t)(m->nlinks + m->njoints), sizeof *s->unk_kind);
    s->unk_index = xcalloc((size_t)(m->nlinks + m->njoints), sizeof *s->unk_index);
    s->link_var = xcalloc((size_t)m->nlinks, sizeof *s->link_var);
    s->joint_var = xcalloc((size_t)m->njoints + 1, sizeof *s->joint_var);
    int *lock = locking_sliders(m);
    if (!s->unk_kind || !s->unk_index || !s->link_var || !s->joint_var || !lock) {
        free(lock);
        return -1;
    }
    for (int l = 0; l < m->nlinks; l++) {
        s->link_var[l] = -1;
        if (l == 0 || l == qlink || lock[l] >= 0)
            continue;
        s->unk_kind[n] = UNK_ANGLE;
        s->unk_index[n] = l;
        s->link_var[l] = n++;
    }
    for (int j = 0; j < m->njoints; j++) {
        s->joint_var[j] = -1;
        if (m->joints[j].kind != MECH_JOINT_SLIDER || j == qslider)
            continue;
        s->unk_kind[n] = UNK_SLIDE;
        s->unk_index[n] = j;
        s->joint_var[j] = n++;
    }
    s->n = n;
    free(lock);
    return 0;
}

/* ---- a file's symbol in LaTeX ----------------------------------------------
 * A `symbol:` is free text. When it is inert LaTeX math as written - letters,
 * digits, primes and Greek letters (phi2, Theta_4, \theta_2, x_{B1}), with
 * at most one subscript and one superscript - it is printed as it is; any
 * other text is printed as text, LaTeX's special characters escaped, so
 * that no symbol can break the document or run a command (\input{...}). */
static const char *const greek[] = {
    "alpha", "beta", "gamma", "delta", "epsilon", "varepsilon", "zeta", "eta", "theta",
    "vartheta", "iota", "kappa", "lambda", "mu", "nu", "xi", "pi", "varpi", "rho", "varrho",
    "sigma", "varsigma", "tau", "upsilon", "phi", "varphi", "chi", "psi", "omega", "Gamma",
    "Delta", "Theta", "Lambda", "Xi", "Pi", "Sigma", "Upsilon", "Phi", "Psi", "Omega"};

/* The length of the math atom at t: a letter, a digit, a prime or a Greek
 * letter's command; 0 for anything else. */
static size_t math_atom(const char *t)
{
    if (isalnum((unsigned char)*t) || *t == '\'')
        return 1;
    if (*t != '\\')
        return 0;
    size_t n = 1;
    while (isalpha((unsigned char)t[n]))
        n++;
    for (size_t i = 0; i < COUNT_OF(greek); i++)
        if (strlen(greek[i]) == n - 1 && strncmp(t + 1, greek[i], n - 1) == 0)
            return n;
    return 0;
}

/* A script's argument at t: one atom, or {atoms and commas}; its length or 0. */
static size_t math_script(const char *t)
{
    if (*t != '{')
        return math_atom(t);
    size_t n = 1, a;
    while ((a = t[n] == ',' ? 1 : math_atom(t + n)) > 0)
        n += a;
    return n > 1 && t[n] == '}' ? n + 1 : 0;
}

static int symbol_is_math(const char *t)
{
    size_t n = 0, a;
    while ((a = math_atom(t + n)) > 0)
        n += a;
    if (n == 0)
        return 0;
    for (const char *script = "_^"; *script; script++)
        if (t[n] == *script) {
            if ((a = math_script(t + n + 1)) == 0)
                return 0;
            n += 1 + a;
        }
    return t[n] == '\0';
}

/* The symbol in LaTeX math: as written, or as upright text, escaped. */
static char *latex_symbol(const char *t)
{
    if (symbol_is_math(t))
        return xstrdup(t);
    char *out = malloc(24 * strlen(t) + 16);
    if (!out)
        return NULL;
    char *p = out + sprintf(out, "\\mathrm{");
    for (; *t; t++) {
        unsigned char c = (unsigned char)*t;
        if (c == '\\')
            p += sprintf(p, "\\backslash{}");
        else if (c == '^' || c == '~')
            p += sprintf(p, "\\text{\\textascii%s}", c == '^' ? "circum" : "tilde");
        else if (c == ' ')
            p += sprintf(p, "\\ ");
        else if (c >= 0x80 && (c & 0xc0) == 0x80)
            continue;  /* a UTF-8 character's continuation byte */
        else if (c >= 0x80)
            *p++ = '?';  /* one per UTF-8 character: pdflatex's math has no glyphs for them */
        else {
            if (strchr("#$%&_{}", c))
                *p++ = '\\';
            *p++ = (char)c;
        }
    }
    strcpy(p, "}");
    return out;
}

/* "coupler" -> "\mathrm{coupler}", with '_' escaped. */
static char *latex_word(const char *w)
{
    size_t n = strlen(w);
    char *out = malloc(2 * n + 16);
    if (!out)
        return NULL;
    char *p = out + sprintf(out, "\\mathrm{");
    for (const char *c = w; *c; c++) {
        if (*c == '_')
            *p++ = '\\';
        *p++ = *c;
    }
    strcpy(p, "}");
    return out;
}

/* Text and LaTeX names of a position variable: an unknown, or q (the
 * coordinate that is the sweep variable, or else the time t of the laws). */
static int position_names(const mech_system *s, int var, char **text, char **latex)
{
    const mech_model *m = s->model;
    const char *symbol, *name;
    int is_angle;
    if (var == SYS_VAR_Q(s->n)) {
        int ql = drivers_sweep_link(m), qj = drivers_sweep_slider(m);
        if (ql < 0 && qj < 0) {
            *text = xstrdup("t");
            *latex = xstrdup("t");
            return *text && *latex ? 0 : -1;
        }
        is_angle = ql >= 0;
        symbol = is_angle ? m->links[ql].symbol : m->joints[qj].symbol;
        name = is_angle ? m->links[ql].name : m->joints[qj].name;
    } else {
        is_angle = s->unk_kind[var] == UNK_ANGLE;
        const int i = s->unk_index[var];
        symbol = is_angle ? m->links[i].symbol : m->joints[i].symbol;
        name = is_angle ? m->links[i].name : m->joints[i].name;
    }
    char buf[160];
    if (symbol) {
        *text = xstrdup(symbol);
        *latex = latex_symbol(symbol);
    } else if (is_angle) {
        snprintf(buf, sizeof buf, "th_%s", name);
        *text = xstrdup(buf);
        char *w = latex_word(name);
        snprintf(buf, sizeof buf, "\\theta_{%s}", w ? w : "?");
        free(w);
        *latex = xstrdup(buf);
    } else {
        *text = xstrdup(name);
        *latex = latex_word(name);
    }
    return *text && *latex ? 0 : -1;
}

static char *decorate(const char *base, const char *before, const char *after)
{
    size_t n = strlen(base) + strlen(before) + strlen(after) + 1;
    char *out = malloc(n);
    if (out)
        snprintf(out, n, "%s%s%s", before, base, after);
    return out;
}

static int make_names(mech_system *s)
{
    int n = s->n, nv = SYS_NVARS(n);
    s->names = xcalloc((size_t)nv, sizeof *s->names);
    s->latex = xcalloc((size_t)nv, sizeof *s->latex);
    if (!s->names || !s->latex)
        return -1;
    s->nnames = nv;
    for (int v = 0; v <= n; v++) {  /* positions and q */
        if (position_names(s, v, &s->names[v], &s->latex[v]) < 0)
            return -1;
        int dv = v == n ? SYS_VAR_QDOT(n) : SYS_VAR_XDOT(n, v);
        s->names[dv] = decorate(s->names[v], "", "'");
        s->latex[dv] = decorate(s->latex[v], "\\dot{", "}");
        if (!s->names[dv] || !s->latex[dv])
            return -1;
    }
    s->names[SYS_VAR_QDDOT(n)] = decorate(s->names[n], "", "''");
    s->latex[SYS_VAR_QDDOT(n)] = decorate(s->latex[n], "\\ddot{", "}");
    return s->names[SYS_VAR_QDDOT(n)] && s->latex[SYS_VAR_QDDOT(n)] ? 0 : -1;
}

/* ---- the residual --------------------------------------------------- */

static int link_angles(mech_system *s, mech_diag *d)
{
    const mech_model *m = s->model;
    expr_ctx *c = &s->ex;
    s->link_angle = xcalloc((size_t)m->nlinks, sizeof *s->link_angle);
    s->slide = xcalloc((size_t)m->njoints + 1, sizeof *s->slide);
    int *src = angle_sources(m), qlink = drivers_sweep_link(m), qslider = drivers_sweep_slider(m);
    if (!s->link_angle || !s->slide || !src) {
        free(src);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    for (int l = 0; l < m->nlinks; l++) {
        /* the link whose angle this one copies through locked sliders */
        int k = src[l];
        if (k < 0) {
            free(src);
            return diag_error(d, m->file, m->links[l].mark,
                              "link '%s' is in a cycle of locked sliders: none of them can turn",
                              m->links[l].name);
        }
        s->link_angle[l] = k == 0 ? c->zero
                           : k == qlink ? expr_var(c, SYS_VAR_Q(s->n))
                                                  : expr_var(c, s->link_var[k]);
    }
    free(src);
    for (int j = 0; j < m->njoints; j++)
        s->slide[j] = m->joints[j].kind != MECH_JOINT_SLIDER ? -1
                      : j == qslider ? expr_var(c, SYS_VAR_Q(s->n))
                                              : expr_var(c, s->joint_var[j]);
    return MECH_OK;
}

/* length * (cos, sin)(angle + offset), written as the papers write it. */
static void rotated(expr_ctx *c, double length, ex angle, double offset, ex *x, ex *y)
{
    ex k = expr_const(c, length);
    const double pi = 3.14159265358979323846;
    if (offset == pi || offset == -pi) {  /* atan2 gives exactly pi for (-r, 0) */
        k = expr_const(c, -length);
        offset = 0.0;
    }
    ex a = expr_add(c, angle, expr_const(c, offset));
    *x = expr_mul(c, k, expr_cos(c, a));
    *y = expr_mul(c, k, expr_sin(c, a));
}

/* A loop term's vector: a body vector (system_coef.c: constants or leaves),
 * or a slider's displacement along its guide. */
static void term_vector(mech_system *s, const loop_term *t, ex *x, ex *y)
{
    expr_ctx *c = &s->ex;
    if (t->kind == TERM_BODY) {
        sys_body_term(s, t, x, y);
        return;
    }
    const mech_joint *j = &s->model->joints[t->joint];
    ex ux, uy;
    rotated(c, (double)t->sign, s->link_angle[j->link[1]], j->angle, &ux, &uy);
    *x = expr_mul(c, s->slide[t->joint], ux);
    *y = expr_mul(c, s->slide[t->joint], uy);
}

/* Sum v[0..n-1] as a balanced tree: depth log2(n) for long loops. */
static ex balanced_sum(expr_ctx *c, ex *v, int n)
{
    if (n == 0)
        return c->zero;
    while (n > 1) {
        int k = 0;
        for (int i = 0; i + 1 < n; i += 2)
            v[k++] = expr_add(c, v[i], v[i + 1]);
        if (n % 2)
            v[k++] = v[n - 1];
        n = k;
    }
    return v[0];
}

/* Loop k's x and y closure sums (xs, ys: room for its terms). */
static void loop_sums(mech_system *s, int k, ex *xs, ex *ys, ex *x, ex *y)
{
    const loop_set *ls = &s->loops;
    int nt = 0;
    for (int t = ls->start[k]; t < ls->start[k + 1]; t++, nt++)
        term_vector(s, &ls->terms[t], &xs[nt], &ys[nt]);
    *x = balanced_sum(&s->ex, xs, nt);
    *y = balanced_sum(&s->ex, ys, nt);
}

static int build_residual(mech_system *s, mech_diag *d)
{
    const mech_model *m = s->model;
    const loop_set *ls = &s->loops;
    int rows = s->m, maxterms = 1;
    for (int k = 0; k < ls->nloops; k++)
        if (ls->start[k + 1] - ls->start[k] > maxterms)
            maxterms = ls->start[k + 1] - ls->start[k];
    s->f = xcalloc((size_t)rows, sizeof *s->f);
    ex *xs = xcalloc((size_t)maxterms, sizeof *xs), *ys = xcalloc((size_t)maxterms, sizeof *ys);
    if (!s->f || !xs || !ys) {
        free(xs);
        free(ys);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    ex q = expr_var(&s->ex, SYS_VAR_Q(s->n)), loop_x = s->ex.zero, loop_y = loop_x;
    for (int r = 0, loop = -1; r < rows; r++) {  /* each row as rows[] describes it */
        const row_desc *rd = &s->rows[r];
        switch (rd->kind) {
        case ROW_LOOP_X:
        case ROW_LOOP_Y:
            if (rd->owner != loop) {  /* the loop's two sums, once */
                loop = rd->owner;
                loop_sums(s, loop, xs, ys, &loop_x, &loop_y);
            }
            s->f[r] = rd->kind == ROW_LOOP_X ? loop_x : loop_y;
            break;
        case ROW_GEAR: s->f[r] = gears_row(s, rd->owner); break;
        case ROW_CAM: s->f[r] = cams_row(s, rd->owner); break;
        case ROW_DRIVER:
            s->f[r] = drivers_row(m, rd->owner, &s->ex, s->link_angle, s->slide, q);
            break;
        }
    }
    free(xs);
    free(ys);
    return MECH_OK;
}

/* ---- derivatives ---------------------------------------------------- */

static int build_jacobian(mech_system *s, int *vars)
{
    int n = s->n, rows = s->m, cap = 4 * rows + 16, nnz = 0;
    expr_ctx *c = &s->ex;
    int *ti = xcalloc((size_t)cap, sizeof *ti), *tj = xcalloc((size_t)cap, sizeof *tj);
    ex *tx = xcalloc((size_t)cap, sizeof *tx);
    s->fq = xcalloc((size_t)rows + 1, sizeof *s->fq);
    s->Jp = xcalloc((size_t)n + 1, sizeof *s->Jp);
    if (!ti || !tj || !tx || !s->fq || !s->Jp)
        goto oom;
    for (int r = 0; r < rows; r++) {
        int nv = expr_vars(c, s->f[r], vars, s->nvars);
        s->fq[r] = c->zero;
        for (int k = 0; k < nv; k++) {
            if (vars[k] >= SYS_NVARS(n))
                continue;  /* a leaf: held constant */
            ex dr = expr_diff(c, s->f[r], vars[k]);
            if (vars[k] == SYS_VAR_Q(n)) {
                s->fq[r] = dr;
                continue;
            }
            if (expr_is_const(c, dr, 0.0))
                continue;  /* structurally present, exactly zero */
            if (nnz == cap) {
                cap *= 2;
                int *a = xrealloc_array(ti, (size_t)cap, sizeof *a);
                if (a) ti = a;
                int *b = xrealloc_array(tj, (size_t)cap, sizeof *b);
                if (b) tj = b;
                ex *x = xrealloc_array(tx, (size_t)cap, sizeof *x);
                if (x) tx = x;
                if (!a || !b || !x)
                    goto oom;
            }
            ti[nnz] = r;
            tj[nnz] = vars[k];
            tx[nnz++] = dr;
        }
    }
    /* triplets (row-major, rows ascending) -> compressed columns */
    s->Ji = xcalloc((size_t)nnz + 1, sizeof *s->Ji);
    s->Jx = xcalloc((size_t)nnz + 1, sizeof *s->Jx);
    int *fill = xcalloc((size_t)n + 1, sizeof *fill);
    if (!s->Ji || !s->Jx || !fill) {
        free(fill);
        goto oom;
    }
    for (int k = 0; k < nnz; k++)
        s->Jp[tj[k] + 1]++;
    for (int j = 0; j < n; j++)
        s->Jp[j + 1] += s->Jp[j];
    for (int k = 0; k < nnz; k++) {
        int at = s->Jp[tj[k]] + fill[tj[k]]++;
        s->Ji[at] = ti[k];
        s->Jx[at] = tx[k];
    }
    s->nnz = nnz;
    free(fill);
    free(ti);
    free(tj);
    free(tx);
    return c->failed ? -1 : 0;
oom:
    free(ti);
    free(tj);
    free(tx);
    return -1;
}

/* vel = -f_q qdot; acc = -(d/dt of (J xdot + f_q qdot) without the xddot term). */
static int build_rates(mech_system *s, int *vars)
{
    int n = s->n, rows = s->m;
    expr_ctx *c = &s->ex;
    ex qdot = expr_var(c, SYS_VAR_QDOT(n)), qddot = expr_var(c, SYS_VAR_QDDOT(n));
    s->vel = xcalloc((size_t)rows + 1, sizeof *s->vel);
    s->acc = xcalloc((size_t)rows + 1, sizeof *s->acc);
    ex *row = xcalloc((size_t)n + 2, sizeof *row);     /* terms of one row */
    int *rowlen = xcalloc((size_t)rows + 1, sizeof *rowlen);
    if (!s->vel || !s->acc || !row || !rowlen) {
        free(row);
        free(rowlen);
        return -1;
    }
    /* v_r = sum_j J_rj xdot_j + f_q,r qdot, gathered row by row from the CSC */
    ex *v = xcalloc((size_t)rows + 1, sizeof *v);
    if (!v) {
        free(row);
        free(rowlen);
        return -1;
    }
    for (int r = 0; r < rows; r++)
        v[r] = c->zero;
    for (int j = 0; j < n; j++)
        for (int k = s->Jp[j]; k < s->Jp[j + 1]; k++) {
            int r = s->Ji[k];
            v[r] = expr_add(c, v[r], expr_mul(c, s->Jx[k], expr_var(c, SYS_VAR_XDOT(n, j))));
        }
    for (int r = 0; r < rows; r++) {
        s->vel[r] = expr_neg(c, expr_mul(c, s->fq[r], qdot));
        ex vr = expr_add(c, v[r], expr_mul(c, s->fq[r], qdot));
        int nv = expr_vars(c, vr, vars, s->nvars), nt = 0;
        for (int k = 0; k < nv; k++) {
            int var = vars[k];
            ex rate;  /* d var / dt */
            if (var < n)
                rate = expr_var(c, SYS_VAR_XDOT(n, var));
            else if (var == SYS_VAR_Q(n))
                rate = qdot;
            else
                continue;  /* velocities: their rates are the unknown xddot or qddot */
            row[nt++] = expr_neg(c, expr_mul(c, expr_diff(c, vr, var), rate));
        }
        row[nt++] = expr_neg(c, expr_mul(c, s->fq[r], qddot));
        s->acc[r] = balanced_sum(c, row, nt);
    }
    free(v);
    free(row);
    free(rowlen);
    return c->failed ? -1 : 0;
}

static int compile(mech_system *s)
{
    int n = s->n, rows = s->m;
    const ex *roots[NPHASES];
    int nroots[NPHASES];
    ex *pos = xcalloc((size_t)(rows + s->nnz) + 1, sizeof *pos);
    if (!pos)
        return -1;
    memcpy(pos, s->f, (size_t)rows * sizeof *pos);
    memcpy(pos + rows, s->Jx, (size_t)s->nnz * sizeof *pos);
    roots[PHASE_POSITION] = pos;
    nroots[PHASE_POSITION] = rows + s->nnz;
    roots[PHASE_VELOCITY] = s->vel;
    nroots[PHASE_VELOCITY] = rows;
    roots[PHASE_ACCELERATION] = s->acc;
    nroots[PHASE_ACCELERATION] = rows;
    int rc = tape_compile(&s->tp, &s->ex, SYS_NVARS(n), NPHASES, roots, nroots);
    free(pos);
    if (rc == 0 && !(s->reg = tape_registers_new(&s->tp)))
        rc = -1;
    return rc;
}

/* ---- public ----------------------------------------------------------- */

void mech_system_free(mech_system **ps)
{
    mech_system *s = ps ? *ps : NULL;
    if (!s)
        return;
    if (s->names)
        for (int v = 0; v < s->nnames; v++) {
            free(s->names[v]);
            free(s->latex[v]);
        }
    if (s->coef_desc)
        for (int k = 0; k < s->nvars - SYS_NVARS(s->n); k++)
            free(s->coef_desc[k]);
    free(s->coef_desc);
    free(s->coef);
    free(s->point_base);
    for (int k = 0; k < s->nparams; k++)
        free(s->dxy[k]);
    free(s->dxy);
    free(s->param);
    free(s->grad);
    free(s->names);
    free(s->latex);
    free(s->rows);
    free(s->unk_kind);
    free(s->unk_index);
    free(s->link_var);
    free(s->joint_var);
    free(s->link_angle);
    free(s->slide);
    loops_free(&s->loops);
    span_tree_free(&s->span);
    expr_free(&s->ex);
    free(s->f);
    free(s->Jp);
    free(s->Ji);
    free(s->Jx);
    free(s->fq);
    free(s->vel);
    free(s->acc);
    tape_free(&s->tp);
    free(s->reg);
    free(s);
    *ps = NULL;
}

int mech_system_new(const mech_model *m, mech_system **out, mech_diag *d)
{
    static const sys_leaves none = {SYS_LEAF_POLAR, NULL, 0};
    mech_diag own, *dd = api_diag(d, &own);
    int rc = m && out ? sys_new_with(m, &none, out, dd)
                      : api_null(dd, "mech_system_new", m ? "out" : "m");
    api_diag_end(d, &own);
    return rc;
}

int sys_new_with(const mech_model *m, const sys_leaves *lv, mech_system **out, mech_diag *d)
{
    *out = NULL;
    if (!m->has_driver)
        return diag_error(d, m->file, (mech_mark){0, 0}, "the mechanism has no driver");
    mech_system *s = xcalloc(1, sizeof *s);
    if (!s || expr_init(&s->ex) < 0) {
        if (s)
            expr_free(&s->ex);  /* what expr_init allocated before it failed */
        free(s);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    s->model = m;
    int rc = MECH_ENOMEM;
    int *vars = NULL;
    if (assign_unknowns(s) < 0)
        goto fail;
    if (span_tree_build(m, &s->span) < 0) {
        diag_nomem(d, m->file, (mech_mark){0, 0});
        goto fail;
    }
    if ((rc = loops_build(m, &s->span, &s->loops, d)) != MECH_OK)
        goto fail;
    s->m = rows_count(m, s->loops.nloops, s->nrows_of);
    rc = MECH_ENOMEM;
    if (!(s->rows = rows_build(m, s->loops.nloops, s->loops.from_file)))
        goto fail;
    /* more equations than unknowns: redundant constraints, which the solver
       treats in the least-squares sense and checks for consistency */
    if (s->m < s->n) {
        rc = diag_error(d, m->file, m->driver.mark,
                        "%d unknowns but %d loop equations (%d loops): the mechanism is "
                        "under-constrained", s->n, s->m, s->loops.nloops);
        goto fail;
    }
    rc = MECH_ENOMEM;
    s->nvars = SYS_NVARS(s->n);
    if (make_names(s) < 0 || sys_leaves_init(s, lv) < 0)
        goto fail;
    if ((rc = link_angles(s, d)) != MECH_OK || (rc = build_residual(s, d)) != MECH_OK)
        goto fail;
    rc = MECH_ENOMEM;
    vars = xcalloc((size_t)s->nvars, sizeof *vars);
    if (!vars || s->ex.failed || build_jacobian(s, vars) < 0 || build_rates(s, vars) < 0)
        goto fail;
    free(vars);
    *out = s;
    return MECH_OK;
fail:
    if (rc == MECH_ENOMEM)
        diag_nomem(d, m->file, (mech_mark){0, 0});
    free(vars);
    mech_system_free(&s);
    return rc;
}

int mech_system_size(const mech_system *s) { return s ? s->n : 0; }

/* The system's own tape, compiled by the first sys_eval_* (only tests
 * call them: the solver compiles its plan's tape, and this one would be a
 * second copy of the same equations at the set-up's peak): 0, or -1 (out
 * of memory, or a system with leaves, whose tape is the plan's). */
int sys_compile_tape(mech_system *s)
{
    if (s->reg)
        return 0;
    if (s->form != SYS_LEAF_POLAR || s->nparams != 0 || !s->f || compile(s) < 0) {
        tape_free(&s->tp);
        return -1;
    }
    return 0;
}

static void fill_nan(double *v, int n)
{
    for (int i = 0; v && i < n; i++)
        v[i] = NAN;
}

void sys_eval_position(mech_system *s, const double *x, double q, double *f, double *Jx)
{
    if (sys_compile_tape(s) < 0) {
        fill_nan(f, s->m);
        fill_nan(Jx, s->nnz);
        return;
    }
    const tape *t = &s->tp;
    double *reg = s->reg;
    for (int i = 0; i < s->n; i++)
        tape_set_var(t, reg, i, x[i]);
    tape_set_var(t, reg, SYS_VAR_Q(s->n), q);
    tape_run(t, reg, PHASE_POSITION);
    for (int r = 0; r < s->m; r++)
        f[r] = tape_value(t, reg, s->f[r]);
    if (Jx)
        for (int k = 0; k < s->nnz; k++)
            Jx[k] = tape_value(t, reg, s->Jx[k]);
}

void sys_eval_velocity_rhs(mech_system *s, double qdot, double *rhs)
{
    if (sys_compile_tape(s) < 0) {
        fill_nan(rhs, s->m);
        return;
    }
    const tape *t = &s->tp;
    double *reg = s->reg;
    tape_set_var(t, reg, SYS_VAR_QDOT(s->n), qdot);
    tape_run(t, reg, PHASE_VELOCITY);
    for (int r = 0; r < s->m; r++)
        rhs[r] = tape_value(t, reg, s->vel[r]);
}

void sys_eval_accel_rhs(mech_system *s, const double *xdot, double qdot, double qddot, double *rhs)
{
    if (sys_compile_tape(s) < 0) {
        fill_nan(rhs, s->m);
        return;
    }
    const tape *t = &s->tp;
    double *reg = s->reg;
    for (int i = 0; i < s->n; i++)
        tape_set_var(t, reg, SYS_VAR_XDOT(s->n, i), xdot[i]);
    tape_set_var(t, reg, SYS_VAR_QDOT(s->n), qdot);
    tape_set_var(t, reg, SYS_VAR_QDDOT(s->n), qddot);
    tape_run(t, reg, PHASE_ACCELERATION);
    for (int r = 0; r < s->m; r++)
        rhs[r] = tape_value(t, reg, s->acc[r]);
}
