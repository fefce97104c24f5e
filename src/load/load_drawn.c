/* src/load/load_drawn.c: the drawn form (docs/format.md section 5.4).
 * `drawing:` gives every point's global position at one pose and the links
 * list point names. The file is read as the local form it stands for: a
 * copy of the tree in which each link's points are written in the link's
 * frame as expressions of the drawn coordinates (so parameters keep moving
 * them, param_expr.c), the ground's points as drawn, and a slider's angle,
 * when left out, from the drawing. The drawn positions stay in the loader
 * for the guesses and the driver's start (load_guess.c). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

/* A string built like printf's; NULL when out of memory. */
static char *textf(const char *fmt, ...) MECH_PRINTF(1, 2);
static char *textf(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(NULL, 0, fmt, ap);
    va_end(ap);
    char *s = n >= 0 ? malloc((size_t)n + 1) : NULL;
    if (!s)
        return NULL;
    va_start(ap, fmt);
    vsnprintf(s, (size_t)n + 1, fmt, ap);
    va_end(ap);
    return s;
}

/* ---- the drawing ---------------------------------------------------- */

/* The index of drawn point `name`, or -1. */
static int drawn_index(const loader *ld, const char *name)
{
    return name_map_get(&ld->drawn_map, name);
}

/* Read `drawing:`: each point once, [x, y] lengths (expressions allowed).
 * 1 when every point was read. */
static int read_drawing(loader *ld, const ynode *map)
{
    size_t errors = ld->d->nerrors;
    if (!load_check_map(ld, map, NULL, 0, "'drawing'", "drawn point"))
        return 0;
    ld->drawn = xcalloc(map->n + 1, sizeof *ld->drawn);
    if (!ld->drawn)
        return load_nomem(ld, map), 0;
    for (size_t i = 0; i < map->n; i++) {
        const ynode *k = map->items[2 * i], *v = map->items[2 * i + 1];
        const char *name = load_get_name(ld, k, "drawn point name");
        if (!name || k->dup_of)
            continue;  /* reported (a point drawn twice too) */
        char what[128];
        snprintf(what, sizeof what, "drawn point '%s'", name);
        drawn_point *p = &ld->drawn[ld->ndrawn];
        if (!load_get_vec2(ld, v, Q_LENGTH, what, p->xy))
            continue;
        p->name = name;
        p->node = v;
        p->mark = k->mark;
        if (name_map_put(&ld->drawn_map, name, ld->ndrawn++) < 0)
            return load_nomem(ld, k), 0;
    }
    return ld->d->nerrors == errors;
}

/* Coordinate `axis` of drawn point i as a length expression: a bare number
 * takes the file's length unit ('+ 0 m' gives it one). */
static char *coord(const loader *ld, int i, int axis)
{
    return textf("((%s) + 0 m)", ld->drawn[i].node->items[axis]->text);
}

/* The expression of (drawn point b) - (drawn point a) along axis. */
static char *delta(const loader *ld, int a, int b, int axis)
{
    char *pb = coord(ld, b, axis), *pa = coord(ld, a, axis);
    char *s = pb && pa ? textf("(%s - %s)", pb, pa) : NULL;
    free(pb);
    free(pa);
    return s;
}

/* The drawn direction from a to b, an angle expression. */
static char *direction(const loader *ld, int a, int b)
{
    char *dx = delta(ld, a, b, 0), *dy = delta(ld, a, b, 1);
    char *s = dx && dy ? textf("atan2(%s, %s)", dy, dx) : NULL;
    free(dx);
    free(dy);
    return s;
}

static int drawn_apart(const loader *ld, int a, int b)
{
    const double *p = ld->drawn[a].xy, *q = ld->drawn[b].xy;
    double size = fmax(fmax(fabs(p[0]), fabs(p[1])), fmax(fabs(q[0]), fabs(q[1])));
    return hypot(q[0] - p[0], q[1] - p[1]) > 1e-12 * fmax(size, 1e-9);
}

/* ---- the links' frames ---------------------------------------------- */

/* A moving link's frame at the drawing: origin at drawn point `origin`,
 * x axis at the angle expression `angle` (NULL: along the global x). */
