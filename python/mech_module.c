/* python/mech_module.c: mech._mech, the C half of the Python module `mech`
 * (python/mech/__init__.py is the other half; docs/api.md, "Python").
 *
 * A thin layer over libmech's public API (include/mech.h): it loads and
 * checks a file with parameter overrides, solves it with the options of
 * `mech solve`, and hands back the columns as numpy arrays (copied from the
 * table: the same doubles `mech solve` prints, as the shortest text that reads back). The GIL is
 * released while a file is loaded and solved: each call has its own model,
 * analysis and table, so threads may solve at once. Errors raise
 * mech.MechError with the library's diagnostics (file:line:column). */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/arrayobject.h>

#include <math.h>
#include <string.h>

#include <mech.h>

#define MAX_SET 64 /* as mech solve --set */

/* What the extension was built for (python/setup.py and the Makefile say;
 * docs/api.md, "Python"): the interpreter, its version, numpy's version. */
#ifndef MECH_BUILT_PYTHON
#define MECH_BUILT_PYTHON "an unknown interpreter"
#endif
#ifndef MECH_BUILT_PYTHON_VERSION
#define MECH_BUILT_PYTHON_VERSION "?"
#endif
#ifndef MECH_BUILT_NUMPY
#define MECH_BUILT_NUMPY "?"
#endif

static PyObject *MechError;

/* ---- errors ---------------------------------------------------------- */

static const char *severity_name(mech_severity s)
{
    return s == MECH_SEV_ERROR ? "error" : s == MECH_SEV_WARNING ? "warning" : "note";
}

/* One diagnostic as mech_diag_print writes it (without the newline). */
static PyObject *diag_line(const mech_diag_entry *e)
{
    if (e->mark.line > 0)
        return PyUnicode_FromFormat("%s:%d:%d: %s: %s", e->file, e->mark.line, e->mark.col,
                                    severity_name(e->severity), e->message);
    return PyUnicode_FromFormat("%s: %s: %s", e->file, severity_name(e->severity), e->message);
}

/* [{'file', 'line', 'column', 'severity', 'message', 'kind'}, ...]; kind is
 * mech_fail_name's word ('no-assembly', 'dead-point', ..., 'none'). */
static PyObject *diag_list(const mech_diag *d)
{
    PyObject *list = PyList_New(0);
    for (size_t i = 0; list && i < d->count; i++) {
        const mech_diag_entry *e = &d->entries[i];
        PyObject *item = Py_BuildValue("{s:s,s:i,s:i,s:s,s:s,s:s}", "file", e->file, "line",
                                       e->mark.line, "column", e->mark.col, "severity",
                                       severity_name(e->severity), "message", e->message,
                                       "kind", mech_fail_name(e->kind));
        if (!item || PyList_Append(list, item) < 0) {
            Py_XDECREF(item);
            Py_CLEAR(list);
            break;
        }
        Py_DECREF(item);
    }
    return list;
}

/* The diagnostics as lines of text, joined by newlines. */
static PyObject *diag_text(const mech_diag *d)
{
    PyObject *lines = PyList_New(0), *sep = NULL, *text = NULL;
    if (!lines)
        return NULL;
    for (size_t i = 0; i < d->count; i++) {
        PyObject *line = diag_line(&d->entries[i]);
        if (!line || PyList_Append(lines, line) < 0) {
            Py_XDECREF(line);
            goto out;
        }
        Py_DECREF(line);
    }
    if (d->truncated) {
        PyObject *line = PyUnicode_FromFormat("(%zu errors in all; only the first %zu are shown)",
                                              d->nerrors, d->max_errors ? d->max_errors : (size_t)100);
        if (!line || PyList_Append(lines, line) < 0) {
            Py_XDECREF(line);
            goto out;
        }
        Py_DECREF(line);
    }
    if ((sep = PyUnicode_FromString("\n")))
        text = PyUnicode_Join(sep, lines);
out:
    Py_XDECREF(sep);
    Py_DECREF(lines);
    return text;
}

/* The failure a status and the diagnostics report: the errors' gravest
 * kind (mech_diag_failure), else the kind the status stands for. */
static mech_fail_kind failure_of(int status, const mech_diag *d)
{
    mech_fail_kind k = d ? mech_diag_failure(d) : MECH_FAIL_NONE;
    if (k != MECH_FAIL_NONE || status == MECH_OK)
        return k;
    return status == MECH_ENOMEM ? MECH_FAIL_NOMEM : status == MECH_EIO ? MECH_FAIL_IO
           : status == MECH_ESOLVE ? MECH_FAIL_NO_ASSEMBLY : MECH_FAIL_INPUT;
}

/* Raise MechError(message) with .status, .kind (mech_fail_name's word of
 * failure_of), .diagnostics and, when partial is not NULL, .partial (the
 * pieces of the rows solved before a failure). message NULL: the
 * diagnostics' text. Returns NULL. */
static PyObject *raise_mech(int status, const mech_diag *d, const char *message, PyObject *partial)
{
    PyObject *msg = NULL, *exc = NULL, *list = NULL, *st = NULL, *kind = NULL;
    if (PyErr_Occurred())
        return NULL;
    msg = message ? PyUnicode_FromString(message) : diag_text(d);
    if (!msg)
        return NULL;
    if (!message && PyUnicode_GetLength(msg) == 0) {
        Py_DECREF(msg);
        msg = PyUnicode_FromFormat("libmech failed with status %d", status);
        if (!msg)
            return NULL;
    }
    exc = PyObject_CallOneArg(MechError, msg);
    list = d ? diag_list(d) : PyList_New(0);
    st = PyLong_FromLong(status);
    kind = PyUnicode_FromString(mech_fail_name(failure_of(status, d)));
    if (exc && list && st && kind && PyObject_SetAttrString(exc, "status", st) == 0 &&
        PyObject_SetAttrString(exc, "kind", kind) == 0 &&
        PyObject_SetAttrString(exc, "diagnostics", list) == 0 &&
        PyObject_SetAttrString(exc, "partial", partial ? partial : Py_None) == 0)
        PyErr_SetObject(MechError, exc);
    Py_XDECREF(kind);
    Py_XDECREF(st);
    Py_XDECREF(list);
    Py_XDECREF(exc);
    Py_DECREF(msg);
    return NULL;
}

/* ---- loading --------------------------------------------------------- */

/* Parameter overrides from a dict {name: text or number}; the texts are
 * UTF-8 buffers of the str objects kept in *keep (released by the caller). */
