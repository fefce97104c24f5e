/* src/load/load_joints.c: the loader's 'joints' (explicit revolutes and
 * sliders), the index of the links carrying each point name, the implicit
 * revolutes of point names shared by links, and the checks that each link
 * has enough points and at most one locked slider. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "load.h"

/* ---- joints --------------------------------------------------------- */

static mech_joint *new_joint(loader *ld)
{
    mech_model *m = ld->m;
    if ((m->njoints & (m->njoints - 1)) == 0) {
        size_t cap = m->njoints ? 2 * (size_t)m->njoints : 4;
        mech_joint *j = xrealloc_array(m->joints, cap, sizeof *j);
        if (!j)
            return NULL;
        m->joints = j;
    }
    mech_joint *j = &m->joints[m->njoints++];
    memset(j, 0, sizeof *j);
    return j;
}

static void set_joint_name(loader *ld, mech_joint *j, const ynode *name_node, const char *deflt)
{
    mech_model *m = ld->m;
    if (name_node) {
        const char *name = load_get_name(ld, name_node, "joint name");
        if (name) {
            int other = find_joint(ld, name);
            if (other >= 0)
                load_err(ld, name_node, "duplicate joint name '%s' (first used at line %d)", name,
                         m->joints[other].mark.line);
            else
                j->name = xstrdup(name);
        }
        if (j->name) {
            name_map_put(&ld->joint_map, j->name, (int)(j - m->joints));
            return;
        }
    }
    /* a default name, made unique with a suffix; the suffixes below the one
     * remembered for this default are all taken (a pin on 10^5 links would
     * otherwise try 2, 3, ... again for each of its joints) */
    char buf[MAX_NAME + 16];
    int k = name_map_get(&ld->next_suffix, deflt);
    snprintf(buf, sizeof buf, "%s", deflt);
    for (k = k < 2 ? 2 : k; find_joint(ld, buf) >= 0; k++)
        snprintf(buf, sizeof buf, "%s_%d", deflt, k);
    j->name = xstrdup(buf);
    if (!j->name)
        return (void)load_nomem(ld, name_node);
    name_map_put(&ld->joint_map, j->name, (int)(j - m->joints));
    int first = find_joint(ld, deflt);  /* its name outlives the map: a stable key */
    if (first >= 0)
        name_map_put(&ld->next_suffix, m->joints[first].name, k);
}

static int get_friction(loader *ld, const ynode *map, mech_joint *j)
{
    const ynode *f = ymap_get(map, "friction"), *r = ymap_get(map, "pin_radius");
    if (f && load_get_quantity(ld, f, Q_NUMBER, "friction coefficient", &j->friction) &&
        (j->friction < 0 || j->friction > 10))
        load_err(ld, f, "friction coefficient %g is out of range (0 to 10)", j->friction);
    if (r && load_get_quantity(ld, r, Q_LENGTH, "pin radius", &j->pin_radius) && j->pin_radius < 0)
        load_err(ld, r, "pin radius is negative");
    if (j->friction > 0 && j->kind == MECH_JOINT_REVOLUTE && !r)
        return load_err(ld, load_key_of(map, "friction"),
                        "revolute joint '%s' has friction but no 'pin_radius' (the friction "
                        "moment needs the pin radius)", j->name), 0;
    return 1;
}

