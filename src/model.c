/* src/model.c: the loaded model: lookups, release, and the structural check
 * (connectivity, Gruebler-Kutzbach mobility, unknowns against equations). */
#include <stdlib.h>
#include <string.h>

#include "internal.h"

int model_point_in_link(const mech_link *l, int name_id)
{
    for (int i = 0; i < l->npoints; i++)
        if (l->points[i].id == name_id)
            return i;
    return -1;
}

int mech_find_link(const mech_model *m, const char *name)
{
    for (int i = 0; i < m->nlinks; i++)
        if (m->links[i].name && strcmp(m->links[i].name, name) == 0)
            return i;
    return -1;
}

int mech_find_joint(const mech_model *m, const char *name)
{
    for (int i = 0; i < m->njoints; i++)
        if (m->joints[i].name && strcmp(m->joints[i].name, name) == 0)
            return i;
    return -1;
}

int mech_find_point(const mech_model *m, const char *name)
{
    for (int i = 0; i < m->npoint_names; i++)
        if (strcmp(m->point_names[i], name) == 0)
            return i;
    return -1;
}

void mech_model_free(mech_model **pm)
{
    mech_model *m = pm ? *pm : NULL;
    if (!m)
        return;
    for (int i = 0; i < m->nparams; i++)
        free(m->params[i].name);
    free(m->params);
    for (int i = 0; i < m->nlinks; i++) {
        mech_link *l = &m->links[i];
        for (int p = 0; p < l->npoints; p++)
            free(l->points[p].name);
        free(l->points);
        free(l->name);
        free(l->symbol);
    }
    free(m->links);
    for (int i = 0; i < m->njoints; i++) {
        free(m->joints[i].name);
        free(m->joints[i].symbol);
    }
    free(m->joints);
    for (int i = 0; i < m->npoint_names; i++)
        free(m->point_names[i]);
    free(m->point_names);
    free(m->driver.values);
    free(m->guesses);
    free(m->branches);
    for (int i = 0; i < m->nloops; i++) {
        free(m->loops[i].points);
        free(m->loops[i].marks);
    }
    free(m->loops);
    free(m->loads);
    free(m->outputs.points);
    free(m->outputs.links);
    free(m->outputs.sliders);
    free(m->file);
    free(m->name);
    free(m->description);
    free(m);
    *pm = NULL;
}

/* ---- structure ------------------------------------------------------ */

static int root_of(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* Links not joined to the ground through any chain of joints. */
static int check_connected(const mech_model *m, int *parent, mech_diag *d)
{
    for (int i = 0; i < m->nlinks; i++)
        parent[i] = i;
    for (int j = 0; j < m->njoints; j++)
        parent[root_of(parent, m->joints[j].link[0])] = root_of(parent, m->joints[j].link[1]);
    int bad = 0;
    for (int i = 1; i < m->nlinks; i++)
        if (root_of(parent, i) != root_of(parent, 0)) {
            diag_error(d, m->file, m->links[i].mark,
                       "link '%s' is not connected to the ground by any chain of joints",
                       m->links[i].name);
            bad = 1;
        }
    return !bad;
}

/* A moving link held by a single joint turns (or slides) freely, unless it is
 * the driven one. */
static int report_dangling(const mech_model *m, const int *njoints_of, mech_diag *d)
{
    int found = 0;
    for (int i = 1; i < m->nlinks; i++) {
        int driven = m->has_driver && m->driver.kind == MECH_DRIVE_ANGLE && m->driver.index == i;
        if (m->has_driver && m->driver.kind == MECH_DRIVE_SLIDER &&
            m->joints[m->driver.index].link[0] == i)
            driven = 1;
        if (njoints_of[i] == 1 && !driven) {
            diag_error(d, m->file, m->links[i].mark,
                       "link '%s' is attached by a single joint, so nothing fixes its position: "
                       "join it to another link or drive it", m->links[i].name);
            found = 1;
        }
    }
    return found;
}

/* Rigid sub-structures: two links joined twice, or three links pinned in a
 * triangle. Returns 1 when one was named. */
static int report_rigid(const mech_model *m, mech_diag *d)
{
    int found = 0;
    for (int a = 0; a < m->njoints && found < 3; a++)
        for (int b = a + 1; b < m->njoints && found < 3; b++) {
            const mech_joint *ja = &m->joints[a], *jb = &m->joints[b];
            int same = (ja->link[0] == jb->link[0] && ja->link[1] == jb->link[1]) ||
                       (ja->link[0] == jb->link[1] && ja->link[1] == jb->link[0]);
            if (same) {
                diag_note(d, m->file, jb->mark,
                          "links '%s' and '%s' are joined twice (joints '%s' and '%s'): together "
                          "they are one rigid body", m->links[ja->link[0]].name,
                          m->links[ja->link[1]].name, ja->name, jb->name);
                found++;
            }
        }
    return found;
}

static void count_joints(const mech_model *m, mech_summary *s, int *njoints_of)
{
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        if (jt->kind == MECH_JOINT_REVOLUTE)
            s->nrevolute++;
        else if (jt->locked)
            s->nprismatic++;
        else
            s->npin_in_slot++;
        njoints_of[jt->link[0]]++;
        njoints_of[jt->link[1]]++;
    }
}