static int get_overrides(PyObject *set, mech_override *ov, int *nov, PyObject **keep)
{
    *nov = 0;
    *keep = PyList_New(0);
    if (!*keep)
        return -1;
    if (set == NULL || set == Py_None)
        return 0;
    if (!PyDict_Check(set)) {
        PyErr_SetString(PyExc_TypeError, "set must be a dict {parameter: value}");
        return -1;
    }
    PyObject *key, *value;
    Py_ssize_t pos = 0;
    while (PyDict_Next(set, &pos, &key, &value)) {
        if (*nov == MAX_SET) {
            PyErr_SetString(PyExc_ValueError, "set: at most 64 parameters");
            return -1;
        }
        if (!PyUnicode_Check(key)) {
            PyErr_SetString(PyExc_TypeError, "set: parameter names must be str");
            return -1;
        }
        PyObject *text;
        if (PyUnicode_Check(value)) {
            text = value;
            Py_INCREF(text);
        } else if (PyFloat_Check(value) || PyLong_Check(value)) {
            text = PyObject_Repr(value); /* the shortest text that reads back the same */
        } else {
            PyErr_Format(PyExc_TypeError, "set: the value of '%U' must be a str like '45 mm' "
                         "or a number", key);
            return -1;
        }
        if (!text)
            return -1;
        int rc = PyList_Append(*keep, text);
        Py_DECREF(text);
        if (rc < 0)
            return -1;
        ov[*nov].name = PyUnicode_AsUTF8(key);
        ov[*nov].text = PyUnicode_AsUTF8(text);
        if (!ov[*nov].name || !ov[*nov].text)
            return -1;
        (*nov)++;
    }
    return 0;
}

/* Load path with the overrides and, when check, run mech_check into *s.
 * Returns the model, or NULL with MechError (or another exception) set. */
static mech_model *load_model(PyObject *path, PyObject *set, int check, mech_summary *s)
{
    mech_override ov[MAX_SET];
    int nov, rc;
    PyObject *keep = NULL, *bytes = NULL;
    mech_model *m = NULL;
    mech_diag d;
    mech_diag_init(&d);
    if (!PyUnicode_FSConverter(path, &bytes))
        return NULL;
    if (get_overrides(set, ov, &nov, &keep) < 0)
        goto out;
    const char *file = PyBytes_AS_STRING(bytes);
    Py_BEGIN_ALLOW_THREADS
    rc = mech_load_file_with(file, ov, nov, &m, &d);
    if (rc == MECH_OK && check && (rc = mech_check(m, s, &d)) != MECH_OK)
        mech_model_free(&m);
    Py_END_ALLOW_THREADS
    if (rc != MECH_OK)
        raise_mech(rc, &d, NULL, NULL);
out:
    mech_diag_free(&d);
    Py_XDECREF(keep);
    Py_DECREF(bytes);
    return m;
}

static PyObject *names_list(const mech_model *m, const int *ids, int n, int kind)
{
    PyObject *list = PyList_New(n);
    for (int i = 0; list && i < n; i++) {
        const char *name = kind == 0 ? m->point_names[ids[i]]
                           : kind == 1 ? m->links[ids[i]].name : m->joints[ids[i]].name;
        PyObject *s = PyUnicode_FromString(name);
        if (!s) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, i, s);
    }
    return list;
}

/* Set d[key] = value and drop the reference to value; -1 on failure. */
static int put(PyObject *d, const char *key, PyObject *value)
{
    if (!value)
        return -1;
    int rc = PyDict_SetItemString(d, key, value);
    Py_DECREF(value);
    return rc;
}

/* [name of link 0, ...] or [point name 0, ...] */
static PyObject *all_names(const mech_model *m, int points)
{
    int n = points ? m->npoint_names : m->nlinks;
    PyObject *list = PyList_New(n);
    for (int i = 0; list && i < n; i++) {
        PyObject *s = PyUnicode_FromString(points ? m->point_names[i] : m->links[i].name);
        if (!s) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, i, s);
    }
    return list;
}

static PyObject *params_dict(const mech_model *m)
{
    PyObject *d = PyDict_New();
    for (int i = 0; d && i < m->nparams; i++) {
        PyObject *v = PyFloat_FromDouble(m->params[i].value);
        if (!v || PyDict_SetItemString(d, m->params[i].name, v) < 0)
            Py_CLEAR(d);
        Py_XDECREF(v);
    }
    return d;
}

static PyObject *joints_list(const mech_model *m)
{
    PyObject *list = PyList_New(m->njoints);
    for (int i = 0; list && i < m->njoints; i++) {
        const mech_joint *j = &m->joints[i];
        const char *kind = j->kind == MECH_JOINT_REVOLUTE ? "revolute"
                           : j->locked ? "prismatic" : "pin-in-slot";
        PyObject *item = Py_BuildValue("{s:s,s:s,s:(ss)}", "name", j->name, "kind", kind, "links",
                                       m->links[j->link[0]].name, m->links[j->link[1]].name);
        if (!item) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, i, item);
    }
    return list;
}

/* Gear pairs and racks (docs/format.md 6.4): name, kind, the two links (a
 * rack: the pinion and its slider), the arm, pitch radii (m), teeth (0 when
 * not given), internal, pressure angle (rad). */
static PyObject *gears_list(const mech_model *m)
{
    PyObject *list = PyList_New(m->ngears);
    for (int i = 0; list && i < m->ngears; i++) {
        const mech_gear *g = &m->gears[i];
        int rack = g->kind == MECH_GEAR_RACK;
        PyObject *item = Py_BuildValue(
            "{s:s,s:s,s:(ss),s:s,s:(dd),s:(ii),s:O,s:d}", "name", g->name, "kind",
            rack ? "rack" : "pair", "links", m->links[g->link[0]].name,
            rack ? m->joints[g->rack].name : m->links[g->link[1]].name, "arm",
            m->links[g->arm].name, "radii", g->radius[0], g->radius[1], "teeth", g->teeth[0],
            g->teeth[1], "internal", g->internal ? Py_True : Py_False, "pressure_angle",
            g->pressure_angle);
        if (!item) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, i, item);
    }
    return list;
}

/* Drivers as laws of time (docs/format.md 7.3): kind, link or joint, the
 * law as written. Empty for a `driver:` file. */