static void load_revolute(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"revolute", "links", "name", "friction", "pin_radius"};
    mech_model *m = ld->m;
    load_check_keys(ld, map, keys, COUNT(keys), "a revolute joint");
    const ynode *pn = ymap_get(map, "revolute"), *ln = ymap_get(map, "links");
    int id = load_find_point_or_report(ld, pn, "joint point");
    if (id < 0)
        return;
    int carriers[2], nc = 0;
    if (ln) {
        if (ln->kind != YNODE_SEQ || ln->n != 2) {
            load_err(ld, ln, "'links' of a revolute joint must list two links [a, b]");
            return;
        }
        for (int i = 0; i < 2; i++) {
            int li = load_find_link_or_report(ld, ln->items[i], "link");
            if (li < 0)
                return;
            if (load_point_in_link(ld, li, id) < 0) {
                load_err(ld, ln->items[i], "link '%s' has no point '%s'", m->links[li].name, pn->text);
                return;
            }
            carriers[nc++] = li;
        }
        if (carriers[0] == carriers[1]) {
            load_err(ld, ln, "a revolute joint joins two different links");
            return;
        }
    } else {
        int first, end;
        load_carriers_of(ld, id, &first, &end);
        for (int c = first; c < end; c++) {
            if (nc == 2) {
                load_err(ld, pn, "point '%s' is on more than two links; say which two this joint "
                                 "joins with 'links: [a, b]'", pn->text);
                return;
            }
            carriers[nc++] = ld->carrier_link[c];
        }
        if (nc < 2) {
            load_err(ld, pn, "point '%s' is on only one link; a revolute joint needs it on two",
                     pn->text);
            return;
        }
    }
    mech_joint *j = new_joint(ld);
    if (!j)
        return (void)load_nomem(ld, map);
    j->kind = MECH_JOINT_REVOLUTE;
    j->is_explicit = 1;
    j->mark = map->mark;
    for (int i = 0; i < 2; i++) {
        j->link[i] = carriers[i];
        j->point[i] = load_point_in_link(ld, carriers[i], id);
    }
    set_joint_name(ld, j, ymap_get(map, "name"), pn->text);
    get_friction(ld, map, j);
}

static int load_slider_joint(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"slider", "link", "on", "through", "angle",
                                       "rotation", "name", "symbol", "friction"};
    mech_model *m = ld->m;
    load_check_keys(ld, map, keys, COUNT(keys), "a slider joint");
    const ynode *pn = ymap_get(map, "slider"), *on = ymap_get(map, "on"),
                *through = ymap_get(map, "through"), *ln = ymap_get(map, "link"),
                *ang = ymap_get(map, "angle"), *rot = ymap_get(map, "rotation");
    const char *missing = !on ? "on" : !through ? "through" : !ang ? "angle" : NULL;
    if (missing)
        return load_err(ld, map, "slider joint is missing '%s' (%s)", missing,
                        !on ? "the link that carries the guide line"
                            : !through ? "a point of the guide link on the line"
                                       : "the line's direction"), 0;
    int id = load_find_point_or_report(ld, pn, "slider point");
    int guide = load_find_link_or_report(ld, on, "guide link");
    if (id < 0 || guide < 0)
        return 0;
    int mover = -1;
    if (ln) {
        mover = load_find_link_or_report(ld, ln, "sliding link");
        if (mover < 0)
            return 0;
        if (load_point_in_link(ld, mover, id) < 0)
            return load_err(ld, ln, "link '%s' has no point '%s'", m->links[mover].name, pn->text), 0;
    } else {
        int nc = 0, first, end;
        load_carriers_of(ld, id, &first, &end);
        for (int c = first; c < end; c++)
            if (ld->carrier_link[c] != guide)
                mover = ld->carrier_link[c], nc++;
        if (nc != 1)
            return load_err(ld, pn, "point '%s' is on %d links; say which one slides with "
                                    "'link: name'", pn->text, nc), 0;
    }
    if (mover == guide)
        return load_err(ld, on, "a slider's link and its guide ('on') must differ"), 0;
    if (load_point_in_link(ld, guide, id) >= 0)
        return load_err(ld, pn, "the guide link '%s' also has a point '%s'; the sliding point "
                                "must be a point of the moving link only", m->links[guide].name,
                        pn->text), 0;
    int tid = load_find_point_or_report(ld, through, "'through' point");
    if (tid < 0)
        return 0;
    int tp = load_point_in_link(ld, guide, tid);
    if (tp < 0)
        return load_err(ld, through, "'through: %s' must be a point of the guide link '%s'",
                        through->text, m->links[guide].name), 0;
    mech_joint *j = new_joint(ld);
    if (!j)
        return load_nomem(ld, map), 0;
    j->kind = MECH_JOINT_SLIDER;
    j->is_explicit = 1;
    j->mark = map->mark;
    j->link[0] = mover;
    j->point[0] = load_point_in_link(ld, mover, id);
    j->link[1] = guide;
    j->point[1] = tp;
    j->locked = 1;
    int h;
    if (load_get_quantity_expr(ld, ang, Q_ANGLE, "slider line angle", &j->angle, &h) &&
        m->pexpr)
        pexpr_set(m->pexpr, PXN_SLIDER_ANGLE, (int)(j - m->joints), h);
    if (rot) {
        if (rot->kind == YNODE_SCALAR && strcmp(rot->text, "free") == 0)
            j->locked = 0;
        else if (!(rot->kind == YNODE_SCALAR && strcmp(rot->text, "locked") == 0))
            load_err(ld, rot, "rotation must be 'locked' (prismatic) or 'free' (pin in slot)");
    }
    char deflt[MAX_NAME + 3];
    snprintf(deflt, sizeof deflt, "s_%s", pn->text);
    set_joint_name(ld, j, ymap_get(map, "name"), deflt);
    const ynode *sym = ymap_get(map, "symbol");
    if (sym)
        j->symbol = load_get_string(ld, sym, "symbol", 32, 0);
    get_friction(ld, map, j);
    return 1;
}

