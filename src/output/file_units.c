/* src/output/file_units.c: results in the file's own units (`mech solve
 * --units file`): each column's SI unit read back as a dimension and
 * written in the file's `units:` (lengths in mm, angles in deg...), the
 * values divided by the unit's size (docs/cli.md, mech solve). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "output.h"

double output_in_file_units(const mech_model *m, const char *unit, double v, char *buf,
                            size_t size)
{
    double si;
    dim d;
    const char *end;
    snprintf(buf, size, "%s", unit);
    if (!m->units || !unit_parse(unit, &si, &d, &end) || *end != '\0' || si != 1.0)
        return v;  /* "-", or not an SI unit: as it is */
    char text[64];
    double scale = file_units_of(m->units, d, text, sizeof text);
    if (scale == 1.0)
        return v;  /* "m/m", "rad" in a file of radians: the text as the columns give it */
    snprintf(buf, size, "%s", text);
    return v / scale;
}

int output_file_units(const mech_model *m, mech_table *t)
{
    for (int c = 0; m->units && c < t->ncolumns; c++) {
        char text[64];
        double one = output_in_file_units(m, t->columns[c].unit, 1.0, text, sizeof text);
        if (one == 1.0)
            continue;
        char *u = xstrdup(text);
        if (!u)
            return MECH_ENOMEM;
        free(t->columns[c].unit);
        t->columns[c].unit = u;
        for (int r = 0; r < t->nrows; r++)
            t->values[(size_t)r * (size_t)t->ncolumns + (size_t)c] *= one;
    }
    return MECH_OK;
}