static PyObject *motions_list(const mech_model *m)
{
    PyObject *list = PyList_New(m->nmotions);
    for (int i = 0; list && i < m->nmotions; i++) {
        const mech_motion *mo = &m->motions[i];
        int angle = mo->kind == MECH_DRIVE_ANGLE;
        PyObject *item = Py_BuildValue(
            "{s:s,s:s,s:s}", "kind", angle ? "angle" : "slider", angle ? "link" : "joint",
            angle ? m->links[mo->index].name : m->joints[mo->index].name, "law", mo->text);
        if (!item) {
            Py_CLEAR(list);
            break;
        }
        PyList_SET_ITEM(list, i, item);
    }
    return list;
}

static PyObject *driver_dict(const mech_model *m)
{
    const mech_driver *dr = &m->driver;
    int angle = dr->kind == MECH_DRIVE_ANGLE;
    if (!m->has_driver)
        return Py_NewRef(Py_None);
    if (dr->kind == MECH_DRIVE_TIME)  /* drivers as laws of time: the sweep of t, in s */
        return Py_BuildValue("{s:s,s:i,s:d,s:d}", "kind", "time", "positions", dr->nvalues,
                             "from", dr->values[0], "to", dr->values[dr->nvalues - 1]);
    return Py_BuildValue("{s:s,s:s,s:i,s:d,s:d,s:d,s:d}", "kind", angle ? "angle" : "slider",
                         angle ? "link" : "joint",
                         angle ? m->links[dr->index].name : m->joints[dr->index].name,
                         "positions", dr->nvalues, "from", dr->values[0], "to",
                         dr->values[dr->nvalues - 1], "speed", dr->speed, "accel", dr->accel);
}

/* The model as a dict (SI units). */
static PyObject *model_dict(const mech_model *m)
{
    const mech_outputs *o = &m->outputs;
    PyObject *d = PyDict_New();
    int ok = d != NULL;
    ok = ok && put(d, "file", PyUnicode_FromString(m->file)) == 0;
    ok = ok && put(d, "name", PyUnicode_FromString(m->name)) == 0;
    ok = ok && put(d, "description", m->description ? PyUnicode_FromString(m->description)
                                                    : Py_NewRef(Py_None)) == 0;
    ok = ok && put(d, "gravity", Py_BuildValue("(dd)", m->gravity[0], m->gravity[1])) == 0;
    ok = ok && put(d, "parameters", params_dict(m)) == 0;
    ok = ok && put(d, "links", all_names(m, 0)) == 0;
    ok = ok && put(d, "points", all_names(m, 1)) == 0;
    ok = ok && put(d, "joints", joints_list(m)) == 0;
    ok = ok && put(d, "driver", driver_dict(m)) == 0;
    ok = ok && put(d, "drivers", motions_list(m)) == 0;
    ok = ok && put(d, "gears", gears_list(m)) == 0;
    ok = ok && put(d, "outputs",
                   Py_BuildValue("{s:N,s:N,s:N,s:O}", "points",
                                 names_list(m, o->points, o->npoints, 0), "links",
                                 names_list(m, o->links, o->nlinks, 1), "sliders",
                                 names_list(m, o->sliders, o->nsliders, 2), "forces",
                                 o->forces ? Py_True : Py_False)) == 0;
    if (!ok)
        Py_CLEAR(d);
    return d;
}

static PyObject *summary_dict(const mech_summary *s)
{
    return Py_BuildValue("{s:i,s:i,s:i,s:i,s:i,s:i,s:i,s:i,s:i,s:i}", "links", s->nlinks,
                         "revolute", s->nrevolute, "prismatic", s->nprismatic, "pin_in_slot",
                         s->npin_in_slot, "unknowns", s->nunknowns, "loops", s->nloops,
                         "equations", s->nequations, "mobility", s->mobility, "drivers",
                         s->ndrivers, "gears", s->ngears);
}

/* _mech.load(path, set=None, check=False) -> dict */
static PyObject *py_load(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"path", "set", "check", NULL};
    PyObject *path, *set = Py_None;
    int check = 0;
    (void)self;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|Op", kwlist, &path, &set, &check))
        return NULL;
    mech_summary s;
    mech_model *m = load_model(path, set, check, &s);
    if (!m)
        return NULL;
    PyObject *d = model_dict(m);
    if (d && check && put(d, "structure", summary_dict(&s)) < 0)
        Py_CLEAR(d);
    mech_model_free(&m);
    return d;
}

/* ---- solving --------------------------------------------------------- */

/* A driver position: a number (SI) or a text for mech_parse_value. */
static int driver_value(PyObject *v, const char *what, int is_angle, double *si)
{
    if (PyUnicode_Check(v)) {
        char err[256];
        const char *text = PyUnicode_AsUTF8(v);
        if (!text)
            return -1;
        if (mech_parse_value(text, is_angle, si, err, sizeof err) != MECH_OK) {
            PyErr_Format(PyExc_ValueError, "%s '%s': %s", what, text, err);
            return -1;
        }
    } else {
        *si = PyFloat_AsDouble(v);
        if (*si == -1.0 && PyErr_Occurred())
            return -1;
    }
    if (!(fabs(*si) <= 1e6)) {
        PyErr_Format(PyExc_ValueError, "%s: a driver position must be finite and within +-1e6 "
                     "(rad or m)", what);
        return -1;
    }
    return 0;
}

/* Choice among names: returns the index in names, or -1 with ValueError. */
static int choice(PyObject *v, const char *what, const char *const *names, int n)
{
    const char *text = PyUnicode_Check(v) ? PyUnicode_AsUTF8(v) : NULL;
    for (int i = 0; text && i < n; i++)
        if (strcmp(text, names[i]) == 0)
            return i;
    if (!PyErr_Occurred())
        PyErr_Format(PyExc_ValueError, "%s must be one of '%s', '%s', '%s', not %R", what,
                     names[0], names[1], names[2], v);
    return -1;
}

typedef struct solve_request {
    PyObject *from, *to, *steps, *outputs, *forces, *tol, *level, *friction;
    int diagnostics, all_blocks;
} solve_request;

/* The request's options into *o (and *sel for outputs; *has_sel says to free
 * it). Returns 0, or -1 with an exception set. */
