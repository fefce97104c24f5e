/* src/load/load_cams.c: the loader's 'cams' (cam-follower pairs, docs/cams.md),
 * checked with file:line:column:
 *
 *   cams:
 *     - {name, cam: LINK, follower: SLIDER | LINK, contact: roller | knife-edge |
 *        flat-faced, base_radius, roller_radius, at: POINT, turning: ccw | cw,
 *        start: ANGLE, face: [A, B], friction: MU,
 *        program: {segments: [...], period, start, continuity}}
 *
 * The cam turns on the arm that guides the follower: a translating
 * follower's slider runs on it, an oscillating follower turns on it. The
 * follower's coordinate at zero lift (c0) comes from the geometry: the
 * roller's centre (knife's tip) on the base circle's offset by the roller's
 * radius, a flat face tangent to the base circle. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

enum { MAX_CAMS = 10000 };

static const double PI = 3.14159265358979323846;

static double mm(double x) { return x * 1e3; }

void model_cams_free(model_cams *c)
{
    if (!c)
        return;
    for (int i = 0; i < c->n; i++) {
        free(c->cam[i].name);
        free(c->cam[i].points);
        law_free(c->cam[i].program);
    }
    free(c->cam);
    free(c);
}

/* 'contact' and the radii it needs. */
static int load_contact(loader *ld, const ynode *map, mech_cam *c)
{
    static const char *const names[] = {"roller", "knife-edge", "flat-faced"};
    const ynode *n = ymap_get(map, "contact"), *b = ymap_get(map, "base_radius"),
                *r = ymap_get(map, "roller_radius");
    if (!n)
        return load_err(ld, map, "a cam needs 'contact': roller, knife-edge or flat-faced (the "
                        "follower's end that touches the cam)"), 0;
    if (!load_want_kind(ld, n, YNODE_SCALAR, "'contact'"))
        return 0;
    int k = 0;
    while (k < 3 && strcmp(n->text, names[k]) != 0)
        k++;
    if (k == 3)
        return load_err(ld, n, "'contact' is roller, knife-edge or flat-faced, not '%s'",
                        n->text), 0;
    c->contact = (cam_contact)k;
    if (!b && !c->points)
        return load_err(ld, map, "a cam needs 'base_radius' (the radius of the base circle, "
                        "the profile's least)"), 0;
    if (b && c->points)
        return load_err(ld, load_key_of(map, "base_radius"), "a cam given by its 'profile' has "
                        "the base circle of the profile (its least distance from the centre): "
                        "'base_radius' does not apply"), 0;
    if (b && !load_get_quantity(ld, b, Q_LENGTH, "base_radius", &c->base))
        return 0;
    if (b && !(c->base > 0.0))
        return load_err(ld, b, "base_radius must be positive"), 0;
    if (c->contact == CAM_ROLLER && !r)
        return load_err(ld, map, "a roller follower needs 'roller_radius'"), 0;
    if (c->contact != CAM_ROLLER && r)
        return load_err(ld, load_key_of(map, "roller_radius"), "'roller_radius' applies to a "
                        "roller follower, not a %s one", names[k]), 0;
    if (r && !load_get_quantity(ld, r, Q_LENGTH, "roller_radius", &c->roller))
        return 0;
    if (r && !(c->roller > 0.0))
        return load_err(ld, r, "roller_radius must be positive"), 0;
    return 1;
}

/* 'turning' and 'start'. */
static int load_phase(loader *ld, const ynode *map, mech_cam *c)
{
    const ynode *t = ymap_get(map, "turning"), *s = ymap_get(map, "start");
    c->sense = 1;
    if (t && !load_want_kind(ld, t, YNODE_SCALAR, "'turning'"))
        return 0;
    if (t && strcmp(t->text, "ccw") != 0 && strcmp(t->text, "cw") != 0)
        return load_err(ld, t, "'turning' is ccw or cw (the sense the cam turns on its arm as "
                        "the program advances), not '%s'", t->text), 0;
    if (t && strcmp(t->text, "cw") == 0)
        c->sense = -1;
    return !s || load_get_quantity(ld, s, Q_ANGLE, "start", &c->start);
}

/* A point of link l by index, in l's frame. */
static const mech_point *point_of(const mech_model *m, int l, int k)
{
    return &m->links[l].points[k];
}

