/* src/load/load.c: YAML document tree -> mech_model, validating as it goes.
 *
 * Schema (docs/format.md is the user's description of it):
 *   name: str                       required
 *   description: str
 *   units: {quantity: unit}         default units for bare numbers
 *   parameters: {name: expr}        named values, usable in later expressions
 *   gravity: [gx, gy]               acceleration
 *   ground: {point: [x, y]}         required, fixed points in the global frame
 *   links: {name: {points: {point: [x, y] | {length, angle, from}},
 *                  symbol, mass, center, inertia}}            required
 *   joints: [{revolute: P, links: [a, b], name, friction, pin_radius}
 *          | {slider: P, link, on, through, angle, rotation, name, symbol, friction}]
 *   driver: {link | slider, angle | displacement, speed, acceleration}  required, or
 *   sweep: {time: RANGE} with drivers: [{link, angle: LAW} | {slider, displacement: LAW}]
 *                                   (laws of the time t: load_drivers.c)
 *   initial: {link or slider name: value}
 *   branch: [{points: [A, B, C], turn: ccw | cw}]
 *   loops: [[A, B, C, A] | "A B C A"]
 *   loads: [{force: [fx, fy], link, at} | {torque, link}
 *         | {distributed, link, from, to, direction}]
 *   springs: [{between: [P, Q], links, name, stiffness, free_length, preload, damping}
 *           | {at: JOINT, name, stiffness, free_angle, preload, damping}]   (load_springs.c)
 *   gears: [{gear, with, teeth, module, radii, internal, arm, pressure_angle, offset, name}
 *          | {pinion, rack, radius, teeth, module, offset, rack_offset, ...}] (load_gears.c)
 *   cams: [{cam, follower, contact, base_radius, roller_radius, at, turning, start,
 *           program, name}] (load_cams.c)
 *   outputs: {points: [...], links: [...], sliders: [...], forces: bool}
 *
 * Every problem is recorded with its file:line:column and loading goes on,
 * so one run reports all the errors it can find.
 *
 * This file owns the entry points (mech_load_*), reading the file and the
 * dispatch of the document's top-level keys to the stages: load_tree.c
 * (shared tree walking), load_links.c, load_joints.c, load_motion.c and
 * load_outputs.c; load.h holds the loader's state. */
#include <errno.h>
#include <fcntl.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "base.h"
#include "load.h"

/* ---- the document -------------------------------------------------- */