static int solve_options(const mech_model *m, const solve_request *r, mech_solve_options *o,
                         mech_outputs *sel, int *has_sel)
{
    int is_angle = m->driver.kind == MECH_DRIVE_TIME ? 2 : m->driver.kind == MECH_DRIVE_ANGLE;
    long steps = 0;
    mech_solve_options_default(o);
    *has_sel = 0;
    if (r->steps != Py_None) {
        steps = PyLong_AsLong(r->steps);
        if (steps == -1 && PyErr_Occurred())
            return -1;
        if (steps < 1 || steps > 1000000) {
            PyErr_SetString(PyExc_ValueError, "steps must be a whole number from 1 to 1000000");
            return -1;
        }
    }
    if ((r->from == Py_None) != (r->to == Py_None)) {
        PyErr_SetString(PyExc_ValueError, "from_ and to go together");
        return -1;
    }
    if (r->from != Py_None) {
        if (driver_value(r->from, "from_", is_angle, &o->from) < 0 ||
            driver_value(r->to, "to", is_angle, &o->to) < 0)
            return -1;
        o->has_range = 1;
        o->steps = steps > 0 ? (int)steps : 360;
    } else if (steps > 0) {
        o->has_range = 1;
        o->from = m->driver.values[0];
        o->to = m->driver.values[m->driver.nvalues - 1];
        o->steps = (int)steps;
    }
    if (r->tol != Py_None) {
        o->tol = PyFloat_AsDouble(r->tol);
        if (o->tol == -1.0 && PyErr_Occurred())
            return -1;
        if (!(o->tol >= 1e-15 && o->tol < 1)) {
            PyErr_SetString(PyExc_ValueError, "tol must be from 1e-15 to below 1");
            return -1;
        }
    }
    if (r->forces != Py_None) {
        int t = PyObject_IsTrue(r->forces);
        if (t < 0)
            return -1;
        o->forces = t ? 1 : -1;
    }
    if (r->level != Py_None) {
        static const char *const levels[] = {"positions", "velocities", "accelerations"};
        static const int want[] = {MECH_WANT_POSITION, MECH_WANT_POSITION | MECH_WANT_VELOCITY,
                                   MECH_WANT_ALL};
        int i = choice(r->level, "level", levels, 3);
        if (i < 0)
            return -1;
        o->want = want[i];
    }
    if (r->friction != Py_None) {
        static const char *const modes[] = {"on", "off", "both"};
        static const int value[] = {MECH_FRICTION_ON, MECH_FRICTION_OFF, MECH_FRICTION_BOTH};
        int i = choice(r->friction, "friction", modes, 3);
        if (i < 0)
            return -1;
        o->friction = value[i];
    }
    o->diagnostics = r->diagnostics;
    o->all_blocks = r->all_blocks;
    if (r->outputs != Py_None) {
        PyObject *list = r->outputs;
        char err[256];
        if (!PyUnicode_Check(list)) { /* a sequence of names: join them */
            PyObject *comma = PyUnicode_FromString(",");
            list = comma ? PyUnicode_Join(comma, r->outputs) : NULL;
            Py_XDECREF(comma);
            if (!list)
                return -1;
        } else {
            Py_INCREF(list);
        }
        const char *text = PyUnicode_AsUTF8(list);
        int rc = text ? mech_outputs_parse(m, text, sel, err, sizeof err) : MECH_EINPUT;
        Py_DECREF(list);
        if (!text)
            return -1;
        if (rc != MECH_OK) {
            char msg[300];
            snprintf(msg, sizeof msg, "%s: error: outputs: %s", m->file, err);
            raise_mech(rc, NULL, msg, NULL);
            return -1;
        }
        *has_sel = 1;
        o->outputs = sel;
    }
    return 0;
}

static PyObject *stats_dict(const mech_solve_stats *s)
{
    return Py_BuildValue(
        "{s:i,s:l,s:i,s:d,s:d,s:d,s:i,s:i,s:i,s:i,s:i,s:i,s:d,s:i,s:d,s:d,s:s,s:d}",
        "steps", s->steps,
        "iterations", s->iterations, "max_iterations", s->max_iterations, "worst_residual",
        s->worst_residual, "min_rcond", s->min_rcond, "worst_rcond_q", s->worst_rcond_q,
        "factorizations", s->factorizations, "refactorizations", s->refactorizations,
        "nunknowns", s->nunknowns, "nsolved", s->nsolved, "nblocks", s->nblocks,
        "nblocks_solved", s->nblocks_solved, "worst_power_residual", s->worst_power_residual,
        "max_friction_iterations", s->max_friction_iterations, "setup_seconds",
        s->setup_seconds, "seconds", s->seconds, "failure", mech_fail_name(s->failure),
        "failure_q", s->failure_q);
}

static PyObject *table_tuple_with(const mech_table *t, PyObject *stats, const mech_diag *d);

/* (names, units, arrays, stats, messages): one contiguous float64 array of
 * nrows per column, the table's doubles copied as they are. */
static PyObject *table_tuple(const mech_table *t, const mech_solve_stats *s, const mech_diag *d)
{
    return table_tuple_with(t, stats_dict(s), d);
}

static PyObject *table_tuple_with(const mech_table *t, PyObject *stats, const mech_diag *d)
{
    if (!stats)
        return NULL;
    PyObject *names = PyList_New(t->ncolumns), *units = PyList_New(t->ncolumns);
    PyObject *arrays = PyList_New(t->ncolumns);
    if (!names || !units || !arrays)
        goto fail;
    for (int c = 0; c < t->ncolumns; c++) {
        PyObject *n = PyUnicode_FromString(t->columns[c].name);
        PyObject *u = PyUnicode_FromString(t->columns[c].unit);
        npy_intp dims[1] = {t->nrows};
        PyObject *a = PyArray_SimpleNew(1, dims, NPY_DOUBLE);
        if (!n || !u || !a) {
            Py_XDECREF(n);
            Py_XDECREF(u);
            Py_XDECREF(a);
            goto fail;
        }
        double *col = (double *)PyArray_DATA((PyArrayObject *)a);
        for (int r = 0; r < t->nrows; r++)
            col[r] = mech_table_get(t, r, c);
        /* read-only, as documented: a Result is what the library computed */
        PyArray_CLEARFLAGS((PyArrayObject *)a, NPY_ARRAY_WRITEABLE);
        PyList_SET_ITEM(names, c, n);
        PyList_SET_ITEM(units, c, u);
        PyList_SET_ITEM(arrays, c, a);
    }
    return Py_BuildValue("(NNNNN)", names, units, arrays, stats, diag_list(d));
fail:
    Py_XDECREF(stats);
    Py_XDECREF(names);
    Py_XDECREF(units);
    Py_XDECREF(arrays);
    return NULL;
}

/* _mech.solve(path, set=None, from_=None, to=None, steps=None, outputs=None,
 *             forces=None, tol=None, level=None, friction=None,
 *             diagnostics=False, all=False) -> (names, units, arrays, stats, messages) */
