/* src/load/load_motion.c: the loader's 'driver' (its link or slider and its
 * range), 'initial' guesses, 'branch' conditions and listed 'loops'. */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

/* ---- driver, guesses, branches, loops ------------------------------ */

/* A driver angle written as bare numbers (no unit, no parameter that could
 * carry one): radians, which a reader of 'to: 360' rarely means. */
static int bare_angle(const loader *ld, const ynode *n, double value)
{
    if (ld->angle_unit_given || value == 0 || n->kind != YNODE_SCALAR)
        return 0;  /* 0 is 0 in any unit */
    for (const char *s = n->text; *s;) {
        if (isdigit((unsigned char)*s) || *s == '.') {  /* a number: 1.5, 2e-3 */
            while (isdigit((unsigned char)*s) || *s == '.')
                s++;
            if ((*s == 'e' || *s == 'E') &&
                (isdigit((unsigned char)s[1]) ||
                 ((s[1] == '+' || s[1] == '-') && isdigit((unsigned char)s[2]))))
                for (s += 2; isdigit((unsigned char)*s); s++) {}
            continue;
        }
        if (!(isalpha((unsigned char)*s) || *s == '_')) {
            s++;
            continue;
        }
        size_t len = 0;
        while (isalnum((unsigned char)s[len]) || s[len] == '_')
            len++;
        char word[MAX_NAME + 1];
        if (len > MAX_NAME)
            return 0;
        memcpy(word, s, len);
        word[len] = '\0';
        if (unit_is_name(s, len) || name_map_get(&ld->param_map, word) >= 0)
            return 0;
        s += len;
    }
    return 1;
}

/* Warn when bare driver angles (radians) span more than a revolution or
 * step by more than 30 deg: 'to: 360' without 'units: {angle: deg}' is 57
 * revolutions. `big` is the bare value to quote. */
static void warn_radians(loader *ld, const ynode *range, const ynode *big, double span,
                         double step)
{
    const double turn = 6.283185307179586, tol = 1 + 1e-4; /* 2 pi; 6.2832 is one turn */
    if (span <= turn * tol && step <= turn / 12 * tol)
        return;
    diag_warning(ld->d, ld->file, range->mark,
                 "driver angle numbers without a unit are radians: this range spans %.3g "
                 "revolutions in steps of up to %.3g deg; for degrees write 'units: {angle: "
                 "deg}' or '%s deg'", span / turn, step * 360 / turn, big->text);
}

/* The bare-angle check of a list of driver angles. */
static void check_list_radians(loader *ld, const ynode *n, const mech_driver *dr)
{
    const ynode *big = NULL;
    double lo = dr->values[0], hi = lo, step = 0, top = 0;
    for (int i = 0; i < dr->nvalues; i++) {
        const ynode *v = n->kind == YNODE_SCALAR ? n : n->items[i];
        double x = dr->values[i];
        if (bare_angle(ld, v, x) && fabs(x) > top)
            big = v, top = fabs(x);
        lo = fmin(lo, x);
        hi = fmax(hi, x);
        if (i > 0)
            step = fmax(step, fabs(x - dr->values[i - 1]));
    }
    if (big)
        warn_radians(ld, n, big, hi - lo, step);
}

