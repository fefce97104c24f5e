/* src/load/load_springs.c: the loader's 'springs' (linear springs and viscous
 * dampers between two points on different links; torsional springs and
 * dampers at a revolute joint), checked with file:line:column.
 *
 *   springs:
 *     - {between: [P, Q], links: [a, b], name, stiffness, free_length, preload, damping}
 *     - {at: JOINT, name, stiffness, free_angle, preload, damping}
 *
 * An entry with 'damping' and no 'stiffness' is a damper alone. The force
 * law and its signs are in docs/forces.md section 7. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

enum { MAX_SPRINGS = 100000 };

/* The two ends of a linear spring: links and points. A point on several
 * links (a pin) attaches to the first carrier in file order that differs
 * from the other end's link. */
static int spring_ends(loader *ld, const ynode *map, mech_spring *s)
{
    const ynode *btw = ymap_get(map, "between"), *links = ymap_get(map, "links");
    if (!load_want_kind(ld, btw, YNODE_SEQ, "'between'"))
        return 0;
    if (btw->n != 2)
        return load_err(ld, btw, "'between' needs two points, [P, Q]"), 0;
    if (links && !load_want_kind(ld, links, YNODE_SEQ, "'links'"))
        return 0;
    if (links && links->n != 2)
        return load_err(ld, links, "'links' needs two links, [a, b]"), 0;
    int id[2], cand[2][8], n[2];
    for (int k = 0; k < 2; k++) {
        id[k] = load_find_point_or_report(ld, btw->items[k], "spring end");
        n[k] = id[k] < 0 ? -1
                         : load_end_candidates(ld, links, k, id[k], btw->items[k], "spring link",
                                               cand[k], 8);
    }
    if (n[0] <= 0 || n[1] <= 0)
        return 0;
    for (int a = 0; a < n[0]; a++)
        for (int b = 0; b < n[1]; b++)
            if (cand[0][a] != cand[1][b]) {
                s->link[0] = cand[0][a];
                s->link[1] = cand[1][b];
                s->point[0] = load_point_in_link(ld, s->link[0], id[0]);
                s->point[1] = load_point_in_link(ld, s->link[1], id[1]);
                return 1;
            }
    return load_err(ld, btw, "both ends of the spring are on link '%s': its length never "
                    "changes; attach it between two links", ld->m->links[cand[0][0]].name), 0;
}

/* The revolute joint of a torsional spring: its receiving link first. */
static int spring_joint(loader *ld, const ynode *at, mech_spring *s)
{
    const char *name = load_get_name(ld, at, "'at'");
    if (!name)
        return 0;
    int j = find_joint(ld, name);
    if (j < 0 || ld->m->joints[j].kind != MECH_JOINT_REVOLUTE)
        return load_err(ld, at, "'%s' is not a revolute joint: a torsional spring sits at a pin "
                        "(give the joint's name)", name), 0;
    const mech_joint *jt = &ld->m->joints[j];
    s->joint = j;
    s->link[0] = jt->link[0] > jt->link[1] ? jt->link[0] : jt->link[1];
    s->link[1] = jt->link[0] > jt->link[1] ? jt->link[1] : jt->link[0];
    s->point[0] = s->point[1] = -1;
    return 1;
}

/* A coefficient that must not be negative. */
static int get_coefficient(loader *ld, const ynode *n, quantity q, const char *what, double *out)
{
    if (!n)
        return 1;
    if (!load_get_quantity(ld, n, q, what, out))
        return 0;
    if (!(*out >= 0.0))
        return load_err(ld, n, "%s must not be negative", what), 0;
    return 1;
}

static int spring_numbers(loader *ld, const ynode *map, mech_spring *s)
{
    int torsion = s->kind == MECH_SPRING_TORSION;
    const ynode *k = ymap_get(map, "stiffness"), *c = ymap_get(map, "damping"),
                *pre = ymap_get(map, "preload"),
                *fr = ymap_get(map, torsion ? "free_angle" : "free_length");
    const char *free_key = torsion ? "free_angle" : "free_length";
    if (!k && !c)
        return load_err(ld, map, "a spring needs 'stiffness', 'damping' or both"), 0;
    if (k && !fr)
        return load_err(ld, map, "a spring with a stiffness needs '%s'", free_key), 0;
    int ok = get_coefficient(ld, k, torsion ? Q_TORSION_STIFFNESS : Q_FORCE_PER_LENGTH,
                             "stiffness", &s->stiffness);
    ok = get_coefficient(ld, c, torsion ? Q_TORSION_DAMPING : Q_DAMPING, "damping",
                         &s->damping) && ok;
    if (pre)
        ok = load_get_quantity(ld, pre, torsion ? Q_TORQUE : Q_FORCE, "preload", &s->preload) && ok;
    if (fr)
        ok = load_get_quantity(ld, fr, torsion ? Q_ANGLE : Q_LENGTH, free_key, &s->free) && ok;
    if (ok && !torsion && fr && !(s->free >= 0.0))
        ok = 0, load_err(ld, fr, "free_length must not be negative");
    return ok;
}

