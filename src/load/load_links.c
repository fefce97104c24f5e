/* src/load/load_links.c: the loader's 'units', 'parameters', 'ground' and
 * 'links' (each link's points, in [x, y] or polar form, its symbol, and its
 * mass, center and inertia); interns the point names. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

/* ---- units and parameters ----------------------------------------- */

void load_units(loader *ld, const ynode *map)
{
    const char *keys[NQUANTITIES];
    for (int q = 1; q < NQUANTITIES; q++)
        keys[q - 1] = quantity_get((quantity)q)->key;
    if (!load_check_keys(ld, map, keys, NQUANTITIES - 1, "units"))
        return;
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        int q = k->kind == YNODE_SCALAR ? quantity_by_key(k->text) : -1;
        if (q < 0 || !load_want_kind(ld, v, YNODE_SCALAR, "a unit"))
            continue;
        double scale;
        dim d;
        const char *end;
        if (!unit_parse(v->text, &scale, &d, &end) || *end != '\0') {
            load_err(ld, v, "unknown unit '%s' for %s", v->text, k->text);
            continue;
        }
        const quantity_info *qi = quantity_get((quantity)q);
        if (!dim_equal(d, qi->d)) {
            const char *noun = NULL;
            for (int o = 0; o < NQUANTITIES; o++)
                if (dim_equal(d, quantity_get((quantity)o)->d))
                    noun = quantity_get((quantity)o)->noun;
            char u[64];
            dim_format(d, u, sizeof u);
            if (noun)
                load_err(ld, v, "'%s' is not a unit of %s (it measures %s; %s is in %s)", v->text,
                         k->text, noun, k->text, qi->si_unit);
            else
                load_err(ld, v, "'%s' is not a unit of %s (it is in %s; %s is in %s)", v->text,
                         k->text, u, k->text, qi->si_unit);
            continue;
        }
        ld->units.scale[q] = scale;
        if (!ld->m->units)
            ld->m->units = xcalloc(1, sizeof *ld->m->units);
        if (ld->m->units) {  /* as written, for results in them (mech solve --units file) */
            snprintf(ld->m->units->text[q], sizeof ld->m->units->text[q], "%s", v->text);
            ld->m->units->scale[q] = scale;
        }
        if (q == Q_ANGLE)
            ld->angle_unit_given = 1;
    }
}

/* What a name already means in an expression, or NULL if it is free. */
static const char *reserved_name(const char *s)
{
    static const char *const words[] = {"sqrt", "sin", "cos", "tan", "atan2"};
    if (strcmp(s, "pi") == 0)
        return "the constant";
    for (size_t i = 0; i < COUNT(words); i++)
        if (strcmp(s, words[i]) == 0)
            return "the function";
    return unit_is_name(s, strlen(s)) ? "the unit" : NULL;
}

/* The value of parameter `name` (key k, value v): the file's definition or
 * its replacement (mech sweep, --set), which must be a quantity of the same
 * dimension; the one evaluated is recorded (p->root). 0, or -1 with the
 * problem reported (or echoing one already). */
static int eval_parameter(loader *ld, const ynode *k, const ynode *v, const char *name,
                          expr_param *p)
{
    char msg[256];
    size_t pos = 0;
    const char *text = v->text;
    for (int o = 0; o < ld->nov; o++)
        if (strcmp(ld->ov[o].name, name) == 0) {
            text = ld->ov[o].text;
            ld->ov_used[o] = 1;
        }
    expr_env recorded = ld->env;  /* the definition used; not the replaced one */
    recorded.record = ld->m->pexpr;
    if (text != v->text && quantity_eval_param(text, &recorded, p, msg, sizeof msg, &pos) < 0) {
        diag_error(ld->d, ld->file, v->mark, "parameter '%s' replaced by '%s': %s", name, text,
                   msg);
        return -1;
    }
    expr_param was = {0};
    if (text != v->text && !p->bare &&
        quantity_eval_param(v->text, &ld->env, &was, msg, sizeof msg, &pos) == 0 && !was.bare &&
        !dim_equal(was.d, p->d)) {
        char du[32], dw[32];
        dim_format(p->d, du, sizeof du);
        dim_format(was.d, dw, sizeof dw);
        diag_error(ld->d, ld->file, v->mark, "parameter '%s' replaced by '%s': a quantity in "
                   "%s, where the file's '%s' is in %s", name, text, du, v->text, dw);
        return -1;
    }
    if (text == v->text && quantity_eval_param(v->text, &recorded, p, msg, sizeof msg, &pos) < 0) {
        int echo = load_uses_bad_param(ld, v->text);
        if (name_map_put(&ld->bad_params, k->text, 1) < 0 || echo)
            return -1;
        mech_mark at = v->mark;
        at.col += (int)pos + (v->quoted ? 1 : 0);
        diag_error(ld->d, ld->file, at, "parameter '%s': %s", name, msg);
        return -1;
    }
    return 0;
}