typedef struct frame {
    const char *name;     /* borrowed from the tree */
    const ynode *key;
    const ynode *points;  /* the list of point names */
    int origin;           /* drawn index; -1: not known */
    char *angle;          /* owned */
    int guide;            /* a locked slider's guide: frame index, 0 the ground; -1 none */
    int done;
} frame;

static int frame_of(const frame *f, int nf, const char *name)
{
    if (strcmp(name, "ground") == 0)
        return 0;
    for (int i = 1; i < nf; i++)
        if (strcmp(f[i].name, name) == 0)
            return i;
    return -1;
}

static const ynode *points_of(const ynode *v)
{
    return v->kind == YNODE_MAP ? ymap_get(v, "points") : v;
}

static int lists_point(const ynode *points, const char *name)
{
    for (size_t i = 0; points && points->kind == YNODE_SEQ && i < points->n; i++)
        if (points->items[i]->kind == YNODE_SCALAR && strcmp(points->items[i]->text, name) == 0)
            return 1;
    return 0;
}

/* The sliding link of slider joint j (a mapping): its 'link', or the one
 * link besides the guide that lists the point. */
static int sliding_frame(const frame *f, int nf, const ynode *j, int guide)
{
    const ynode *ln = ymap_get(j, "link"), *pn = ymap_get(j, "slider");
    if (ln && ln->kind == YNODE_SCALAR)
        return frame_of(f, nf, ln->text);
    int found = -1;
    for (int i = 1; pn && pn->kind == YNODE_SCALAR && i < nf; i++)
        if (i != guide && lists_point(f[i].points, pn->text))
            found = found < 0 ? i : -2;
    return found;
}

static int is_locked(const ynode *j)
{
    const ynode *rot = ymap_get(j, "rotation");
    return !rot || rot->kind != YNODE_SCALAR || strcmp(rot->text, "free") != 0;
}

/* Mark the links held by a locked slider: their frame turns with the guide. */
static void find_locked(frame *f, int nf, const ynode *joints)
{
    for (size_t i = 0; joints && joints->kind == YNODE_SEQ && i < joints->n; i++) {
        const ynode *j = joints->items[i], *on = ymap_get(j, "on");
        if (!ymap_get(j, "slider") || !on || on->kind != YNODE_SCALAR || !is_locked(j))
            continue;
        int g = frame_of(f, nf, on->text), s = g >= 0 ? sliding_frame(f, nf, j, g) : -1;
        if (s > 0)
            f[s].guide = g;
    }
}

/* The drawn index of a link's k-th listed point, or -1 (reported once, in
 * rewrite_points). */
static int listed(const loader *ld, const frame *fr, size_t k)
{
    const ynode *p = fr->points->items[k];
    return p->kind == YNODE_SCALAR ? drawn_index(ld, p->text) : -1;
}

/* The frame of link i: origin at its first point; x axis towards its second,
 * or the guide's for a locked block. 0 when it must wait for its guide. */
static int make_frame(loader *ld, frame *f, int i)
{
    frame *fr = &f[i];
    fr->origin = fr->points->n ? listed(ld, fr, 0) : -1;
    if (fr->guide >= 0) {
        if (!f[fr->guide].done)
            return 0;
        fr->angle = f[fr->guide].angle ? xstrdup(f[fr->guide].angle) : NULL;
    } else if (fr->points->n >= 2 && fr->origin >= 0) {
        int second = listed(ld, fr, 1);
        if (second >= 0 && !drawn_apart(ld, fr->origin, second))
            load_err(ld, fr->points->items[1], "link '%s': its first two points '%s' and '%s' "
                     "are drawn at one place, so they give its frame no direction; list "
                     "another point second", fr->name, ld->drawn[fr->origin].name,
                     ld->drawn[second].name);
        else if (second >= 0)
            fr->angle = direction(ld, fr->origin, second);
    }
    fr->done = 1;
    return 1;
}

static void make_frames(loader *ld, frame *f, int nf)
{
    f[0].done = 1;
    for (int pass = 0; pass < nf; pass++)  /* a guide's frame before its blocks' */
        for (int i = 1; i < nf; i++)
            if (!f[i].done)
                make_frame(ld, f, i);
}