/* A slider that could not be made leaves its block with a single point:
 * that link is not also reported as having too few points. */
static void load_slider(loader *ld, const ynode *map)
{
    if (load_slider_joint(ld, map))
        return;
    const ynode *pn = ymap_get(map, "slider");
    int id = pn && pn->kind == YNODE_SCALAR ? find_point(ld, pn->text) : -1;
    int first, end;
    load_carriers_of(ld, id, &first, &end);
    for (int c = first; c < end; c++)
        ld->link_failed[ld->carrier_link[c]] |= LINK_FAILED;
}

/* Index the links that carry each point name (see load_carriers_of); points are
 * all known once the links are read. */
void load_index_carriers(loader *ld)
{
    mech_model *m = ld->m;
    size_t n = (size_t)m->npoint_names, total = 0;
    for (int li = 0; li < m->nlinks; li++)
        total += (size_t)m->links[li].npoints;
    ld->carrier_start = xcalloc(n + 2, sizeof *ld->carrier_start);
    ld->carrier_link = xcalloc(total, sizeof *ld->carrier_link);
    ld->carrier_point = xcalloc(total, sizeof *ld->carrier_point);
    if (!ld->carrier_start || !ld->carrier_link || !ld->carrier_point)
        return (void)load_nomem(ld, NULL);
    int *fill = ld->carrier_start + 1;  /* counts, then the next free slot of each id */
    for (int li = 0; li < m->nlinks; li++)
        for (int p = 0; p < m->links[li].npoints; p++)
            if (m->links[li].points[p].id >= 0)
                fill[m->links[li].points[p].id + 1]++;
    for (size_t i = 0; i < n; i++)
        fill[i + 1] += fill[i];
    for (int li = 0; li < m->nlinks; li++)  /* in link order: each id's carriers ascend */
        for (int p = 0; p < m->links[li].npoints; p++) {
            int id = m->links[li].points[p].id;
            if (id < 0)
                continue;
            ld->carrier_link[fill[id]] = li;
            ld->carrier_point[fill[id]++] = p;
        }
    /* fill[id] is now the end of id's carriers, i.e. carrier_start[id + 1] */
    ld->carrier_start[0] = 0;
    ld->carrier_ids = (int)n;
}

void load_joints(loader *ld, const ynode *seq)
{
    if (!load_want_kind(ld, seq, YNODE_SEQ, "'joints'"))
        return;
    if (seq->n > MAX_LIST)
        return (void)load_err(ld, seq, "too many joints (%zu; at most %d)", seq->n, MAX_LIST);
    for (size_t i = 0; i < seq->n; i++) {
        const ynode *j = seq->items[i];
        if (!load_want_kind(ld, j, YNODE_MAP, "a joint"))
            continue;
        const ynode *r = ymap_get(j, "revolute"), *s = ymap_get(j, "slider");
        if (r && s)
            load_err(ld, j, "a joint is either 'revolute' or 'slider', not both");
        else if (r)
            load_revolute(ld, j);
        else if (s)
            load_slider(ld, j);
        else
            load_err(ld, j, "a joint needs 'revolute: POINT' or 'slider: POINT'");
    }
}

