/* src/equations/system_coef.c: the leaves of the equations (system.h, sys_leaves) and
 * the body vectors that read them. One build for every use: the numbers that
 * the chosen parameters move are leaves, the others constants, folded as
 * the solver folds them; the form says what a leaf is:
 *   SYS_LEAF_POLAR      r (cos, sin)(theta + a), r and a leaves when a chosen
 *                       parameter moves them (no parameter: the solver's system;
 *                       the varied ones: the sweep's registers);
 *   SYS_LEAF_NAMED      the same leaves named: the parameter the user wrote (`r`,
 *                       `-e`) or a named length |AB| / angle <AB (mech equations);
 *   SYS_LEAF_CARTESIAN  R(theta) (P1 - P0), the coordinates of P0 and P1 being
 *                       leaves (sensitivity.c differentiates through them).
 * Which numbers a parameter moves comes from the model's parameter
 * expressions (param_expr.h): d(point)/d(parameter), exact, no file read. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "load.h"
#include "equations.h"

static const double PI_ = 3.14159265358979323846;

/* A new leaf variable k = nvars - SYS_NVARS(n): what it is, and for
 * printing (SYS_LEAF_NAMED) its names and description (owned from here on,
 * freed with the system). Its variable number, or -1. */
static int add_leaf(mech_system *s, sys_coef what, char *text, char *latex, char *desc)
{
    int k = s->nvars - SYS_NVARS(s->n);
    sys_coef *grown = xrealloc_array(s->coef, (size_t)k + 1, sizeof *grown);
    if (grown) {
        s->coef = grown;
        s->coef[k] = what;
    }
    if (grown && s->form != SYS_LEAF_NAMED)
        return s->nvars++;
    int nv = s->nvars + 1;
    char **nt = grown ? xrealloc_array(s->names, (size_t)nv, sizeof *nt) : NULL;
    if (nt)
        s->names = nt;
    char **nl = nt ? xrealloc_array(s->latex, (size_t)nv, sizeof *nl) : NULL;
    if (nl)
        s->latex = nl;
    char **nd = nl ? xrealloc_array(s->coef_desc, (size_t)k + 1, sizeof *nd) : NULL;
    if (nd)
        s->coef_desc = nd;
    if (!nd || !text || !latex || (!desc && what.kind != LEAF_PARAM)) {
        free(text);
        free(latex);
        free(desc);
        s->ex.failed = 1;  /* the system build then fails: out of memory */
        return -1;
    }
    s->names[s->nvars] = text;
    s->latex[s->nvars] = latex;
    s->coef_desc[k] = desc;
    s->nnames = nv;
    return s->nvars++;
}

/* A name in LaTeX: one character as it is; a letter and a subscript for
 * "l1", "l3a", "xF"; a word in italics otherwise ('_' escaped). */
static char *latex_name(const char *w)
{
    size_t n = strlen(w);
    char *out = malloc(2 * n + 24);
    if (!out)
        return NULL;
    if (n == 1) {
        strcpy(out, w);
        return out;
    }
    int sub = (w[1] >= '0' && w[1] <= '9') || (w[1] >= 'A' && w[1] <= 'Z');
    char *p = out + (sub ? sprintf(out, "%c_{", w[0]) : sprintf(out, "\\mathit{"));
    for (const char *c = w + (sub ? 1 : 0); *c; c++) {
        if (*c == '_')
            *p++ = '\\';
        *p++ = *c;
    }
    strcpy(p, "}");
    return out;
}

static char *text_of(const char *fmt, const char *a, const char *b)
{
    size_t n = strlen(fmt) + strlen(a) + strlen(b) + 1;
    char *out = malloc(n);
    if (out)
        snprintf(out, n, fmt, a, b);
    return out;
}

static const mech_param *chosen(const mech_system *s, int k)
{
    return &s->model->params[s->param[k]];
}

/* The chosen parameters and what they move: d(points)/dp of each. */
static int choose_parameters(mech_system *s, const sys_leaves *lv, int npoints)
{
    int np = lv->nparams;
    if (np == 0)
        return 0;  /* the solver's system: nothing moves */
    s->param = xcalloc((size_t)np + 1, sizeof *s->param);
    s->dxy = xcalloc((size_t)np + 1, sizeof *s->dxy);
    s->grad = xcalloc(2 * (size_t)np + 2, sizeof *s->grad);
    if (!s->param || !s->dxy || !s->grad)
        return -1;
    for (int k = 0; k < np; k++) {
        s->param[k] = lv->params[k];
        s->nparams = k + 1;
        if (!(s->dxy[k] = xcalloc(2 * (size_t)npoints + 1, sizeof *s->dxy[k])) ||
            pexpr_point_gradient(s->model, s->param[k], s->dxy[k]) < 0)
            return -1;
    }
    return 0;
}

