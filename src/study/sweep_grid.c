/* src/study/sweep_grid.c: what a sweep varies (src/study/study.h): the grid of
 * mech_sweep_vary and mech_sweep_list ("l=130mm:150mm:5", "r=30mm,40mm";
 * every combination, the last parameter fastest), or the random samples of
 * mech_sweep_options.nrandom within the tolerances of the file's parameters
 * (sweep_random.c draws them); a variant's parameter texts and SI values
 * from its index (docs/batch.md). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "study.h"

/* "130mm" -> 130 and "mm" */
static int split_number(const char *s, double *v, char *unit, size_t size)
{
    char *end;
    *v = strtod(s, &end);
    if (end == s)
        return -1;
    while (*end == ' ')
        end++;
    snprintf(unit, size, "%s", end);
    return 0;
}

static int add_text(sweep_axis *a, const char *text)
{
    char **t = realloc(a->texts, (size_t)(a->count + 1) * sizeof *t);
    if (!t)
        return -1;
    a->texts = t;
    a->texts[a->count] = strdup(text);
    return a->texts[a->count++] ? 0 : -1;
}

/* The first control character of s (a byte below 32, or 127), or 0. The
 * values become CSV cells and terminal text: a newline would add rows. */
static int control_char(const char *s)
{
    for (; *s; s++)
        if ((unsigned char)*s < 32 || *s == 127)
            return (unsigned char)*s;
    return 0;
}

/* The SI values of axis a's texts and their unit, for the CSV (the solve
 * CSV's dialect: numbers in SI, the unit in the header). A value is a
 * quantity on its own: a number with a unit ("45mm", "0.5 rad/s") or a bare
 * number (unit "-", the file's unit where it is used); every value of one
 * parameter has the same dimension. MECH_OK, MECH_EINPUT or MECH_ENOMEM. */
static int axis_values(sweep_axis *a, const char *opt, const char *arg, mech_diag *d)
{
    unit_defaults u;
    unit_defaults_init(&u);
    expr_env env = {&u, NULL, 0, NULL};
    a->si = calloc((size_t)a->count, sizeof *a->si);
    if (!a->si)
        return MECH_ENOMEM;
    expr_param first = {0};
    for (int i = 0; i < a->count; i++) {
        expr_param p = {0};
        char err[256], unit[32];
        size_t pos = 0;
        if (quantity_eval_param(a->texts[i], &env, &p, err, sizeof err, &pos) < 0 ||
            !isfinite(p.value))
            return sweep_arg_error(d, "%s %s: value '%s' is not a number with a unit such as "
                                   "45mm (%s)", opt, arg, a->texts[i],
                                   isfinite(p.value) ? err : "not finite");
        if (p.bare)
            snprintf(unit, sizeof unit, "-");
        else
            dim_format(p.d, unit, sizeof unit);
        if (i == 0) {
            first = p;
            snprintf(a->unit, sizeof a->unit, "%s", unit);
        } else if (p.bare != first.bare || !dim_equal(p.d, first.d)) {
            return sweep_arg_error(d, "%s %s: value '%s' is in %s, '%s' in %s; every value of "
                                   "parameter '%s' has the same dimension", opt, arg,
                                   a->texts[i], unit, a->texts[0], a->unit, a->name);
        }
        a->si[i] = p.value;
    }
    return MECH_OK;
}

/* FROM:TO:COUNT into the axis's texts: COUNT values evenly from FROM to TO
 * ("%.15g" and the unit). 1 when it is not such a spec, -1 out of memory. */
static int expand_range(sweep_axis *a, char *spec)
{
    char *save = NULL;
    char *from = strtok_r(spec, ":", &save), *to = strtok_r(NULL, ":", &save);
    char *count = strtok_r(NULL, ":", &save), *end = NULL;
    double f, t;
    char uf[32], ut[32];
    long n = count ? strtol(count, &end, 10) : 0;
    if (!from || !to || !count || *end || n < 1 || n > 1000000 ||
        split_number(from, &f, uf, sizeof uf) < 0 || split_number(to, &t, ut, sizeof ut) < 0 ||
        strcmp(uf, ut) != 0)
        return 1;
    for (long i = 0; i < n; i++) {
        char text[96];
        double v = n == 1 ? f : f + (t - f) * (double)i / (double)(n - 1);
        snprintf(text, sizeof text, "%.15g%s%s", v, uf[0] ? " " : "", uf);
        if (add_text(a, text) < 0)
            return -1;
    }
    return 0;
}

/* A,B,... into the axis's texts. 1 when there is none, -1 out of memory. */
static int split_list(sweep_axis *a, char *spec)
{
    char *save = NULL;
    for (char *w = strtok_r(spec, ",", &save); w; w = strtok_r(NULL, ",", &save))
        if (add_text(a, w) < 0)
            return -1;
    return a->count == 0;
}

static void axis_free(sweep_axis *a)
{
    for (int i = 0; i < a->count; i++)
        free(a->texts[i]);
    free(a->texts);
    free(a->si);
    a->texts = NULL;
    a->si = NULL;
    a->count = 0;
}

