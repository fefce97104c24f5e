/* src/load/load_programs.c: a driver's `program:` (docs/format.md 7.3,
 * docs/motion-programs.md): its variable (`of`, a law of t), its segments
 * (dwell, rise, return with a standard law or a user's f(u)), and the
 * checks at load: the segments cover the period, and s, s', s'' meet at
 * every boundary (as far as `continuity` asks). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

/* the file's unit of quantity q: its text and SI per unit */
static double unit_of(const loader *ld, quantity q, char *buf, size_t size)
{
    return file_units_of(ld->m->units, quantity_get(q)->d, buf, size);
}

/* Report `msg` of a law's text at node n (its column when on one line). */
static void law_error(loader *ld, const ynode *n, size_t pos, const char *who, const char *msg)
{
    mech_mark at = n->mark;
    if (!strchr(n->text, '\n'))
        at.col += (int)pos + (n->quoted ? 1 : 0);
    diag_error(ld->d, ld->file, at, "%s: %s", who, msg);
}

/* A user's law f(u) of a segment: 1, or 0 reported. */
static int user_law(loader *ld, const ynode *n, const char *who, prog_segment *sg)
{
    char msg[256];
    size_t pos = 0;
    quantity none = Q_NUMBER;
    struct mech_law *ul = law_new('u');
    if (!(sg->user_law = ul))
        return load_nomem(ld, n), 0;
    int rc = law_parse_into(n->text, &none, 1, &ld->env, ul, NULL, msg, sizeof msg, &pos);
    if (rc == MECH_ENOMEM)
        return load_nomem(ld, n), 0;
    if (rc < 0) {
        char full[400];
        snprintf(full, sizeof full, "law '%s' is no standard law (cycloidal, harmonic, 3-4-5, "
                 "4-5-6-7, modified-trapezoid, modified-sine) and no expression of u: %s",
                 n->text, msg);
        law_error(ld, n, pos, who, full);
        return 0;
    }
    if (ul->n > PROG_USER_MAX_NODES)
        return load_err(ld, n, "a segment's law has at most %d operations",
                        PROG_USER_MAX_NODES), 0;
    sg->user = (rt_law){ul->nodes, ul->n, ul->root, NULL};  /* the view rt_law.h reads */
    double d[3], buf[4 * PROG_USER_MAX_NODES];
    for (int end = 0; end <= 1; end++) {
        double f = law_eval3(ul, end, buf, d);
        if (!(fabs(f - end) <= 1e-9))
            return load_err(ld, n, "%s: a segment's law f(u) must go from f(0) = 0 to "
                            "f(1) = 1 (the lift scales it); f(%d) = %.10g", who, end, f), 0;
    }
    return 1;
}

static const char *kind_name(prog_kind k)
{
    return k == PROG_RISE ? "rise" : k == PROG_RETURN ? "return" : "dwell";
}

/* One segment {rise: H, over: B, law: L} / {return: ...} / {dwell: B}. */
static int load_segment(loader *ld, const ynode *e, quantity q, quantity xq, const char *who,
                        prog_segment *sg)
{
    static const char *const keys[] = {"rise", "return", "dwell", "over", "law"};
    if (!load_want_kind(ld, e, YNODE_MAP, "a program segment") ||
        !load_check_keys(ld, e, keys, COUNT(keys), "segment"))
        return 0;
    const ynode *ri = ymap_get(e, "rise"), *re = ymap_get(e, "return"),
                *dw = ymap_get(e, "dwell"), *ov = ymap_get(e, "over"), *lw = ymap_get(e, "law");
    sg->line = e->mark.line, sg->col = e->mark.col;
    if ((ri != NULL) + (re != NULL) + (dw != NULL) != 1)
        return load_err(ld, e, "a segment is one of {rise: LIFT, over: SPAN, law: LAW}, "
                               "{return: LIFT, over: SPAN, law: LAW}, {dwell: SPAN}"), 0;
    sg->kind = ri ? PROG_RISE : re ? PROG_RETURN : PROG_DWELL;
    if (dw) {
        if (ov || lw)
            return load_err(ld, load_key_of(e, ov ? "over" : "law"), "a dwell takes its span "
                            "alone: {dwell: SPAN}"), 0;
        sg->shape = SHAPE_NONE;
        if (!load_get_quantity(ld, dw, xq, "a dwell's span", &sg->span))
            return 0;
    } else {
        if (!ov || !lw)
            return load_err(ld, e, "a %s needs 'over: SPAN' and 'law: LAW' (cycloidal, "
                            "harmonic, 3-4-5, 4-5-6-7, modified-trapezoid, modified-sine, or "
                            "an expression of u in [0, 1])", kind_name(sg->kind)), 0;
        double h;
        if (!load_get_quantity(ld, ri ? ri : re, q, "a lift", &h) ||
            !load_get_quantity(ld, ov, xq, "a span", &sg->span))
            return 0;
        if (!(h > 0)) {
            char su[24];
            double ss = unit_of(ld, q, su, sizeof su);
            return load_err(ld, ri ? ri : re, "%s: a lift must be positive (a %s of "
                            "%.10g %s goes the other way: write '%s')", who, kind_name(sg->kind),
                            h / ss, su, ri ? "return" : "rise"), 0;
        }
        sg->lift = sg->kind == PROG_RISE ? h : -h;
        if (!load_want_kind(ld, lw, YNODE_SCALAR, "a segment's law"))
            return 0;
        sg->shape = prog_shape_by_name(lw->text);
        if (sg->shape == SHAPE_NONE) {
            sg->shape = SHAPE_USER;
            if (!user_law(ld, lw, who, sg))
                return 0;
        }
        prog_shape_init(sg);
    }
    if (!(sg->span > 0) || !isfinite(sg->span))
        return load_err(ld, dw ? dw : ov, "a span must be positive"), 0;
    return 1;
}

