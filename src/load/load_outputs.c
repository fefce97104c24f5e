/* src/load/load_outputs.c: the loader's 'loads' (forces, torques, distributed
 * loads on links) and 'outputs' (the points, links and sliders tabulated),
 * with the default outputs when the file gives none. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

/* ---- loads and outputs --------------------------------------------- */

/* The link a load acts on: `link:` when given, else the only link with the point. */
static int load_target_link(loader *ld, const ynode *map, int point_id, const ynode *pnode)
{
    mech_model *m = ld->m;
    const ynode *ln = ymap_get(map, "link");
    if (ln) {
        int li = load_find_link_or_report(ld, ln, "loaded link");
        if (li >= 0 && point_id >= 0 && load_point_in_link(ld, li, point_id) < 0) {
            load_err(ld, pnode, "link '%s' has no point '%s'", m->links[li].name, pnode->text);
            return -1;
        }
        return li;
    }
    if (point_id < 0)
        return load_err(ld, map, "this load needs 'link: NAME'"), -1;
    int found = -1, nc = 0, first, end;
    load_carriers_of(ld, point_id, &first, &end);
    for (int c = first; c < end; c++)
        found = ld->carrier_link[c], nc++;
    if (nc != 1)
        return load_err(ld, pnode, "point '%s' is on %d links; say which one is loaded with 'link: NAME'",
                        pnode->text, nc), -1;
    return found;
}

/* The keys of one kind of load (0 force, 1 torque, 2 distributed) that
 * belong to another kind are errors, at the key: a torque 'at' a point
 * would read as if the point mattered. */
static int keys_apply(loader *ld, const ynode *map, int kind)
{
    static const char *const noun[] = {"force", "torque", "distributed load"};
    static const char *const own[][4] = {{"at", NULL}, {NULL}, {"from", "to", "direction", NULL}};
    static const char *const others[] = {"at", "from", "to", "direction"};
    int ok = 1;
    for (size_t i = 0; i < COUNT(others); i++) {
        const ynode *k = load_key_of(map, others[i]);
        int mine = 0;
        for (int o = 0; own[kind][o]; o++)
            mine |= strcmp(own[kind][o], others[i]) == 0;
        if (k && !mine)
            ok = 0, load_err(ld, k, "'%s' does not apply to a %s", others[i], noun[kind]);
    }
    return ok;
}

static void load_one_load(loader *ld, const ynode *map, mech_load *l)
{
    static const char *const keys[] = {"force", "torque", "distributed", "link", "at",
                                       "from", "to", "direction", "between", "links"};
    if (!load_check_keys(ld, map, keys, COUNT(keys), "a load"))
        return;
    if (ymap_get(map, "between") || ymap_get(map, "links"))
        return load_state_line(ld, map);  /* a force along a line (load_state_loads.c) */
    const ynode *f = ymap_get(map, "force"), *t = ymap_get(map, "torque"),
                *dl = ymap_get(map, "distributed");
    if ((f != NULL) + (t != NULL) + (dl != NULL) != 1)
        return (void)load_err(ld, map, "a load is exactly one of 'force', 'torque' or 'distributed'");
    l->mark = map->mark;
    if (!keys_apply(ld, map, f ? 0 : t ? 1 : 2))
        return;
    int ok = 1;
    if (f) {
        l->kind = MECH_LOAD_FORCE;
        const ynode *at = ymap_get(map, "at");
        if (!at)
            return (void)load_err(ld, map, "a force needs 'at: POINT'");
        int id = load_find_point_or_report(ld, at, "load point");
        l->link = load_target_link(ld, map, id, at);
        if (load_state_wanted(ld, f))  /* an expression of the motion: not in m->loads */
            return load_state_load(ld, map, f, l->link,
                                   id >= 0 && l->link >= 0 ? load_point_in_link(ld, l->link, id) : -1);
        ok = load_get_vec2(ld, f, Q_FORCE, "force", l->force) && id >= 0 && l->link >= 0;
        if (ok)
            l->point[0] = load_point_in_link(ld, l->link, id);
    } else if (t) {
        l->kind = MECH_LOAD_TORQUE;
        l->link = load_target_link(ld, map, -1, NULL);
        if (load_state_wanted(ld, t))
            return load_state_load(ld, map, t, l->link, -1);
        ok = load_get_quantity(ld, t, Q_TORQUE, "torque", &l->torque) && l->link >= 0;
    } else {
        l->kind = MECH_LOAD_DISTRIBUTED;
        const ynode *from = ymap_get(map, "from"), *to = ymap_get(map, "to"),
                    *dir = ymap_get(map, "direction");
        if (!from || !to)
            return (void)load_err(ld, map, "a distributed load needs 'from: POINT' and 'to: POINT'");
        int a = load_find_point_or_report(ld, from, "load start");
        int b = load_find_point_or_report(ld, to, "load end");
        l->link = load_target_link(ld, map, a, from);
        ok = load_get_quantity(ld, dl, Q_FORCE_PER_LENGTH, "distributed load", &l->intensity);
        l->direction = -1.57079632679489661923;  /* default: downwards (-90 deg) */
        if (dir)
            ok = load_get_quantity(ld, dir, Q_ANGLE, "load direction", &l->direction) && ok;
        if (ok && a >= 0 && b >= 0 && l->link >= 0) {
            l->point[0] = load_point_in_link(ld, l->link, a);
            l->point[1] = load_point_in_link(ld, l->link, b);
            if (l->point[1] < 0)
                ok = 0, load_err(ld, to, "link '%s' has no point '%s'",
                                      ld->m->links[l->link].name, to->text);
        } else {
            ok = 0;
        }
    }
    if (ok && l->link == 0)
        ok = 0, load_err(ld, map, "a load on the ground does nothing; put it on a moving link");
    if (ok)
        ld->m->nloads++;
}

