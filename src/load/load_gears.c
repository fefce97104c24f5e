/* src/load/load_gears.c: the loader's 'gears' (gear pairs, external or internal,
 * on the ground or on a moving arm; racks and pinions), checked with
 * file:line:column (docs/format.md, section "Gears").
 *
 *   gears:
 *     - {name, gear: A, with: B, teeth: [za, zb], module, radii: [ra, rb],
 *        internal, arm, pressure_angle, offset: [oa, ob]}
 *     - {name, pinion: P, rack: SLIDER, radius | teeth + module, pressure_angle,
 *        offset, rack_offset}
 *
 * The pitch radii come from 'radii', or from 'teeth' and 'module' (r = m z / 2),
 * or from 'teeth' alone and the centre distance of the pivots. The centre
 * distance must be ra + rb (external) or |ra - rb| (internal), the rack's
 * line must be the pinion's pitch radius from its centre. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

enum { MAX_GEARS = 100000 };

static const double PI = 3.14159265358979323846;

int load_find_pivot(const loader *ld, int g, int c, int *pg, int *pc)
{
    const mech_model *m = ld->m;
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (jt->kind != MECH_JOINT_REVOLUTE)
            continue;
        for (int side = 0; side < 2; side++)
            if (jt->link[side] == g && jt->link[1 - side] == c) {
                *pg = jt->point[side];
                *pc = jt->point[1 - side];
                return 1;
            }
    }
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (jt->kind != MECH_JOINT_REVOLUTE)
            continue;
        for (int side = 0; side < 2; side++) {
            if (jt->link[side] != g)
                continue;
            int id = m->links[g].points[jt->point[side]].id;
            int k = load_point_in_link(ld, c, id);
            if (k >= 0) {
                *pg = jt->point[side];
                *pc = k;
                return 1;
            }
        }
    }
    return 0;
}

/* Gear g's number k (PXN_GEAR: radius[0], radius[1], offset[0], offset[1])
 * has handle h in the parameter expressions. */
static void gear_expr(loader *ld, const mech_gear *g, int k, int h)
{
    if (ld->m->pexpr)
        pexpr_set(ld->m->pexpr, PXN_GEAR, 4 * (int)(g - ld->m->gears) + k, h);
}

/* The pitch radius 0.5 * mod * z of a gear with z teeth. */
static pxq pitch_radius(loader *ld, pxq mod, int z)
{
    pxq half = load_expr(ld, PX_SCALE, 0.5, mod, pxq_fixed(0), pxq_fixed(0), 0.5 * mod.v);
    return load_expr(ld, PX_SCALE, (double)z, half, pxq_fixed(0), pxq_fixed(0),
                     0.5 * mod.v * z);
}

/* Length in mm for messages. */
static double mm(double x) { return x * 1e3; }

static int get_pair_of_counts(loader *ld, const ynode *n, const char *what, int out[2])
{
    if (!load_want_kind(ld, n, YNODE_SEQ, what))
        return 0;
    if (n->n != 2)
        return load_err(ld, n, "%s needs two tooth counts, [z_gear, z_with]", what), 0;
    for (int k = 0; k < 2; k++) {
        long z;
        if (!load_get_count(ld, n->items[k], "a tooth count", 1, 100000, &z))
            return 0;
        out[k] = (int)z;
    }
    return 1;
}

/* The pressure angle (default 20 deg). */
static int get_pressure_angle(loader *ld, const ynode *map, mech_gear *g)
{
    const ynode *pa = ymap_get(map, "pressure_angle");
    g->pressure_angle = 20.0 * PI / 180.0;
    if (!pa)
        return 1;
    if (!load_get_quantity(ld, pa, Q_ANGLE, "pressure_angle", &g->pressure_angle))
        return 0;
    if (!(g->pressure_angle >= 0.0 && g->pressure_angle < 45.0 * PI / 180.0))
        return load_err(ld, pa, "pressure_angle must be at least 0 deg and less than 45 deg"), 0;
    return 1;
}