void load_range(loader *ld, const ynode *n, quantity q, mech_driver *dr)
{
    const char *what = q == Q_ANGLE ? "driver angle" : q == Q_TIME ? "sweep time"
                                                                    : "driver displacement";
    if (n->kind == YNODE_SCALAR || n->kind == YNODE_SEQ) {
        size_t count = n->kind == YNODE_SCALAR ? 1 : n->n;
        if (count == 0 || count > MAX_STEPS)
            return (void)load_err(ld, n, "%s list must have 1 to %d values", what, MAX_STEPS);
        dr->values = xcalloc(count, sizeof *dr->values);
        if (!dr->values)
            return (void)load_nomem(ld, n);
        for (size_t i = 0; i < count; i++) {
            const ynode *v = n->kind == YNODE_SCALAR ? n : n->items[i];
            if (load_get_quantity(ld, v, q, what, &dr->values[i]))
                dr->nvalues++;
        }
        if (q == Q_ANGLE && dr->nvalues == (int)count)
            check_list_radians(ld, n, dr);
        return;
    }
    static const char *const keys[] = {"from", "to", "steps"};
    load_check_keys(ld, n, keys, COUNT(keys), what);
    const ynode *from = ymap_get(n, "from"), *to = ymap_get(n, "to"), *steps = ymap_get(n, "steps");
    if (!from || !to || !steps)
        return (void)load_err(ld, n, "%s range is missing '%s' (write {from: ..., to: ..., steps: N})",
                              what, !from ? "from" : !to ? "to" : "steps");
    double a, b;
    long s;
    int ok = load_get_quantity(ld, from, q, what, &a);
    ok = load_get_quantity(ld, to, q, what, &b) && ok;
    ok = load_get_count(ld, steps, "'steps'", 1, MAX_STEPS, &s) && ok;
    if (!ok)
        return;
    if (!isfinite(b - a))  /* from -1e308 to 1e308: the positions would be inf and NaN */
        return (void)load_err(ld, n, "%s range is too wide (from %g to %g)", what, a, b);
    int bare_a = q == Q_ANGLE && bare_angle(ld, from, a);
    int bare_b = q == Q_ANGLE && bare_angle(ld, to, b);
    if (bare_a || bare_b)
        warn_radians(ld, n, bare_b && (!bare_a || fabs(b) >= fabs(a)) ? to : from, fabs(b - a),
                     fabs(b - a) / (double)s);
    dr->values = xcalloc((size_t)s + 1, sizeof *dr->values);
    if (!dr->values)
        return (void)load_nomem(ld, n);
    for (long i = 0; i <= s; i++)  /* s intervals, s + 1 positions, both ends included */
        dr->values[i] = a + (b - a) * (double)i / (double)s;
    dr->nvalues = (int)s + 1;
}

void load_driver(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"link", "slider", "angle", "displacement", "speed",
                                       "acceleration"};
    mech_model *m = ld->m;
    mech_driver *dr = &m->driver;
    const ynode *fk = map && map->kind == YNODE_MAP ? load_key_of(map, "free") : NULL;
    if (fk)
        return (void)load_err(ld, fk, "a free driver is an entry of 'drivers:' with 'sweep: "
                                      "{time: ...}', not 'driver:' (docs/format.md 7.4)");
    if (!load_check_keys(ld, map, keys, COUNT(keys), "driver"))
        return;
    dr->mark = map->mark;
    const ynode *ln = ymap_get(map, "link"), *sn = ymap_get(map, "slider"),
                *ang = ymap_get(map, "angle"), *disp = ymap_get(map, "displacement"),
                *speed = ymap_get(map, "speed"), *acc = ymap_get(map, "acceleration");
    if (!ln && !sn)
        return (void)load_err(ld, map, "the driver needs 'link: NAME' (a link turned through "
                                       "'angle') or 'slider: NAME' (a slider moved through "
                                       "'displacement')");
    if (ln && sn) {
        const ynode *kl = load_key_of(map, "link"), *ks = load_key_of(map, "slider");
        const ynode *second = kl->mark.line > ks->mark.line ||
                              (kl->mark.line == ks->mark.line && kl->mark.col > ks->mark.col)
                                  ? kl : ks;
        return (void)load_err(ld, second, "the driver has both 'link' and 'slider'; give one: "
                                          "'link: NAME' to turn a link or 'slider: NAME' to move a "
                                          "slider");
    }
    quantity pos = ln ? Q_ANGLE : Q_LENGTH;
    if (ln) {
        dr->kind = MECH_DRIVE_ANGLE;
        dr->index = load_find_link_or_report(ld, ln, "driver link");
        if (dr->index == 0)
            return (void)load_err(ld, ln, "the ground is fixed and cannot be the driver; name the "
                                          "link that the motor turns");
        if (disp) {
            load_err(ld, load_key_of(map, "displacement"),
                     "a link driver takes 'angle', not 'displacement' (that is for a slider "
                     "driver)");
            if (!ang)
                return;
        }
        for (int ji = 0; dr->index > 0 && ji < m->njoints; ji++)
            if (m->joints[ji].kind == MECH_JOINT_SLIDER && m->joints[ji].locked &&
                m->joints[ji].link[0] == dr->index)
                return (void)load_err(ld, ln, "link '%s' cannot turn (it is held by locked slider "
                                              "'%s'); drive the slider instead",
                                      m->links[dr->index].name, m->joints[ji].name);
    } else {
        dr->kind = MECH_DRIVE_SLIDER;
        dr->index = load_slider_by_name(ld, sn, "driver slider");
        if (ang) {
            load_err(ld, load_key_of(map, "angle"),
                     "a slider driver takes 'displacement', not 'angle' (that is for a link "
                     "driver)");
            if (!disp)
                return;
        }
    }
    if (dr->index < 0)
        return;
    const ynode *range = ln ? ang : disp;
    if (!range)
        return (void)load_err(ld, map, "the driver has no '%s' (its range)", ln ? "angle" : "displacement");
    load_range(ld, range, pos, dr);
    dr->speed = 1.0;  /* documented default: 1 rad/s or 1 m/s */
    if (speed)
        load_get_quantity(ld, speed, ln ? Q_ANGULAR_SPEED : Q_SPEED, "driver speed", &dr->speed);
    if (acc)
        load_get_quantity(ld, acc, ln ? Q_ANGULAR_ACCELERATION : Q_ACCELERATION, "driver acceleration",
                          &dr->accel);
    m->has_driver = dr->nvalues > 0;
    /* the one driver: its coordinate held to the law q (drivers.c) */
    if (m->has_driver && drivers_add_sweep(m) < 0)
        load_nomem(ld, map);
}