static void load_document(loader *ld, const ynode *root)
{
    static const char *const keys[] = {"name", "description", "units", "parameters", "gravity",
                                       "ground", "links", "joints", "driver", "initial",
                                       "branch", "loops", "loads", "springs", "gears", "cams",
                                       "outputs", "sweep", "drivers", "drawing", "fit"};
    mech_model *m = ld->m;
    size_t errors = ld->d->nerrors;
    if (!load_check_keys(ld, root, keys, COUNT(keys), "the mechanism"))
        return;
    const ynode *v;
    static const char *const required[] = {"name", "ground", "links", "driver"};
    for (size_t i = 0; i < COUNT(required); i++)
        if (!ymap_get(root, required[i]) &&
            !(strcmp(required[i], "driver") == 0 && ymap_get(root, "drivers")) && !load_misspelt(root, required[i], keys, COUNT(keys)))
            load_err(ld, root, "missing '%s' (a mechanism file needs name, ground, links and driver)",
                     required[i]);
    if ((v = ymap_get(root, "name")))
        m->name = load_get_string(ld, v, "'name'", 200, 0);
    if ((v = ymap_get(root, "description")))
        m->description = load_get_string(ld, v, "'description'", 4000, 1);
    if ((v = ymap_get(root, "units")))
        load_units(ld, v);
    if ((v = ymap_get(root, "parameters")))
        load_parameters(ld, v);
    if ((v = ymap_get(root, "gravity")))
        load_get_vec2(ld, v, Q_ACCELERATION, "gravity", m->gravity);
    if ((v = ymap_get(root, "drawing")) && !(root = load_drawn_tree(ld, root, v)))
        return;  /* reported; the links cannot be read without their drawing */
    const ynode *links = ymap_get(root, "links");
    size_t nlinks = 1 + (links && links->kind == YNODE_MAP ? links->n : 0);
    m->links = xcalloc(nlinks, sizeof *m->links);
    ld->link_failed = xcalloc(nlinks, sizeof *ld->link_failed);
    if (!m->links || !ld->link_failed)
        return (void)load_nomem(ld, root);
    m->nlinks = 1;
    if ((v = ymap_get(root, "ground")))
        load_ground(ld, v);
    else
        load_ground(ld, NULL);
    if (links)
        load_links(ld, links);
    else
        ld->links_bad = 1;
    load_index_carriers(ld);
    if ((v = ymap_get(root, "joints")))
        load_joints(ld, v);
    load_add_implicit_revolutes(ld);
    if ((v = ymap_get(root, "gears")))  /* before the points check: a gear may have one */
        load_gears(ld, v);
    if ((v = ymap_get(root, "cams")))  /* likewise: a cam may have its pivot alone */
        load_cams(ld, v);
    load_check_link_points(ld);
    load_warn_point_typos(ld, ymap_get(root, "outputs"));
    const ynode *dv = ymap_get(root, "drivers"), *sw = ymap_get(root, "sweep");
    if ((v = ymap_get(root, "driver")) && (dv || sw))
        load_err(ld, load_key_of(root, dv ? "drivers" : "sweep"),
                 "'driver' and '%s' together: give 'driver' (one driver, swept through its "
                 "range) or 'drivers' with 'sweep' (laws of the time t)", dv ? "drivers" : "sweep");
    else if (v)
        load_driver(ld, v);
    else if (dv || sw)
        load_sweep_drivers(ld, sw, dv);
    if ((v = ymap_get(root, "initial")))
        load_initial(ld, v);
    if ((v = ymap_get(root, "branch")))
        load_branches(ld, v);
    if (ld->d->nerrors == errors)
        load_guesses_from_points(ld);
    if (ld->d->nerrors == errors)
        load_cams_place(ld);  /* an oscillating follower's base: the one nearest its guess */
    if ((v = ymap_get(root, "loops")))
        load_loops(ld, v);
    if ((v = ymap_get(root, "loads")))
        load_loads(ld, v);
    if ((v = ymap_get(root, "springs")))
        load_springs(ld, v);
    if ((v = ymap_get(root, "outputs")))
        load_outputs(ld, v);
    else
        load_default_outputs(m);
    if ((v = ymap_get(root, "fit")))
        load_fit(ld, v);
}

static int load_string_with(const char *text, size_t len, const char *name,
                            const mech_override *ov, int nov, mech_model **out, mech_diag *d);
static int load_file_path(const char *path, const mech_override *ov, int nov, mech_model **out,
                          mech_diag *d);

/* The public loads (include/mech.h, "NULL arguments"): the file `path` or
 * the text, out and d optional. */
static int load_checked(const char *func, const char *path, const char *text, size_t len,
                        const char *name, const mech_override *ov, int nov, mech_model **out,
                        mech_diag *d)
{
    mech_model *model = NULL;
    mech_diag own, *dd = api_diag(d, &own);
    const char *missing = path || text ? NULL : strcmp(func, "mech_load_string") ? "path" : "text";
    int rc = missing ? api_null(dd, func, missing) : api_overrides(func, ov, nov, dd);
    if (rc == MECH_OK)
        rc = path ? load_file_path(path, ov, nov, &model, dd)
                  : load_string_with(text, len, name, NULL, 0, &model, dd);
    if (out)
        *out = model;
    else
        mech_model_free(&model);  /* the caller wanted the file checked only */
    api_diag_end(d, &own);
    return rc;
}

int mech_load_string(const char *text, size_t len, const char *name, mech_model **out,
                     mech_diag *d)
{
    return load_checked("mech_load_string", NULL, text, len, name ? name : "<string>", NULL, 0,
                        out, d);
}

/* Overrides naming no parameter of the file. */
static void unused_overrides(loader *ld)
{
    for (int o = 0; o < ld->nov; o++)
        if (!ld->ov_used[o])
            diag_error(ld->d, ld->file, (mech_mark){0, 0},
                       "no parameter '%s' in the file's 'parameters:' to replace",
                       ld->ov[o].name);
}