/* A parameter's definition: the scalar `40 mm`, or the `value` of
 * {value: 40 mm, tolerance: 0.05 mm} (*tol: the tolerance's node). NULL
 * when reported. */
static const ynode *parameter_value(loader *ld, const ynode *v, const char *name,
                                    const ynode **tol)
{
    if (v->kind != YNODE_MAP)
        return load_want_kind(ld, v, YNODE_SCALAR, "a parameter value") ? v : NULL;
    static const char *const keys[] = {"value", "tolerance"};
    char where[128];
    snprintf(where, sizeof where, "parameter '%s'", name);
    load_check_keys(ld, v, keys, COUNT(keys), where);
    const ynode *val = ymap_get(v, "value");
    if (!val && load_misspelt(v, "value", keys, COUNT(keys)))
        return NULL;  /* reported as a typo */
    if (!val) {
        load_err(ld, v, "parameter '%s' needs a 'value' (as {value: 40 mm, tolerance: "
                        "0.05 mm})", name);
        return NULL;
    }
    *tol = ymap_get(v, "tolerance");
    return load_want_kind(ld, val, YNODE_SCALAR, "a parameter value") ? val : NULL;
}

/* The tolerance of parameter p (+-, SI): a quantity of p's dimension (a bare
 * number only for a bare p), not negative. 0, or -1 with the problem reported. */
static int eval_tolerance(loader *ld, const ynode *t, const char *name, const expr_param *p,
                          double *out)
{
    char msg[256];
    size_t pos = 0;
    expr_param tp = {0};
    if (!load_want_kind(ld, t, YNODE_SCALAR, "a tolerance"))
        return -1;
    if (quantity_eval_param(t->text, &ld->env, &tp, msg, sizeof msg, &pos) < 0)
        return load_err(ld, t, "tolerance of parameter '%s': %s", name, msg), -1;
    char du[32], dt[32];
    dim_format(p->d, du, sizeof du);
    dim_format(tp.d, dt, sizeof dt);
    if (tp.bare != p->bare || (!p->bare && !dim_equal(tp.d, p->d)))
        return load_err(ld, t, "tolerance of parameter '%s' must be in the value's unit (%s), "
                               "not '%s'", name, p->bare ? "a bare number" : du, t->text), -1;
    if (tp.value < 0)
        return load_err(ld, t, "tolerance of parameter '%s' is negative (write the +- "
                               "half-width: 0.05 mm)", name), -1;
    *out = tp.value;
    return 0;
}

void load_parameters(loader *ld, const ynode *map)
{
    if (!load_check_map(ld, map, NULL, 0, "'parameters'", "parameter"))
        return;
    if (map->n > MAX_PARAMS)
        return (void)load_err(ld, map, "too many parameters (%zu; at most %d)", map->n, MAX_PARAMS);
    mech_model *m = ld->m;
    m->params = xcalloc(map->n, sizeof *m->params);
    ld->params = xcalloc(map->n, sizeof *ld->params);
    int record = ld->expressions && map->n;  /* what the parameters move, as expressions */
    m->pexpr = record ? pexpr_new() : NULL;
    if (!m->params || !ld->params || (record && !m->pexpr)) {
        load_nomem(ld, map);
        return;
    }
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = load_get_name(ld, k, "parameter name");
        if (!name)
            continue;
        const char *taken = reserved_name(name);
        if (taken) {
            load_err(ld, k, "parameter name '%s' is already %s '%s' in expressions; choose another "
                            "name", name, taken, name);
            /* its uses would each fail again ("unit 'm' without a number"):
             * this one error says it */
            if (name_map_put(&ld->bad_params, k->text, 1) < 0)
                load_nomem(ld, k);
            continue;
        }
        if (k->dup_of)
            continue; /* duplicate key, already reported */
        const ynode *tol = NULL;
        const ynode *def = parameter_value(ld, v, name, &tol);
        expr_param p = {0};
        double tolerance = 0.0;
        if (def && eval_parameter(ld, k, def, name, &p) != 0)
            continue;  /* reported, and its uses are not reported again */
        if (!def || (tol && eval_tolerance(ld, tol, name, &p, &tolerance) != 0)) {
            if (name_map_put(&ld->bad_params, k->text, 1) < 0)  /* no echo from its uses */
                load_nomem(ld, k);
            continue;
        }
        mech_param *mp = &m->params[m->nparams];
        mp->name = xstrdup(name);
        if (!mp->name || name_map_put(&ld->param_map, mp->name, m->nparams) < 0) {
            free(mp->name);
            mp->name = NULL;
            load_nomem(ld, k);
            continue;
        }
        mp->value = p.value;
        mp->tol = tolerance;
        mp->mark = k->mark;
        if (!p.bare)
            dim_format(p.d, mp->unit, sizeof mp->unit);
        p.name = mp->name;
        if (m->pexpr)
            pexpr_set_param(m->pexpr, m->nparams, p.root);
        ld->params[m->nparams++] = p;
        ld->env.nparams = m->nparams;
        ld->env.params = ld->params;
        ld->env.param_index = &ld->param_map;
    }
}

