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

/* A free driver (docs/format.md 7.4): `free: true`, `initial: {value, speed}`,
 * `load:` (a torque on a link driver). Its law for the other commands:
 * value + speed (t - t0). Returns 0 when it was reported. */
static int load_free(loader *ld, const ynode *e, mech_motion *mo, int is_link, const ynode *ini,
                     const ynode *lo)
{
    static const char *const ikeys[] = {"value", "speed"};
    mech_model *m = ld->m;
    if (!ini)
        return load_err(ld, e, "a free driver needs 'initial: {value: ..., speed: ...}' (its %s "
                               "and %s at the first time)", is_link ? "angle" : "displacement",
                        is_link ? "angular speed" : "speed"), 0;
    if (!load_want_kind(ld, ini, YNODE_MAP, "'initial'") ||
        !load_check_keys(ld, ini, ikeys, COUNT(ikeys), "initial"))
        return 0;
    const ynode *v = ymap_get(ini, "value"), *w = ymap_get(ini, "speed");
    if (!v)
        return load_err(ld, ini, "'initial' needs 'value: ...' (the %s at the first time)",
                        is_link ? "angle" : "displacement"), 0;
    free_driver fd = {(int)(mo - m->drivers), 0.0, 0.0, -1, e->mark};
    if (!load_get_quantity(ld, v, is_link ? Q_ANGLE : Q_LENGTH, "initial value", &fd.value))
        return 0;
    if (w && !load_get_quantity(ld, w, is_link ? Q_ANGULAR_SPEED : Q_SPEED, "initial speed",
                                &fd.speed))
        return 0;
    const mech_joint *jt = is_link ? NULL : &m->joints[mo->index];
    if (lo && jt && jt->link[1] != 0)
        return load_err(ld, load_key_of(e, "load"), "a free slider's 'load' needs a guide on "
                        "the ground ('%s' slides on '%s'): give the force on the moving link "
                        "in 'loads:'", jt->name, m->links[jt->link[1]].name), 0;
    if (lo) {
        int before = m->state_loads ? m->state_loads->nloads : 0;
        if (jt)  /* along the guide's line, at the sliding point, + along the displacement */
            load_state_along(ld, e, lo, jt->link[0], jt->point[0], jt->angle);
        else
            load_state_load(ld, e, lo, mo->index, -1);
        if (m->state_loads && m->state_loads->nloads > before)
            fd.load = m->state_loads->nloads - 1;
        else
            return 0;
    }
    struct free_drivers *f = m->free_drivers;
    if (!f && !(f = m->free_drivers = xcalloc(1, sizeof *f)))
        return load_nomem(ld, e), 0;
    free_driver *grown = realloc(f->d, (size_t)(f->n + 1) * sizeof *grown);
    if (!grown)
        return load_nomem(ld, e), 0;
    f->d = grown;
    f->d[f->n++] = fd;
    double t0 = m->driver.nvalues > 0 ? m->driver.values[0] : 0.0;
    mo->law = law_linear(fd.value - fd.speed * t0, fd.speed);
    mo->text = xstrdup("free");
    if (!mo->law || !mo->text)
        return load_nomem(ld, e), 0;
    return 1;
}

/* One entry: {link: NAME, angle: LAW} or {slider: NAME, displacement: LAW},
 * or a free one: {link: NAME, free: true, initial: {...}, load: ...}. */
static void load_motion(loader *ld, const ynode *e, mech_motion *mo)
{
    static const char *const keys[] = {"link", "slider", "angle", "displacement", "free",
                                       "initial", "load"};
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
    const ynode *fr = ymap_get(e, "free"), *ini = ymap_get(e, "initial"),
                *lo = ymap_get(e, "load");
    int is_free = 0;
    if (fr && !load_get_bool(ld, fr, "'free'", &is_free))
        return;
    if (is_free && law)
        return (void)load_err(ld, load_key_of(e, ln ? "angle" : "displacement"),
                              "a free driver has no law: its motion follows from the loads "
                              "(remove '%s' or 'free: true')", ln ? "angle" : "displacement");
    if (!is_free && (ini || lo))
        return (void)load_err(ld, load_key_of(e, ini ? "initial" : "load"),
                              "'%s' belongs to a free driver ('free: true')",
                              ini ? "initial" : "load");
    if (is_free)
        law = NULL;
    if (wrong)
        return (void)load_err(ld, load_key_of(e, ln ? "displacement" : "angle"),
                              ln ? "a link driver takes 'angle', not 'displacement'"
                                 : "a slider driver takes 'displacement', not 'angle'");
    if (!law && !is_free)
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
    if (is_free) {
        if (mo->index >= 0 && !load_free(ld, e, mo, ln != NULL, ini, lo))
            mo->index = -1;
        return;
    }
    const char *who = ln ? ln->text : sn->text;
    if (law->kind == YNODE_MAP) {  /* {program: {...}} */
        static const char *const pkeys[] = {"program"};
        const ynode *pm = ymap_get(law, "program");
        if (!load_check_keys(ld, law, pkeys, COUNT(pkeys), "a driver's law"))
            return;
        if (!pm)
            return (void)load_err(ld, law, "a driver's law is an expression of t or "
                                           "{program: {...}}");
        char whom[MAX_NAME + 16];
        snprintf(whom, sizeof whom, "driver '%s'", who);
        if (!load_program(ld, pm, ln ? Q_ANGLE : Q_LENGTH, whom, &mo->law))
            return;
        snprintf(mo->law->name, sizeof mo->law->name, "p_%s", who);
        char text[160];
        const ynode *of = ymap_get(pm, "of");
        snprintf(text, sizeof text, "program of %s, %d segments", of ? of->text : "t",
                 mo->law->progs[0]->n);
        if (!(mo->text = xstrdup(text)))
            load_nomem(ld, law);
        return;
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
    snprintf(mo->law->name, sizeof mo->law->name, "p_%s", who);
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