static int load_tree_with(const ynode *root, const char *name, const mech_override *ov,
                          int nov, int expressions, mech_model **out, mech_diag *d);

static int load_string_with(const char *text, size_t len, const char *name,
                            const mech_override *ov, int nov, mech_model **out, mech_diag *d)
{
    *out = NULL;
    size_t first = d->count;
    ynode *root = ytree_parse(text, len, name, NULL, d);
    if (!root)
        return diag_status_since(d, first, MECH_EINPUT);
    int rc = load_tree_with(root, name, ov, nov, 1, out, d);
    ytree_free(root);
    return rc;
}

/* The model of a parsed document (read only: threads may share the tree);
 * expressions: with its parameter expressions (mech_model.pexpr). */
static int load_tree_with(const ynode *root, const char *name, const mech_override *ov,
                          int nov, int expressions, mech_model **out, mech_diag *d)
{
    *out = NULL;
    size_t errors_before = d->nerrors, first = d->count;
    loader ld = {0};
    ld.file = name;
    ld.d = d;
    ld.ov = ov;
    ld.nov = nov;
    ld.expressions = expressions;
    unsigned char used[64] = {0};
    ld.ov_used = used;
    if (nov > 64)
        return diag_error(d, name, (mech_mark){0, 0}, "at most 64 parameter replacements");
    ld.m = xcalloc(1, sizeof *ld.m);
    unit_defaults_init(&ld.units);
    ld.env.units = &ld.units;
    if (!ld.m)
        return diag_nomem(d, name, (mech_mark){0, 0});
    if (!(ld.m->file = xstrdup(name))) {
        free(ld.m);
        return diag_nomem(d, name, (mech_mark){0, 0});
    }
    if (root->kind != YNODE_MAP)
        load_err(&ld, root, "a mechanism file must be a mapping of keys ('name:', 'ground:', "
                            "'links:', 'driver:', ...), not %s", ynode_kind_name(root->kind));
    else
        load_document(&ld, root);
    unused_overrides(&ld);
    if (ld.m->pexpr && ld.m->pexpr->failed)
        diag_nomem(d, name, (mech_mark){0, 0});
    free(ld.params);
    free(ld.link_failed);
    name_map_free(&ld.bad_params);
    name_map_free(&ld.param_map);
    name_map_free(&ld.next_suffix);
    free(ld.carrier_start);
    free(ld.carrier_link);
    free(ld.carrier_point);
    name_map_free(&ld.point_map);
    name_map_free(&ld.link_map);
    name_map_free(&ld.joint_map);
    name_map_free(&ld.drawn_map);
    free(ld.drawn);
    free(ld.pguess);
    ytree_free(ld.drawn_root);
    if (d->nerrors > errors_before) {
        mech_model_free(&ld.m);
        return diag_status_since(d, first, MECH_EINPUT);  /* out of memory, or invalid */
    }
    *out = ld.m;
    return MECH_OK;
}

/* What a file that is not a regular file is, for the message. */
static const char *file_kind(mode_t mode)
{
    return S_ISDIR(mode) ? "a directory" : S_ISFIFO(mode) ? "a FIFO (named pipe)"
         : S_ISCHR(mode) || S_ISBLK(mode) ? "a device" : S_ISSOCK(mode) ? "a socket"
         : "a special file";
}

/* Open a mechanism file: a regular file of at most `max` bytes, checked
 * before anything is read (O_NONBLOCK: opening a FIFO does not wait for a
 * writer). NULL with *rc set and the problem recorded. */
static FILE *open_input(const char *path, size_t max, mech_diag *d, int *rc)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        *rc = MECH_EIO;
        diag_fail(d, MECH_FAIL_IO, path, (mech_mark){0, 0}, "cannot open: %s", strerror(errno));
    } else if (!S_ISREG(st.st_mode)) {
        *rc = MECH_EIO;
        diag_fail(d, MECH_FAIL_IO, path, (mech_mark){0, 0}, "cannot read: %s, not a regular "
                  "file", file_kind(st.st_mode));
    } else if ((uintmax_t)st.st_size > (uintmax_t)max) {
        *rc = MECH_EINPUT;
        diag_error(d, path, (mech_mark){0, 0}, "file too large (%jd bytes; at most %zu)",
                   (intmax_t)st.st_size, max);
    } else {
        int flags = fcntl(fd, F_GETFL);
        FILE *f = flags >= 0 && fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == 0 ? fdopen(fd, "rb")
                                                                            : NULL;
        if (f)
            return f;
        *rc = MECH_EIO;
        char ebuf[128];
        diag_fail(d, MECH_FAIL_IO, path, (mech_mark){0, 0}, "cannot open: %s",
                  diag_strerror(errno, ebuf, sizeof ebuf));
    }
    if (fd >= 0)
        close(fd);
    return NULL;
}