/* ---- points and links --------------------------------------------- */

static int intern_point(loader *ld, const char *name)
{
    mech_model *m = ld->m;
    int id = find_point(ld, name);
    if (id >= 0)
        return id;
    if ((m->npoint_names & (m->npoint_names - 1)) == 0) {
        size_t cap = m->npoint_names ? 2 * (size_t)m->npoint_names : 4;
        char **p = xrealloc_array(m->point_names, cap, sizeof *p);
        if (!p)
            return -1;
        m->point_names = p;
    }
    char *copy = xstrdup(name);
    if (!copy || name_map_put(&ld->point_map, copy, m->npoint_names) < 0) {
        free(copy);
        return -1;
    }
    m->point_names[m->npoint_names] = copy;
    return m->npoint_names++;
}

/* The index of point `name` among the points of `l` read so far, or -1;
 * `index` (name -> index, or NULL) keeps a link of 10^6 points linear. */
static int point_of_link(const mech_link *l, const name_map *index, const char *name)
{
    if (index)
        return name_map_get(index, name);
    for (int i = 0; i < l->npoints; i++)
        if (l->points[i].name && strcmp(l->points[i].name, name) == 0)
            return i;
    return -1;
}

/* A point: [x, y] or {length, angle, from}. `l` holds the points read so far
 * (their handles: `link`'s in the parameter expressions). h: the handles of
 * x and y (PX_FIXED when no parameter moves them). */
static int load_point_coords(loader *ld, const mech_link *l, int link, const name_map *index,
                             const ynode *v, const char *what, double *x, double *y, int *h)
{
    h[0] = h[1] = PX_FIXED;
    if (v->kind == YNODE_SEQ) {
        double xy[2] = {0, 0};
        int ok = load_get_vec2_expr(ld, v, Q_LENGTH, what, xy, h);
        *x = xy[0];
        *y = xy[1];
        return ok;
    }
    if (v->kind != YNODE_MAP) {
        load_err(ld, v, "%s must be [x, y] or {length: ..., angle: ...}", what);
        return 0;
    }
    static const char *const keys[] = {"length", "angle", "from"};
    load_check_keys(ld, v, keys, COUNT(keys), what);
    const ynode *len = ymap_get(v, "length"), *ang = ymap_get(v, "angle"), *from = ymap_get(v, "from");
    if (!len || !ang) {
        load_err(ld, v, "%s: missing '%s' (polar form needs length and angle)", what,
                 len ? "angle" : "length");
        return 0;
    }
    pxq r, a, x0 = pxq_fixed(0), y0 = pxq_fixed(0);
    int ok = load_get_quantity_expr(ld, len, Q_LENGTH, what, &r.v, &r.h);
    ok = load_get_quantity_expr(ld, ang, Q_ANGLE, what, &a.v, &a.h) && ok;
    if (from) {
        const char *fname = load_get_name(ld, from, "'from'");
        int i = fname ? point_of_link(l, index, fname) : -1;
        if (i >= 0) {
            x0 = (pxq){l->points[i].x, pexpr_point(ld->m->pexpr, link, i, 0)};
            y0 = (pxq){l->points[i].y, pexpr_point(ld->m->pexpr, link, i, 1)};
        }
        if (fname && i < 0) {
            load_err(ld, from, "'from: %s' must name a point listed earlier in link '%s'", fname,
                     l->name);
            ok = 0;
        }
    }
    if (!ok)
        return 0;  /* r or a may be unset */
    *x = x0.v + r.v * cos(a.v);
    *y = y0.v + r.v * sin(a.v);
    h[0] = load_expr(ld, PX_POLAR_X, 0.0, x0, r, a, *x).h;
    h[1] = load_expr(ld, PX_POLAR_Y, 0.0, y0, r, a, *y).h;
    return 1;
}

