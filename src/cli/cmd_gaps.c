/* src/cli/cmd_gaps.c: the words for a gap of a partial sweep (issue 17), the
 * same in `mech solve` and `mech report`: the rows missing, why, and the
 * assembly limits found, with the driver in deg or mm. */
#include <math.h>
#include <stdio.h>

#include "cli.h"

/* Requested driver position i (as mech_analysis_new lists them). */
static double requested_q(const mech_model *m, const mech_solve_options *o, int i)
{
    if (!o->has_range)
        return m->driver.values[i];
    int steps = o->steps > 0 ? o->steps : 1;
    return i == steps ? o->to : o->from + (o->to - o->from) * i / steps;
}

/* A driver position as users read it: degrees or millimetres, with
 * `decimals` decimals. */
static void q_text(const mech_model *m, double q, int decimals, char *buf, size_t size)
{
    int angle = m->driver.kind == MECH_DRIVE_ANGLE, time = m->driver.kind == MECH_DRIVE_TIME;
    snprintf(buf, size, "%.*f %s", decimals,
             angle ? q * 57.295779513082321 : time ? q : q * 1e3,
             angle ? "deg" : time ? "s" : "mm");
}

/* Decimals that a limit found to 1e-12 of the row spacing h deserves,
 * bounded by the position's own rounding floor (about 1e-11 of it, rad or m). */
static int limit_decimals(const mech_model *m, double q, double h)
{
    double unit = m->driver.kind == MECH_DRIVE_ANGLE ? 57.295779513082321
                  : m->driver.kind == MECH_DRIVE_TIME ? 1.0 : 1e3;
    double acc = fmax(1e-12 * fabs(h), 1e-11 * fmax(fabs(q), fabs(h))) * unit;
    int d = (int)floor(-log10(acc));
    return d < 0 ? 0 : d > 12 ? 12 : d;
}

static const char *gap_words(mech_gap_kind k)
{
    switch (k) {
    case MECH_GAP_NO_ASSEMBLY: return "the mechanism does not assemble";
    case MECH_GAP_DEAD_POINT: return "a dead point or limit position the driver cannot pass";
    case MECH_GAP_CHANGE_POINT: return "a change point, where two assembly branches cross";
    case MECH_GAP_BRANCH: return "the mechanism leaves the declared branch";
    default: return "the solution jumps to another assembly";
    }
}

void cmd_gap_line(const mech_model *m, const mech_solve_options *o, const mech_table *t, int i,
                  char *line, size_t size)
{
    const mech_gap *g = &t->gaps[i];
    int n = t->nrequested;
    double h = n > 1 ? fabs(requested_q(m, o, n - 1) - requested_q(m, o, 0)) / (n - 1) : 1.0;
    char q1[64], q2[64], l1[64] = "", l2[64] = "", rows[200];
    q_text(m, requested_q(m, o, g->first_row), 6, q1, sizeof q1);
    q_text(m, requested_q(m, o, g->last_row), 6, q2, sizeof q2);
    if (g->from_limit)
        q_text(m, g->from, limit_decimals(m, g->from, h), l1, sizeof l1);
    if (g->to_limit)
        q_text(m, g->to, limit_decimals(m, g->to, h), l2, sizeof l2);
    if (g->first_row == g->last_row)
        snprintf(rows, sizeof rows, "row %d of %d (driver at %s)", g->first_row + 1, n, q1);
    else
        snprintf(rows, sizeof rows, "rows %d to %d of %d (driver at %s to %s)",
                 g->first_row + 1, g->last_row + 1, n, q1, q2);
    snprintf(line, size, "%s not solved: %s%s%s%s%s%s", rows, gap_words(g->kind),
             l1[0] || l2[0] ? "; limits found: " : "", l1[0] ? "from " : "", l1,
             l1[0] && l2[0] ? " to " : l2[0] ? "to " : "", l2);
}