/* ---- writing the local form ------------------------------------------ */

/* Point q in frame fr: [x, y] in the link's own frame, as expressions. */
static ynode *local_point(const loader *ld, const frame *fr, int q, mech_mark at)
{
    ynode *seq = ynode_new(YNODE_SEQ, NULL, at);
    char *x = NULL, *y = NULL;
    if (q == fr->origin || fr->origin < 0) {  /* no origin: reported at its first point */
        x = xstrdup("0");
        y = xstrdup("0");
    } else {
        char *dx = delta(ld, fr->origin, q, 0), *dy = delta(ld, fr->origin, q, 1);
        const char *a = fr->angle;
        if (dx && dy && !a) {
            x = xstrdup(dx);
            y = xstrdup(dy);
        } else if (dx && dy) {
            x = textf("%s * cos(%s) + %s * sin(%s)", dx, a, dy, a);
            y = textf("%s * cos(%s) - %s * sin(%s)", dy, a, dx, a);
        }
        free(dx);
        free(dy);
    }
    if (!seq || !x || !y || ynode_push(seq, ynode_new(YNODE_SCALAR, x, at)) < 0 ||
        ynode_push(seq, ynode_new(YNODE_SCALAR, y, at)) < 0) {
        ytree_free(seq);
        seq = NULL;
    }
    free(x);
    free(y);
    return seq;
}

/* The mapping point name -> coordinates of a link (fr NULL: the ground, as
 * drawn). NULL when reported. */
static ynode *rewrite_points(loader *ld, const frame *fr, const ynode *names, const char *link)
{
    if (names->kind != YNODE_SEQ) {
        load_err(ld, names, "with 'drawing:', the points of %s are a list of drawn point "
                            "names (such as [O, A]), not %s", link, ynode_kind_name(names->kind));
        return NULL;
    }
    ynode *map = ynode_new(YNODE_MAP, NULL, names->mark);
    for (size_t k = 0; map && k < names->n; k++) {
        const ynode *p = names->items[k];
        const char *name = load_get_name(ld, p, "point name");
        int q = name ? drawn_index(ld, name) : -1;
        if (name && q < 0)
            load_err(ld, p, "point '%s' of %s is not in 'drawing:' (draw it there)", name, link);
        if (q < 0 || (fr && fr->origin < 0))
            continue;  /* reported (the first point: at it) */
        ld->drawn[q].on_link = 1;
        ynode *at = fr ? local_point(ld, fr, q, p->mark) : ytree_copy(ld->drawn[q].node);
        if (ynode_push(map, ynode_new(YNODE_SCALAR, name, p->mark)) < 0 || ynode_push(map, at) < 0) {
            ytree_free(map);
            return NULL;
        }
    }
    return map;
}

/* Replace the value of `key` in map by v (taken); -1 when v is NULL. */
static int replace_value(ynode *map, const char *key, ynode *v)
{
    if (!v)
        return -1;
    for (size_t i = 0; i < map->n; i++)
        if (map->items[2 * i]->text && strcmp(map->items[2 * i]->text, key) == 0) {
            ytree_free(map->items[2 * i + 1]);
            map->items[2 * i + 1] = v;
            return 0;
        }
    ytree_free(v);
    return -1;
}

/* A global [x, y] at the drawing (a centre of mass) in frame fr: the
 * point is drawn as an extra one, only for this. */
static ynode *local_of_global(loader *ld, const frame *fr, const ynode *xy)
{
    double v[2];
    if (!load_get_vec2(ld, xy, Q_LENGTH, "center of mass", v))
        return NULL;
    drawn_point *d = xrealloc_array(ld->drawn, (size_t)ld->ndrawn + 1, sizeof *d);
    if (!d)
        return NULL;
    ld->drawn = d;
    d[ld->ndrawn] = (drawn_point){.name = NULL, .node = xy, .xy = {v[0], v[1]}, .on_link = 1};
    return local_point(ld, fr, ld->ndrawn++, xy->mark);
}