/* The points of a link; returns 0 when some point had an error. A point with
 * wrong coordinates is kept (at 0, 0) so that its name still joins links and
 * the error is not echoed by every use of the name. */
static int load_points(loader *ld, mech_link *l, const ynode *map)
{
    char where[128];
    snprintf(where, sizeof where, "link '%s'", l->name);
    if (map->kind != YNODE_MAP) {
        ld->points_bad = 1;
        return load_err(ld, map, "the points of link '%s' must be a mapping from point name to "
                                 "coordinates (such as 'A: [20, 0]'), not %s", l->name,
                        ynode_kind_name(map->kind)), 0;
    }
    size_t errors = ld->d->nerrors;
    load_check_map(ld, map, NULL, 0, where, "point");
    int max = l->is_ground ? MAX_GROUND_POINTS : MAX_POINTS_PER_LINK;
    if (map->n > (size_t)max) {
        load_err(ld, map, "link '%s' has %zu points; at most %d", l->name, map->n, max);
        return 0;
    }
    l->points = xcalloc(map->n, sizeof *l->points);
    if (!l->points) {
        load_nomem(ld, map);
        return 0;
    }
    name_map index = {0};  /* point name -> index, for 'from' */
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = load_get_name(ld, k, "point name");
        if (!name)
            ld->points_bad = 1;
        if (!name || k->dup_of)
            continue;  /* invalid or duplicate (reported) */
        char what[128];
        snprintf(what, sizeof what, "point '%s' of link '%s'", name, l->name);
        mech_point *p = &l->points[l->npoints];
        int link = (int)(l - ld->m->links), h[2];
        if (!load_point_coords(ld, l, link, &index, v, what, &p->x, &p->y, h)) {
            p->x = p->y = 0;
            ld->link_failed[link] |= LINK_UNPLACED;
        }
        if (ld->m->pexpr)
            pexpr_set_point(ld->m->pexpr, link, l->npoints, h[0], h[1]);
        p->name = xstrdup(name);
        p->id = intern_point(ld, name);
        p->mark = k->mark;
        if (!p->name || p->id < 0 || name_map_put(&index, p->name, l->npoints) < 0) {
            load_nomem(ld, k);
            free(p->name);  /* not counted in npoints: freed here, not with the link */
            p->name = NULL;
            break;
        }
        l->npoints++;
    }
    name_map_free(&index);
    return ld->d->nerrors == errors;
}

static const char *const link_keys[] = {"points", "symbol", "mass", "center", "inertia"};

/* Number k of link l's mass (PXN_MASS: mass, inertia, center[0], center[1])
 * has handle h. */
static void mass_expr(loader *ld, const mech_link *l, int k, int h)
{
    if (ld->m->pexpr)
        pexpr_set(ld->m->pexpr, PXN_MASS, 4 * (int)(l - ld->m->links) + k, h);
}