/* Union-find over the links carrying one point name (local indices). */
static int uf_find(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

static int local_index(const int *carrier, int k, int link)
{
    for (int i = 0; i < k; i++)
        if (carrier[i] == link)
            return i;
    return -1;
}

/* Pin together the links that carry point `id` (carrier[0..k-1], point index
 * cpoint[]), adding revolutes to the first carrier where the explicit joints
 * at that point (joint indices ej[0..ne-1]) leave them apart. */
static void pin_carriers(loader *ld, int id, const int *carrier, const int *cpoint, int k,
                         const int *ej, int ne, int *parent)
{
    mech_model *m = ld->m;
    for (int i = 0; i < k; i++)
        parent[i] = i;
    for (int e = 0; e < ne; e++) {
        const mech_joint *j = &m->joints[ej[e]];
        int a = local_index(carrier, k, j->link[0]), b = local_index(carrier, k, j->link[1]);
        parent[uf_find(parent, a)] = uf_find(parent, b);
    }
    for (int c = 1; c < k; c++) {
        if (uf_find(parent, c) == uf_find(parent, 0))
            continue;
        parent[uf_find(parent, c)] = uf_find(parent, 0);
        mech_joint *j = new_joint(ld);
        if (!j)
            return (void)load_nomem(ld, NULL);
        j->kind = MECH_JOINT_REVOLUTE;
        j->link[0] = carrier[0];
        j->point[0] = cpoint[0];
        j->link[1] = carrier[c];
        j->point[1] = cpoint[c];
        j->mark = m->links[carrier[c]].points[cpoint[c]].mark;
        set_joint_name(ld, j, NULL, m->point_names[id]);
    }
}

/* Every point name on two or more links pins them together: add the revolute
 * joints that the explicit ones do not already provide. Linear in the number
 * of points (grouped by name in compressed-row form). */
void load_add_implicit_revolutes(loader *ld)
{
    mech_model *m = ld->m;
    size_t n = (size_t)m->npoint_names, total = 0;
    for (int li = 0; li < m->nlinks; li++)
        total += (size_t)m->links[li].npoints;
    int nexplicit = m->njoints;
    int *start = xcalloc(n + 1, sizeof *start);          /* carriers of id: start[id]..start[id+1] */
    int *carrier = xcalloc(total, sizeof *carrier), *cpoint = xcalloc(total, sizeof *cpoint);
    int *estart = xcalloc(n + 1, sizeof *estart);        /* explicit revolutes by point id */
    int *ej = xcalloc((size_t)nexplicit, sizeof *ej);
    int *fill = xcalloc(n + 1, sizeof *fill), *parent = xcalloc(total, sizeof *parent);
    if (!start || !carrier || !cpoint || !estart || !ej || !fill || !parent) {
        load_nomem(ld, NULL);
        goto done;
    }
    for (int li = 0; li < m->nlinks; li++)
        for (int p = 0; p < m->links[li].npoints; p++)
            start[m->links[li].points[p].id + 1]++;
    for (int ji = 0; ji < nexplicit; ji++)
        if (m->joints[ji].kind == MECH_JOINT_REVOLUTE)
            estart[m->links[m->joints[ji].link[0]].points[m->joints[ji].point[0]].id + 1]++;
    for (size_t i = 0; i < n; i++) {
        start[i + 1] += start[i];
        estart[i + 1] += estart[i];
    }
    for (int li = 0; li < m->nlinks; li++)
        for (int p = 0; p < m->links[li].npoints; p++) {
            int id = m->links[li].points[p].id, at = start[id] + fill[id]++;
            carrier[at] = li;
            cpoint[at] = p;
        }
    memset(fill, 0, (n + 1) * sizeof *fill);
    for (int ji = 0; ji < nexplicit; ji++)
        if (m->joints[ji].kind == MECH_JOINT_REVOLUTE) {
            int id = m->links[m->joints[ji].link[0]].points[m->joints[ji].point[0]].id;
            ej[estart[id] + fill[id]++] = ji;
        }
    for (size_t id = 0; id < n; id++) {
        int k = start[id + 1] - start[id];
        if (k >= 2)
            pin_carriers(ld, (int)id, carrier + start[id], cpoint + start[id], k,
                         ej + estart[id], estart[id + 1] - estart[id], parent);
    }
done:
    free(start);
    free(carrier);
    free(cpoint);
    free(estart);
    free(ej);
    free(fill);
    free(parent);
}

/* Do all the points of link `l` coincide (within 1e-12 of the link's
 * largest coordinate, the rounding of polar points)? Then its angle is
 * undefined. */
static int points_coincide(const mech_link *l)
{
    double scale = 0, spread = 0;
    for (int i = 0; i < l->npoints; i++) {
        scale = fmax(scale, fmax(fabs(l->points[i].x), fabs(l->points[i].y)));
        spread = fmax(spread, fmax(fabs(l->points[i].x - l->points[0].x),
                                   fabs(l->points[i].y - l->points[0].y)));
    }
    return spread <= 1e-12 * scale;
}

/* Links need two distinct points, unless a slider carries them (a piston
 * block); a link is held by at most one locked slider. One pass over the joints, with
 * per-link marks, so that many links or sliders stay linear. */
void load_check_link_points(loader *ld)
{
    mech_model *m = ld->m;
    int *locked_by = xcalloc((size_t)m->nlinks, sizeof *locked_by); /* 1 + joint, or 0 */
    unsigned char *slides = xcalloc((size_t)m->nlinks, sizeof *slides);
    if (!locked_by || !slides) {
        load_nomem(ld, NULL);
        goto done;
    }
    for (int ji = 0; ji < m->njoints; ji++)
        if (m->joints[ji].kind == MECH_JOINT_SLIDER)
            slides[m->joints[ji].link[0]] = 1;
    for (int g = 0; g < m->ngears; g++)  /* a gear turning on its pivot: one point will do */
        slides[m->gears[g].link[0]] = slides[m->gears[g].link[1]] = 1;
    for (int c = 0; c < model_ncams(m); c++)  /* a cam on its pivot likewise (a cam whose */
        if (m->cams->cam[c].cam > 0 && m->cams->cam[c].cam < m->nlinks)  /* link failed: -1) */
            slides[m->cams->cam[c].cam] = 1;
    for (int li = 1; li < m->nlinks; li++) {
        const mech_link *l = &m->links[li];
        if (!l->name || (ld->link_failed[li] & LINK_FAILED) || slides[li])
            continue;
        if (l->npoints >= 2 && !(ld->link_failed[li] & LINK_UNPLACED) && points_coincide(l))
            diag_error(ld->d, ld->file, l->mark,
                       "link '%s': all its %d points are at the same place, so its angle is "
                       "undefined (a link needs two distinct points)", l->name, l->npoints);
        if (l->npoints >= 2)
            continue;
        diag_error(ld->d, ld->file, l->mark,
                   "link '%s' has %d point%s; a link needs at least two (only a slider "
                   "block may have one)", l->name, l->npoints, l->npoints == 1 ? "" : "s");
    }
    for (int ji = 0; ji < m->njoints; ji++) {
        const mech_joint *j = &m->joints[ji];
        if (j->kind != MECH_JOINT_SLIDER || !j->locked)
            continue;
        int first = locked_by[j->link[0]] - 1;
        if (first < 0)
            locked_by[j->link[0]] = ji + 1;
        else
            diag_error(ld->d, ld->file, j->mark,
                       "link '%s' is held by two locked sliders ('%s' and '%s'); make one "
                       "'rotation: free'", m->links[j->link[0]].name, m->joints[first].name,
                       j->name);
    }
done:
    free(locked_by);
    free(slides);
}

/* Do two names differ only in their digits ("P1", "P2")? A numbered
 * series, not a typo. */
static int differ_in_digits_only(const char *a, const char *b)
{
    for (;; a++, b++) {
        while (*a >= '0' && *a <= '9')
            a++;
        while (*b >= '0' && *b <= '9')
            b++;
        if (*a != *b)
            return 0;
        if (!*a)
            return 1;
    }
}

/* The point `name` is listed under `outputs: {points: [...]}` (the node
 * `outputs`, or NULL): a point of one link the file means to tabulate. */
static int named_output(const ynode *outputs, const char *name)
{
    const ynode *pts = outputs && outputs->kind == YNODE_MAP ? ymap_get(outputs, "points") : NULL;
    for (size_t i = 0; pts && pts->kind == YNODE_SEQ && i < pts->n; i++)
        if (pts->items[i]->kind == YNODE_SCALAR && strcmp(pts->items[i]->text, name) == 0)
            return 1;
    return 0;
}

/* A point name on one link only, in no joint, joins nothing: when it is
 * close to the name of a point of another link ("b" or "BB" where another
 * link has "B"), shared or not, it is likely a typo that left a point
 * unconnected; a warning at it (the later of the two in the file) names
 * the near one. Names differing only in digits (P1, P2) are a series, not
 * a typo, and a point named in `outputs` is one the file means to have on
 * one link only (a coupler point). Bounded: a file of very many points
 * skips it. */
void load_warn_point_typos(loader *ld, const ynode *outputs)
{
    mech_model *m = ld->m;
    int n = m->npoint_names;
    if (n == 0)
        return;
    int *count = xcalloc((size_t)n, sizeof *count), *first = xcalloc((size_t)n, sizeof *first);
    const char **cand = xcalloc((size_t)n, sizeof *cand);
    int *cand_link = xcalloc((size_t)n, sizeof *cand_link);
    if (!count || !first || !cand || !cand_link || n > 2000)
        goto done;
    for (int id = 0; id < n; id++)
        first[id] = -1;
    for (int li = 0; li < m->nlinks; li++)
        for (int p = 0; p < m->links[li].npoints; p++) {
            int id = m->links[li].points[p].id;
            if (id >= 0 && id < n) {
                count[id]++;
                if (first[id] < 0)
                    first[id] = li;
            }
        }
    for (int ji = 0; ji < m->njoints; ji++)  /* a point in a joint joins */
        for (int k = 0; k < 2; k++) {
            const mech_joint *j = &m->joints[ji];
            if (j->link[k] < 0 || j->link[k] >= m->nlinks || j->point[k] < 0 ||
                j->point[k] >= m->links[j->link[k]].npoints)
                continue;
            int id = m->links[j->link[k]].points[j->point[k]].id;
            if (id >= 0 && id < n)
                count[id] += 2;
        }
    size_t ncand = 0;  /* shared names, then the lone names of earlier links */
    for (int id = 0; id < n; id++)
        if (count[id] >= 2)
            cand_link[ncand] = first[id], cand[ncand++] = m->point_names[id];
    for (int li = 0; li < m->nlinks; li++) {
        size_t before = ncand;
        for (int p = 0; p < m->links[li].npoints; p++) {
            const mech_point *pt = &m->links[li].points[p];
            if (pt->id < 0 || pt->id >= n || count[pt->id] != 1 || !pt->name)
                continue;
            if (ncand < (size_t)n)
                cand_link[ncand] = li, cand[ncand++] = pt->name;
            const char *near = NULL;
            for (size_t i = 0; i < before && !near; i++)
                if (strcasecmp(pt->name, cand[i]) == 0 && cand_link[i] != li)
                    near = cand[i];
            if (!near)
                near = nearest_name(pt->name, cand, before);
            if (!near || differ_in_digits_only(pt->name, near) || named_output(outputs, pt->name))
                continue;
            int nl = -1;
            for (size_t i = 0; i < before && nl < 0; i++)
                if (cand[i] == near)
                    nl = cand_link[i];
            if (nl == li || nl < 0)
                continue;
            diag_warning(ld->d, ld->file, pt->mark,
                         "point '%s' of link '%s' is on no other link and in no joint, so it "
                         "joins nothing (did you mean '%s', as on link '%s'?)",
                         pt->name, m->links[li].name, near, m->links[nl].name);
        }
    }
done:
    free(count);
    free(first);
    free(cand);
    free(cand_link);
}