/* s, s', s'' at the start (end 0) or the end (end 1) of segment sg */
static void seg_ends(const prog_segment *sg, int end, double v[3])
{
    double f[4];
    prog_shape_eval(sg, end, f);
    v[0] = sg->s0 + sg->lift * f[0];
    v[1] = sg->lift * f[1] / sg->span;
    v[2] = sg->lift * f[2] / (sg->span * sg->span);
}

static void seg_label(const mech_program *p, int i, char *buf, size_t size)
{
    const prog_segment *sg = &p->seg[i];
    if (sg->kind == PROG_DWELL)
        snprintf(buf, size, "segment %d (dwell)", i + 1);
    else
        snprintf(buf, size, "segment %d (%s, %s)", i + 1, kind_name(sg->kind),
                 prog_shape_name(sg->shape));
}

/* s, s', s'' meet at every boundary, the period's end included (order:
 * as far as p->continuity). 1, or 0 reported at the later segment. */
static int check_boundaries(loader *ld, const mech_program *p, quantity q, quantity xq,
                            const char *who)
{
    double hmax = 0, vmax = 0, amax = 0;
    for (int i = 0; i < p->n; i++) {
        double h = fabs(p->seg[i].lift), b = p->seg[i].span;
        hmax = fmax(hmax, h), vmax = fmax(vmax, h / b), amax = fmax(amax, h / (b * b));
    }
    double tol[3] = {1e-9 * hmax, 1e-9 * vmax, 1e-9 * amax};
    static const char *const what[3] = {"a displacement", "a velocity", "an acceleration"};
    char su[24], xu[24], l1[96], l2[96];
    double ss = unit_of(ld, q, su, sizeof su), xs = unit_of(ld, xq, xu, sizeof xu);
    for (int j = 1; j <= p->n; j++) {  /* in order, the period's end last */
        int i = j % p->n, prev = j - 1;
        double left[3], right[3];
        seg_ends(&p->seg[prev], 1, left);
        seg_ends(&p->seg[i], 0, right);
        if (i == 0)
            left[0] -= p->net;  /* the next period starts net higher */
        for (int k = 0; k <= p->continuity; k++) {
            double jump = right[k] - left[k];
            if (!(fabs(jump) > tol[k]))
                continue;
            seg_label(p, prev, l1, sizeof l1);
            seg_label(p, i, l2, sizeof l2);
            double shown = jump / ss * pow(xs, k);
            char unit[64];
            snprintf(unit, sizeof unit, k == 0 ? "%s" : k == 1 ? "%s/%s" : "%s/%s^2", su, xu);
            char in_time[80] = "";  /* with `speed:`, x' is known: the jump in time */
            if (p->speed != 0 && k > 0)
                snprintf(in_time, sizeof in_time, " = %.6g %s/s%s in time", jump / ss *
                         pow(p->speed, k), su, k == 2 ? "^2" : "");
            diag_error(ld->d, ld->file, (mech_mark){p->seg[i].line, p->seg[i].col},
                       "%s: %s jump of %.6g %s (d%ss/dx%s%s) at %.10g %s between %s and "
                       "%s%s", who, what[k], shown, unit, k == 2 ? "2" : "", k == 2 ? "2" : "",
                       in_time, p->seg[i].x0 > 0 ? p->seg[i].x0 / xs : p->period / xs, xu, l1, l2,
                       k == 2 ? ": use laws whose accelerations meet, or 'continuity: velocity'"
                       : k == 1 ? ": use laws whose velocities meet" : "");
            return 0;
        }
    }
    return 1;
}