int sys_leaves_init(mech_system *s, const sys_leaves *lv)
{
    const mech_model *m = s->model;
    s->form = lv->form;
    s->point_base = xcalloc((size_t)m->nlinks + 1, sizeof *s->point_base);
    if (!s->point_base)
        return -1;
    for (int l = 0; l < m->nlinks; l++)
        s->point_base[l + 1] = s->point_base[l] + m->links[l].npoints;
    if (choose_parameters(s, lv, s->point_base[m->nlinks]) < 0)
        return -1;
    if (s->form == SYS_LEAF_CARTESIAN) {  /* point g's x and y: leaves 2 g and 2 g + 1 */
        int npoints = s->point_base[m->nlinks];
        if (!(s->coef = xcalloc(2 * (size_t)npoints + 1, sizeof *s->coef)))
            return -1;
        for (int l = 0, g = 0; l < m->nlinks; l++)
            for (int i = 0; i < m->links[l].npoints; i++, g++)
                for (int c = 0; c < 2; c++)
                    s->coef[2 * g + c] = (sys_coef){LEAF_COORD, l, i, c, -1};
        s->nvars = SYS_COORD(s->n, npoints);
        return 0;
    }
    if (s->form != SYS_LEAF_NAMED)
        return 0;
    for (int k = 0; k < s->nparams; k++) {  /* the parameters: variables nvars + k */
        const char *name = chosen(s, k)->name;
        if (add_leaf(s, (sys_coef){LEAF_PARAM, -1, -1, -1, s->param[k]}, xstrdup(name),
                     latex_name(name), NULL) < 0)
            return -1;
    }
    return 0;
}

double sys_leaf_value(const mech_system *s, const mech_model *m, int var)
{
    const sys_coef *c = &s->coef[var - SYS_NVARS(s->n)];
    const mech_link *l = c->link >= 0 ? &m->links[c->link] : NULL;
    switch (c->kind) {
    case LEAF_PARAM:
        return m->params[c->param].value;
    case LEAF_COORD:
        return c->p1 ? l->points[c->p0].y : l->points[c->p0].x;
    default: {
        loop_term t = {TERM_BODY, c->link, c->p0, c->p1, -1, 0};
        double dx, dy, r, a;
        sys_body_vector(m, &t, &dx, &dy, &r, &a);
        return c->kind == LEAF_ANGLE ? a : r;
    }
    }
}

static void cartesian_body(mech_system *s, const loop_term *t, ex *x, ex *y)
{
    expr_ctx *c = &s->ex;
    int g0 = s->point_base[t->link] + t->p0, g1 = s->point_base[t->link] + t->p1;
    ex ux = expr_sub(c, expr_var(c, SYS_COORD(s->n, g1)), expr_var(c, SYS_COORD(s->n, g0)));
    ex uy = expr_sub(c, expr_var(c, SYS_COORD(s->n, g1) + 1),
                     expr_var(c, SYS_COORD(s->n, g0) + 1));
    ex th = s->link_angle[t->link], co = expr_cos(c, th), si = expr_sin(c, th);
    *x = expr_sub(c, expr_mul(c, ux, co), expr_mul(c, uy, si));  /* R(theta) u */
    *y = expr_add(c, expr_mul(c, ux, si), expr_mul(c, uy, co));
}

/* How the length r and angle a of the vector P0 -> P1 of a link depend on
 * the chosen parameters: dr[k], da[k] = d r / d p_k, d a / d p_k. */
static void body_gradient(const mech_system *s, const loop_term *t, double dx, double dy,
                          double *dr, double *da)
{
    int g0 = s->point_base[t->link] + t->p0, g1 = s->point_base[t->link] + t->p1;
    double r2 = dx * dx + dy * dy, r = sqrt(r2);
    for (int k = 0; k < s->nparams; k++) {
        double ddx = s->dxy[k][2 * g1] - s->dxy[k][2 * g0];
        double ddy = s->dxy[k][2 * g1 + 1] - s->dxy[k][2 * g0 + 1];
        dr[k] = r > 0 ? (dx * ddx + dy * ddy) / r : 0.0;         /* d |u| = u.du / |u| */
        da[k] = r > 0 ? (dx * ddy - dy * ddx) / r2 : 0.0;        /* d atan2 = u x du / |u|^2 */
    }
}