/* The arm both gears of a pair turn on: 'arm', or the ground. */
static int pair_arm(loader *ld, const ynode *map, mech_gear *g)
{
    const ynode *arm = ymap_get(map, "arm");
    g->arm = arm ? load_find_link_or_report(ld, arm, "'arm'") : 0;
    if (g->arm < 0)
        return 0;
    const ynode *where = arm ? arm : map;
    for (int k = 0; k < 2; k++) {
        if (g->link[k] == g->arm)
            return load_err(ld, where, "gear '%s' is the arm '%s' itself: a gear turns on its "
                            "arm", ld->m->links[g->link[k]].name, ld->m->links[g->arm].name), 0;
        if (!load_find_pivot(ld, g->link[k], g->arm, &g->pivot[k], &g->arm_pivot[k]))
            return load_err(ld, where, "gear '%s' has no pivot on %s '%s' (no revolute joint "
                            "joins them)%s", ld->m->links[g->link[k]].name,
                            arm ? "the arm" : "the", ld->m->links[g->arm].name,
                            arm ? "" : "; give the link both gears turn on as 'arm:'"), 0;
    }
    return 1;
}

/* Pitch radii of a pair from 'radii', 'teeth' and 'module', or 'teeth' and
 * the centre distance d; then the centre distance checked. */
static int pair_radii(loader *ld, const ynode *map, mech_gear *g, pxq d)
{
    const ynode *radii = ymap_get(map, "radii"), *teeth = ymap_get(map, "teeth"),
                *module = ymap_get(map, "module");
    if (!radii && !teeth)
        return load_err(ld, map, "a gear pair needs 'teeth: [z_gear, z_with]' (with an optional "
                        "'module') or 'radii: [r_gear, r_with]'"), 0;
    if (radii && (teeth || module))
        return load_err(ld, radii, "give either 'radii' or 'teeth' (and 'module'), not both"), 0;
    if (module && !teeth)
        return load_err(ld, module, "'module' needs 'teeth'"), 0;
    pxq mod = pxq_fixed(0.0);
    int hr[2] = {PX_FIXED, PX_FIXED};
    if (radii) {
        if (!load_get_vec2_expr(ld, radii, Q_LENGTH, "'radii'", g->radius, hr))
            return 0;
        if (!(g->radius[0] > 0.0 && g->radius[1] > 0.0))
            return load_err(ld, radii, "pitch radii must be positive"), 0;
    } else {
        if (!get_pair_of_counts(ld, teeth, "'teeth'", g->teeth))
            return 0;
        if (module && !load_get_quantity_expr(ld, module, Q_LENGTH, "module", &mod.v, &mod.h))
            return 0;
        if (module && !(mod.v > 0.0))
            return load_err(ld, module, "module must be positive"), 0;
    }
    if (g->internal && (radii ? g->radius[0] == g->radius[1] : g->teeth[0] == g->teeth[1]))
        return load_err(ld, radii ? radii : teeth, "an internal pair needs a ring larger than "
                        "its pinion (equal sizes cannot mesh inside each other)"), 0;
    if (teeth && !module) {  /* the module from the centre distance */
        int zs = g->internal ? abs(g->teeth[0] - g->teeth[1]) : g->teeth[0] + g->teeth[1];
        pxq twice = load_expr(ld, PX_SCALE, 2.0, d, pxq_fixed(0), pxq_fixed(0), 2.0 * d.v);
        mod = load_expr(ld, PX_DIV, 0.0, twice, pxq_fixed((double)zs), pxq_fixed(0),
                        2.0 * d.v / zs);
        if (!(mod.v > 0.0))
            return load_err(ld, teeth, "the pivots of the pair coincide: no module fits "
                            "(give 'module' or move a pivot)"), 0;
    }
    for (int k = 0; k < 2 && teeth; k++) {
        pxq r = pitch_radius(ld, mod, g->teeth[k]);
        g->radius[k] = r.v;
        hr[k] = r.h;
    }
    gear_expr(ld, g, 0, hr[0]);
    gear_expr(ld, g, 1, hr[1]);
    double want = g->internal ? fabs(g->radius[0] - g->radius[1]) : g->radius[0] + g->radius[1];
    if (fabs(d.v - want) > 1e-6 * (g->radius[0] + g->radius[1]))
        return load_err(ld, radii ? radii : teeth,
                        "the pivots of gears '%s' and '%s' are %.6g mm apart on '%s', but %s "
                        "gears of pitch radii %.6g mm and %.6g mm need a centre distance of "
                        "%.6g mm", ld->m->links[g->link[0]].name, ld->m->links[g->link[1]].name,
                        mm(d.v), ld->m->links[g->arm].name,
                        g->internal ? "internal" : "external", mm(g->radius[0]),
                        mm(g->radius[1]), mm(want)), 0;
    return 1;
}