static PyObject *py_solve(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"path", "set", "from_", "to", "steps", "outputs", "forces", "tol",
                             "level", "friction", "diagnostics", "all", NULL};
    PyObject *path, *set = Py_None;
    solve_request r = {Py_None, Py_None, Py_None, Py_None, Py_None, Py_None, Py_None, Py_None, 0, 0};
    (void)self;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|OOOOOOOOOpp", kwlist, &path, &set, &r.from,
                                     &r.to, &r.steps, &r.outputs, &r.forces, &r.tol, &r.level,
                                     &r.friction, &r.diagnostics, &r.all_blocks))
        return NULL;
    mech_summary s;
    mech_model *m = load_model(path, set, 1, &s);
    if (!m)
        return NULL;
    mech_solve_options o;
    mech_outputs sel = {0};
    int has_sel = 0, rc;
    PyObject *result = NULL;
    if (solve_options(m, &r, &o, &sel, &has_sel) == 0) {
        mech_table t = {0};
        mech_solve_stats st;
        mech_diag d;
        memset(&st, 0, sizeof st);
        mech_diag_init(&d);
        Py_BEGIN_ALLOW_THREADS
        rc = mech_solve(m, &o, &t, &st, &d);
        Py_END_ALLOW_THREADS
        result = table_tuple(&t, &st, &d);
        if (result && rc != MECH_OK) {
            raise_mech(rc, &d, NULL, result);
            Py_CLEAR(result);
        }
        mech_table_free(&t);
        mech_diag_free(&d);
    }
    if (has_sel)
        mech_outputs_free(&sel);
    mech_model_free(&m);
    return result;
}

/* _mech.simulate(path, to=None, step=None, rtol=None, atol=None, method=None)
 * -> (names, units, arrays, stats, messages): mech_simulate (docs/dynamics.md) */
static PyObject *py_simulate(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"path", "to", "step", "rtol", "atol", "method", "stop_at_rest",
                             "stop_when", NULL};
    PyObject *path, *to = Py_None, *step = Py_None, *rtol = Py_None, *atol = Py_None;
    const char *method = NULL, *stop_when = NULL;
    int stop_at_rest = 0;
    (void)self;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|OOOOzpz", kwlist, &path, &to, &step, &rtol,
                                     &atol, &method, &stop_at_rest, &stop_when))
        return NULL;
    mech_simulate_options o;
    mech_simulate_options_default(&o);
    o.stop_at_rest = stop_at_rest;
    o.stop_when = stop_when;
    PyObject *nums[] = {to, step, rtol, atol};
    double *into[] = {&o.to, &o.step, &o.rtol, &o.atol};
    for (int k = 0; k < 4; k++)
        if (nums[k] != Py_None) {
            *into[k] = PyFloat_AsDouble(nums[k]);
            if (*into[k] == -1.0 && PyErr_Occurred())
                return NULL;
        }
    if (method && strcmp(method, "bdf") != 0 && strcmp(method, "adams") != 0)
        return PyErr_Format(PyExc_ValueError, "method is 'bdf' or 'adams', not '%s'", method);
    o.method = method && strcmp(method, "adams") == 0 ? MECH_SIM_ADAMS : MECH_SIM_BDF;
    if (!(o.rtol > 0.0) || !(o.atol > 0.0) || (step != Py_None && !(o.step > 0.0)))
        return PyErr_Format(PyExc_ValueError, "rtol, atol and step must be positive");
    mech_summary sm;
    mech_model *m = load_model(path, Py_None, 1, &sm);
    if (!m)
        return NULL;
    mech_table t = {0};
    mech_simulate_stats st;
    mech_diag d;
    int rc;
    memset(&st, 0, sizeof st);
    mech_diag_init(&d);
    Py_BEGIN_ALLOW_THREADS
    rc = mech_simulate(m, &o, &t, &st, &d);
    Py_END_ALLOW_THREADS
    PyObject *stats = Py_BuildValue(
        "{s:l,s:l,s:l,s:l,s:l,s:i,s:d,s:d,s:d,s:d}", "steps", st.steps, "rhs_evals",
        st.rhs_evals, "jac_evals", st.jac_evals, "evaluations", st.evaluations,
        "force_solves", st.force_solves, "rows", st.rows, "worst_residual", st.worst_residual,
        "worst_free_load", st.worst_free_load, "stop_time", st.stop_time, "seconds",
        st.seconds);
    PyObject *result = table_tuple_with(&t, stats, &d);
    if (result && rc != MECH_OK) {
        raise_mech(rc, &d, NULL, result);
        Py_CLEAR(result);
    }
    mech_table_free(&t);
    mech_diag_free(&d);
    mech_model_free(&m);
    return result;
}

/* ---- synthesis (mech_fit) ---------------------------------------------- */

/* A list of str into texts (UTF-8 buffers owned by the str objects, which
 * the list keeps); NULL/None: none. -1 with an exception set. */
static int str_list(PyObject *list, const char *what, const char **out, int max, int *n)
{
    *n = 0;
    if (list == NULL || list == Py_None)
        return 0;
    if (!PyList_Check(list) && !PyTuple_Check(list)) {
        PyErr_Format(PyExc_TypeError, "%s must be a list of str", what);
        return -1;
    }
    Py_ssize_t len = PySequence_Fast_GET_SIZE(list);
    if (len > max) {
        PyErr_Format(PyExc_ValueError, "%s: at most %d", what, max);
        return -1;
    }
    for (Py_ssize_t i = 0; i < len; i++) {
        PyObject *item = PySequence_Fast_GET_ITEM(list, i);
        if (!PyUnicode_Check(item)) {
            PyErr_Format(PyExc_TypeError, "%s must be a list of str", what);
            return -1;
        }
        if (!(out[i] = PyUnicode_AsUTF8(item)))
            return -1;
    }
    *n = (int)len;
    return 0;
}

/* _mech.fit(path, free=None, target=None, columns=None, weights=None,
 * starts=0, jobs=0, whole_range=False, free_timing=False) -> dict:
 * mech_fit (docs/synthesis.md), the best solution in SI */