/* "(depends on l3a, lk)" for a leaf with gradient g. */
static void depends_on(const mech_system *s, const double *g, char *buf, size_t size)
{
    size_t k = (size_t)snprintf(buf, size, "depends on");
    const char *sep = " ";
    for (int i = 0; i < s->nparams && k < size; i++)
        if (g[i] != 0.0) {
            k += (size_t)snprintf(buf + k, size - k, "%s%s", sep, chosen(s, i)->name);
            sep = ", ";
        }
}

static ex as_parameter(mech_system *s, double v, const double *g);

/* The leaf of a length or angle that depends on parameters: the parameter
 * itself when the number is exactly +-p (gradient +-1 in p alone), else a
 * named leaf |AB| or <AB (one per vector, found again by name). */
static ex named_leaf(mech_system *s, const loop_term *t, int is_angle, double v, const double *g)
{
    expr_ctx *c = &s->ex;
    ex leaf = as_parameter(s, v, g);
    if (leaf >= 0)
        return leaf;
    const mech_link *l = &s->model->links[t->link];
    const char *a = l->points[t->p0].name, *b = l->points[t->p1].name;
    char *text = text_of(is_angle ? "<%s%s" : "|%s%s|", a, b);
    for (int var = SYS_NVARS(s->n) + s->nparams; text && var < s->nvars; var++)
        if (strcmp(s->names[var], text) == 0) {
            free(text);
            return expr_var(c, var);
        }
    char dep[256], desc[512];
    depends_on(s, g, dep, sizeof dep);
    snprintf(desc, sizeof desc, "%s = %.10g %s: the %s of %s - %s in link '%s' (%s)",
             text ? text : "?", v, is_angle ? "rad" : "m", is_angle ? "angle" : "length", b, a,
             l->name, dep);
    char *la = latex_name(a), *lb = latex_name(b);
    char *latex = la && lb ? text_of(is_angle ? "\\angle %s%s" : "\\overline{%s%s}", la, lb) : NULL;
    free(la);
    free(lb);
    sys_coef what = {is_angle ? LEAF_ANGLE : LEAF_LENGTH, t->link, t->p0, t->p1, -1};
    int var = add_leaf(s, what, text, latex, xstrdup(desc));
    return var < 0 ? c->zero : expr_var(c, var);
}

/* The leaf +-p for a number v with gradient g that is exactly +-p, or -1. */
static ex as_parameter(mech_system *s, double v, const double *g)
{
    int only = -1, count = 0;
    for (int k = 0; k < s->nparams; k++)
        if (g[k] != 0.0) {
            only = k;
            count++;
        }
    if (count != 1)
        return -1;
    /* a bare parameter (`La: 38`) enters scaled by the default unit: g = 0.001 */
    const mech_param *pp = chosen(s, only);
    double scale = fabs(g[only]), sign = g[only] > 0 ? 1.0 : -1.0, p = pp->value;
    if (fabs(v - sign * scale * p) > 1e-12 * fabs(scale * p))
        return -1;
    int k = only;
    if (fabs(scale - 1.0) >= 1e-12 && !s->coef_desc[k]) {
        char desc[256];
        snprintf(desc, sizeof desc, "%s = %.10g: %.10g in the file's default unit", pp->name,
                 scale * p, p);
        if (!(s->coef_desc[k] = xstrdup(desc)))
            s->ex.failed = 1;
    }
    ex leaf = expr_var(&s->ex, SYS_NVARS(s->n) + only);
    return sign > 0 ? leaf : expr_neg(&s->ex, leaf);
}

/* A vector of the ground, written (dx, dy) when each component is a
 * constant or +-p (`[xF, -a]` to O gives -xF, a); 0 when it is not. */
static int ground_components(mech_system *s, const loop_term *t, double dx, double dy, ex *x,
                             ex *y)
{
    int g0 = s->point_base[t->link] + t->p0, g1 = s->point_base[t->link] + t->p1;
    ex out[2];
    double v[2] = {dx, dy}, *g = s->grad;
    for (int i = 0; i < 2; i++) {
        int varies = 0;
        for (int k = 0; k < s->nparams; k++) {
            g[k] = s->dxy[k][2 * g1 + i] - s->dxy[k][2 * g0 + i];
            varies |= g[k] != 0.0;
        }
        out[i] = varies ? as_parameter(s, v[i], g) : expr_const(&s->ex, v[i]);
    }
    if (out[0] < 0 || out[1] < 0)
        return 0;
    *x = out[0];
    *y = out[1];
    return 1;
}

/* Parameters beyond this many are not named: naming takes one pass over the
 * model's parameter expressions per parameter. */
enum { MAX_NAMED_PARAMS = 200 };

