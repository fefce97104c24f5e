/* src/output/describe.c: a checked model's summary lines (describe.h), shared by
 * `mech check` and `mech report`. */
#include <stdio.h>
#include <string.h>

#include "output.h"
#include "load.h"
#include "equations.h"
#include "forces.h"

/* The sweep of the time when q is the time, then one line per driver: the
 * sweep's own with its positions, a law as written. */
static void driver_lines(const mech_model *m, char *b, size_t n, describe_emit emit, void *ctx)
{
    const mech_driver *dr = &m->driver;
    if (!m->has_driver) {
        emit(ctx, "driver", "none");
        return;
    }
    if (dr->kind == MECH_DRIVE_TIME) {
        snprintf(b, n, "time t from %g s to %g s, %d position%s", dr->values[0],
                 dr->values[dr->nvalues - 1], dr->nvalues, dr->nvalues == 1 ? "" : "s");
        emit(ctx, "sweep", b);
    }
    for (int i = 0; i < m->ndrivers; i++) {
        int angle = m->drivers[i].kind == MECH_DRIVE_ANGLE;
        if (drivers_is_sweep(m, i))
            snprintf(b, n, "%s of %s '%s', %d position%s", angle ? "angle" : "displacement",
                     angle ? "link" : "slider", drivers_name(m, i), dr->nvalues,
                     dr->nvalues == 1 ? "" : "s");
        else if (drivers_free_of(m, i)) {
            const free_driver *f = drivers_free_of(m, i);
            snprintf(b, n, "%s of %s '%s' = free, from %.6g %s at %.6g %s%s",
                     angle ? "angle" : "displacement", angle ? "link" : "slider",
                     drivers_name(m, i), angle ? f->value * 57.29577951308232 : f->value * 1e3,
                     angle ? "deg" : "mm", f->speed, angle ? "rad/s" : "m/s",
                     f->load >= 0 ? ", with its load" : "");
        } else
            snprintf(b, n, "%s of %s '%s' = %s", angle ? "angle" : "displacement",
                     angle ? "link" : "slider", drivers_name(m, i), m->drivers[i].text);
        emit(ctx, "driver", b);
    }
}

void model_describe(const mech_model *m, const mech_summary *s, describe_emit emit, void *ctx)
{
    char b[512];
    int nsliders = s->nprismatic + s->npin_in_slot;
    snprintf(b, sizeof b, "%d (ground + %d moving)", s->nlinks, s->nlinks - 1);
    emit(ctx, "links", b);
    snprintf(b, sizeof b, "%d (%d revolute, %d prismatic slider, %d pin-in-slot slider)",
             s->nrevolute + nsliders, s->nrevolute, s->nprismatic, s->npin_in_slot);
    emit(ctx, "joints", b);
    snprintf(b, sizeof b, "%d (%d link angles + %d slider displacements - %d driver%s)",
             s->nunknowns, s->nlinks - 1 - s->nprismatic, nsliders, s->ndrivers,
             s->ndrivers == 1 ? "" : "s");
    emit(ctx, "unknowns", b);
    snprintf(b, sizeof b, "%d independent%s, %d equations", s->nloops,
             m->nloops ? " (listed in the file)" : " (found automatically)", s->nequations);
    emit(ctx, "loops", b);
    char mesh[64];  /* each gear pair, rack or cam removes one freedom */
    check_higher_pairs_text(s, mesh, sizeof mesh);
    snprintf(b, sizeof b, "%d = 3*(%d-1) - 2*%d - %d%s, drivers %d", s->mobility, s->nlinks,
             s->nrevolute + s->nprismatic, s->npin_in_slot, mesh, s->ndrivers);
    emit(ctx, "mobility", b);
    driver_lines(m, b, sizeof b, emit, ctx);
    snprintf(b, sizeof b, "%d points, %d links, %d sliders%s", m->outputs.npoints,
             m->outputs.nlinks, m->outputs.nsliders, m->outputs.forces ? ", forces" : "");
    emit(ctx, "outputs", b);
    for (int i = 0; i < m->nsprings; i++) {
        springs_describe(m, i, b, sizeof b);
        emit(ctx, "spring", b);
    }
    for (int i = 0; m->state_loads && i < m->state_loads->nloads; i++) {
        state_loads_describe(m, i, b, sizeof b);
        emit(ctx, "load", b);
    }
    for (int i = 0; i < m->ngears; i++) {
        gears_describe(m, i, b, sizeof b);
        emit(ctx, "gears", b);
    }
    for (int i = 0; i < model_ncams(m); i++) {
        cams_describe(m, i, b, sizeof b);
        emit(ctx, "cam", b);
        cams_design(m, i, b, sizeof b);
        emit(ctx, "cam design", b);
    }
}