/* The keys of the other kind are errors at the key. */
static int keys_fit(loader *ld, const ynode *map, int torsion)
{
    static const char *const linear_only[] = {"between", "links", "free_length"};
    static const char *const torsion_only[] = {"at", "free_angle"};
    const char *const *bad = torsion ? linear_only : torsion_only;
    size_t nbad = torsion ? COUNT(linear_only) : COUNT(torsion_only);
    int ok = 1;
    for (size_t i = 0; i < nbad; i++) {
        const ynode *key = load_key_of(map, bad[i]);
        if (key)
            ok = 0, load_err(ld, key, "'%s' does not apply to a %s spring", bad[i],
                             torsion ? "torsional ('at:')" : "linear ('between:')");
    }
    return ok;
}

static char *default_name(const mech_model *m, const mech_spring *s)
{
    char buf[3 * 64 + 16];
    if (s->kind == MECH_SPRING_TORSION)
        snprintf(buf, sizeof buf, "%s_%s", s->stiffness > 0 ? "torsion" : "damper",
                 m->joints[s->joint].name);
    else
        snprintf(buf, sizeof buf, "%s_%s_%s", s->stiffness > 0 ? "spring" : "damper",
                 m->links[s->link[0]].points[s->point[0]].name,
                 m->links[s->link[1]].points[s->point[1]].name);
    return xstrdup(buf);
}

static void load_one_spring(loader *ld, const ynode *map, mech_spring *s, name_map *names)
{
    static const char *const keys[] = {"between", "links", "at", "name", "stiffness",
                                       "free_length", "free_angle", "preload", "damping"};
    if (!load_check_keys(ld, map, keys, COUNT(keys), "a spring"))
        return;
    const ynode *btw = ymap_get(map, "between"), *at = ymap_get(map, "at"),
                *nm = ymap_get(map, "name");
    if ((btw != NULL) == (at != NULL))
        return (void)load_err(ld, map, "a spring is either 'between: [P, Q]' (linear) or "
                              "'at: JOINT' (torsional)");
    memset(s, 0, sizeof *s);
    s->mark = map->mark;
    s->kind = at ? MECH_SPRING_TORSION : MECH_SPRING_LINEAR;
    s->joint = -1;
    if (!keys_fit(ld, map, at != NULL))
        return;
    int ok = at ? spring_joint(ld, at, s) : spring_ends(ld, map, s);
    ok = spring_numbers(ld, map, s) && ok;
    const char *given = nm ? load_get_name(ld, nm, "spring name") : NULL;
    if (!ok || (nm && !given))
        return;
    s->name = given ? xstrdup(given) : default_name(ld->m, s);
    if (!s->name)
        return (void)load_nomem(ld, map);
    if (name_map_get(names, s->name) >= 0) {
        load_err(ld, nm ? nm : map, "a second spring named '%s'%s", s->name,
                 nm ? "" : " (give each a 'name:')");
        free(s->name);
        s->name = NULL;
        return;
    }
    if (name_map_put(names, s->name, ld->m->nsprings) < 0)
        return (void)load_nomem(ld, map);
    ld->m->nsprings++;
}

void load_springs(loader *ld, const ynode *seq)
{
    mech_model *m = ld->m;
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'springs'"))
        return;
    if (seq->n > MAX_SPRINGS)
        return (void)load_err(ld, seq, "too many springs (%zu; at most %d)", seq->n, MAX_SPRINGS);
    m->springs = xcalloc(seq->n + 1, sizeof *m->springs);
    if (!m->springs)
        return (void)load_nomem(ld, seq);
    name_map names = {0};
    for (size_t i = 0; i < seq->n; i++)
        load_one_spring(ld, seq->items[i], &m->springs[m->nsprings], &names);
    name_map_free(&names);
}