static int system_new_named(const mech_model *m, mech_system **out, mech_diag *d)
{
    *out = NULL;
    if (m->nparams == 0 || m->nparams > MAX_NAMED_PARAMS)
        return mech_system_new(m, out, d);
    int *all = xcalloc((size_t)m->nparams, sizeof *all);
    if (!all)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    for (int k = 0; k < m->nparams; k++)
        all[k] = k;
    sys_leaves named = {SYS_LEAF_NAMED, all, m->nparams};
    int rc = sys_new_with(m, &named, out, d);
    free(all);
    return rc;
}

int mech_system_new_named(const mech_model *m, mech_system **out, mech_diag *d)
{
    mech_diag own, *dd = api_diag(d, &own);
    int rc = m && out ? system_new_named(m, out, dd)
                      : api_null(dd, "mech_system_new_named", m ? "out" : "m");
    api_diag_end(d, &own);
    return rc;
}

/* ---- SYS_LEAF_POLAR: the moved lengths and angles as leaves ------------- */

int sys_coef_var(const mech_system *s, const loop_term *t, int is_angle)
{
    sys_leaf_kind kind = is_angle ? LEAF_ANGLE : LEAF_LENGTH;
    for (int k = 0; k < s->nvars - SYS_NVARS(s->n); k++) {
        const sys_coef *c = &s->coef[k];
        if (c->kind == kind && c->link == t->link && c->p0 == t->p0 && c->p1 == t->p1)
            return SYS_NVARS(s->n) + k;
    }
    return -1;
}

void sys_body_vector(const mech_model *m, const loop_term *t, double *dx, double *dy, double *r,
                     double *a)
{
    const mech_link *l = &m->links[t->link];
    *dx = l->points[t->p1].x - l->points[t->p0].x;
    *dy = l->points[t->p1].y - l->points[t->p0].y;
    *r = hypot(*dx, *dy);
    *a = atan2(*dy, *dx);
}

/* The leaf of t's length or angle: one per vector and kind (a loop crossing
 * the vector again finds it). */
static ex polar_leaf(mech_system *s, const loop_term *t, int is_angle)
{
    int var = sys_coef_var(s, t, is_angle);
    if (var < 0)
        var = add_leaf(s, (sys_coef){is_angle ? LEAF_ANGLE : LEAF_LENGTH, t->link, t->p0, t->p1,
                                     -1}, NULL, NULL, NULL);
    return var < 0 ? s->ex.zero : expr_var(&s->ex, var);
}

/* r (cos, sin)(theta + a), with r and a leaves when a chosen parameter moves
 * them (a nonzero derivative at the model's values): named (the parameter or
 * |AB|, <AB) or not (variant_regs.c checks every variant's other numbers
 * against these and re-analyses a variant where they moved). With no
 * parameter chosen, the solver's constants. */
static void polar_body(mech_system *s, const loop_term *t, ex *x, ex *y)
{
    expr_ctx *c = &s->ex;
    double dx, dy, r, a;
    sys_body_vector(s->model, t, &dx, &dy, &r, &a);
    int named = s->form == SYS_LEAF_NAMED, np = s->nparams;
    if (named && t->link == 0 && ground_components(s, t, dx, dy, x, y))
        return;
    double *dr = s->grad, *da = np ? s->grad + np : NULL;  /* no parameter: none */
    body_gradient(s, t, dx, dy, dr, da);
    int r_varies = 0, a_varies = 0;
    for (int k = 0; k < np; k++) {
        r_varies |= dr[k] != 0.0;
        a_varies |= da[k] != 0.0;
    }
    ex len = !r_varies ? expr_const(c, r)
             : named ? named_leaf(s, t, 0, r, dr) : polar_leaf(s, t, 0);
    ex ang;
    if (a_varies) {
        ang = expr_add(c, s->link_angle[t->link],
                       named ? named_leaf(s, t, 1, a, da) : polar_leaf(s, t, 1));
    } else {
        if (a == PI_ || a == -PI_) {  /* atan2 gives exactly pi for (-r, 0): -r (cos, sin)(theta) */
            len = expr_neg(c, len);
            a = 0.0;
        }
        ang = expr_add(c, s->link_angle[t->link], expr_const(c, a));
    }
    *x = expr_mul(c, len, expr_cos(c, ang));
    *y = expr_mul(c, len, expr_sin(c, ang));
}

void sys_body_term(mech_system *s, const loop_term *t, ex *x, ex *y)
{
    if (s->form == SYS_LEAF_CARTESIAN)
        cartesian_body(s, t, x, y);
    else
        polar_body(s, t, x, y);
}