static PyObject *py_fit(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"path", "free", "target", "columns", "weights", "starts", "jobs",
                             "whole_range", "free_timing", "transmission", NULL};
    PyObject *path, *columns = Py_None, *weights = Py_None, *bytes = NULL, *tbytes = NULL;
    PyObject *target = Py_None;
    const char *free_text = NULL;
    mech_fit_options o;
    mech_fit_options_default(&o);
    (void)self;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "O|zOOOiippz", kwlist, &path, &free_text,
                                     &target, &columns, &weights, &o.starts, &o.jobs,
                                     &o.whole_range, &o.free_timing, &o.transmission))
        return NULL;
    if (o.starts < 0 || o.starts > 100000 || o.jobs < 0)
        return PyErr_Format(PyExc_ValueError, "starts must be 1 to 100000 (0: the default), "
                            "jobs >= 0");
    const char *cols[64], *ws[64];
    if (str_list(columns, "columns", cols, 64, &o.ncolumns) < 0 ||
        str_list(weights, "weights", ws, 64, &o.nweights) < 0)
        return NULL;
    o.columns = cols;
    o.weights = ws;
    o.free = free_text;
    if (!PyUnicode_FSConverter(path, &bytes))
        return NULL;
    if (target != Py_None && !PyUnicode_FSConverter(target, &tbytes)) {
        Py_DECREF(bytes);
        return NULL;
    }
    o.target = tbytes ? PyBytes_AS_STRING(tbytes) : NULL;
    const char *file = PyBytes_AS_STRING(bytes);
    mech_fit_result r;
    mech_diag d;
    int rc;
    mech_diag_init(&d);
    Py_BEGIN_ALLOW_THREADS
    rc = mech_fit(file, &o, &r, &d);
    Py_END_ALLOW_THREADS
    PyObject *result = NULL, *params = NULL, *worst = NULL, *margins = NULL;
    if (rc != MECH_OK) {
        raise_mech(rc, &d, NULL, NULL);
        goto out;
    }
    params = PyDict_New();
    worst = PyDict_New();
    margins = PyDict_New();
    if (!params || !worst || !margins)
        goto out;
    for (int k = 0; k < r.nfree; k++) {
        PyObject *v = PyFloat_FromDouble(r.values[k]);
        if (!v || PyDict_SetItemString(params, r.names[k], v) < 0) {
            Py_XDECREF(v);
            goto out;
        }
        Py_DECREF(v);
    }
    for (int j = 0; j < r.ncolumns; j++) {
        PyObject *v = PyFloat_FromDouble(r.worst_error[j]);
        if (!v || PyDict_SetItemString(worst, r.columns[j], v) < 0) {
            Py_XDECREF(v);
            goto out;
        }
        Py_DECREF(v);
    }
    for (int c = 0; c < r.nconstraints; c++) {
        PyObject *v = PyFloat_FromDouble(r.margins[c]);
        if (!v || PyDict_SetItemString(margins, r.constraints[c], v) < 0) {
            Py_XDECREF(v);
            goto out;
        }
        Py_DECREF(v);
    }
    result = Py_BuildValue("{s:O,s:d,s:O,s:O,s:l,s:d,s:i,s:s,s:i,s:i,s:i}", "params", params,
                           "objective", r.objective, "worst_error", worst, "margins", margins,
                           "solves", r.solves, "seconds", r.seconds, "info", r.info, "status",
                           r.info >= 1 && r.info <= 4 ? "converged" : "not converged",
                           "starts", r.starts, "accepted", r.accepted, "violated", r.violated);
out:
    Py_XDECREF(params);
    Py_XDECREF(worst);
    Py_XDECREF(margins);
    mech_fit_result_free(&r);
    mech_diag_free(&d);
    Py_XDECREF(tbytes);
    Py_DECREF(bytes);
    return result;
}

/* ---- sweeps (mech_sweep) ------------------------------------------------ */

/* The rows of a sweep as mech_sweep_run hands them over, written straight
 * into arrays made before it runs, one slot per variant: no Python object
 * is touched while the GIL is released, and a variant leaves nothing but its
 * row (and, when it was not solved, its messages). */
typedef struct sweep_rows {
    int np, nm;
    long long *index;
    double *param[64], *metric[64];
    signed char *status;
    long long *rows;
    char **messages;  /* [count] the messages of a variant not solved, else NULL */
} sweep_rows;

static void sweep_row(void *ctx, const mech_variant *v)
{
    sweep_rows *r = ctx;
    long i = v->row;
    r->index[i] = v->index;
    for (int k = 0; k < r->np; k++)
        r->param[k][i] = v->params[k];
    r->status[i] = (signed char)v->status;
    r->rows[i] = v->rows;
    for (int k = 0; k < r->nm; k++)
        r->metric[k][i] = v->metrics[k];
    if (v->status != MECH_VARIANT_OK)
        r->messages[i] = strdup(v->messages);  /* NULL when out of memory: left out */
}

/* A new 1-D array of n items of type and its data in *data, appended to
 * the list; -1 when out of memory. */
static int new_column(PyObject *list, npy_intp n, int type, void **data)
{
    PyObject *a = PyArray_ZEROS(1, &n, type, 0);
    if (!a || PyList_Append(list, a) < 0) {
        Py_XDECREF(a);
        return -1;
    }
    Py_DECREF(a);
    *data = PyArray_DATA((PyArrayObject *)a);
    return 0;
}

/* The grid ([(is_list, spec), ...]) and the metrics ([spec, ...]) into s. */
static int sweep_specs(mech_sweep *s, PyObject *grid, PyObject *metrics, mech_diag *d)
{
    PyObject *g = PySequence_Fast(grid, "grid: a list of (is_list, spec)");
    PyObject *m = g ? PySequence_Fast(metrics, "metrics: a list of str") : NULL;
    int rc = g && m ? MECH_OK : -100;
    for (Py_ssize_t i = 0; rc == MECH_OK && i < PySequence_Fast_GET_SIZE(g); i++) {
        int is_list;
        const char *spec;
        if (!PyArg_ParseTuple(PySequence_Fast_GET_ITEM(g, i), "ps", &is_list, &spec))
            rc = -100;
        else
            rc = is_list ? mech_sweep_list(s, spec, d) : mech_sweep_vary(s, spec, d);
    }
    for (Py_ssize_t i = 0; rc == MECH_OK && i < PySequence_Fast_GET_SIZE(m); i++) {
        const char *spec = PyUnicode_AsUTF8(PySequence_Fast_GET_ITEM(m, i));
        rc = spec ? mech_sweep_metric(s, spec, d) : -100;
    }
    Py_XDECREF(g);
    Py_XDECREF(m);
    return rc;
}

/* (names, units, arrays, status, messages, stats, nparams) of a prepared
 * sweep run: the columns variant, the parameters, rows, the metrics; the
 * status codes apart (the status column comes after the parameters). */