/* One link of the drawn form: [names] or {points: [names], mass, center, ...}. */
static ynode *rewrite_link(loader *ld, const frame *fr, const ynode *v)
{
    char link[96];
    snprintf(link, sizeof link, "link '%s'", fr->name);
    if (!fr->points)
        return ytree_copy(v);  /* no 'points': reported by load_link */
    ynode *pts = rewrite_points(ld, fr, fr->points, link);
    if (!pts || v->kind != YNODE_MAP) {
        if (!pts)
            return NULL;
        ynode *m = ynode_new(YNODE_MAP, NULL, v->mark);
        if (!m || ynode_push(m, ynode_new(YNODE_SCALAR, "points", v->mark)) < 0 ||
            ynode_push(m, pts) < 0) {
            ytree_free(m);
            return NULL;
        }
        return m;
    }
    ynode *m = ytree_copy(v);
    if (!m || replace_value(m, "points", pts) < 0)
        return ytree_free(m), NULL;
    const ynode *center = ymap_get(v, "center");
    if (center && center->kind == YNODE_SEQ &&
        replace_value(m, "center", local_of_global(ld, fr, center)) < 0)
        return ytree_free(m), NULL;
    return m;
}

/* The angle of a slider's line in its guide's frame: from the drawing
 * (through -> slider point) when left out; else the global angle given,
 * which the slider point must lie on. */
static int rewrite_slider(loader *ld, const frame *f, int nf, ynode *j)
{
    const ynode *pn = ymap_get(j, "slider"), *on = ymap_get(j, "on"), *tn = ymap_get(j, "through"),
                *ang = ymap_get(j, "angle");
    if (!pn || !on || !tn || pn->kind != YNODE_SCALAR || on->kind != YNODE_SCALAR ||
        tn->kind != YNODE_SCALAR)
        return 0;  /* reported by load_joints */
    int b = drawn_index(ld, pn->text), t = drawn_index(ld, tn->text), g = frame_of(f, nf, on->text);
    if (b < 0 || t < 0 || g < 0)
        return 0;
    const char *guide = g ? f[g].angle : NULL;
    char *text;
    if (!ang) {
        if (!drawn_apart(ld, t, b))
            return load_err(ld, tn, "slider '%s': the slider point and its 'through' point '%s' "
                                    "are drawn at one place, so they give the guide no "
                                    "direction; give 'angle'", pn->text, tn->text), -1;
        char *dir = direction(ld, t, b);
        text = dir && guide ? textf("%s - %s", dir, guide) : dir ? xstrdup(dir) : NULL;
        free(dir);
    } else {
        double a;
        if (!load_get_quantity(ld, ang, Q_ANGLE, "slider line angle", &a))
            return -1;
        const double *pb = ld->drawn[b].xy, *pt = ld->drawn[t].xy;
        double off = (pb[0] - pt[0]) * sin(a) - (pb[1] - pt[1]) * cos(a);
        double size = fmax(fmax(fabs(pb[0]), fabs(pb[1])), fmax(fabs(pt[0]), fabs(pt[1])));
        if (fabs(off) > 1e-9 * fmax(size, 1e-9))
            return load_err(ld, pn, "slider point '%s' is drawn %.6g mm off its guide (the line "
                                    "through '%s' at %.6g deg)", pn->text, fabs(off) * 1e3,
                            tn->text, a * 180.0 / 3.14159265358979323846), -1;
        text = guide ? textf("(%s) - %s", ang->text, guide) : NULL;
        if (!guide)
            return 0;  /* on the ground: the angle as written */
    }
    if (!text)
        return load_nomem(ld, j), -1;
    ynode *v = ynode_new(YNODE_SCALAR, text, ang ? ang->mark : pn->mark);
    free(text);
    if (!v)
        return load_nomem(ld, j), -1;
    if (ang)
        return replace_value(j, "angle", v);
    if (ynode_push(j, ynode_new(YNODE_SCALAR, "angle", pn->mark)) < 0 || ynode_push(j, v) < 0)
        return load_nomem(ld, j), -1;
    return 0;
}