static void load_mass(loader *ld, mech_link *l, const ynode *map)
{
    const ynode *mass = ymap_get(map, "mass"), *center = ymap_get(map, "center"),
                *inertia = ymap_get(map, "inertia");
    if (!mass && !center && !inertia)
        return;
    char what[128];
    if (!mass && load_misspelt(map, "mass", link_keys, COUNT(link_keys)))
        return;  /* reported as a typo */
    if (!mass) {
        load_err(ld, center ? center : inertia, "link '%s' has '%s' but no 'mass'", l->name,
                 center ? "center" : "inertia");
        return;
    }
    snprintf(what, sizeof what, "mass of link '%s'", l->name);
    int h[2];
    if (!load_get_quantity_expr(ld, mass, Q_MASS, what, &l->mass, &h[0]))
        return;
    mass_expr(ld, l, 0, h[0]);
    if (l->mass < 0)
        load_err(ld, mass, "%s is negative", what);
    if ((!center && load_misspelt(map, "center", link_keys, COUNT(link_keys))) ||
        (!inertia && load_misspelt(map, "inertia", link_keys, COUNT(link_keys))))
        return;
    if (!center || !inertia) {
        load_err(ld, mass, "link '%s' has a mass but no '%s' (give both center and inertia)", l->name,
                 center ? "inertia" : "center");
        return;
    }
    snprintf(what, sizeof what, "center of mass of link '%s'", l->name);
    if (center->kind == YNODE_SCALAR && load_valid_name(center->text)) {
        int found = 0, link = (int)(l - ld->m->links);
        for (int i = 0; i < l->npoints; i++)
            if (strcmp(l->points[i].name, center->text) == 0) {
                l->center[0] = l->points[i].x;
                l->center[1] = l->points[i].y;
                mass_expr(ld, l, 2, pexpr_point(ld->m->pexpr, link, i, 0));
                mass_expr(ld, l, 3, pexpr_point(ld->m->pexpr, link, i, 1));
                found = 1;
            }
        if (!found) {
            load_err(ld, center, "%s: '%s' is not a point of link '%s'", what, center->text, l->name);
            return;
        }
    } else if (!load_point_coords(ld, l, (int)(l - ld->m->links), NULL, center, what,
                                  &l->center[0], &l->center[1], h)) {
        return;
    } else {
        mass_expr(ld, l, 2, h[0]);
        mass_expr(ld, l, 3, h[1]);
    }
    snprintf(what, sizeof what, "inertia of link '%s'", l->name);
    if (!load_get_quantity_expr(ld, inertia, Q_INERTIA, what, &l->inertia, &h[0]))
        return;
    mass_expr(ld, l, 1, h[0]);
    if (l->inertia < 0) {
        load_err(ld, inertia, "%s is negative", what);
        return;
    }
    l->has_mass = 1;
}

void load_ground(loader *ld, const ynode *map)
{
    mech_link *g = &ld->m->links[0];
    g->name = xstrdup("ground");
    g->is_ground = 1;
    if (!g->name || name_map_put(&ld->link_map, g->name, 0) < 0)
        load_nomem(ld, map);
    if (map) {
        g->mark = map->mark;
        if (!load_points(ld, g, map))
            ld->link_failed[0] |= LINK_FAILED;
    }
}

static void load_link(loader *ld, mech_link *l, const ynode *k, const ynode *v)
{
    l->name = xstrdup(k->text);
    l->mark = k->mark;
    if (!l->name)
        return (void)load_nomem(ld, k);
    char where[128];
    snprintf(where, sizeof where, "link '%s'", l->name);
    unsigned char *failed = &ld->link_failed[l - ld->m->links];
    if (v->kind != YNODE_MAP) {
        *failed |= LINK_FAILED;
        return (void)load_err(ld, v, "link '%s' must be a mapping with its 'points' (and optionally "
                                     "'mass', 'center', 'inertia', 'symbol'), not %s", l->name,
                              ynode_kind_name(v->kind));
    }
    load_check_keys(ld, v, link_keys, COUNT(link_keys), where);
    const ynode *points = ymap_get(v, "points"), *sym = ymap_get(v, "symbol");
    if (!points) {
        *failed |= LINK_FAILED;
        if (!load_misspelt(v, "points", link_keys, COUNT(link_keys)))
            load_err(ld, k, "link '%s' has no 'points'", l->name);
    } else if (!load_points(ld, l, points)) {
        *failed |= LINK_FAILED;
    }
    if (sym)
        l->symbol = load_get_string(ld, sym, "symbol", 32, 0);
    load_mass(ld, l, v);
}

void load_links(loader *ld, const ynode *map)
{
    mech_model *m = ld->m;
    if (map->kind != YNODE_MAP) {
        ld->links_bad = 1;
        return (void)load_err(ld, map, "'links' must be a mapping from each link's name to "
                                       "its points (such as 'crank: {points: {O: [0, 0], "
                                       "A: [20, 0]}}'), not %s", ynode_kind_name(map->kind));
    }
    load_check_map(ld, map, NULL, 0, NULL, "link");
    if (map->n == 0) {
        ld->links_bad = 1;
        load_err(ld, map, "'links' is empty: a mechanism needs at least one moving link");
        return;
    }
    if (map->n >= MAX_LINKS) {
        load_err(ld, map, "too many links (%zu; at most %d moving links)", map->n, MAX_LINKS - 1);
        return;
    }
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = load_get_name(ld, k, "link name");
        if (!name || k->dup_of)
            continue;
        if (strcmp(name, "ground") == 0) {
            load_err(ld, k, "'ground' is the fixed link: give its points under the top-level 'ground' key");
            continue;
        }
        if (name_map_put(&ld->link_map, name, m->nlinks) < 0)
            return (void)load_nomem(ld, k);
        load_link(ld, &m->links[m->nlinks++], k, v);
    }
}