static PyObject *sweep_result(mech_sweep *s, mech_diag *d)
{
    npy_intp n = mech_sweep_count(s);
    sweep_rows r = {mech_sweep_nparams(s), mech_sweep_nmetrics(s)};
    PyObject *names = PyList_New(0), *units = PyList_New(0), *arrays = PyList_New(0);
    PyObject *status = NULL, *messages = PyDict_New(), *result = NULL;
    void *data;
    r.messages = calloc((size_t)n + 1, sizeof *r.messages);
    int bad = !names || !units || !arrays || !messages || !r.messages ||
              r.np > 64 || r.nm > 64 || new_column(arrays, n, NPY_INT64, &data) < 0;
    r.index = bad ? NULL : data;
    for (int k = 0; !bad && k < r.np; k++)
        bad = new_column(arrays, n, NPY_DOUBLE, (void **)&r.param[k]) < 0;
    bad = bad || new_column(arrays, n, NPY_INT64, &data) < 0;
    r.rows = bad ? NULL : data;
    for (int k = 0; !bad && k < r.nm; k++)
        bad = new_column(arrays, n, NPY_DOUBLE, (void **)&r.metric[k]) < 0;
    if (!bad && (status = PyArray_ZEROS(1, &n, NPY_INT8, 0)))
        r.status = PyArray_DATA((PyArrayObject *)status);
    if (bad || !status)
        goto out;
    mech_sweep_sink sink = {sweep_row, NULL, &r};
    mech_sweep_stats st = {0};
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = mech_sweep_run(s, &sink, &st, d);
    Py_END_ALLOW_THREADS
    if (rc != MECH_OK) {
        raise_mech(rc, d, NULL, NULL);
        goto out;
    }
    const char *unit;
    for (int c = 0; c < 2 + r.np + r.nm; c++) {  /* the CSV's header, without status */
        const char *name = c == 0 ? (unit = "-", "variant")
                           : c <= r.np ? mech_sweep_param(s, c - 1, &unit)
                           : c == r.np + 1 ? (unit = "-", "rows")
                           : mech_sweep_metric_label(s, c - r.np - 2, &unit);
        PyObject *pn = PyUnicode_FromString(name), *pu = PyUnicode_FromString(unit);
        int fail = !pn || !pu || PyList_Append(names, pn) < 0 || PyList_Append(units, pu) < 0;
        Py_XDECREF(pn);
        Py_XDECREF(pu);
        if (fail)
            goto out;
    }
    for (npy_intp i = 0; i < n; i++) {
        if (!r.messages[i])
            continue;
        PyObject *key = PyLong_FromLongLong(r.index[i]);
        PyObject *text = PyUnicode_DecodeUTF8(r.messages[i], (Py_ssize_t)strlen(r.messages[i]),
                                              "replace");
        int fail = !key || !text || PyDict_SetItem(messages, key, text) < 0;
        Py_XDECREF(key);
        Py_XDECREF(text);
        if (fail)
            goto out;
    }
    result = Py_BuildValue("(OOOOO{s:l,s:l,s:l,s:l}i)", names, units, arrays, status, messages,
                           "total", mech_sweep_total(s), "solved", st.solved, "shared",
                           st.shared, "alone", st.alone, r.np);
out:
    for (npy_intp i = 0; r.messages && i < n; i++)
        free(r.messages[i]);
    free(r.messages);
    Py_XDECREF(names);
    Py_XDECREF(units);
    Py_XDECREF(arrays);
    Py_XDECREF(status);
    Py_XDECREF(messages);
    if (!result && !PyErr_Occurred())
        PyErr_NoMemory();
    return result;
}

/* _mech.sweep(path, grid, metrics, random=0, seed=1, forces=False, shard=(0, 1),
 *             index_offset=0, jobs=0)
 *   -> (names, units, arrays, status, messages, stats, nparams) */
static PyObject *py_sweep(PyObject *self, PyObject *args, PyObject *kw)
{
    static char *kwlist[] = {"path", "grid", "metrics", "random", "seed", "forces", "shard",
                             "index_offset", "jobs", NULL};
    PyObject *path, *grid, *metrics, *bytes = NULL, *result = NULL;
    mech_sweep_options o;
    mech_sweep_options_default(&o);
    (void)self;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "OOO|lKp(ii)li", kwlist, &path, &grid, &metrics,
                                     &o.nrandom, &o.seed, &o.forces, &o.shard_k, &o.shard_m,
                                     &o.index_offset, &o.nthreads) ||
        !PyUnicode_FSConverter(path, &bytes))
        return NULL;
    mech_sweep *s = NULL;
    mech_diag d;
    mech_diag_init(&d);
    int rc = mech_sweep_new(&s);
    if (rc == MECH_OK)
        rc = sweep_specs(s, grid, metrics, &d);
    if (rc == MECH_OK) {
        const char *file = PyBytes_AS_STRING(bytes);
        Py_BEGIN_ALLOW_THREADS
        rc = mech_sweep_prepare(s, file, &o, &d);
        Py_END_ALLOW_THREADS
    }
    if (rc == MECH_OK)
        result = sweep_result(s, &d);
    else if (rc != -100)
        raise_mech(rc, &d, NULL, NULL);
    mech_diag_free(&d);
    mech_sweep_free(&s);
    Py_DECREF(bytes);
    return result;
}

/* _mech.read(path) -> (names, units, arrays, {}, messages): a table that
 * mech solve or simulate wrote, CSV or HDF5 (mech_table_read) */
static PyObject *py_read(PyObject *self, PyObject *args, PyObject *kw)
{
    (void)self;
    static char *kwlist[] = {"path", NULL};
    const char *path;
    if (!PyArg_ParseTupleAndKeywords(args, kw, "s", kwlist, &path))
        return NULL;
    mech_diag d;
    mech_diag_init(&d);
    mech_table t;
    int rc;
    Py_BEGIN_ALLOW_THREADS
    rc = mech_table_read(path, &t, &d);
    Py_END_ALLOW_THREADS
    PyObject *out = rc == MECH_OK ? table_tuple_with(&t, PyDict_New(), &d)
                                  : raise_mech(rc, &d, "cannot read the table", NULL);
    mech_table_free(&t);
    mech_diag_free(&d);
    return out;
}