/* A point's guessed position [x, y] (a global length pair), for
 * load_guess.c. */
static void load_point_guess(loader *ld, const ynode *k, const ynode *v, int id)
{
    char what[128];
    snprintf(what, sizeof what, "initial guess for point '%s'", k->text);
    double xy[2];
    if (v->kind != YNODE_SEQ)
        return (void)load_err(ld, v, "%s must be its position [x, y] (global, at the first "
                                     "driver position)", what);
    if (!load_get_vec2(ld, v, Q_LENGTH, what, xy))
        return;
    point_guess *g = xrealloc_array(ld->pguess, (size_t)ld->npguess + 1, sizeof *g);
    if (!g)
        return (void)load_nomem(ld, k);
    ld->pguess = g;
    g[ld->npguess++] = (point_guess){id, {xy[0], xy[1]}, k->mark};
}

void load_initial(loader *ld, const ynode *map)
{
    mech_model *m = ld->m;
    if (!load_check_map(ld, map, NULL, 0, "'initial'", "initial guess for"))
        return;
    m->guesses = xcalloc(map->n, sizeof *m->guesses);
    int *locked_of = load_locked_sliders(m);
    if (!m->guesses || !locked_of) {
        free(locked_of);
        return (void)load_nomem(ld, map);
    }
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = load_get_name(ld, k, "initial guess name");
        if (!name || k->dup_of)
            continue;
        mech_guess *g = &m->guesses[m->nguesses];
        g->mark = k->mark;
        int li = find_link(ld, name), ji = find_joint(ld, name);
        if (li == 0)
            load_err(ld, k, "the ground does not move; it needs no initial guess");
        else if (li > 0 && m->has_driver && m->driver.kind == MECH_DRIVE_ANGLE &&
                 m->driver.index == li)
            load_err(ld, k, "'%s' is the driver; its angle comes from 'driver'", name);
        else if (li > 0) {
            g->index = li;
            if (locked_of[li] >= 0)
                diag_warning(ld->d, ld->file, k->mark, "the initial guess for '%s' has no "
                             "effect: a block on a locked slider turns with its guide", name);
            if (load_get_quantity(ld, v, Q_ANGLE, "initial angle", &g->value))
                m->nguesses++;
        } else if (ji >= 0 && m->joints[ji].kind == MECH_JOINT_SLIDER && m->has_driver &&
                   m->driver.kind == MECH_DRIVE_SLIDER && m->driver.index == ji) {
            load_err(ld, k, "'%s' is the driver; its displacement comes from 'driver'", name);
        } else if (ji >= 0 && m->joints[ji].kind == MECH_JOINT_SLIDER) {
            g->is_slider = 1;
            g->index = ji;
            if (load_get_quantity(ld, v, Q_LENGTH, "initial displacement", &g->value))
                m->nguesses++;
        } else if (li < 0 && find_point(ld, name) >= 0) {
            load_point_guess(ld, k, v, find_point(ld, name));
        } else if (load_errors_full(ld)) {
            load_err(ld, k, "unknown link or slider");
        } else {
            size_t nn = (size_t)m->nlinks + (size_t)m->njoints, c = 0;
            const char **names = xcalloc(nn, sizeof *names);
            for (int j = 1; names && j < m->nlinks; j++)
                names[c++] = m->links[j].name;
            for (int j = 0; names && j < m->njoints; j++)
                if (m->joints[j].kind == MECH_JOINT_SLIDER)
                    names[c++] = m->joints[j].name;
            load_err_unknown(ld, k, "link or slider", "moving links and sliders", name, names, c);
            free(names);
        }
    }
    free(locked_of);
}