/* The distance of the pair's pivots on the arm. */
static pxq centre_distance(loader *ld, const mech_gear *g)
{
    const mech_link *arm = &ld->m->links[g->arm];
    pxq c[2][2];  /* the pivots' x and y */
    for (int k = 0; k < 2; k++)
        for (int i = 0; i < 2; i++) {
            const mech_point *p = &arm->points[g->arm_pivot[k]];
            c[k][i] = (pxq){i ? p->y : p->x, pexpr_point(ld->m->pexpr, g->arm, g->arm_pivot[k], i)};
        }
    pxq dx = load_expr(ld, PX_SUB, 0.0, c[1][0], c[0][0], pxq_fixed(0), c[1][0].v - c[0][0].v);
    pxq dy = load_expr(ld, PX_SUB, 0.0, c[1][1], c[0][1], pxq_fixed(0), c[1][1].v - c[0][1].v);
    return load_expr(ld, PX_HYPOT, 0.0, dx, dy, pxq_fixed(0), hypot(dx.v, dy.v));
}

static int load_pair(loader *ld, const ynode *map, mech_gear *g)
{
    mech_model *m = ld->m;
    const ynode *a = ymap_get(map, "gear"), *b = ymap_get(map, "with"),
                *in = ymap_get(map, "internal"), *off = ymap_get(map, "offset");
    if (!a || !b)
        return load_err(ld, map, "a gear pair needs 'gear' and 'with' (the two links that "
                        "mesh)"), 0;
    g->kind = MECH_GEAR_PAIR;
    g->rack = -1;
    g->link[0] = load_find_link_or_report(ld, a, "'gear'");
    g->link[1] = load_find_link_or_report(ld, b, "'with'");
    if (g->link[0] < 0 || g->link[1] < 0)
        return 0;
    if (g->link[0] == g->link[1])
        return load_err(ld, b, "gear '%s' cannot mesh with itself", m->links[g->link[0]].name), 0;
    if (in && !load_get_bool(ld, in, "'internal'", &g->internal))
        return 0;
    int ho[2];
    if (off && !load_get_vec2_expr(ld, off, Q_ANGLE, "'offset'", g->offset, ho))
        return 0;
    for (int k = 0; k < 2 && off; k++)
        gear_expr(ld, g, 2 + k, ho[k]);
    if (!get_pressure_angle(ld, map, g) || !pair_arm(ld, map, g))
        return 0;
    return pair_radii(ld, map, g, centre_distance(ld, g));
}