static int rewrite_joints(loader *ld, const frame *f, int nf, ynode *joints)
{
    int ok = 1;
    for (size_t i = 0; joints && joints->kind == YNODE_SEQ && i < joints->n; i++) {
        ynode *j = joints->items[i];
        if (j->kind == YNODE_MAP && ymap_get(j, "slider") && rewrite_slider(ld, f, nf, j) < 0)
            ok = 0;
    }
    return ok;
}

/* The frames of the links: [0] the ground. */
static frame *frames_of(loader *ld, const ynode *links, const ynode *joints, int *nf)
{
    *nf = 1 + (int)(links && links->kind == YNODE_MAP ? links->n : 0);
    frame *f = xcalloc((size_t)*nf, sizeof *f);
    if (!f)
        return NULL;
    f[0].name = "ground";
    for (int i = 1; i < *nf; i++) {
        f[i].key = links->items[2 * (i - 1)];
        f[i].name = f[i].key->kind == YNODE_SCALAR ? f[i].key->text : "";
        f[i].points = points_of(links->items[2 * i - 1]);
        f[i].guide = -1;
        f[i].origin = -1;
        if (!f[i].points || f[i].points->kind != YNODE_SEQ)
            f[i].points = NULL, f[i].done = 1;  /* reported by rewrite_link */
    }
    find_locked(f, *nf, joints);
    make_frames(ld, f, *nf);
    return f;
}

static void free_frames(frame *f, int nf)
{
    for (int i = 0; f && i < nf; i++)
        free(f[i].angle);
    free(f);
}

/* Links whose value is not a list of names (a local form's mapping). */
static int rewrite_links(loader *ld, const frame *f, int nf, ynode *links)
{
    int ok = 1;
    for (int i = 1; i < nf; i++) {
        const ynode *v = links->items[2 * i - 1];
        const ynode *pts = points_of(v);
        if (pts && pts->kind != YNODE_SEQ) {
            char link[96];
            snprintf(link, sizeof link, "link '%s'", f[i].name);
            rewrite_points(ld, NULL, pts, link);  /* reports the shape */
            ok = 0;
            continue;
        }
        ynode *nv = rewrite_link(ld, &f[i], v);
        if (!nv) {
            ok = 0;
            continue;
        }
        ytree_free(links->items[2 * i - 1]);
        links->items[2 * i - 1] = nv;
    }
    return ok;
}

static void warn_undrawn_use(loader *ld)
{
    for (int i = 0; i < ld->ndrawn; i++)
        if (ld->drawn[i].name && !ld->drawn[i].on_link)
            diag_warning(ld->d, ld->file, ld->drawn[i].mark, "point '%s' is drawn but on no "
                         "link and not on the ground", ld->drawn[i].name);
}

const ynode *load_drawn_tree(loader *ld, const ynode *root, const ynode *drawing)
{
    size_t errors = ld->d->nerrors;
    if (!read_drawing(ld, drawing))
        return NULL;
    ynode *copy = ytree_copy(root);
    if (!copy)
        return load_nomem(ld, root), NULL;
    ld->drawn_root = copy;
    ynode *links = ymap_get(copy, "links"), *joints = ymap_get(copy, "joints"),
          *ground = ymap_get(copy, "ground");
    if (links && links->kind != YNODE_MAP)
        return copy;  /* reported by load_links */
    int nf = 0;
    frame *f = frames_of(ld, links, joints, &nf);
    if (!f)
        return load_nomem(ld, root), NULL;
    if (ground && ld->d->nerrors == errors)
        replace_value(copy, "ground", rewrite_points(ld, NULL, ground, "the ground"));
    if (ld->d->nerrors == errors)
        rewrite_joints(ld, f, nf, joints);  /* before the links: the frames are theirs */
    if (ld->d->nerrors == errors && links)
        rewrite_links(ld, f, nf, links);
    free_frames(f, nf);
    if (ld->d->nerrors != errors)
        return NULL;
    warn_undrawn_use(ld);
    return copy;
}

int load_drawn_at(const loader *ld, int id, double xy[2])
{
    if (!ld->drawn)
        return 0;
    int i = drawn_index(ld, ld->m->point_names[id]);
    if (i < 0)
        return 0;
    xy[0] = ld->drawn[i].xy[0];
    xy[1] = ld->drawn[i].xy[1];
    return 1;
}