void load_loads(loader *ld, const ynode *seq)
{
    mech_model *m = ld->m;
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'loads'"))
        return;
    if (seq->n > MAX_LOADS)
        return (void)load_err(ld, seq, "too many loads (%zu; at most %d)", seq->n, MAX_LOADS);
    m->loads = xcalloc(seq->n, sizeof *m->loads);
    if (!m->loads)
        return (void)load_nomem(ld, seq);
    for (size_t i = 0; i < seq->n; i++)
        load_one_load(ld, seq->items[i], &m->loads[m->nloads]);
}

typedef int (*resolve_fn)(loader *ld, const ynode *n);

static int resolve_point(loader *ld, const ynode *n)
{
    return load_find_point_or_report(ld, n, "output point");
}
static int resolve_link(loader *ld, const ynode *n)
{
    return load_find_link_or_report(ld, n, "output link");
}
static int resolve_slider(loader *ld, const ynode *n)
{
    return load_slider_by_name(ld, n, "output slider");
}
static int resolve_cam(loader *ld, const ynode *n)
{
    const model_cams *cs = ld->m->cams;
    for (int i = 0; cs && n->text && i < cs->n; i++)
        if (cs->cam[i].name && strcmp(cs->cam[i].name, n->text) == 0)
            return i;
    return load_err(ld, n, "'%s' is not a cam of the file's 'cams:'%s", n->text ? n->text : "",
                    cs && cs->n ? "" : " (it has none)"), -1;
}

/* The names of list `what`, resolved by fn to indices below `range`; a name
 * given twice is an error at its second place, as `--outputs` refuses it
 * (its columns would be repeated). */
static void load_name_list(loader *ld, const ynode *seq, const char *what, resolve_fn fn,
                           int range, int **out, int *count)
{
    if (!load_want_kind(ld, seq, YNODE_SEQ, what))
        return;
    if (seq->n > MAX_LIST)
        return (void)load_err(ld, seq, "too many %s (%zu; at most %d)", what, seq->n, MAX_LIST);
    *out = xcalloc(seq->n, sizeof **out);
    const ynode **first = xcalloc((size_t)range + 1, sizeof *first);  /* each index's item */
    if (!*out || !first) {
        free(first);
        return (void)load_nomem(ld, seq);
    }
    for (size_t i = 0; i < seq->n; i++) {
        const ynode *item = seq->items[i];
        int v = fn(ld, item);
        if (v < 0)
            continue;  /* reported by fn */
        if (v < range && first[v]) {
            load_err(ld, item, "'%s' is listed twice in %s (first at %d:%d)", item->text, what,
                     first[v]->mark.line, first[v]->mark.col);
            continue;
        }
        if (v < range)
            first[v] = item;
        (*out)[(*count)++] = v;
    }
    free(first);
}

void load_default_outputs(mech_model *m)
{
    mech_outputs *o = &m->outputs;
    o->points = xcalloc((size_t)m->npoint_names, sizeof *o->points);
    o->links = xcalloc((size_t)m->nlinks, sizeof *o->links);
    o->sliders = xcalloc((size_t)m->njoints, sizeof *o->sliders);
    if (!o->points || !o->links || !o->sliders)
        return;
    for (int i = 0; i < m->npoint_names; i++)
        o->points[o->npoints++] = i;
    for (int i = 1; i < m->nlinks; i++)
        o->links[o->nlinks++] = i;
    for (int i = 0; i < m->njoints; i++)
        if (m->joints[i].kind == MECH_JOINT_SLIDER)
            o->sliders[o->nsliders++] = i;
}

void load_outputs(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"points", "links", "sliders", "cams", "forces"};
    mech_outputs *o = &ld->m->outputs;
    if (!load_check_keys(ld, map, keys, COUNT(keys), "outputs"))
        return;
    const ynode *p = ymap_get(map, "points"), *l = ymap_get(map, "links"),
                *s = ymap_get(map, "sliders"), *f = ymap_get(map, "forces");
    if (p)
        load_name_list(ld, p, "'points'", resolve_point, ld->m->npoint_names, &o->points,
                       &o->npoints);
    if (l)
        load_name_list(ld, l, "'links'", resolve_link, ld->m->nlinks, &o->links, &o->nlinks);
    if (s)
        load_name_list(ld, s, "'sliders'", resolve_slider, ld->m->njoints, &o->sliders,
                       &o->nsliders);
    const ynode *c = ymap_get(map, "cams");
    if (c)
        load_name_list(ld, c, "'cams'", resolve_cam, model_ncams(ld->m) + 1, &o->cams,
                       &o->ncams);
    if (f)
        load_get_bool(ld, f, "'forces'", &o->forces);
}