/* `of`: the program's variable, a law of t (an angle, a length or a time),
 * parsed into the driver's law l. 1, or 0 reported. */
/* `speed:` a constant rate of x in t (x = speed * of): an angular speed
 * (the cam angle) or a speed; *xq the variable's quantity then. */
static int load_speed(loader *ld, const ynode *sp, const char *who, double *out, quantity *xq)
{
    char msg[256];
    size_t pos = 0;
    if (!load_want_kind(ld, sp, YNODE_SCALAR, "'speed'"))
        return 0;
    if (quantity_eval(sp->text, Q_ANGULAR_SPEED, &ld->env, out, msg, sizeof msg, &pos) == 0)
        *xq = Q_ANGLE;
    else if (quantity_eval(sp->text, Q_SPEED, &ld->env, out, msg, sizeof msg, &pos) == 0)
        *xq = Q_LENGTH;
    else
        return load_err(ld, sp, "%s: 'speed' is the rate of the program's variable: "
                        "an angular speed (60 rpm) or a speed (m/s), not '%s'", who,
                        sp->text), 0;
    if (!(*out != 0) || !isfinite(*out))
        return load_err(ld, sp, "%s: 'speed' must not be 0", who), 0;
    return 1;
}

static int load_variable(loader *ld, const ynode *map, const char *who, struct mech_law *l,
                         mech_program *p, quantity *xq)
{
    static const quantity wants[] = {Q_TIME, Q_ANGLE, Q_LENGTH};
    const ynode *of = ymap_get(map, "of"), *sp = ymap_get(map, "speed");
    char msg[256];
    size_t pos = 0;
    if (of && !load_want_kind(ld, of, YNODE_SCALAR, "'of'"))
        return 0;
    int rc = law_parse_into(of ? of->text : "t", wants, sp ? 1 : 3, &ld->env, l, xq, msg,
                            sizeof msg, &pos);
    if (rc == 0 && sp) {  /* x = speed * of */
        if (!load_speed(ld, sp, who, &p->speed, xq))
            return 0;
        int k = law_add_node(l, LAW_CONST, -1, -1, p->speed);
        int root = k < 0 ? -1 : law_add_node(l, LAW_MUL, k, l->root, 0.0);
        if (root < 0)
            return load_nomem(ld, map), 0;
        l->root = root;
    }
    if (rc == MECH_ENOMEM)
        return load_nomem(ld, map), 0;
    if (rc < 0) {
        law_error(ld, of ? of : map, pos, who, msg);
        return 0;
    }
    return 1;
}

static int load_continuity(loader *ld, const ynode *n, const char *who, int *out)
{
    static const char *const names[] = {"displacement", "velocity", "acceleration"};
    *out = 2;
    if (!n)
        return 1;
    if (!load_want_kind(ld, n, YNODE_SCALAR, "'continuity'"))
        return 0;
    for (int k = 0; k < 3; k++)
        if (strcmp(n->text, names[k]) == 0)
            return *out = k, 1;
    return load_err(ld, n, "%s: 'continuity' is displacement, velocity or "
                           "acceleration (checked at every boundary up to it), not '%s'", who,
                    n->text), 0;
}

/* The segments: their places in the period, their starting displacements. */
static int load_segments(loader *ld, const ynode *seq, quantity q, quantity xq, const char *who,
                         mech_program *p)
{
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'segments'"))
        return 0;
    if (seq->n == 0 || seq->n > 1000)
        return load_err(ld, seq, "a program has 1 to 1000 segments, not %zu", seq->n), 0;
    if (!(p->seg = xcalloc(seq->n, sizeof *p->seg)))
        return load_nomem(ld, seq), 0;
    double x = 0, s = 0;
    for (size_t i = 0; i < seq->n; i++) {
        prog_segment *sg = &p->seg[p->n++];
        if (!load_segment(ld, seq->items[i], q, xq, who, sg))
            return 0;
        sg->x0 = x, sg->s0 = s;
        x += sg->span, s += sg->lift;
    }
    p->net = s;
    p->period = x;
    return 1;
}

