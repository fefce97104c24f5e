/* src/solve/pose.c: the pose a file states for its mechanism, drawn beside the
 * assembled one by `mech draw` (docs/plots.md, "mech draw"). Today that is
 * the solver's first Newton iterate at row 0 (continuation.c,
 * cont_start_values): each unknown at its `initial:` guess, else 0, the
 * drivers at their values, and the link frames placed along the spanning
 * tree from the ground (kinematics.c), so a loop the guesses do not close
 * shows its gap. A file in the drawn form has its drawing's positions as
 * its guesses (load_guess.c), so the same iterate at the drawn driver
 * value is the drawing (mech_pose.kind MECH_POSE_DRAWN). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "load.h"
#include "solve.h"

void mech_pose_free(mech_pose *p)
{
    if (!p)
        return;
    free(p->frame);
    memset(p, 0, sizeof *p);
}

/* The first iterate: guesses, zeros, the drivers at q; pos[n] is q. */
static void first_iterate(const mech_model *m, const mech_system *s, double q, double *pos)
{
    for (int i = 0; i < s->n; i++)
        pos[i] = 0.0;
    for (int g = 0; g < m->nguesses; g++) {
        const mech_guess *gs = &m->guesses[g];
        int var = gs->is_slider ? s->joint_var[gs->index] : s->link_var[gs->index];
        if (var >= 0 && var < s->n)
            pos[var] = gs->value;
    }
    drivers_guess(m, s->link_var, s->joint_var, q, pos);
    pos[s->n] = q;
}

/* Every link's frame placed by kin_update from pos (n + 1 values). */
static int place_frames(const mech_model *m, const mech_system *s, const double *pos,
                        double *frame)
{
    kin_tree kt;
    kin_state ks;
    if (kin_tree_build(&kt, s) != MECH_OK)
        return MECH_ENOMEM;
    double *attach = xcalloc(4 * (size_t)m->nlinks + 1, sizeof *attach);
    if (!attach || kin_state_init(&ks, m) != 0) {
        free(attach);
        kin_tree_free(&kt);
        return MECH_ENOMEM;
    }
    kt.attach = attach;
    kin_tree_numbers(&kt, m);
    for (int l = 1; l < m->nlinks; l++)
        kt.active[l] = 1;
    kin_tree_finish(&kt);
    kin_update(&kt, &ks, pos, NULL, NULL);
    for (int l = 0; l < m->nlinks; l++) {
        int placed = l == 0 || kt.span->depth[l] >= 0;
        frame[3 * l] = placed ? ks.F[l].o[0] : NAN;
        frame[3 * l + 1] = placed ? ks.F[l].o[1] : NAN;
        frame[3 * l + 2] = placed ? ks.F[l].th : NAN;
    }
    kin_state_free(&ks);
    kin_tree_free(&kt);
    free(attach);
    return MECH_OK;
}

int mech_pose_guess(const mech_model *m, double q, mech_pose *out, mech_diag *d)
{
    if (out)
        memset(out, 0, sizeof *out);
    if (!m || !out) {
        mech_diag own, *dd = api_diag(d, &own);
        int rc = api_null(dd, "mech_pose_guess", m ? "out" : "m");
        api_diag_end(d, &own);
        return rc;
    }
    mech_system *s = NULL;
    int rc = mech_system_new(m, &s, d);
    if (rc != MECH_OK)
        return rc;
    double *pos = xcalloc((size_t)s->n + 1, sizeof *pos);
    out->frame = xcalloc(3 * (size_t)m->nlinks, sizeof *out->frame);
    rc = pos && out->frame ? MECH_OK : MECH_ENOMEM;
    if (rc == MECH_OK) {
        first_iterate(m, s, q, pos);
        rc = place_frames(m, s, pos, out->frame);
    }
    free(pos);
    mech_system_free(&s);
    if (rc != MECH_OK) {
        mech_pose_free(out);
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    }
    out->kind = m->has_start ? MECH_POSE_DRAWN  /* the drawing's positions are the guesses */
                : m->nguesses > 0 ? MECH_POSE_GUESSED : MECH_POSE_NONE;
    out->q = q;
    out->nlinks = m->nlinks;
    return MECH_OK;
}

void mech_pose_point(const mech_model *m, const mech_pose *p, int link, int k, double xy[2])
{
    if (!m || !p || !xy)
        return;
    if (!p->frame || p->nlinks != m->nlinks || link < 0 || link >= m->nlinks || k < 0 ||
        k >= m->links[link].npoints) {
        xy[0] = xy[1] = NAN;  /* no such point in this pose */
        return;
    }
    const double *f = p->frame + 3 * link;
    const mech_point *pt = &m->links[link].points[k];
    double c = cos(f[2]), s = sin(f[2]);
    xy[0] = f[0] + c * pt->x - s * pt->y;
    xy[1] = f[1] + s * pt->x + c * pt->y;
}