int grid_add(mech_sweep *s, const char *arg, int is_list, mech_diag *d)
{
    const char *opt = is_list ? "--list" : "--vary";
    int cc = control_char(arg);
    if (cc)
        return sweep_arg_error(d, "%s: a control character (byte 0x%02x) in the value; "
                               "parameter values are text on one line", opt, (unsigned)cc);
    if (s->ngrid == SWEEP_MAX_GRID)
        return sweep_arg_error(d, "at most 8 --vary/--list options ('%s')", arg);
    const char *eq = strchr(arg, '=');
    if (!eq || eq == arg || (size_t)(eq - arg) >= sizeof s->axes[0].name)
        return sweep_arg_error(d, "expected NAME=..., not '%s'", arg);
    sweep_axis *a = &s->axes[s->naxes];
    memset(a, 0, sizeof *a);
    snprintf(a->name, sizeof a->name, "%.*s", (int)(eq - arg), arg);
    snprintf(a->spec, sizeof a->spec, "%s %s", opt, arg);
    for (int k = 0; k < s->naxes; k++)
        if (strcmp(s->axes[k].name, a->name) == 0)
            return sweep_arg_error(d, "%s %s: parameter '%s' is already varied by an earlier "
                                   "--vary or --list (give all its values in one option)", opt,
                                   arg, a->name);
    char *spec = strdup(eq + 1);
    int bad = !spec ? -1 : is_list ? split_list(a, spec) : expand_range(a, spec);
    free(spec);
    int rc = bad < 0 ? MECH_ENOMEM
             : bad ? sweep_arg_error(d, is_list ? "--list needs NAME=A,B,..., not '%s'"
                                            : "--vary needs NAME=FROM:TO:COUNT with the same unit "
                                              "on FROM and TO, not '%s'", arg)
             : axis_values(a, opt, arg, d);
    if (rc != MECH_OK) {  /* the axis is not kept */
        axis_free(a);
        return rc;
    }
    s->naxes++;
    s->ngrid++;
    return MECH_OK;
}

int grid_random_axis(mech_sweep *s, const char *name, const char *unit, double nominal,
                     double tol, mech_diag *d)
{
    if (s->naxes == SWEEP_MAX_AXES)
        return sweep_arg_error(d, "--random: more than 32 parameters with a tolerance");
    sweep_axis *a = &s->axes[s->naxes++];
    memset(a, 0, sizeof *a);
    snprintf(a->name, sizeof a->name, "%s", name);
    snprintf(a->unit, sizeof a->unit, "%s", unit[0] ? unit : "-");
    a->nominal = nominal;
    a->tol = tol;
    return MECH_OK;
}

int grid_random_axes(mech_sweep *s, const mech_model *m, mech_diag *d)
{
    for (int k = 0; k < m->nparams; k++) {
        const mech_param *p = &m->params[k];
        int rc = p->tol > 0.0 ? grid_random_axis(s, p->name, p->unit, p->value, p->tol, d)
                              : MECH_OK;
        if (rc != MECH_OK)
            return rc;
    }
    if (s->naxes == 0)
        return sweep_arg_error(d, "--random: no parameter of '%s' has a tolerance (give one as "
                               "r: {value: 40 mm, tolerance: 0.05 mm})", s->path);
    return MECH_OK;
}

int grid_total(mech_sweep *s, mech_diag *d)
{
    long total = s->opt.nrandom > 0 ? s->opt.nrandom : 1;
    for (int k = 0; s->opt.nrandom == 0 && k < s->naxes; k++)
        if ((total *= s->axes[k].count) > SWEEP_MAX_VARIANTS)
            return sweep_arg_error(d, "more than 10^7 variants");
    s->total = total;
    return MECH_OK;
}

/* The index into axis k of grid variant v (offset included): axis k's
 * index is a mixed-radix digit, the last axis the fastest. */
static int axis_index(const mech_sweep *s, long v, int k)
{
    v -= s->opt.index_offset;
    for (int j = s->naxes - 1; j > k; j--)
        v /= s->axes[j].count;
    return (int)(v % s->axes[k].count);
}

double grid_value(const mech_sweep *s, long index, int k)
{
    const sweep_axis *a = &s->axes[k];
    if (s->opt.nrandom > 0)
        return a->nominal + a->tol * sweep_random_unit(s->opt.seed, index, k);
    return a->si[axis_index(s, index, k)];
}

void grid_overrides(const mech_sweep *s, long index, mech_override *ov, sweep_text *text)
{
    for (int k = 0; k < s->naxes; k++) {
        const sweep_axis *a = &s->axes[k];
        ov[k].name = a->name;
        if (s->opt.nrandom > 0) {
            int unit = strcmp(a->unit, "-") != 0;
            snprintf(text[k], sizeof text[k], "%.17g%s%s", grid_value(s, index, k),
                     unit ? " " : "", unit ? a->unit : "");
            ov[k].text = text[k];
        } else {
            ov[k].text = a->texts[axis_index(s, index, k)];
        }
    }
}

static const mech_param *find_param(const mech_model *m, const char *name)
{
    for (int k = 0; k < m->nparams; k++)
        if (strcmp(m->params[k].name, name) == 0)
            return &m->params[k];
    return NULL;
}

int grid_bare_values(const mech_sweep *s, mech_diag *d)
{
    mech_model *m = NULL;
    mech_diag quiet;
    mech_diag_init(&quiet);
    int n = 0;
    if (mech_load_file(s->path, &m, &quiet) == MECH_OK)
        for (int k = 0; k < s->naxes; k++) {
            const sweep_axis *a = &s->axes[k];
            const mech_param *p = find_param(m, a->name);
            if (!a->spec[0] || strcmp(a->unit, "-") != 0 || !p || !p->unit[0])
                continue;
            sweep_arg_error(d, "%s: the value '%s' has no unit, but parameter '%s' has one in "
                            "the file (%s = %g %s, line %d): give the values a unit too; as "
                            "bare numbers the file does not load (below)", a->spec, a->texts[0],
                            a->name, a->name, p->value, p->unit, p->mark.line);
            n++;
        }
    mech_model_free(&m);
    mech_diag_free(&quiet);
    return n;
}

void grid_free(mech_sweep *s)
{
    for (int k = 0; k < s->naxes; k++)
        axis_free(&s->axes[k]);
    s->naxes = s->ngrid = 0;
}