/* `period`, when given, is what the segments cover. */
static int check_period(loader *ld, const ynode *pn, quantity xq, const char *who,
                        const mech_program *p)
{
    double period;
    if (!pn)
        return 1;
    if (!load_get_quantity(ld, pn, xq, "the period", &period))
        return 0;
    if (fabs(period - p->period) <= 1e-12 * period)
        return 1;
    char xu[24];
    double xs = unit_of(ld, xq, xu, sizeof xu);
    return load_err(ld, pn, "%s: the segments cover %.10g %s, not the period %.10g %s: "
                    "%s of %.10g %s after segment %d", who, p->period / xs, xu, period / xs, xu,
                    p->period < period ? "a gap" : "an overlap", fabs(period - p->period) / xs,
                    xu, p->n), 0;
}

/* A cam's program: its variable is the law's own (the cam angle, x = t),
 * an angle; 'of' and 'speed' do not apply. */
static int cam_variable(struct mech_law *l, quantity *xq)
{
    *xq = Q_ANGLE;
    return (l->root = law_add_node(l, LAW_T, -1, -1, 0.0)) >= 0;
}

int law_take_program(struct mech_law *l, mech_program *p)
{
    struct mech_program **slot = xcalloc(1, sizeof *slot);
    const rt_program **rslot = xcalloc(1, sizeof *rslot);
    if (!slot || !rslot) {
        free(slot);
        free((void *)rslot);
        return 0;
    }
    slot[0] = p;
    rslot[0] = &p->rt;
    l->progs = slot;
    l->rtprogs = rslot;
    l->nprogs = 1;
    return 1;
}

int load_program(loader *ld, const ynode *map, quantity q, const char *who,
                 struct mech_law **out)
{
    return load_program_as(ld, map, q, who, 0, out);
}

int load_program_as(loader *ld, const ynode *map, quantity q, const char *who, int of_cam,
                    struct mech_law **out)
{
    static const char *const keys[] = {"of", "speed", "period", "start", "continuity",
                                       "segments"};
    *out = NULL;
    if (!load_want_kind(ld, map, YNODE_MAP, "'program'") ||
        !load_check_keys(ld, map, keys, COUNT(keys), "program"))
        return 0;
    for (int k = 0; k < 2 && of_cam; k++) {
        const ynode *key = load_key_of(map, keys[k]);
        if (key)
            return load_err(ld, key, "a cam's program has no '%s': its variable is the cam's "
                            "angle (turned from 'start')", keys[k]), 0;
    }
    const ynode *seq = ymap_get(map, "segments"), *st = ymap_get(map, "start");
    if (!seq)
        return load_err(ld, map, "a program needs 'segments: [...]' ({rise: LIFT, over: SPAN, "
                                 "law: LAW}, {dwell: SPAN}, {return: ...})"), 0;
    struct mech_law *l = law_new('t');
    mech_program *p = xcalloc(1, sizeof *p);
    if (!l || !p || !law_take_program(l, p)) {
        law_free(l);
        free(p);
        return load_nomem(ld, map), 0;
    }
    quantity xq = Q_TIME;
    int ok = (of_cam ? cam_variable(l, &xq) || (load_nomem(ld, map), 0)
                     : load_variable(ld, map, who, l, p, &xq)) &&
             load_continuity(ld, ymap_get(map, "continuity"), who, &p->continuity) &&
             (!st || load_get_quantity(ld, st, q, "the start", &p->start)) &&
             load_segments(ld, seq, q, xq, who, p) &&
             (p->rt = (rt_program){p->seg, p->n, p->start, p->period, p->net}, 1) &&
             check_period(ld, ymap_get(map, "period"), xq, who, p) &&
             check_boundaries(ld, p, q, xq, who);
    if (ok) {
        int root = law_add_node(l, LAW_PROGRAM, l->root, 0, 0.0);
        ok = root >= 0;
        l->root = root;
        if (!ok)
            load_nomem(ld, map);
    }
    if (!ok) {
        law_free(l);
        return 0;
    }
    *out = l;
    return 1;
}