/* Read a whole file into memory, refusing more than `max` bytes (checked
 * again while reading: the file may grow). */
char *load_read_file(const char *path, size_t max, size_t *len, mech_diag *d, int *rc)
{
    FILE *f = open_input(path, max, d, rc);
    if (!f)
        return NULL;
    size_t cap = 1 << 16, n = 0;
    char *buf = malloc(cap);
    while (buf) {
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap)
            break;  /* end of file or error */
        if (cap > max)
            break;
        char *bigger = realloc(buf, 2 * cap);
        if (!bigger) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = bigger;
        cap *= 2;
    }
    int failed = ferror(f);
    fclose(f);
    *rc = MECH_OK;
    if (!buf) {
        *rc = MECH_ENOMEM;
        diag_nomem(d, path, (mech_mark){0, 0});
    } else if (failed) {
        *rc = MECH_EIO;
        diag_fail(d, MECH_FAIL_IO, path, (mech_mark){0, 0}, "read error");
    } else if (n > max) {
        *rc = MECH_EINPUT;
        diag_error(d, path, (mech_mark){0, 0}, "file too large (more than %zu bytes)", max);
    }
    if (*rc != MECH_OK) {
        free(buf);
        return NULL;
    }
    *len = n;
    return buf;
}

int mech_load_file(const char *path, mech_model **out, mech_diag *d)
{
    return load_checked("mech_load_file", path, NULL, 0, path, NULL, 0, out, d);
}

int mech_load_file_with(const char *path, const mech_override *ov, int nov, mech_model **out,
                        mech_diag *d)
{
    return load_checked("mech_load_file_with", path, NULL, 0, path, ov, nov, out, d);
}

/* The file at path (read whole, bounded) with its overrides. */
static int load_file_path(const char *path, const mech_override *ov, int nov, mech_model **out,
                          mech_diag *d)
{
    *out = NULL;
    size_t len = 0;
    int rc;
    char *buf = load_read_file(path, yaml_default_limits.max_bytes, &len, d, &rc);
    if (!buf)
        return rc;
    rc = load_string_with(buf, len, path, ov, nov, out, d);
    free(buf);
    return rc;
}

/* ---- a document parsed once, loaded many times (mech sweep) --------- */

struct load_doc {
    char *path;
    ynode *root;
};

int load_doc_read(const char *path, load_doc **out, mech_diag *d)
{
    *out = NULL;
    size_t len = 0;
    int rc;
    char *buf = load_read_file(path, yaml_default_limits.max_bytes, &len, d, &rc);
    if (!buf)
        return rc;
    size_t first = d->count;
    load_doc *doc = xcalloc(1, sizeof *doc);
    if (doc && (doc->path = xstrdup(path)))
        doc->root = ytree_parse(buf, len, path, NULL, d);
    free(buf);
    if (!doc || !doc->root) {
        rc = doc && doc->path ? diag_status_since(d, first, MECH_EINPUT) : MECH_ENOMEM;
        load_doc_free(&doc);
        return rc;
    }
    *out = doc;
    return MECH_OK;
}

int load_doc_model(const load_doc *doc, const mech_override *ov, int nov, mech_model **out,
                   mech_diag *d)
{
    return load_tree_with(doc->root, doc->path, ov, nov, 1, out, d);
}

int load_doc_numbers(const load_doc *doc, const mech_override *ov, int nov, mech_model **out,
                     mech_diag *d)
{
    return load_tree_with(doc->root, doc->path, ov, nov, 0, out, d);
}

void load_doc_free(load_doc **doc)
{
    if (!doc || !*doc)
        return;
    ytree_free((*doc)->root);
    free((*doc)->path);
    free(*doc);
    *doc = NULL;
}
