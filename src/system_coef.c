/* src/system_coef.c: the body vectors of the loop equations when the
 * model's numbers are not folded into constants (system.h, sys_mode):
 *   SYS_NAMED      r cos(theta + a), r sin(theta + a) with r and a the
 *                  parameter the user wrote (`r`, `-e`) or a named length
 *                  |AB| / angle <AB when they depend on parameters in another
 *                  way; numbers that depend on no parameter stay constants,
 *                  exactly as the solver's system folds them (mech equations);
 *   SYS_CARTESIAN  R(theta) (P1 - P0), the coordinates of P0 and P1 being
 *                  variables (sensitivity.c differentiates through them).
 * Which numbers depend on which parameter comes from the seeded loads'
 * d(point)/d(parameter) (sys_params.dxy). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "param_grad.h"
#include "system.h"

static const double PI_ = 3.14159265358979323846;

/* A new coefficient variable with its names and description (all owned
 * from here on, freed with the system); its variable number, or -1. */
static int add_coefficient(mech_system *s, char *text, char *latex, char *desc)
{
    int k = s->nvars - SYS_NVARS(s->n), nv = s->nvars + 1;
    char **nt = xrealloc_array(s->names, (size_t)nv, sizeof *nt);
    if (nt)
        s->names = nt;
    char **nl = nt ? xrealloc_array(s->latex, (size_t)nv, sizeof *nl) : NULL;
    if (nl)
        s->latex = nl;
    char **nd = nl ? xrealloc_array(s->coef_desc, (size_t)k + 1, sizeof *nd) : NULL;
    if (!nd || !text || !latex) {
        free(text);
        free(latex);
        free(desc);
        s->ex.failed = 1;  /* the system build then fails: out of memory */
        return -1;
    }
    s->coef_desc = nd;
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

int sys_coefficients_init(mech_system *s)
{
    const mech_model *m = s->model;
    s->point_base = xcalloc((size_t)m->nlinks + 1, sizeof *s->point_base);
    if (!s->point_base)
        return -1;
    for (int l = 0; l < m->nlinks; l++)
        s->point_base[l + 1] = s->point_base[l] + m->links[l].npoints;
    if (s->mode == SYS_CARTESIAN)
        s->nvars = SYS_COORD(s->n, s->point_base[m->nlinks]);
    if (s->mode != SYS_NAMED)
        return 0;
    for (int k = 0; k < s->params->nparams; k++)  /* the parameters: variables nvars + k */
        if (add_coefficient(s, xstrdup(s->params->names[k]), latex_name(s->params->names[k]),
                            NULL) < 0)
            return -1;
    return 0;
}

void sys_cartesian_body(mech_system *s, const loop_term *t, ex *x, ex *y)
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
 * the parameters: dr[k], da[k] = d r / d p_k, d a / d p_k. */
static void body_gradient(const mech_system *s, const loop_term *t, double dx, double dy,
                          double *dr, double *da)
{
    const sys_params *pp = s->params;
    int g0 = s->point_base[t->link] + t->p0, g1 = s->point_base[t->link] + t->p1;
    double r2 = dx * dx + dy * dy, r = sqrt(r2);
    for (int k = 0; k < pp->nparams; k++) {
        double ddx = pp->dxy[k][2 * g1] - pp->dxy[k][2 * g0];
        double ddy = pp->dxy[k][2 * g1 + 1] - pp->dxy[k][2 * g0 + 1];
        dr[k] = r > 0 ? (dx * ddx + dy * ddy) / r : 0.0;         /* d |u| = u.du / |u| */
        da[k] = r > 0 ? (dx * ddy - dy * ddx) / r2 : 0.0;        /* d atan2 = u x du / |u|^2 */
    }
}

/* "(depends on l3a, lk)" for a coefficient with gradient g. */
static void depends_on(const mech_system *s, const double *g, char *buf, size_t size)
{
    size_t k = (size_t)snprintf(buf, size, "depends on");
    const char *sep = " ";
    for (int i = 0; i < s->params->nparams && k < size; i++)
        if (g[i] != 0.0) {
            k += (size_t)snprintf(buf + k, size - k, "%s%s", sep, s->params->names[i]);
            sep = ", ";
        }
}

static ex as_parameter(mech_system *s, double v, const double *g);

/* The leaf of a length or angle that depends on parameters: the parameter
 * itself when the number is exactly +-p (gradient +-1 in p alone), else a
 * named coefficient |AB| or <AB (one per vector, found again by name). */
static ex named_leaf(mech_system *s, const loop_term *t, int is_angle, double v, const double *g)
{
    expr_ctx *c = &s->ex;
    const sys_params *pp = s->params;
    ex leaf = as_parameter(s, v, g);
    if (leaf >= 0)
        return leaf;
    const mech_link *l = &s->model->links[t->link];
    const char *a = l->points[t->p0].name, *b = l->points[t->p1].name;
    char *text = text_of(is_angle ? "<%s%s" : "|%s%s|", a, b);
    for (int var = SYS_NVARS(s->n) + pp->nparams; text && var < s->nvars; var++)
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
    int var = add_coefficient(s, text, latex, xstrdup(desc));
    return var < 0 ? c->zero : expr_var(c, var);
}

/* The leaf +-p for a number v with gradient g that is exactly +-p, or -1. */
static ex as_parameter(mech_system *s, double v, const double *g)
{
    const sys_params *pp = s->params;
    int only = -1, count = 0;
    for (int k = 0; k < pp->nparams; k++)
        if (g[k] != 0.0) {
            only = k;
            count++;
        }
    if (count != 1)
        return -1;
    /* a bare parameter (`La: 38`) enters scaled by the default unit: g = 0.001 */
    double scale = fabs(g[only]), sign = g[only] > 0 ? 1.0 : -1.0, p = pp->values[only];
    if (fabs(v - sign * scale * p) > 1e-12 * fabs(scale * p))
        return -1;
    int k = only;
    if (fabs(scale - 1.0) >= 1e-12 && !s->coef_desc[k]) {
        char desc[256];
        snprintf(desc, sizeof desc, "%s = %.10g: %.10g in the file's default unit", pp->names[k],
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
    const sys_params *pp = s->params;
    int g0 = s->point_base[t->link] + t->p0, g1 = s->point_base[t->link] + t->p1;
    ex out[2];
    double v[2] = {dx, dy};
    double *g = xcalloc((size_t)pp->nparams + 1, sizeof *g);
    if (!g)
        return 0;
    for (int i = 0; i < 2; i++) {
        int varies = 0;
        for (int k = 0; k < pp->nparams; k++) {
            g[k] = pp->dxy[k][2 * g1 + i] - pp->dxy[k][2 * g0 + i];
            varies |= g[k] != 0.0;
        }
        out[i] = varies ? as_parameter(s, v[i], g) : expr_const(&s->ex, v[i]);
    }
    free(g);
    if (out[0] < 0 || out[1] < 0)
        return 0;
    *x = out[0];
    *y = out[1];
    return 1;
}

/* Parameters beyond this many are not named (one load of the file each);
 * nor are they when the file cannot be read again (a model from a string). */
enum { MAX_NAMED_PARAMS = 200 };

int mech_system_new_named(const mech_model *m, mech_system **out, mech_diag *d)
{
    *out = NULL;
    if (m->nparams == 0 || m->nparams > MAX_NAMED_PARAMS || !m->file)
        return mech_system_new(m, out, d);
    param_grad *g = xcalloc(1, sizeof *g);
    if (!g)
        return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    mech_diag quiet;  /* a model from a string has no file to read again: numbers */
    mech_diag_init(&quiet);
    int rc = pgrad_build(m, NULL, 0, NULL, 0, 0, g, &quiet);
    mech_diag_free(&quiet);
    if (rc != MECH_OK) {
        free(g);
        return mech_system_new(m, out, d);
    }
    rc = sys_new_with(m, SYS_NAMED, &g->view, out, d);
    if (rc != MECH_OK) {
        pgrad_free(g);
        free(g);
        return rc;
    }
    (*out)->grad = g;
    return MECH_OK;
}

/* ---- SYS_REGISTERS: the varied coefficients as register leaves ---------- */

/* The variable of the length or angle of t's vector: one per vector and
 * kind (a loop crossing the vector again finds it). */
int sys_coef_var(const mech_system *s, const loop_term *t, int is_angle)
{
    for (int k = 0; k < s->nvars - SYS_NVARS(s->n); k++) {
        const sys_coef *c = &s->coef[k];
        if (c->link == t->link && c->p0 == t->p0 && c->p1 == t->p1 && c->is_angle == is_angle)
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

static ex register_leaf(mech_system *s, const loop_term *t, int is_angle)
{
    int var = sys_coef_var(s, t, is_angle), nc = s->nvars - SYS_NVARS(s->n);
    if (var >= 0)
        return expr_var(&s->ex, var);
    sys_coef *grown = xrealloc_array(s->coef, (size_t)nc + 1, sizeof *grown);
    if (!grown) {
        s->ex.failed = 1;  /* the system build then fails: out of memory */
        return s->ex.zero;
    }
    s->coef = grown;
    s->coef[nc] = (sys_coef){t->link, t->p0, t->p1, is_angle};
    return expr_var(&s->ex, s->nvars++);
}

/* As the numeric system's body vector r (cos, sin)(theta + a), with r
 * and a leaves when they depend on one of the parameters (a nonzero
 * derivative at the model's values): named leaves (SYS_NAMED: the
 * parameter or |AB|, <AB) or register leaves (SYS_REGISTERS: variant_regs.c
 * checks every variant's other numbers against these and re-analyses a
 * variant where they moved). */
static void body_with_leaves(mech_system *s, const loop_term *t, int registers, ex *x, ex *y)
{
    expr_ctx *c = &s->ex;
    double dx, dy, r, a;
    sys_body_vector(s->model, t, &dx, &dy, &r, &a);
    int np = s->params->nparams;
    if (!registers && t->link == 0 && ground_components(s, t, dx, dy, x, y))
        return;
    double *dr = xcalloc((size_t)np + 1, sizeof *dr), *da = xcalloc((size_t)np + 1, sizeof *da);
    if (!dr || !da) {
        free(dr);
        free(da);
        c->failed = 1;
        *x = *y = c->zero;
        return;
    }
    body_gradient(s, t, dx, dy, dr, da);
    int r_varies = 0, a_varies = 0;
    for (int k = 0; k < np; k++) {
        r_varies |= dr[k] != 0.0;
        a_varies |= da[k] != 0.0;
    }
    ex len = !r_varies ? expr_const(c, r)
             : registers ? register_leaf(s, t, 0) : named_leaf(s, t, 0, r, dr);
    ex ang;
    if (a_varies) {
        ang = expr_add(c, s->link_angle[t->link],
                       registers ? register_leaf(s, t, 1) : named_leaf(s, t, 1, a, da));
    } else {
        if (a == PI_ || a == -PI_) {  /* as the numeric system: -r (cos, sin)(theta) */
            len = expr_neg(c, len);
            a = 0.0;
        }
        ang = expr_add(c, s->link_angle[t->link], expr_const(c, a));
    }
    free(dr);
    free(da);
    *x = expr_mul(c, len, expr_cos(c, ang));
    *y = expr_mul(c, len, expr_sin(c, ang));
}

void sys_named_body(mech_system *s, const loop_term *t, ex *x, ex *y)
{
    body_with_leaves(s, t, 0, x, y);
}

void sys_register_body(mech_system *s, const loop_term *t, ex *x, ex *y)
{
    body_with_leaves(s, t, 1, x, y);
}