int mech_check(const mech_model *m, mech_summary *s, mech_diag *d)
{
    memset(s, 0, sizeof *s);
    s->nlinks = m->nlinks;
    s->ndrivers = m->has_driver ? 1 : 0;
    int *work = xcalloc((size_t)m->nlinks, sizeof *work);
    int *njoints_of = xcalloc((size_t)m->nlinks, sizeof *njoints_of);
    if (!work || !njoints_of) {
        free(work);
        free(njoints_of);
        return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    }
    count_joints(m, s, njoints_of);
    int joints = m->njoints;
    int nangles = m->nlinks - 1 - s->nprismatic;
    int nsliders = s->nprismatic + s->npin_in_slot;
    s->nunknowns = nangles + nsliders - s->ndrivers;
    s->nloops = joints - m->nlinks + 1;
    s->nequations = 2 * s->nloops;
    s->mobility = 3 * (m->nlinks - 1) - 2 * (s->nrevolute + s->nprismatic) - s->npin_in_slot;
    size_t before = d->nerrors;
    int connected = check_connected(m, work, d);
    int dangling = report_dangling(m, njoints_of, d);
    if (connected && !dangling && s->mobility != s->ndrivers) {
        mech_mark at = m->has_driver ? m->driver.mark : (mech_mark){0, 0};
        if (s->mobility > s->ndrivers) {
            diag_error(d, m->file, at,
                       "under-constrained: the mechanism has %d degrees of freedom "
                       "(Gruebler: 3*(%d-1) - 2*%d - %d) but %d driver; %d unknowns for %d loop "
                       "equations. Add a joint or a link, or lock a slider",
                       s->mobility, m->nlinks, s->nrevolute + s->nprismatic, s->npin_in_slot,
                       s->ndrivers, s->nunknowns, s->nequations);
        } else {
            diag_error(d, m->file, at,
                       "over-constrained: the mechanism has %d degree%s of freedom "
                       "(Gruebler: 3*(%d-1) - 2*%d - %d) but %d driver; %d unknowns for %d loop "
                       "equations. Remove a joint or free a slider's rotation",
                       s->mobility, s->mobility == 1 || s->mobility == -1 ? "" : "s", m->nlinks,
                       s->nrevolute + s->nprismatic, s->npin_in_slot, s->ndrivers,
                       s->nunknowns, s->nequations);
            report_rigid(m, d);
        }
    }
    if (!m->has_driver)
        diag_error(d, m->file, (mech_mark){0, 0}, "the mechanism has no driver");
    free(work);
    free(njoints_of);
    return d->nerrors > before ? MECH_EINPUT : MECH_OK;
}