/* A branch condition whose turn A -> B -> C can never be strictly ccw or cw:
 * a point named twice, or the three fixed on one link (or the ground) on
 * one line, coincident points included (cross product 0 within 1e-12 of
 * the link's size squared). Reported at the condition; returns 0. */
static int branch_can_turn(loader *ld, const ynode *b, const mech_branch *br)
{
    const mech_model *m = ld->m;
    const int *p = br->point;
    const char *a = m->point_names[p[0]], *bb = m->point_names[p[1]], *c = m->point_names[p[2]];
    int twice = p[0] == p[1] || p[0] == p[2] ? p[0] : p[1] == p[2] ? p[1] : -1;
    if (twice >= 0)
        return load_err(ld, b, "branch condition [%s, %s, %s] names point '%s' twice, so its "
                               "turn is never strictly ccw or cw", a, bb, c,
                        m->point_names[twice]), 0;
    int first, end;
    load_carriers_of(ld, p[0], &first, &end);
    for (int k = first; k < end; k++) {
        int li = ld->carrier_link[k], i1 = load_point_in_link(ld, li, p[1]),
            i2 = load_point_in_link(ld, li, p[2]);
        if (i1 < 0 || i2 < 0 || ld->link_failed[li])
            continue;
        const mech_link *l = &m->links[li];
        const mech_point *q0 = &l->points[ld->carrier_point[k]], *q1 = &l->points[i1],
                         *q2 = &l->points[i2];
        double ux = q1->x - q0->x, uy = q1->y - q0->y, vx = q2->x - q1->x, vy = q2->y - q1->y;
        double size = fmax(fmax(fabs(ux), fabs(uy)), fmax(fabs(vx), fabs(vy)));
        if (fabs(ux * vy - uy * vx) <= 1e-12 * size * size)  /* (B - A) x (C - B) */
            return load_err(ld, b, "branch condition [%s, %s, %s]: the three points are fixed "
                                   "on one line on link '%s', so the turn is never strictly ccw "
                                   "or cw", a, bb, c, l->name), 0;
    }
    return 1;
}

/* A side condition whose points never differ strictly in the direction
 * asked: one point named twice, the two at one place on a link, or both on
 * the ground on the wrong side (or level). Reported; returns 0. */
static int branch_can_side(loader *ld, const ynode *b, const mech_branch *br, const char *word)
{
    const mech_model *m = ld->m;
    const char *a = m->point_names[br->point[0]], *c = m->point_names[br->point[1]];
    if (br->point[0] == br->point[1])
        return load_err(ld, b, "branch condition '%s %s %s' names one point twice, so it never "
                               "holds", a, word, c), 0;
    int first, end;
    load_carriers_of(ld, br->point[0], &first, &end);
    for (int k = first; k < end; k++) {
        int li = ld->carrier_link[k], i1 = load_point_in_link(ld, li, br->point[1]);
        if (i1 < 0 || ld->link_failed[li])
            continue;
        const mech_link *l = &m->links[li];
        const mech_point *p0 = &l->points[ld->carrier_point[k]], *p1 = &l->points[i1];
        double dx = p0->x - p1->x, dy = p0->y - p1->y, size = fmax(fabs(p0->x), fabs(p0->y));
        double size1 = fmax(fmax(fabs(p1->x), fabs(p1->y)), size);
        double d = br->kind == MECH_BRANCH_X ? dx : dy;
        if (fabs(dx) <= 1e-12 * size1 && fabs(dy) <= 1e-12 * size1)
            return load_err(ld, b, "branch condition '%s %s %s': the two points are at one "
                                   "place on link '%s', so it never holds", a, word, c,
                            l->name), 0;
        if (l->is_ground && !(d * br->sign > 1e-12 * size1))
            return load_err(ld, b, "branch condition '%s %s %s': both points are fixed on the "
                                   "ground, and %s is not %s %s", a, word, c, a, word, c), 0;
    }
    return 1;
}

