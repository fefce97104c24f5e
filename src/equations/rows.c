/* src/equations/rows.c: the equation system's row descriptors (rows.h): built once
 * with the system, then read to assemble, print and name its rows. */
#include <stdlib.h>

#include "load.h"
#include "equations.h"

int rows_count(const mech_model *m, int nloops, int *count)
{
    int n[ROW_KINDS] = {nloops, nloops, m->ngears, model_ncams(m), drivers_rows(m)};
    if (count)
        for (int k = 0; k < ROW_KINDS; k++)
            count[k] = n[k];
    return 2 * nloops + m->ngears + n[ROW_CAM] + n[ROW_DRIVER];
}

row_desc *rows_build(const mech_model *m, int nloops, int loops_listed)
{
    int total = rows_count(m, nloops, NULL), r = 0;
    row_desc *rows = xcalloc((size_t)total + 1, sizeof *rows);
    if (!rows)
        return NULL;
    for (int k = 0; k < nloops; k++) {
        mech_mark at = loops_listed && k < m->nloops ? m->loops[k].mark : (mech_mark){0, 0};
        rows[r++] = (row_desc){ROW_LOOP_X, k, at};
        rows[r++] = (row_desc){ROW_LOOP_Y, k, at};
    }
    for (int g = 0; g < m->ngears; g++)
        rows[r++] = (row_desc){ROW_GEAR, g, m->gears[g].mark};
    for (int c = 0; c < model_ncams(m); c++)
        rows[r++] = (row_desc){ROW_CAM, c, m->cams->cam[c].mark};
    for (int k = 0; k < m->ndrivers; k++)  /* the sweep's own driver has no row */
        if (!drivers_is_sweep(m, k))
            rows[r++] = (row_desc){ROW_DRIVER, k, m->drivers[k].mark};
    return rows;
}

const char *rows_constraint(const mech_model *m, row_kind kind, int owner, char *buf,
                            size_t size)
{
    if (kind == ROW_GEAR)
        snprintf(buf, size, "gear pair '%s'", m->gears[owner].name);
    else if (kind == ROW_CAM)
        snprintf(buf, size, "cam '%s'", m->cams->cam[owner].name);
    else
        snprintf(buf, size, "driver '%s'", drivers_name(m, owner));
    return buf;
}

/* "loop 2 (A-B-C-D-A)": a listed loop by its points, one found
 * automatically by the point each of its terms starts from. */
static const char *loop_label(const mech_system *s, int k, char *buf, size_t size)
{
    const mech_model *m = s->model;
    const loop_set *ls = &s->loops;
    size_t at = (size_t)snprintf(buf, size, "loop %d (", k + 1);
    if (ls->from_file && k < m->nloops) {
        for (int i = 0; i < m->loops[k].npoints && at < size; i++)
            at += (size_t)snprintf(buf + at, size - at, "%s%s", i ? "-" : "",
                                   m->point_names[m->loops[k].points[i]]);
    } else {
        const char *first = NULL;  /* the point each term starts from */
        for (int t = ls->start[k]; t < ls->start[k + 1] && at < size; t++) {
            const loop_term *lt = &ls->terms[t];
            const char *p;
            if (lt->kind == TERM_BODY) {
                p = m->links[lt->link].points[lt->p0].name;
            } else {
                const mech_joint *j = &m->joints[lt->joint];
                int side = lt->sign > 0 ? 1 : 0;  /* + runs guide point -> mover */
                p = m->links[j->link[side]].points[j->point[side]].name;
            }
            first = first ? first : p;
            at += (size_t)snprintf(buf + at, size - at, "%s-", p);
        }
        if (at < size)
            at += (size_t)snprintf(buf + at, size - at, "%s", first ? first : "?");
    }
    if (at < size)
        snprintf(buf + at, size - at, ")");
    return buf;
}

const char *rows_owner(const mech_system *s, int r, char *buf, size_t size)
{
    if (r < 0 || r >= s->m) {  /* no row (a system without equations) */
        snprintf(buf, size, "the equations");
        return buf;
    }
    const row_desc *rd = &s->rows[r];
    if (rd->kind == ROW_LOOP_X || rd->kind == ROW_LOOP_Y)
        return loop_label(s, rd->owner, buf, size);
    return rows_constraint(s->model, rd->kind, rd->owner, buf, size);
}

int rows_same_owner(const mech_system *s, int a, int b)
{
    const row_desc *x = &s->rows[a], *y = &s->rows[b];
    int loop_x = x->kind == ROW_LOOP_X || x->kind == ROW_LOOP_Y;
    int loop_y = y->kind == ROW_LOOP_X || y->kind == ROW_LOOP_Y;
    return x->owner == y->owner && (loop_x && loop_y ? 1 : x->kind == y->kind);
}