/* Translating: the follower's slider on the arm; c0 the slider's
 * displacement where the contact meets the base circle (the rise along the
 * line's direction, away from the cam on that side). */
static int place_translating(loader *ld, const ynode *fn, mech_cam *c)
{
    const mech_model *m = ld->m;
    const mech_joint *jt = &m->joints[c->slider];
    if (!jt->locked)
        return load_err(ld, fn, "the follower slider '%s' is a pin in a slot: a translating "
                        "follower is a locked slider", jt->name), 0;
    c->follower = jt->link[0];
    c->arm = jt->link[1];
    if (!load_find_pivot(ld, c->cam, c->arm, &c->cam_pivot[0], &c->cam_pivot[1]))
        return load_err(ld, fn, "the cam '%s' has no pivot on '%s', the follower's guide (no "
                        "revolute joint joins them): the cam must turn on the link that guides "
                        "its follower", m->links[c->cam].name, m->links[c->arm].name), 0;
    if (c->points && !cam_points_base(ld, c))
        return 0;
    const mech_point *o = point_of(m, c->arm, c->cam_pivot[1]);
    const mech_point *t = point_of(m, c->arm, jt->point[1]);
    double ux = cos(jt->angle), uy = sin(jt->angle);
    double along = (o->x - t->x) * ux + (o->y - t->y) * uy;
    c->offset = (t->x - o->x) * -uy + (t->y - o->y) * ux;  /* the line's side of the centre */
    double reach = c->base + c->roller, d0 = reach;
    if (c->contact != CAM_FLAT_FACED) {
        if (fabs(c->offset) >= reach)
            return load_err(ld, fn, "the follower's line (slider '%s') passes %.6g mm from the "
                            "cam's centre %s, not inside the base circle%s (%.6g mm): the "
                            "follower cannot touch the cam", jt->name, mm(fabs(c->offset)),
                            o->name, c->roller > 0 ? " plus the roller" : "", mm(reach)), 0;
        d0 = sqrt(reach * reach - c->offset * c->offset);
    }
    c->c0 = along + d0;
    c->rise = 1;
    return 1;
}

/* Oscillating: the arm is a link both the cam and the follower turn on. */
static int find_arm(loader *ld, const ynode *fn, mech_cam *c)
{
    const mech_model *m = ld->m;
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (jt->kind != MECH_JOINT_REVOLUTE)
            continue;
        for (int side = 0; side < 2; side++) {
            int a = jt->link[1 - side];
            if (jt->link[side] != c->follower || a == c->cam)
                continue;
            if (load_find_pivot(ld, c->cam, a, &c->cam_pivot[0], &c->cam_pivot[1])) {
                c->arm = a;
                c->follower_pivot[0] = jt->point[side];
                c->follower_pivot[1] = jt->point[1 - side];
                return 1;
            }
        }
    }
    return load_err(ld, fn, "the follower '%s' and the cam '%s' turn on no common link: an "
                    "oscillating follower turns on the link the cam turns on (its arm)",
                    m->links[c->follower].name, m->links[c->cam].name), 0;
}

/* An oscillating flat face: 'face: [A, B]', two points of the follower. */
static int load_face(loader *ld, const ynode *map, mech_cam *c)
{
    const ynode *fc = ymap_get(map, "face");
    if (load_key_of(map, "at"))
        return load_err(ld, load_key_of(map, "at"), "a flat-faced follower touches along its "
                        "face: give 'face: [A, B]', not 'at'"), 0;
    if (!fc)
        return load_err(ld, map, "an oscillating flat-faced follower needs 'face: [A, B]': two "
                        "points of the follower on its face"), 0;
    if (!load_want_kind(ld, fc, YNODE_SEQ, "'face'"))
        return 0;
    if (fc->n != 2)
        return load_err(ld, fc, "'face' needs two points of the follower, [A, B]"), 0;
    for (int k = 0; k < 2; k++) {
        int id = load_find_point_or_report(ld, fc->items[k], "'face'");
        if (id < 0)
            return 0;
        c->face[k] = load_point_in_link(ld, c->follower, id);
        if (c->face[k] < 0)
            return load_err(ld, fc->items[k], "point '%s' is not on the follower '%s'",
                            fc->items[k]->text, ld->m->links[c->follower].name), 0;
    }
    const mech_link *f = &ld->m->links[c->follower];
    const mech_point *a = &f->points[c->face[0]], *b = &f->points[c->face[1]];
    if (a->x == b->x && a->y == b->y)
        return load_err(ld, fc, "the face's two points are at one place"), 0;
    return 1;
}