/* {points: [A, B, C], turn: ccw|cw} */
static int branch_turn(loader *ld, const ynode *b, const ynode *pts, mech_branch *br)
{
    const ynode *turn = ymap_get(b, "turn");
    if (!turn)
        return load_err(ld, b, "a branch condition with 'points' needs 'turn: ccw' or 'cw'"), 0;
    if (pts->kind != YNODE_SEQ || pts->n != 3)
        return load_err(ld, pts, "'points' of a branch condition must list three points"), 0;
    int ok = 1;
    for (int k = 0; k < 3; k++)
        ok = (br->point[k] = load_find_point_or_report(ld, pts->items[k], "branch point")) >= 0
             && ok;
    if (turn->kind == YNODE_SCALAR && strcmp(turn->text, "ccw") == 0)
        br->sign = 1;
    else if (turn->kind == YNODE_SCALAR && strcmp(turn->text, "cw") == 0)
        br->sign = -1;
    else
        ok = 0, load_err(ld, turn, "'turn' must be 'ccw' (counter-clockwise) or 'cw' (clockwise)");
    return ok && branch_can_turn(ld, b, br);
}

/* {point: D, right_of|left_of|above|below: C} */
static int branch_side(loader *ld, const ynode *b, const ynode *pt, mech_branch *br)
{
    static const char *const words[] = {"right_of", "left_of", "above", "below"};
    const ynode *other = NULL;
    int w = -1;
    for (int k = 0; k < 4; k++)
        if (ymap_get(b, words[k])) {
            if (other)
                return load_err(ld, b, "a branch condition gives one of right_of, left_of, "
                                       "above, below"), 0;
            other = ymap_get(b, words[k]), w = k;
        }
    if (!other)
        return load_err(ld, b, "a branch condition with 'point' needs 'right_of', 'left_of', "
                               "'above' or 'below' another point"), 0;
    br->kind = w < 2 ? MECH_BRANCH_X : MECH_BRANCH_Y;
    br->sign = w % 2 == 0 ? 1 : -1;
    int ok = (br->point[0] = load_find_point_or_report(ld, pt, "branch point")) >= 0;
    ok = (br->point[1] = load_find_point_or_report(ld, other, "branch point")) >= 0 && ok;
    br->point[2] = br->point[1];
    static const char *const shown[] = {"right of", "left of", "above", "below"};
    return ok && branch_can_side(ld, b, br, shown[w]);
}

/* {slider: S, sign: positive|negative} */
static int branch_slider(loader *ld, const ynode *b, const ynode *sl, mech_branch *br)
{
    const ynode *sign = ymap_get(b, "sign");
    br->kind = MECH_BRANCH_SLIDER;
    br->point[0] = br->point[1] = br->point[2] = -1;
    int ok = (br->slider = load_slider_by_name(ld, sl, "branch slider")) >= 0;
    if (sign && sign->kind == YNODE_SCALAR && strcmp(sign->text, "positive") == 0)
        br->sign = 1;
    else if (sign && sign->kind == YNODE_SCALAR && strcmp(sign->text, "negative") == 0)
        br->sign = -1;
    else
        ok = 0, load_err(ld, sign ? sign : b, "a slider branch condition needs 'sign: positive' "
                                              "or 'negative'");
    return ok;
}

void load_branches(loader *ld, const ynode *seq)
{
    mech_model *m = ld->m;
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'branch'"))
        return;
    if (seq->n > MAX_LIST)
        return (void)load_err(ld, seq, "too many branch conditions (%zu; at most %d)", seq->n,
                              MAX_LIST);
    m->branches = xcalloc(seq->n, sizeof *m->branches);
    if (!m->branches)
        return (void)load_nomem(ld, seq);
    for (size_t i = 0; i < seq->n; i++) {
        static const char *const keys[] = {"points", "turn", "point", "right_of", "left_of",
                                           "above", "below", "slider", "sign", "first_only"};
        const ynode *b = seq->items[i];
        if (!load_check_keys(ld, b, keys, COUNT(keys), "a branch condition"))
            continue;
        const ynode *pts = ymap_get(b, "points"), *pt = ymap_get(b, "point"),
                    *sl = ymap_get(b, "slider"), *fo = ymap_get(b, "first_only");
        mech_branch *br = &m->branches[m->nbranches];
        memset(br, 0, sizeof *br);
        br->mark = b->mark;
        br->slider = -1;
        int ok = 0;
        if ((pts != NULL) + (pt != NULL) + (sl != NULL) != 1)
            load_err(ld, b, "a branch condition is one of {points: [A, B, C], turn: ccw|cw}, "
                            "{point: D, right_of|left_of|above|below: C}, {slider: S, sign: "
                            "positive|negative}");
        else
            ok = pts ? branch_turn(ld, b, pts, br)
                 : pt ? branch_side(ld, b, pt, br) : branch_slider(ld, b, sl, br);
        if (ok && fo && !load_get_bool(ld, fo, "'first_only'", &br->first_only))
            ok = 0;
        if (ok)
            m->nbranches++;
    }
}