static int load_rack(loader *ld, const ynode *map, mech_gear *g)
{
    mech_model *m = ld->m;
    const ynode *p = ymap_get(map, "pinion"), *r = ymap_get(map, "rack"),
                *rad = ymap_get(map, "radius"), *teeth = ymap_get(map, "teeth"),
                *module = ymap_get(map, "module"), *arm = ymap_get(map, "arm"),
                *off = ymap_get(map, "offset"), *roff = ymap_get(map, "rack_offset");
    if (!r)
        return load_err(ld, map, "a rack and pinion needs 'rack' (a slider joint)"), 0;
    g->kind = MECH_GEAR_RACK;
    g->link[0] = load_find_link_or_report(ld, p, "'pinion'");
    g->rack = load_slider_by_name(ld, r, "'rack'");
    if (g->link[0] < 0 || g->rack < 0)
        return 0;
    const mech_joint *jt = &m->joints[g->rack];
    if (!jt->locked)
        return load_err(ld, r, "the rack slider '%s' is a pin in a slot: a rack must translate "
                        "(a locked slider)", jt->name), 0;
    g->link[1] = jt->link[0];
    g->arm = jt->link[1];
    if (arm) {
        int c = load_find_link_or_report(ld, arm, "'arm'");
        if (c < 0)
            return 0;
        if (c != g->arm)
            return load_err(ld, arm, "the pinion must turn on the rack's guide '%s', not on "
                            "'%s'", m->links[g->arm].name, m->links[c].name), 0;
    }
    if (g->link[0] == g->link[1] || g->link[0] == g->arm)
        return load_err(ld, p, "the pinion '%s' is the rack's own %s", m->links[g->link[0]].name,
                        g->link[0] == g->arm ? "guide" : "link"), 0;
    if (!load_find_pivot(ld, g->link[0], g->arm, &g->pivot[0], &g->arm_pivot[0]))
        return load_err(ld, p, "pinion '%s' has no pivot on the rack's guide '%s' (no revolute "
                        "joint joins them)", m->links[g->link[0]].name, m->links[g->arm].name), 0;
    g->pivot[1] = g->arm_pivot[1] = -1;
    if (!get_pressure_angle(ld, map, g))
        return 0;
    int hq;
    if (off && !load_get_quantity_expr(ld, off, Q_ANGLE, "'offset'", &g->offset[0], &hq))
        return 0;
    if (off)
        gear_expr(ld, g, 2, hq);
    if (roff && !load_get_quantity_expr(ld, roff, Q_LENGTH, "'rack_offset'", &g->offset[1], &hq))
        return 0;
    if (roff)
        gear_expr(ld, g, 3, hq);
    if (!rad && !teeth)
        return load_err(ld, map, "a rack and pinion needs 'radius' (the pinion's pitch radius) "
                        "or 'teeth' and 'module'"), 0;
    if (rad && (teeth || module))
        return load_err(ld, rad, "give either 'radius' or 'teeth' and 'module', not both"), 0;
    if (rad && !load_get_quantity_expr(ld, rad, Q_LENGTH, "radius", &g->radius[0], &hq))
        return 0;
    if (rad)
        gear_expr(ld, g, 0, hq);
    if (teeth) {
        long z;
        pxq mod;
        if (!module)
            return load_err(ld, teeth, "a pinion's 'teeth' needs a 'module'"), 0;
        if (!load_get_count(ld, teeth, "'teeth'", 1, 100000, &z) ||
            !load_get_quantity_expr(ld, module, Q_LENGTH, "module", &mod.v, &mod.h))
            return 0;
        g->teeth[0] = (int)z;
        pxq pitch = pitch_radius(ld, mod, g->teeth[0]);
        g->radius[0] = pitch.v;
        gear_expr(ld, g, 0, pitch.h);
    }
    if (!(g->radius[0] > 0.0))
        return load_err(ld, rad ? rad : module, "the pitch radius must be positive"), 0;
    /* the side of the rack's line (the slider's line through its guide
       point) the pinion's centre is on, and its distance */
    const mech_link *gl = &m->links[g->arm];
    const mech_point *c = &gl->points[g->arm_pivot[0]], *t = &gl->points[jt->point[1]];
    double h = cos(jt->angle) * (c->y - t->y) - sin(jt->angle) * (c->x - t->x);
    if (fabs(fabs(h) - g->radius[0]) > 1e-6 * g->radius[0])
        return load_err(ld, rad ? rad : teeth, "the pinion's centre %s is %.6g mm from the "
                        "rack's pitch line (the line of slider '%s'), but its pitch radius is "
                        "%.6g mm", c->name, mm(fabs(h)), jt->name, mm(g->radius[0])), 0;
    g->side = h > 0.0 ? 1 : -1;
    return 1;
}

