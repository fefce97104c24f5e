/* src/load/load_drivers.c: the loader's 'sweep' and 'drivers' (docs/format.md
 * section 7.3): the sweep variable (the time t and its range) and one or
 * more drivers, each a link angle or a slider displacement given as a law
 * of t (drivers.c parses the laws). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"

static void load_sweep(loader *ld, const ynode *map)
{
    static const char *const keys[] = {"time"};
    mech_driver *dr = &ld->m->driver;
    if (!load_want_kind(ld, map, YNODE_MAP, "'sweep'") ||
        !load_check_keys(ld, map, keys, COUNT(keys), "sweep"))
        return;
    const ynode *t = ymap_get(map, "time");
    if (!t)
        return (void)load_err(ld, map, "the sweep needs 'time: {from: 0 s, to: 1 s, steps: N}' "
                                        "(the sweep variable t of the drivers' laws)");
    dr->kind = MECH_DRIVE_TIME;
    dr->index = 0;
    dr->mark = map->mark;
    load_range(ld, t, Q_TIME, dr);
    dr->speed = 1.0;  /* dt/dt: the rates the solver publishes are time rates */
    dr->accel = 0.0;
}

/* One entry: {link: NAME, angle: LAW} or {slider: NAME, displacement: LAW}. */
static void load_motion(loader *ld, const ynode *e, mech_motion *mo)
{
    static const char *const keys[] = {"link", "slider", "angle", "displacement"};
    mech_model *m = ld->m;
    mo->index = -1;
    mo->mark = e->mark;
    if (!load_want_kind(ld, e, YNODE_MAP, "a driver") ||
        !load_check_keys(ld, e, keys, COUNT(keys), "driver"))
        return;
    const ynode *ln = ymap_get(e, "link"), *sn = ymap_get(e, "slider"),
                *ang = ymap_get(e, "angle"), *disp = ymap_get(e, "displacement");
    if ((ln != NULL) == (sn != NULL))
        return (void)load_err(ld, e, ln ? "a driver has both 'link' and 'slider'; give one"
                                        : "a driver needs 'link: NAME' with 'angle: LAW' or "
                                          "'slider: NAME' with 'displacement: LAW'");
    const ynode *law = ln ? ang : disp, *wrong = ln ? disp : ang;
    if (wrong)
        return (void)load_err(ld, load_key_of(e, ln ? "displacement" : "angle"),
                              ln ? "a link driver takes 'angle', not 'displacement'"
                                 : "a slider driver takes 'displacement', not 'angle'");
    if (!law)
        return (void)load_err(ld, e, "the driver has no '%s' (its law of the time t, such as "
                                     "'%s')", ln ? "angle" : "displacement",
                              ln ? "10 rad/s * t" : "0.1 m + 0.02 m/s * t");
    if (ln) {
        mo->kind = MECH_DRIVE_ANGLE;
        mo->index = load_find_link_or_report(ld, ln, "driver link");
        if (mo->index == 0) {
            mo->index = -1;
            return (void)load_err(ld, ln, "the ground is fixed and cannot be driven; name the "
                                          "link that the motor turns");
        }
        for (int ji = 0; mo->index > 0 && ji < m->njoints; ji++)
            if (m->joints[ji].kind == MECH_JOINT_SLIDER && m->joints[ji].locked &&
                m->joints[ji].link[0] == mo->index) {
                load_err(ld, ln, "link '%s' cannot turn (it is held by locked slider '%s'); "
                                 "drive the slider instead",
                         m->links[mo->index].name, m->joints[ji].name);
                mo->index = -1;
                return;
            }
    } else {
        mo->kind = MECH_DRIVE_SLIDER;
        mo->index = load_slider_by_name(ld, sn, "driver slider");
    }
    if (!load_want_kind(ld, law, YNODE_SCALAR, "a driver's law"))
        return;
    char msg[256];
    size_t pos = 0;
    int rc = law_parse(law->text, ln ? Q_ANGLE : Q_LENGTH, &ld->env, &mo->law, msg, sizeof msg,
                       &pos);
    if (rc == MECH_ENOMEM)
        return (void)load_nomem(ld, law);
    if (rc < 0) {
        mech_mark at = law->mark;
        if (!strchr(law->text, '\n'))
            at.col += (int)pos + (law->quoted ? 1 : 0);
        diag_error(ld->d, ld->file, at, "driver '%s': %s", ln ? ln->text : sn->text, msg);
        return;
    }
    mo->text = xstrdup(law->text);
    if (!mo->text)
        load_nomem(ld, law);
}

void load_sweep_drivers(loader *ld, const ynode *sweep, const ynode *drivers)
{
    mech_model *m = ld->m;
    if (!drivers)
        return (void)load_err(ld, sweep, "'sweep' goes with 'drivers' (laws of t); with "
                                         "'driver' the sweep is the driver's own range");
    if (!sweep)
        return (void)load_err(ld, drivers, "'drivers' needs 'sweep: {time: {from: 0 s, to: "
                                           "1 s, steps: N}}' (the range of t)");
    if (!load_want_kind(ld, drivers, YNODE_SEQ, "'drivers'"))
        return;
    if (drivers->n == 0)
        return (void)load_err(ld, drivers, "'drivers' is empty: list one driver per degree of "
                                           "freedom");
    if (drivers->n > 1000)
        return (void)load_err(ld, drivers, "at most 1000 drivers");
    m->drivers = xcalloc(drivers->n, sizeof *m->drivers);
    if (!m->drivers)
        return (void)load_nomem(ld, drivers);
    load_sweep(ld, sweep);
    int ok = 1;
    for (size_t i = 0; i < drivers->n; i++) {
        mech_motion *mo = &m->drivers[m->ndrivers++];
        load_motion(ld, drivers->items[i], mo);
        if (mo->index < 0 || !mo->law) {
            ok = 0;
            continue;
        }
        for (int k = 0; k + 1 < m->ndrivers; k++) {
            const mech_motion *o = &m->drivers[k];
            if (o->law && o->kind == mo->kind && o->index == mo->index) {
                load_err(ld, drivers->items[i], "%s '%s' has two drivers (the first at line "
                         "%d): one law per link or slider",
                         mo->kind == MECH_DRIVE_ANGLE ? "link" : "slider",
                         drivers_name(m, m->ndrivers - 1), o->mark.line);
                ok = 0;
                break;
            }
        }
    }
    m->has_driver = ok && m->driver.kind == MECH_DRIVE_TIME && m->driver.nvalues > 0;
    m->motions = m->drivers;  /* the view of 0.1's callers: the laws of time */
    m->nmotions = m->ndrivers;
}
