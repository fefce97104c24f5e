/* src/study/sweep_metrics.c: what a sweep measures (src/study/study.h): each
 * metric of mech_sweep_metric ("range:x_B.s", "transmission:coupler,rocker",
 * "flywheel:0.02", ...) read, checked against the columns of the base
 * variant's table before any variant is solved, and computed from each
 * variant's table (docs/batch.md). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "study.h"

int metric_add(mech_sweep *s, const char *arg, mech_diag *d)
{
    static const struct {
        const char *prefix;
        sweep_metric_kind kind;
    } kinds[] = {{"range:", MET_RANGE},   {"max:", MET_MAX},
                 {"min:", MET_MIN},       {"maxabs:", MET_MAXABS},
                 {"transmission:", MET_TRANSMISSION}, {"flywheel:", MET_FLYWHEEL}};
    if (s->nmetrics == SWEEP_MAX_METRICS)
        return sweep_arg_error(d, "at most 32 metrics ('%s')", arg);
    sweep_metric *mt = &s->metrics[s->nmetrics];
    memset(mt, 0, sizeof *mt);
    for (size_t k = 0; k < COUNT_OF(kinds); k++) {
        size_t n = strlen(kinds[k].prefix);
        if (strncmp(arg, kinds[k].prefix, n) != 0 || !arg[n])
            continue;
        mt->kind = kinds[k].kind;
        snprintf(mt->label, sizeof mt->label, "%s", arg);
        for (char *c = mt->label; *c; c++)  /* the label is a CSV header cell */
            if (*c == ',')
                *c = '/';
        if (mt->kind == MET_TRANSMISSION) {
            const char *comma = strchr(arg + n, ',');
            if (!comma || comma == arg + n || !comma[1])
                return sweep_arg_error(d, "transmission:LINK1,LINK2, not '%s'", arg);
            snprintf(mt->col, sizeof mt->col, "%.*s.angle", (int)(comma - arg - n), arg + n);
            snprintf(mt->col2, sizeof mt->col2, "%s.angle", comma + 1);
        } else if (mt->kind == MET_FLYWHEEL) {
            char *end;
            mt->cs = strtod(arg + n, &end);
            if (*end || !(mt->cs > 0 && mt->cs < 1))
                return sweep_arg_error(d, "flywheel:CS needs 0 < CS < 1, not '%s'", arg);
            snprintf(mt->col, sizeof mt->col, "driver.torque");
        } else {
            snprintf(mt->col, sizeof mt->col, "%s", arg + n);
        }
        s->nmetrics++;
        return MECH_OK;
    }
    return sweep_arg_error(d, "unknown metric '%s' (range:, max:, min:, maxabs:, transmission:, "
                           "flywheel:)", arg);
}

/* MECH_OK when column `col` of metric mt is in t; else an error naming it,
 * with the nearest column when it looks like a typo. */
static int check_column(const sweep_metric *mt, const char *col, const mech_table *t, int with_forces,
                        mech_diag *d)
{
    if (mech_table_column(t, col) >= 0)
        return MECH_OK;
    const char *near = NULL;
    const char **names = t->ncolumns <= 1000 ? xcalloc((size_t)t->ncolumns, sizeof *names) : NULL;
    for (int c = 0; names && c < t->ncolumns; c++)
        names[c] = t->columns[c].name;
    if (names)
        near = nearest_name(col, names, (size_t)t->ncolumns);
    int rc = sweep_arg_error(d, "--metric %s: no column '%s' in the output of 'mech solve "
                             "FILE%s'%s%s%s%s", mt->label, col, with_forces ? " --forces" : "",
                             near ? " (did you mean '" : "", near ? near : "", near ? "'?)" : "",
                             mt->kind == MET_TRANSMISSION
                             ? "; transmission: takes two moving links" : "");
    free(names);
    return rc;
}

int metric_check(mech_sweep *s, const mech_table *t, mech_diag *d)
{
    for (int k = 0; t->ncolumns > 0 && k < s->nmetrics; k++) {
        const sweep_metric *mt = &s->metrics[k];
        if (check_column(mt, mt->col, t, s->opt.forces, d) != MECH_OK ||
            (mt->kind == MET_TRANSMISSION && check_column(mt, mt->col2, t, s->opt.forces, d)))
            return MECH_EINPUT;
    }
    for (int k = 0; k < s->nmetrics; k++) {  /* the header's units */
        sweep_metric *mt = &s->metrics[k];
        int c = mech_table_column(t, mt->col);
        snprintf(mt->unit, sizeof mt->unit, "%s", mt->kind == MET_TRANSMISSION ? "rad"
                 : mt->kind == MET_FLYWHEEL ? "kg*m^2"
                 : c >= 0 && t->columns[c].unit ? t->columns[c].unit : "-");
    }
    return MECH_OK;
}

double metric_value(const sweep_metric *mt, const mech_table *t, const mech_model *m, FILE *msg)
{
    flywheel_figures fw;
    char why[200];
    if (mt->kind == MET_FLYWHEEL && flywheel_compute(t, m, mt->cs, &fw, why, sizeof why) < 0)
        return fprintf(msg, "metric %s: %s\n", mt->label, why), NAN;
    if (mt->kind == MET_FLYWHEEL && !fw.full_cycle)
        fprintf(msg, "metric %s: the rows are not one full turn\n", mt->label);
    int c = mech_table_column(t, mt->col), c2 = -1;
    if (mt->kind == MET_TRANSMISSION)
        c2 = mech_table_column(t, mt->col2);
    if (c < 0 || (mt->kind == MET_TRANSMISSION && c2 < 0)) {
        fprintf(msg, "metric %s: no column %s in the output (see 'mech solve --outputs')\n",
                mt->label, c < 0 ? mt->col : mt->col2);
        return NAN;
    }
    double lo = INFINITY, hi = -INFINITY, big = 0.0, tmin = INFINITY;
    for (int i = 0; i < t->nrows; i++) {
        double x = mech_table_get(t, i, c);
        lo = fmin(lo, x);
        hi = fmax(hi, x);
        big = fmax(big, fabs(x));
        if (c2 >= 0) {  /* angle between the link axes, folded to 0..pi/2 */
            double a = fabs(remainder(x - mech_table_get(t, i, c2), 3.14159265358979323846));
            tmin = fmin(tmin, fmin(a, 3.14159265358979323846 - a));
        }
    }
    switch (mt->kind) {
    case MET_RANGE: return hi - lo;
    case MET_MAX: return hi;
    case MET_MIN: return lo;
    case MET_MAXABS: return big;
    case MET_TRANSMISSION: return tmin;  /* rad, as every angle of the CSVs */
    case MET_FLYWHEEL: return fw.inertia;
    }
    return NAN;
}
