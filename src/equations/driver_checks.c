/* src/equations/driver_checks.c: the drivers against the mechanism's
 * structure (the laws themselves are load/drivers.c's): over- and
 * under-driven against the mobility (mech check), and conflicting drivers
 * found in the system's rows by a maximum matching (solve.c). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <btf.h>

#include "equations.h"

void drivers_report_count(const mech_model *m, int mobility, mech_diag *d)
{
    int nd = drivers_rows(m);
    char list[512];
    size_t at = 0;
    list[0] = '\0';
    if (nd > mobility) {  /* the drivers past the mobility conflict with the others */
        for (int i = mobility; i < nd && at < sizeof list; i++)
            at += (size_t)snprintf(list + at, sizeof list - at, "%s'%s'", i > mobility ? ", " : "",
                                   drivers_name(m, i));
        diag_error(d, m->file, m->drivers[mobility].mark,
                   "over-driven: the mechanism has %d degree%s of freedom but %d drivers; the "
                   "driver%s of %s conflict%s with the others (remove %s)",
                   mobility, mobility == 1 ? "" : "s", nd, nd - mobility == 1 ? "" : "s", list,
                   nd - mobility == 1 ? "s" : "", nd - mobility == 1 ? "it" : "them");
        return;
    }
    /* the links on the ground, or sliding on it, that no law drives: one of
       them is left free */
    int count = 0;
    for (int j = 0; j < m->njoints && at < sizeof list; j++) {
        const mech_joint *jt = &m->joints[j];
        int l = jt->link[0] == 0 ? jt->link[1] : jt->link[1] == 0 ? jt->link[0] : -1;
        if (l <= 0)
            continue;
        int driven = jt->kind == MECH_JOINT_SLIDER ? drivers_of_slider(m, j) >= 0
                                                    : drivers_of_link(m, l) >= 0;
        if (driven)
            continue;
        const char *name = jt->kind == MECH_JOINT_SLIDER ? jt->name : m->links[l].name;
        at += (size_t)snprintf(list + at, sizeof list - at, "%s%s '%s'", count++ ? ", " : "",
                               jt->kind == MECH_JOINT_SLIDER ? "slider" : "link", name);
    }
    diag_error(d, m->file, m->drivers[0].mark,
               "under-driven: the mechanism has %d degrees of freedom but %d driver%s, so %d "
               "motion%s %s free%s%s%s; add a driver for each (a link angle or a slider "
               "displacement as a law of t)",
               mobility, nd, nd == 1 ? "" : "s", mobility - nd, mobility - nd == 1 ? "" : "s",
               mobility - nd == 1 ? "is" : "are", count ? " (not driven: " : "",
               count ? list : "", count ? ")" : "");
}

/* Names of the listed items into buf: "'a', 'b' and 3 more". */
static void name_list(char *buf, size_t size, const char *const *names, int count)
{
    size_t at = 0;
    buf[0] = '\0';
    for (int i = 0; i < count && i < 8 && at < size; i++)
        at += (size_t)snprintf(buf + at, size - at, "%s'%s'", i == 0 ? "" : ", ", names[i]);
    if (count > 8 && at < size)
        snprintf(buf + at, size - at, " and %d more", count - 8);
}

/* Breadth-first over alternating paths of a maximum matching (the
 * Dulmage-Mendelsohn decomposition): from the unmatched rows (from_rows) or
 * columns, mark the rows and columns reached. Each node is queued once. */
static void alternate(int nr, int nc, const int *Ap, const int *Ai, const int *rp, const int *rc,
                      const int *row_match, const int *col_match, int from_rows,
                      unsigned char *row_seen, unsigned char *col_seen, int *queue)
{
    int head = 0, tail = 0;
    if (from_rows) {
        for (int r = 0; r < nr; r++)
            if (row_match[r] < 0)
                row_seen[r] = 1, queue[tail++] = r;
        while (head < tail) {
            int r = queue[head++];
            for (int p = rp[r]; p < rp[r + 1]; p++) {
                int c = rc[p];
                if (col_seen[c])
                    continue;
                col_seen[c] = 1;
                int r2 = col_match[c];
                if (r2 >= 0 && !row_seen[r2])
                    row_seen[r2] = 1, queue[tail++] = r2;
            }
        }
        return;
    }
    for (int c = 0; c < nc; c++)
        if (col_match[c] < 0)
            col_seen[c] = 1, queue[tail++] = c;
    while (head < tail) {
        int c = queue[head++];
        for (int p = Ap[c]; p < Ap[c + 1]; p++) {
            int r = Ai[p];
            if (row_seen[r])
                continue;
            row_seen[r] = 1;
            int c2 = row_match[r];
            if (c2 >= 0 && !col_seen[c2])
                col_seen[c2] = 1, queue[tail++] = c2;
        }
    }
}