static void load_one_gear(loader *ld, const ynode *map, mech_gear *g, name_map *names)
{
    static const char *const keys[] = {"name", "gear", "with", "teeth", "module", "radii",
                                       "internal", "arm", "pressure_angle", "offset",
                                       "pinion", "rack", "radius", "rack_offset"};
    static const char *const pair_only[] = {"gear", "with", "radii", "internal"};
    static const char *const rack_only[] = {"pinion", "rack", "radius", "rack_offset"};
    if (!load_want_kind(ld, map, YNODE_MAP, "a gear pair") ||
        !load_check_keys(ld, map, keys, COUNT(keys), "a gear pair"))
        return;
    memset(g, 0, sizeof *g);
    g->mark = map->mark;
    int rack = ymap_get(map, "pinion") != NULL;
    const char *const *bad = rack ? pair_only : rack_only;
    size_t nbad = rack ? COUNT(pair_only) : COUNT(rack_only);
    for (size_t i = 0; i < nbad; i++) {
        const ynode *key = load_key_of(map, bad[i]);
        if (key)
            return (void)load_err(ld, key, "'%s' does not apply to a %s", bad[i],
                                  rack ? "rack and pinion ('pinion:')" : "gear pair ('gear:')");
    }
    int ok = rack ? load_rack(ld, map, g) : load_pair(ld, map, g);
    for (int k = 0; k < 2 && !ok; k++)  /* no echo: "link 'g1' has 1 point" */
        if (g->link[k] > 0 && g->link[k] < ld->m->nlinks)
            ld->link_failed[g->link[k]] |= LINK_FAILED;
    const ynode *nm = ymap_get(map, "name");
    const char *given = nm ? load_get_name(ld, nm, "gear name") : NULL;
    if (!ok || (nm && !given))
        return;
    char buf[2 * MAX_NAME + 16];
    if (!given)
        snprintf(buf, sizeof buf, "%s_%s", ld->m->links[g->link[0]].name,
                 rack ? ld->m->joints[g->rack].name : ld->m->links[g->link[1]].name);
    g->name = xstrdup(given ? given : buf);
    if (!g->name)
        return (void)load_nomem(ld, map);
    if (name_map_get(names, g->name) >= 0) {
        load_err(ld, nm ? nm : map, "a second gear pair named '%s'%s", g->name,
                 nm ? "" : " (give each a 'name:')");
        free(g->name);
        g->name = NULL;
        return;
    }
    if (name_map_put(names, g->name, ld->m->ngears) < 0) {
        free(g->name);  /* not counted in ngears: freed here, not with the model */
        g->name = NULL;
        return (void)load_nomem(ld, map);
    }
    ld->m->ngears++;
}

void load_gears(loader *ld, const ynode *seq)
{
    mech_model *m = ld->m;
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'gears'"))
        return;
    if (seq->n > MAX_GEARS)
        return (void)load_err(ld, seq, "too many gear pairs (%zu; at most %d)", seq->n, MAX_GEARS);
    m->gears = xcalloc(seq->n + 1, sizeof *m->gears);
    if (!m->gears)
        return (void)load_nomem(ld, seq);
    name_map names = {0};
    for (size_t i = 0; i < seq->n; i++)
        load_one_gear(ld, seq->items[i], &m->gears[m->ngears], &names);
    name_map_free(&names);
}