static PyMethodDef methods[] = {
    {"sweep", (PyCFunction)(void (*)(void))py_sweep, METH_VARARGS | METH_KEYWORDS,
     "sweep(path, grid, metrics, random=0, seed=1, forces=False, shard=(0, 1), "
     "index_offset=0, jobs=0) -> (names, units, arrays, status, messages, stats, nparams): "
     "mech_sweep, one row per variant"},
    {"load", (PyCFunction)(void (*)(void))py_load, METH_VARARGS | METH_KEYWORDS,
     "load(path, set=None, check=False) -> dict: the model (SI units); with check, "
     "also its structure (mech check)"},
    {"solve", (PyCFunction)(void (*)(void))py_solve, METH_VARARGS | METH_KEYWORDS,
     "solve(path, set=None, from_=None, to=None, steps=None, outputs=None, forces=None, "
     "tol=None, level=None, friction=None, diagnostics=False, all=False) -> "
     "(names, units, arrays, stats, messages)"},
    {"read", (PyCFunction)(void (*)(void))py_read, METH_VARARGS | METH_KEYWORDS,
     "read(path) -> (names, units, arrays, {}, messages): a CSV or HDF5 table that mech "
     "solve or simulate wrote"},
    {"simulate", (PyCFunction)(void (*)(void))py_simulate, METH_VARARGS | METH_KEYWORDS,
     "simulate(path, to=None, step=None, rtol=None, atol=None, method=None, "
     "stop_at_rest=False, stop_when=None) -> "
     "(names, units, arrays, stats, messages): mech_simulate"},
    {"fit", (PyCFunction)(void (*)(void))py_fit, METH_VARARGS | METH_KEYWORDS,
     "fit(path, free=None, target=None, columns=None, weights=None, starts=0, jobs=0, "
     "whole_range=False, free_timing=False, transmission=None) -> dict: mech_fit (synthesis)"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef module = {PyModuleDef_HEAD_INIT, "mech._mech",
                                    "libmech for Python (use the package mech)", -1, methods,
                                    NULL, NULL, NULL, NULL};

/* FAIL_KINDS: the words of mech_fail_name, in the order of the enum. */
static int add_fail_kinds(PyObject *mod)
{
    PyObject *names = PyList_New(0);
    for (int k = 0; names && strcmp(mech_fail_name((mech_fail_kind)k), "unknown") != 0; k++) {
        PyObject *n = PyUnicode_FromString(mech_fail_name((mech_fail_kind)k));
        if (!n || PyList_Append(names, n) < 0)
            Py_CLEAR(names);
        Py_XDECREF(n);
    }
    PyObject *kinds = names ? PyList_AsTuple(names) : NULL;
    Py_XDECREF(names);
    int rc = kinds ? PyModule_AddObjectRef(mod, "FAIL_KINDS", kinds) : -1;
    Py_XDECREF(kinds);
    return rc;
}

/* numpy's C API did not load (another interpreter than the one built for,
 * without numpy or with another numpy): an ImportError that says what the
 * extension was built for, what runs it, and how to build it for that. */
static void numpy_import_failed(void)
{
    PyObject *type, *value, *tb;
    PyErr_Fetch(&type, &value, &tb);
    PyObject *why = value ? PyObject_Str(value) : NULL;
    PyObject *exe = PySys_GetObject("executable");  /* borrowed */
    PyObject *np = PyImport_ImportModule("numpy");
    PyObject *npv = np ? PyObject_GetAttrString(np, "__version__") : NULL;
    PyErr_Clear();
    char version[32];
    snprintf(version, sizeof version, "%s", Py_GetVersion());
    version[strcspn(version, " ")] = '\0';
    PyObject *has = npv ? PyUnicode_FromFormat("numpy %S", npv) : PyUnicode_FromString("no numpy");
    PyErr_Format(PyExc_ImportError,
                 "mech's extension was built for %s (Python %s) with numpy %s; this is %S "
                 "(Python %s) with %S, and numpy's C API did not load (%S). Build mech for "
                 "this interpreter: make install PYTHON=%S, or %S -m pip install "
                 "--no-build-isolation ./python (docs/api.md, Python)",
                 MECH_BUILT_PYTHON, MECH_BUILT_PYTHON_VERSION, MECH_BUILT_NUMPY,
                 exe ? exe : Py_None, version, has ? has : Py_None, why ? why : Py_None,
                 exe ? exe : Py_None, exe ? exe : Py_None);
    Py_XDECREF(has);
    Py_XDECREF(npv);
    Py_XDECREF(np);
    Py_XDECREF(why);
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(tb);
}

/* _mech.BUILT_FOR: {'python': path, 'python_version': ..., 'numpy': ...}. */
static int add_built_for(PyObject *mod)
{
    PyObject *built = Py_BuildValue("{ssssss}", "python", MECH_BUILT_PYTHON, "python_version",
                                    MECH_BUILT_PYTHON_VERSION, "numpy", MECH_BUILT_NUMPY);
    int rc = built ? PyModule_AddObjectRef(mod, "BUILT_FOR", built) : -1;
    Py_XDECREF(built);
    return rc;
}

PyMODINIT_FUNC PyInit__mech(void);

PyMODINIT_FUNC PyInit__mech(void)
{
    if (_import_array() < 0) {  /* not import_array(): it prints, and says less */
        numpy_import_failed();
        return NULL;
    }
    PyObject *mod = PyModule_Create(&module);
    if (!mod)
        return NULL;
    MechError = PyErr_NewExceptionWithDoc(
        "mech.MechError",
        "A mechanism file that does not load or check, or a solve that fails. str(e) holds "
        "the library's messages, one 'file:line:column: error: message' per line; e.status "
        "is the libmech status (EINPUT, ENOMEM, EIO, ESOLVE), e.kind what failed (one of "
        "FAIL_KINDS: 'input', 'io', 'no-memory', 'no-assembly', 'dead-point', "
        "'change-point', 'branch', 'jump', 'redundant', 'not-converged', 'non-finite', "
        "'far-from-guess', 'on-ground-point', 'still-slider', 'folded-loop', 'still-outputs'), "
        "e.diagnostics the messages as dicts (each with its 'kind'), e.partial the rows "
        "solved before a failed solve (or None).",
        NULL, NULL);
    if (!MechError || PyModule_AddObjectRef(mod, "MechError", MechError) < 0 ||
        PyModule_AddStringConstant(mod, "VERSION", MECH_VERSION) < 0 ||
        add_built_for(mod) < 0 ||
        PyModule_AddIntConstant(mod, "EINPUT", MECH_EINPUT) < 0 ||
        PyModule_AddIntConstant(mod, "ENOMEM", MECH_ENOMEM) < 0 ||
        PyModule_AddIntConstant(mod, "EIO", MECH_EIO) < 0 ||
        PyModule_AddIntConstant(mod, "ESOLVE", MECH_ESOLVE) < 0 || add_fail_kinds(mod) < 0) {
        Py_DECREF(mod);
        return NULL;
    }
    return mod;
}