/* A loop written as a string: "A B D A", "A-B-D-A" or, when every point name
 * is one character, "ABDA". Splits into a fresh array of names. */
static int split_loop_string(loader *ld, const ynode *n, char ***out, int *count)
{
    const char *s = n->text;
    int spaced = strpbrk(s, " -,") != NULL;
    size_t cap = strlen(s) + 1;
    char **names = xcalloc(cap, sizeof *names);
    if (!names)
        return 0;
    int c = 0;
    while (*s) {
        if (*s == ' ' || *s == '-' || *s == ',') {
            s++;
            continue;
        }
        size_t len = spaced ? strcspn(s, " -,") : 1;
        names[c] = malloc(len + 1);
        if (!names[c])
            break;
        memcpy(names[c], s, len);
        names[c++][len] = '\0';
        s += len;
    }
    (void)ld;
    *out = names;
    *count = c;
    return 1;
}

static void load_loop(loader *ld, const ynode *n, mech_loop *lp)
{
    mech_model *m = ld->m;
    char **names = NULL;
    int count = 0, ok = 1;
    if (n->kind == YNODE_SCALAR) {
        if (!split_loop_string(ld, n, &names, &count))
            return (void)load_nomem(ld, n);
    } else if (n->kind != YNODE_SEQ) {
        return (void)load_err(ld, n, "a loop must be a list of point names [A, B, C, A] or a "
                                     "string \"A B C A\"");
    }
    int len = n->kind == YNODE_SCALAR ? count : (int)n->n;
    if (len > MAX_LOOP_POINTS) {
        for (int i = 0; i < count; i++)
            free(names[i]);
        free(names);
        return (void)load_err(ld, n, "loop too long (%d points; at most %d)", len, MAX_LOOP_POINTS);
    }
    lp->points = xcalloc((size_t)len, sizeof *lp->points);
    lp->marks = xcalloc((size_t)len, sizeof *lp->marks);
    lp->mark = n->mark;
    for (int i = 0; lp->points && lp->marks && i < len; i++) {
        const ynode *item = n->kind == YNODE_SEQ ? n->items[i] : n;
        const char *name = n->kind == YNODE_SEQ ? load_get_name(ld, item, "loop point") : names[i];
        lp->marks[i] = item->mark;
        int id = name ? find_point(ld, name) : -1;
        if (name && id < 0 && !ld->links_bad && !ld->points_bad)
            load_err_unknown(ld, item, "point", "points", name, (const char *const *)m->point_names,
                             (size_t)m->npoint_names);
        ok = ok && id >= 0;
        lp->points[i] = id;
    }
    lp->npoints = len;
    for (int i = 0; i < count; i++)
        free(names[i]);
    free(names);
    if (!ok || !lp->points)
        return;
    if (len < 4)
        load_err(ld, n, "a loop must visit at least three points and return to the first "
                        "(e.g. [A, B, C, A])");
    else if (lp->points[0] != lp->points[len - 1])
        diag_error(ld->d, ld->file, lp->marks[len - 1],
                   "loop does not close: it starts at '%s' but ends at '%s' (end it with '%s')",
                   m->point_names[lp->points[0]], m->point_names[lp->points[len - 1]],
                   m->point_names[lp->points[0]]);
}

void load_loops(loader *ld, const ynode *seq)
{
    mech_model *m = ld->m;
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'loops'"))
        return;
    if (seq->n > MAX_LOOPS)
        return (void)load_err(ld, seq, "too many loops listed (%zu; at most %d); leave 'loops' out "
                                       "and they are found automatically", seq->n, MAX_LOOPS);
    m->loops = xcalloc(seq->n, sizeof *m->loops);
    if (!m->loops)
        return (void)load_nomem(ld, seq);
    for (size_t i = 0; i < seq->n; i++)
        load_loop(ld, seq->items[i], &m->loops[m->nloops++]);
}