static int load_oscillating(loader *ld, const ynode *map, const ynode *fn, mech_cam *c)
{
    const ynode *at = ymap_get(map, "at");
    c->motion = CAM_OSCILLATING;
    if (!find_arm(ld, fn, c) || (c->points && !cam_points_base(ld, c)))
        return 0;
    if (c->contact == CAM_FLAT_FACED)
        return load_face(ld, map, c);
    if (!at)
        return load_err(ld, map, "an oscillating follower needs 'at': its point at the "
                        "roller's centre (or the knife's tip)"), 0;
    int id = load_find_point_or_report(ld, at, "'at'");
    if (id < 0)
        return 0;
    c->at = load_point_in_link(ld, c->follower, id);
    if (c->at < 0)
        return load_err(ld, at, "point '%s' is not on the follower '%s'", at->text,
                        ld->m->links[c->follower].name), 0;
    return 1;
}

/* The follower's guess less the arm's (0 when none is given). */
static double guess_on_arm(const mech_model *m, const mech_cam *c)
{
    double guess = 0.0;
    for (int g = 0; g < m->nguesses; g++)
        if (!m->guesses[g].is_slider && m->guesses[g].index == c->follower)
            guess += m->guesses[g].value;
    for (int g = 0; g < m->nguesses; g++)
        if (!m->guesses[g].is_slider && m->guesses[g].index == c->arm)
            guess -= m->guesses[g].value;
    return guess;
}

/* The oscillating follower's angle on the arm where the roller's centre
 * (knife's tip) is base + roller from the cam's centre: of the two, the
 * one nearest the follower's guess (its `initial:` angle less the arm's,
 * else 0). */
static void place_oscillating(loader *ld, mech_cam *c)
{
    const mech_model *m = ld->m;
    const mech_point *pf = point_of(m, c->follower, c->follower_pivot[0]);
    const mech_point *pa = point_of(m, c->arm, c->follower_pivot[1]);
    const mech_point *r = point_of(m, c->follower, c->at);
    const mech_point *o = point_of(m, c->arm, c->cam_pivot[1]);
    double vx = r->x - pf->x, vy = r->y - pf->y, wx = o->x - pa->x, wy = o->y - pa->y;
    double len = hypot(vx, vy), d = hypot(wx, wy), reach = c->base + c->roller;
    if (len == 0.0 || d == 0.0)
        return (void)diag_error(ld->d, ld->file, c->mark, "cam '%s': the follower's %s is at "
                                "its pivot", c->name, len == 0.0 ? "contact point" :
                                "pivot is the cam's centre, and its");
    double cs = (len * len + d * d - reach * reach) / (2.0 * len * d);
    if (!(fabs(cs) < 1.0))
        return (void)diag_error(ld->d, ld->file, c->mark, "cam '%s': the follower's point %s "
                                "(%.6g mm from its pivot, which is %.6g mm from the cam's "
                                "centre) cannot reach the base circle%s (%.6g mm)", c->name,
                                r->name, mm(len), mm(d), c->roller > 0 ? " plus the roller" :
                                "", mm(reach));
    double guess = guess_on_arm(m, c);
    double base = atan2(wy, wx) - atan2(vy, vx), a = acos(cs), best = 0.0, bestd = INFINITY;
    for (int k = 0; k < 2; k++) {
        double psi = base + (k ? -a : a);
        psi -= 2.0 * PI * floor((psi - guess + PI) / (2.0 * PI));  /* nearest the guess */
        if (fabs(psi - guess) < bestd) {
            bestd = fabs(psi - guess);
            best = psi;
            c->rise = k ? -1 : 1;  /* + a: the centre moves out as psi grows */
        }
    }
    c->c0 = best;
}

/* An oscillating flat face: the follower's angle psi on the arm where the
 * face's line is the base radius from the cam's centre, d(psi) = (P - O)
 * . R(psi) J w + k = +-base (w the face's direction in the follower, k =
 * (A - P_f) . J w): of the solutions, the one nearest the guess; the lift
 * moves the face away from the centre. */