int drivers_report_structure(const mech_system *s, mech_diag *d)
{
    const mech_model *m = s->model;
    int nr = s->m, nc = s->n;
    size_t big = (size_t)(nr > nc ? nr : nc) + 1;
    int *row_match = xcalloc(big, sizeof *row_match), *col_match = xcalloc(big, sizeof *col_match);
    int *work = xcalloc(5 * big, sizeof *work), *queue = xcalloc(big, sizeof *queue);
    int *rp = xcalloc(big + 1, sizeof *rp), *rc = xcalloc((size_t)s->nnz + 1, sizeof *rc);
    unsigned char *rs = xcalloc(big, 1), *cs = xcalloc(big, 1);
    unsigned char *rs2 = xcalloc(big, 1), *cs2 = xcalloc(big, 1);
    const char **names = xcalloc(big, sizeof *names);
    int rcode = MECH_EINPUT;
    if (!row_match || !col_match || !work || !queue || !rp || !rc || !rs || !cs || !rs2 || !cs2 ||
        !names) {
        diag_nomem(d, m->file, (mech_mark){0, 0});
        rcode = MECH_ENOMEM;
        goto done;
    }
    double done_work;
    btf_maxtrans(nr, nc, s->Jp, s->Ji, 0.0, &done_work, row_match, work);
    for (int c = 0; c < nc; c++)
        col_match[c] = -1;
    for (int r = 0; r < nr; r++)
        if (row_match[r] >= 0)
            col_match[row_match[r]] = r;
    /* the row-wise pattern */
    for (int p = 0; p < s->nnz; p++)
        rp[s->Ji[p] + 1]++;
    for (int r = 0; r < nr; r++)
        rp[r + 1] += rp[r];
    for (int c = 0; c < nc; c++)
        for (int p = s->Jp[c]; p < s->Jp[c + 1]; p++)
            rc[rp[s->Ji[p]] + queue[s->Ji[p]]++] = c;
    alternate(nr, nc, s->Jp, s->Ji, rp, rc, row_match, col_match, 1, rs, cs, queue);
    alternate(nr, nc, s->Jp, s->Ji, rp, rc, row_match, col_match, 0, rs2, cs2, queue);
    /* the drivers among the over-determined rows, the unknowns left free */
    int nconf = 0, nfree = 0, at_driver = -1;
    char conf[512], freed[512];
    for (int r = 0; r < nr; r++)
        if (rs[r] && s->rows[r].kind == ROW_DRIVER) {
            names[nconf++] = drivers_name(m, s->rows[r].owner);
            at_driver = at_driver < 0 ? r : at_driver;
        }
    name_list(conf, sizeof conf, names, nconf);
    for (int c = 0; c < nc; c++)  /* the link or slider of each free unknown */
        if (cs2[c])
            names[nfree++] = s->unk_kind[c] == UNK_ANGLE ? m->links[s->unk_index[c]].name
                                                         : m->joints[s->unk_index[c]].name;
    name_list(freed, sizeof freed, names, nfree);
    mech_mark at = at_driver >= 0 ? s->rows[at_driver].mark : m->driver.mark;
    if (nconf > 0 && nfree > 0)
        diag_error(d, m->file, at,
                   "the drivers do not match the mechanism's freedoms: the driver%s of %s "
                   "over-determine%s the part of the mechanism %s move%s, while %s move%s "
                   "freely; drive one of those instead", nconf == 1 ? "" : "s", conf,
                   nconf == 1 ? "s" : "", nconf == 1 ? "it" : "they", nconf == 1 ? "s" : "",
                   freed, nfree == 1 ? "s" : "");
    else if (nconf > 0)
        diag_error(d, m->file, at, "the driver%s of %s over-determine%s the mechanism (the loop "
                   "equations and the other drivers already fix %s)", nconf == 1 ? "" : "s",
                   conf, nconf == 1 ? "s" : "", nconf == 1 ? "it" : "them");
    else
        diag_error(d, m->file, at, "the loop equations are structurally singular: the motion "
                   "of %s is determined by no equation (see 'mech equations')",
                   nfree ? freed : "some link or slider");
done:
    free(row_match);
    free(col_match);
    free(work);
    free(queue);
    free(rp);
    free(rc);
    free(rs);
    free(cs);
    free(rs2);
    free(cs2);
    free(names);
    return rcode;
}