static void place_face(loader *ld, mech_cam *c)
{
    const mech_model *m = ld->m;
    const mech_point *pa = &m->links[c->arm].points[c->follower_pivot[1]];
    const mech_point *o = &m->links[c->arm].points[c->cam_pivot[1]];
    double w[2], k = cam_face(m, c, w), wx = w[0], wy = w[1];
    double dx = pa->x - o->x, dy = pa->y - o->y, dl = hypot(dx, dy);
    double om = atan2(wx, -wy), ga = atan2(dy, dx), guess = guess_on_arm(m, c), best = NAN;
    for (int side = -1; side <= 1; side += 2) {
        double cs = (side * c->base - k) / dl;
        if (!(dl > 0.0 && fabs(cs) < 1.0))
            continue;
        for (int sg = -1; sg <= 1; sg += 2) {
            double psi = ga - om + sg * acos(cs);
            psi -= 2.0 * PI * floor((psi - guess + PI) / (2.0 * PI));
            if (isnan(best) || fabs(psi - guess) < fabs(best - guess)) {
                best = psi;
                /* d|d|/dpsi = side * -dl sin(psi + om - ga) = side * -dl * sg sin(acos) */
                c->rise = -side * sg > 0 ? 1 : -1;
            }
        }
    }
    if (isnan(best))
        return (void)diag_error(ld->d, ld->file, c->mark, "cam '%s': the follower's face cannot "
                                "touch the base circle (%.6g mm) at any angle", c->name,
                                mm(c->base));
    c->c0 = best;
}

/* 'follower': a slider (translating) or a link (oscillating). */
static int load_follower(loader *ld, const ynode *map, mech_cam *c)
{
    const mech_model *m = ld->m;
    const ynode *fn = ymap_get(map, "follower");
    c->slider = c->at = c->face[0] = c->face[1] = -1;
    if (!fn)
        return load_err(ld, map, "a cam needs 'follower': a slider (a translating follower) or "
                        "a link (an oscillating one)"), 0;
    if (!load_want_kind(ld, fn, YNODE_SCALAR, "'follower'"))
        return 0;
    int j = mech_find_joint(m, fn->text);
    if (j >= 0 && m->joints[j].kind == MECH_JOINT_SLIDER) {
        const ynode *at = load_key_of(map, "at");
        if (at)
            return load_err(ld, at, "a translating follower touches the cam at its slider's "
                            "point: 'at' does not apply"), 0;
        c->motion = CAM_TRANSLATING;
        c->slider = j;
        return place_translating(ld, fn, c);
    }
    c->follower = load_find_link_or_report(ld, fn, "'follower'");
    if (c->follower < 0)
        return 0;
    if (c->follower == c->cam)
        return load_err(ld, fn, "the cam '%s' cannot follow itself", m->links[c->cam].name), 0;
    return load_oscillating(ld, map, fn, c);
}

/* 'friction': the Coulomb coefficient at the contact, 0 to 1. */
static int load_friction(loader *ld, const ynode *n, mech_cam *c)
{
    if (!n)
        return 1;
    if (!load_get_quantity(ld, n, Q_NUMBER, "friction", &c->friction))
        return 0;
    if (!(c->friction >= 0.0 && c->friction <= 1.0))
        return load_err(ld, n, "a cam's friction coefficient is from 0 to 1, not %g",
                        c->friction), 0;
    if (c->contact == CAM_ROLLER && c->friction > 0.0)
        return load_err(ld, n, "a roller rolls on the cam: there is no sliding friction at its "
                        "contact (its losses are its pin's); 'friction' applies to a "
                        "knife-edge or a flat face"), 0;
    return 1;
}

/* A disc cam's profile closes over a turn: its program returns to its
 * start (no net lift) and repeats a whole number of times in 360 deg. */
static int closed_profile(loader *ld, const ynode *pm, mech_cam *c)
{
    const struct mech_program *p = c->program->progs[0];
    double k = 2.0 * PI / p->period, scale = c->motion == CAM_TRANSLATING ? 1e3 : 180.0 / PI;
    if (fabs(p->net) > 1e-12 * (1.0 + fabs(p->start)))
        return load_err(ld, pm, "cam '%s': the program rises %.6g %s more than it returns over "
                        "its period: a cam's profile must come back to where it started",
                        c->name, p->net * scale, c->motion == CAM_TRANSLATING ? "mm" : "deg"), 0;
    if (fabs(k - round(k)) > 1e-9 * k || round(k) < 1.0)
        return load_err(ld, pm, "cam '%s': the program's period %.6g deg does not divide a turn "
                        "(360 deg) a whole number of times: the profile would not close",
                        c->name, p->period * 180.0 / PI), 0;
    return 1;
}

static int load_one(loader *ld, const ynode *map, mech_cam *c)
{
    const ynode *cn = ymap_get(map, "cam"), *pm = ymap_get(map, "program"),
                *pr = ymap_get(map, "profile");
    c->mark = map->mark;
    if (!cn)
        return load_err(ld, map, "a cam needs 'cam': the link that carries the profile"), 0;
    c->cam = load_find_link_or_report(ld, cn, "'cam'");
    if (c->cam < 0)
        return 0;
    if (c->cam == 0)
        return load_err(ld, cn, "the ground cannot be the cam: a cam turns"), 0;
    if (pm && pr)
        return load_err(ld, load_key_of(map, "profile"), "a cam has 'program' (the follower's "
                        "lift, the profile derived) or 'profile' (its points, the lift "
                        "derived), not both"), 0;
    if (pr && !cam_points_load(ld, pr, c))
        return 0;
    if (!load_contact(ld, map, c) || !load_phase(ld, map, c) || !load_follower(ld, map, c) ||
        !load_friction(ld, ymap_get(map, "friction"), c))
        return 0;
    if (pr)
        return 1;  /* the lift comes from the points once the follower is placed */
    if (!pm)
        return load_err(ld, map, "a cam needs 'program' (the follower's lift against the cam's "
                        "angle: segments of rise, dwell and return) or 'profile' (the "
                        "profile's points)"), 0;
    char who[MAX_NAME + 16];
    snprintf(who, sizeof who, "cam '%s'", c->name);
    if (!load_program_as(ld, pm, c->motion == CAM_TRANSLATING ? Q_LENGTH : Q_ANGLE, who, 1,
                         &c->program))
        return 0;
    snprintf(c->program->name, sizeof c->program->name, "s_%s", c->name);
    return closed_profile(ld, pm, c);
}

/* The pair's name: 'name', else CAM_FOLLOWER. */
static int name_cam(loader *ld, const ynode *map, mech_cam *c, name_map *names)
{
    const ynode *nm = ymap_get(map, "name"), *cn = ymap_get(map, "cam"),
                *fn = ymap_get(map, "follower");
    const char *given = nm ? load_get_name(ld, nm, "cam name") : NULL;
    if (nm && !given)
        return 0;
    char buf[2 * MAX_NAME + 16];
    snprintf(buf, sizeof buf, "%s_%s", cn && cn->text ? cn->text : "cam",
             fn && fn->text ? fn->text : "follower");
    if (!(c->name = xstrdup(given ? given : buf)))
        return load_nomem(ld, map), 0;
    if (name_map_get(names, c->name) >= 0)
        return load_err(ld, nm ? nm : map, "a second cam named '%s'%s", c->name,
                        nm ? "" : " (give each a 'name:')"), 0;
    if (name_map_put(names, c->name, 0) < 0)
        return load_nomem(ld, map), 0;
    return 1;
}

void load_cams(loader *ld, const ynode *seq)
{
    static const char *const keys[] = {"name", "cam", "follower", "contact", "base_radius",
                                       "roller_radius", "at", "face", "turning", "start",
                                       "friction", "program", "profile"};
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'cams'"))
        return;
    if (seq->n > MAX_CAMS)
        return (void)load_err(ld, seq, "too many cams (%zu; at most %d)", seq->n, MAX_CAMS);
    model_cams *cs = xcalloc(1, sizeof *cs);
    mech_cam *arr = cs ? xcalloc(seq->n + 1, sizeof *arr) : NULL;
    if (!arr) {
        free(cs);
        return (void)load_nomem(ld, seq);
    }
    cs->cam = arr;
    ld->m->cams = cs;
    name_map names = {0};
    for (size_t i = 0; i < seq->n; i++) {
        const ynode *map = seq->items[i];
        mech_cam *c = &cs->cam[cs->n];
        if (!load_want_kind(ld, map, YNODE_MAP, "a cam") ||
            !load_check_keys(ld, map, keys, COUNT(keys), "a cam"))
            continue;
        int ok = name_cam(ld, map, c, &names) && load_one(ld, map, c);
        cs->n++;  /* counted either way: its name and program are freed with the model */
        if (!ok && c->cam > 0)
            ld->link_failed[c->cam] |= LINK_FAILED;
    }
    name_map_free(&names);
}

/* The design quantities over the period, sampled every 0.1 deg of the cam
 * (and at least 100 times a segment); an undercut profile is an error at
 * the first angle found, a pressure angle above the usual limit a warning. */
static void scan_design(loader *ld, mech_cam *c)
{
    const struct mech_program *p = c->program->progs[0];
    int n = (int)ceil(p->period / (0.1 * PI / 180.0));
    if (n < 100 * p->n && !c->points)  /* a profile's spline: one sample a piece */
        n = 100 * p->n;
    c->pressure_max = 0.0, c->rho_pitch_min = c->rho_profile_min = INFINITY;
    c->face_lo = INFINITY, c->face_hi = -INFINITY;
    double undercut = NAN, undercut_rho = 0.0;
    for (int k = 0; k < n; k++) {
        cam_point g;
        cam_geometry(ld->m, c, p->period * k / n, &g);
        if (fabs(g.pressure) > c->pressure_max)
            c->pressure_max = fabs(g.pressure), c->pressure_at = g.x;
        if (g.rho_pitch > 0.0 && g.rho_pitch < c->rho_pitch_min)
            c->rho_pitch_min = g.rho_pitch, c->rho_pitch_at = g.x;
        if (g.rho_profile < c->rho_profile_min)
            c->rho_profile_min = g.rho_profile, c->rho_profile_at = g.x;
        c->face_lo = fmin(c->face_lo, g.face), c->face_hi = fmax(c->face_hi, g.face);
        int cusp = c->contact == CAM_FLAT_FACED ? g.rho_profile < 0.0
                   : c->contact == CAM_ROLLER && g.rho_pitch > 0.0 && g.rho_pitch < c->roller;
        if (cusp && isnan(undercut))
            undercut = g.x, undercut_rho = c->contact == CAM_ROLLER ? g.rho_pitch : g.rho_profile;
    }
    double deg = 180.0 / PI;
    if (!isnan(undercut) && c->contact == CAM_ROLLER)
        diag_error(ld->d, ld->file, c->mark, "cam '%s': the profile is undercut at %.4g deg of "
                   "the cam: the pitch curve's radius of curvature there, %.6g mm, is below the "
                   "roller's %.6g mm (a larger base circle, a smaller roller or a gentler law "
                   "avoids it)", c->name, undercut * deg, mm(undercut_rho), mm(c->roller));
    else if (!isnan(undercut))
        diag_error(ld->d, ld->file, c->mark, "cam '%s': the profile is undercut at %.4g deg of "
                   "the cam: its radius of curvature base + s + s'' there is %.6g mm, negative "
                   "(a larger base circle or a gentler law avoids it)", c->name,
                   undercut * deg, mm(undercut_rho));
    double limit = (c->motion == CAM_TRANSLATING ? 30.0 : 35.0) / deg;
    if (isnan(undercut) && c->pressure_max > limit)
        diag_warning(ld->d, ld->file, c->mark, "cam '%s': the pressure angle reaches %.4g deg at "
                     "%.4g deg of the cam, above the %.0f deg usual for %s follower (the "
                     "follower may jam; a larger base circle or a longer rise lowers it)",
                     c->name, c->pressure_max * deg, c->pressure_at * deg, limit * deg,
                     c->motion == CAM_TRANSLATING ? "a translating" : "an oscillating");
}

void load_cams_place(loader *ld)
{
    model_cams *cs = ld->m->cams;
    for (int i = 0; cs && i < cs->n; i++) {
        mech_cam *c = &cs->cam[i];
        size_t before = ld->d->nerrors;
        if (c->motion == CAM_OSCILLATING && (c->program || c->points))
            (c->contact == CAM_FLAT_FACED ? place_face : place_oscillating)(ld, c);
        if (c->points && !c->program && ld->d->nerrors == before)
            cam_points_program(ld, c);
        if (c->program && ld->d->nerrors == before)
            scan_design(ld, c);
    }
}
