/* src/cli/cmd_convert.c: `mech convert`, a mechanism file from the drawn
 * form to the local form or back (docs/cli.md, docs/format.md 5.4). The
 * source text is copied and only the top-level sections that change are
 * written anew (drawing, ground, links, the joints whose slider angle
 * changes, initial), so comments outside them stay. The positions are the
 * solved first row of the sweep. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "load.h"

enum { TO_AUTO, TO_DRAWN, TO_LOCAL };

typedef struct convert_args {
    const char *file;
    const char *out;
    int to;
} convert_args;

static const cmd_word forms[] = {{"drawn", TO_DRAWN}, {"local", TO_LOCAL}, {NULL, 0}};

static const cmd_opt options[] = {
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = offsetof(convert_args, out),
     .flags = CMD_RUN_ONLY, .label = "-o, --output FILE",
     .help = "write the converted file there (default: standard output)"},
    {.names = "--to", .kind = CMD_OPT_WORD, .at = offsetof(convert_args, to), .words = forms,
     .expect = "is drawn or local", .label = "--to drawn|local",
     .help = "the form to write (default: the other one)"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_convert_spec = {
    .name = "convert",
    .summary = "write a mechanism file in the drawn or the local form",
    .usage = "usage: mech convert [--to drawn|local] [-o OUT] FILE\n",
    .about = "Write FILE in the other form (docs/format.md 5.4): a drawn file (with\n"
             "'drawing:') in the local form, each link's points in its own frame and\n"
             "initial guesses for the assembly; a local file in the drawn form, every\n"
             "point at its solved position at the driver's first value. The text is\n"
             "copied and only the sections that change are rewritten: comments outside\n"
             "drawing, ground, links, initial (and joints, when a slider's angle\n"
             "changes) are kept. Numbers are written in the file's units.\n",
    .opts = options,
    .column = 20,
    .exits = "exit status: 0 written, 1 the first position does not assemble, 2 invalid\n"
             "file or usage, 3 a file cannot be read or written\n",
    .max_files = 1,
    .file_at = offsetof(convert_args, file),
    .min_files = 1,
    .no_files = "no file given (usage: mech convert [--to drawn|local] [-o OUT] FILE)",
};

/* ---- the first position --------------------------------------------- */

typedef struct pose {
    mech_table t;
    double len, ang;   /* the file's length and angle units, SI per unit */
} pose;

static double col(const pose *p, const char *name, const char *field)
{
    char c[160];
    snprintf(c, sizeof c, "%s.%s", name, field);
    int i = mech_table_column(&p->t, c);
    return i >= 0 ? mech_table_get(&p->t, 0, i) : 0.0;
}

/* Row 0 with every point, moving link and slider as a column. */
static int solve_first(const mech_model *m, pose *p)
{
    size_t cap = 16;
    for (int i = 0; i < m->npoint_names; i++)
        cap += strlen(m->point_names[i]) + 1;
    for (int i = 1; i < m->nlinks; i++)
        cap += strlen(m->links[i].name) + 1;
    for (int j = 0; j < m->njoints; j++)
        cap += strlen(m->joints[j].name) + 1;
    char *list = calloc(cap, 1), err[256];
    if (!list)
        return MECH_ENOMEM;
    for (int i = 0; i < m->npoint_names; i++)
        strcat(strcat(list, *list ? "," : ""), m->point_names[i]);
    for (int i = 1; i < m->nlinks; i++)
        strcat(strcat(list, ","), m->links[i].name);
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER)
            strcat(strcat(list, ","), m->joints[j].name);
    mech_outputs outs;
    int rc = mech_outputs_parse(m, list, &outs, err, sizeof err);
    free(list);
    if (rc != MECH_OK) {
        fprintf(stderr, "mech convert: %s\n", err);
        return rc;
    }
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.want = MECH_WANT_POSITION;
    o.outputs = &outs;
    o.forces = -1;
    mech_diag d;
    mech_diag_init(&d);
    mech_analysis *a = NULL;
    rc = mech_analysis_new(m, &o, &a, &d);
    if (rc == MECH_OK)
        rc = mech_analysis_solve(a, m->driver.values, 1, &p->t, NULL, &d);
    if (rc == MECH_OK && p->t.nrows < 1)
        rc = MECH_ESOLVE;
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    mech_analysis_free(&a);
    mech_outputs_free(&outs);
    return rc;
}

/* The SI size of the file's unit for `key` under units: (1 when not given). */
static double file_unit(const ynode *root, const char *key)
{
    const ynode *u = ymap_get(ymap_get(root, "units"), key);
    double scale = 1.0;
    dim d;
    const char *end;
    if (!u || u->kind != YNODE_SCALAR || !unit_parse(u->text, &scale, &d, &end))
        return 1.0;
    return scale;
}

/* ---- writing --------------------------------------------------------- */

typedef struct text {
    char *s;
    size_t n, cap;
    int failed;
} text;

static void put(text *t, const char *fmt, ...) MECH_PRINTF(2, 3);
static void put(text *t, const char *fmt, ...)
{
    va_list ap;
    for (int pass = 0; pass < 2 && !t->failed; pass++) {
        va_start(ap, fmt);
        int k = vsnprintf(t->s ? t->s + t->n : NULL, t->s ? t->cap - t->n : 0, fmt, ap);
        va_end(ap);
        if (k < 0) {
            t->failed = 1;
        } else if (t->s && t->n + (size_t)k < t->cap) {
            t->n += (size_t)k;
            return;
        } else {
            size_t cap = 2 * (t->cap + (size_t)k) + 64;
            char *s = realloc(t->s, cap);
            if (!s)
                t->failed = 1;
            else
                t->s = s, t->cap = cap;
        }
    }
}

/* A number in the file's unit: shortest text that reads back within rounding. */
static void put_num(text *t, double si, double unit)
{
    double v = si / unit + 0.0;
    if (fabs(v) < 1e-13 * fmax(1.0, 1.0 / unit) * unit / unit && fabs(v) < 1e-12)
        v = 0.0;
    put(t, "%.15g", v);
}

/* A scalar as written (quoted again when it was). */
static void put_scalar(text *t, const ynode *n)
{
    if (n->kind != YNODE_SCALAR)
        return;
    put(t, n->quoted ? "\"%s\"" : "%s", n->text);
}

/* A flow mapping of a joint's keys, with its angle (SI) replacing or adding
 * 'angle' when angle_si is finite. */
static void put_joint(text *t, const ynode *j, double angle_si, double ang)
{
    put(t, "  - {");
    int any = 0;
    for (size_t i = 0; i < j->n; i++) {
        const ynode *k = j->items[2 * i], *v = j->items[2 * i + 1];
        if (strcmp(k->text, "angle") == 0 && isfinite(angle_si))
            continue;
        put(t, "%s%s: ", any++ ? ", " : "", k->text);
        put_scalar(t, v);
    }
    if (isfinite(angle_si)) {
        put(t, "%sangle: ", any ? ", " : "");
        put_num(t, angle_si, ang);
    }
    put(t, "}\n");
}

/* ---- drawn -> local -------------------------------------------------- */

static void put_local_points(text *t, const mech_link *l, double len)
{
    put(t, "{");
    for (int i = 0; i < l->npoints; i++) {
        put(t, "%s%s: [", i ? ", " : "", l->points[i].name);
        put_num(t, l->points[i].x, len);
        put(t, ", ");
        put_num(t, l->points[i].y, len);
        put(t, "]");
    }
    put(t, "}");
}

static void local_ground(text *t, const mech_model *m, const ynode *root, const pose *p)
{
    const ynode *drawing = ymap_get(root, "drawing");
    put(t, "ground:\n");
    for (int i = 0; i < m->links[0].npoints; i++) {
        const mech_point *q = &m->links[0].points[i];
        const ynode *xy = ymap_get(drawing, q->name);
        put(t, "  %s: [", q->name);
        if (xy && xy->kind == YNODE_SEQ && xy->n == 2) {  /* as drawn: expressions kept */
            put_scalar(t, xy->items[0]);
            put(t, ", ");
            put_scalar(t, xy->items[1]);
        } else {
            put_num(t, q->x, p->len);
            put(t, ", ");
            put_num(t, q->y, p->len);
        }
        put(t, "]\n");
    }
}

static void local_links(text *t, const mech_model *m, const ynode *root, const pose *p)
{
    const ynode *links = ymap_get(root, "links");
    put(t, "links:\n");
    for (int li = 1; li < m->nlinks; li++) {
        const mech_link *l = &m->links[li];
        const ynode *v = ymap_get(links, l->name);
        if (!v || v->kind != YNODE_MAP) {
            put(t, "  %s: {points: ", l->name);
            put_local_points(t, l, p->len);
            put(t, "}\n");
            continue;
        }
        put(t, "  %s:\n    points: ", l->name);
        put_local_points(t, l, p->len);
        put(t, "\n");
        for (size_t i = 0; i < v->n; i++) {
            const ynode *k = v->items[2 * i], *x = v->items[2 * i + 1];
            if (strcmp(k->text, "points") == 0)
                continue;
            put(t, "    %s: ", k->text);
            if (strcmp(k->text, "center") == 0 && x->kind == YNODE_SEQ) {
                put(t, "[");
                put_num(t, l->center[0], p->len);
                put(t, ", ");
                put_num(t, l->center[1], p->len);
                put(t, "]");
            } else {
                put_scalar(t, x);
            }
            put(t, "\n");
        }
    }
}

/* The guesses that give the drawn assembly at the first driver value: the
 * solved first row's angles and displacements. */
static void local_initial(text *t, const mech_model *m, const pose *p)
{
    int *locked_of = load_locked_sliders(m);
    if (!locked_of) {
        t->failed = 1;
        return;
    }
    put(t, "initial:                 # the drawn assembly, at the driver's first value\n");
    for (int li = 1; li < m->nlinks; li++) {
        int driven = 0;
        for (int k = 0; k < m->ndrivers; k++)
            driven |= m->drivers[k].kind == MECH_DRIVE_ANGLE && m->drivers[k].index == li;
        if (driven || locked_of[li] >= 0)
            continue;
        put(t, "  %s: ", m->links[li].name);
        put_num(t, col(p, m->links[li].name, "angle"), p->ang);
        put(t, "\n");
    }
    for (int j = 0; j < m->njoints; j++) {
        int driven = 0;
        for (int k = 0; k < m->ndrivers; k++)
            driven |= m->drivers[k].kind == MECH_DRIVE_SLIDER && m->drivers[k].index == j;
        if (m->joints[j].kind != MECH_JOINT_SLIDER || driven)
            continue;
        put(t, "  %s: ", m->joints[j].name);
        put_num(t, col(p, m->joints[j].name, "s"), p->len);
        put(t, "\n");
    }
    free(locked_of);
}

/* ---- local -> drawn -------------------------------------------------- */

static void drawn_drawing(text *t, const mech_model *m, const pose *p)
{
    put(t, "drawing:                 # every point at the driver's first value\n");
    for (int i = 0; i < m->npoint_names; i++) {
        put(t, "  %s: [", m->point_names[i]);
        put_num(t, col(p, m->point_names[i], "x"), p->len);
        put(t, ", ");
        put_num(t, col(p, m->point_names[i], "y"), p->len);
        put(t, "]\n");
    }
}

/* Point indices of l in the drawn form's order: a point at the frame's
 * origin first, one on its +x axis second, when there are such. 0 when the
 * frame is not along two of its points (its angle would change). */
static int drawn_order(const mech_link *l, int *order)
{
    int o = -1, x = -1;
    for (int i = 0; i < l->npoints; i++) {
        double px = l->points[i].x, py = l->points[i].y;
        if (o < 0 && px == 0.0 && py == 0.0)
            o = i;
        else if (x < 0 && py == 0.0 && px > 0.0)
            x = i;
    }
    int n = 0;
    if (o >= 0 && x >= 0)
        order[n++] = o, order[n++] = x;
    for (int i = 0; i < l->npoints; i++)
        if (!(o >= 0 && x >= 0 && (i == o || i == x)))
            order[n++] = i;
    return (o >= 0 && x >= 0) || l->npoints < 2;
}

static void drawn_links(text *t, const mech_model *m, const ynode *root, const pose *p,
                        const char *file)
{
    const ynode *links = ymap_get(root, "links");
    int *locked_of = load_locked_sliders(m);
    put(t, "links:\n");
    for (int li = 1; li < m->nlinks; li++) {
        const mech_link *l = &m->links[li];
        int *order = locked_of ? calloc((size_t)l->npoints + 1, sizeof *order) : NULL;
        if (!order) {
            t->failed = 1;
            break;
        }
        if (!drawn_order(l, order) && locked_of[li] < 0)
            fprintf(stderr, "%s: warning: link '%s' has no point at its frame's origin with "
                    "another on its x axis: its angle in the drawn form is the direction "
                    "from '%s' to '%s'\n", file, l->name, l->points[order[0]].name,
                    l->points[order[1]].name);
        const ynode *v = ymap_get(links, l->name);
        int extra = v && v->kind == YNODE_MAP && v->n > 1;
        put(t, extra ? "  %s:\n    points: [" : "  %s: [", l->name);
        for (int i = 0; i < l->npoints; i++)
            put(t, "%s%s", i ? ", " : "", l->points[order[i]].name);
        put(t, "]\n");
        double th = col(p, l->name, "angle"), c = cos(th), s = sin(th);
        const mech_point *q = &l->points[0];
        double X = col(p, q->name, "x"), Y = col(p, q->name, "y");
        for (size_t i = 0; extra && i < v->n; i++) {
            const ynode *k = v->items[2 * i], *x = v->items[2 * i + 1];
            if (strcmp(k->text, "points") == 0)
                continue;
            put(t, "    %s: ", k->text);
            if (strcmp(k->text, "center") == 0 && x->kind != YNODE_SCALAR) {
                double dx = l->center[0] - q->x, dy = l->center[1] - q->y;
                put(t, "[");
                put_num(t, X + c * dx - s * dy, p->len);
                put(t, ", ");
                put_num(t, Y + s * dx + c * dy, p->len);
                put(t, "]");
            } else {
                put_scalar(t, x);
            }
            put(t, "\n");
        }
        free(order);
    }
    free(locked_of);
}

/* ---- the joints: a slider's angle, local <-> global ---------------- */

/* 1 when some slider's angle text must change: drawn -> local, a slider
 * without 'angle' or on a moving guide; local -> drawn, on a moving guide. */
static int joints_change(const mech_model *m, const ynode *joints, int to)
{
    for (int j = 0, k = 0; j < m->njoints; j++) {
        if (m->joints[j].kind != MECH_JOINT_SLIDER)
            continue;
        const ynode *n = NULL;
        for (; joints && (size_t)k < joints->n && !n; k++)
            if (ymap_get(joints->items[k], "slider"))
                n = joints->items[k];
        if (m->joints[j].link[1] != 0 || (to == TO_LOCAL && n && !ymap_get(n, "angle")))
            return 1;
    }
    return 0;
}

static void convert_joints(text *t, const mech_model *m, const ynode *joints, const pose *p,
                           int to)
{
    put(t, "joints:\n");
    int j = 0;
    for (size_t i = 0; i < joints->n; i++) {
        const ynode *n = joints->items[i];
        if (!ymap_get(n, "slider")) {
            put_joint(t, n, NAN, p->ang);
            continue;
        }
        while (j < m->njoints && m->joints[j].kind != MECH_JOINT_SLIDER)
            j++;
        const mech_joint *jt = &m->joints[j++ < m->njoints ? j - 1 : 0];
        double guide = jt->link[1] ? col(p, m->links[jt->link[1]].name, "angle") : 0.0;
        put_joint(t, n, to == TO_LOCAL ? jt->angle : jt->angle + guide, p->ang);
    }
}

/* ---- the sections ---------------------------------------------------- */

/* The lines of a top-level key: from its line to its last line that is not
 * blank or a comment before the next key (comments above a key stay its). */
typedef struct span {
    const char *key;
    int first, last;  /* 1-based lines */
} span;

static int is_blank_or_comment(const char *line, const char *end)
{
    while (line < end && (*line == ' ' || *line == '\t'))
        line++;
    return line == end || *line == '#' || *line == '\r';
}

static const char **line_starts(const char *s, size_t len, int *nlines)
{
    int n = 1;
    for (size_t i = 0; i < len; i++)
        n += s[i] == '\n';
    const char **v = calloc((size_t)n + 2, sizeof *v);
    if (!v)
        return NULL;
    int k = 0;
    v[k++] = s;
    for (size_t i = 0; i < len; i++)
        if (s[i] == '\n')
            v[k++] = s + i + 1;
    v[k] = s + len;
    *nlines = k;  /* v[i]: line i + 1; v[nlines]: the end */
    return v;
}

static span *spans_of(const ynode *root, const char **lines, int nlines)
{
    span *sp = calloc(root->n + 1, sizeof *sp);
    if (!sp)
        return NULL;
    for (size_t i = 0; i < root->n; i++) {
        const ynode *k = root->items[2 * i];
        int next = i + 1 < root->n ? root->items[2 * i + 2]->mark.line : nlines + 1;
        int last = next - 1;
        while (last > k->mark.line && is_blank_or_comment(lines[last - 1], lines[last]))
            last--;
        sp[i] = (span){k->text, k->mark.line, last};
    }
    return sp;
}

/* What becomes of a top-level section: its text anew, or NULL (kept as
 * written); *drop: left out. */
static void section(text *t, const char *key, const mech_model *m, const ynode *root,
                    const pose *p, int to, const char *file, int *kept)
{
    *kept = 0;
    const ynode *joints = ymap_get(root, "joints");
    if (strcmp(key, "drawing") == 0 && to == TO_LOCAL)
        return;
    if (strcmp(key, "ground") == 0 && to == TO_LOCAL)
        return local_ground(t, m, root, p);
    if (strcmp(key, "ground") == 0) {
        drawn_drawing(t, m, p);
        put(t, "ground: [");
        for (int i = 0; i < m->links[0].npoints; i++)
            put(t, "%s%s", i ? ", " : "", m->links[0].points[i].name);
        put(t, "]\n");
        return;
    }
    if (strcmp(key, "links") == 0)
        return to == TO_LOCAL ? local_links(t, m, root, p) : drawn_links(t, m, root, p, file);
    if (strcmp(key, "joints") == 0 && joints && joints->kind == YNODE_SEQ &&
        joints_change(m, joints, to))
        return convert_joints(t, m, joints, p, to);
    if (strcmp(key, "initial") == 0)
        return to == TO_LOCAL ? local_initial(t, m, p) : (void)0;
    *kept = 1;
}

static int write_converted(text *t, const char *src, size_t len, const ynode *root,
                           const mech_model *m, const pose *p, int to, const char *file)
{
    int nlines = 0;
    const char **lines = line_starts(src, len, &nlines);
    span *sp = lines ? spans_of(root, lines, nlines) : NULL;
    if (!sp) {
        free(lines);
        return MECH_ENOMEM;
    }
    int at = 1;  /* the next source line to copy */
    for (size_t i = 0; i < root->n; i++) {
        put(t, "%.*s", (int)(lines[sp[i].first - 1] - lines[at - 1]), lines[at - 1]);
        int kept;
        section(t, sp[i].key, m, root, p, to, file, &kept);
        if (kept)
            put(t, "%.*s", (int)(lines[sp[i].last] - lines[sp[i].first - 1]),
                lines[sp[i].first - 1]);
        at = sp[i].last + 1;
    }
    put(t, "%.*s", (int)(lines[nlines] - lines[at - 1]), lines[at - 1]);
    if (to == TO_LOCAL && !ymap_get(root, "initial")) {
        if (t->n && t->s[t->n - 1] != '\n')
            put(t, "\n");
        local_initial(t, m, p);
    }
    free(sp);
    free(lines);
    return t->failed ? MECH_ENOMEM : MECH_OK;
}

int cmd_convert(int argc, char **argv)
{
    convert_args a = {NULL, NULL, TO_AUTO};
    int code = cmd_opts_parse(&cmd_convert_spec, argc, argv, &a);
    if (code >= 0)
        return code;
    mech_model *m = NULL;
    code = cmd_load_checked(a.file, &m);
    if (code != MECH_EXIT_OK)
        return code;
    size_t len = 0;
    int rc;
    mech_diag d;
    mech_diag_init(&d);
    char *src = load_read_file(a.file, yaml_default_limits.max_bytes, &len, &d, &rc);
    ynode *root = src ? ytree_parse(src, len, a.file, NULL, &d) : NULL;
    mech_diag_print(&d, stderr);  /* the file changed since it was loaded */
    mech_diag_free(&d);
    pose p = {.t = {0}};
    text t = {0};
    if (src && !root)
        rc = MECH_EINPUT;
    if (rc == MECH_OK) {
        int drawn = ymap_get(root, "drawing") != NULL;
        int to = a.to == TO_AUTO ? (drawn ? TO_LOCAL : TO_DRAWN) : a.to;
        p.len = file_unit(root, "length");
        p.ang = file_unit(root, "angle");
        if ((to == TO_LOCAL) != drawn) {
            rc = MECH_OK;  /* already in that form: copied as it is */
            put(&t, "%.*s", (int)len, src);
        } else if ((rc = solve_first(m, &p)) == MECH_OK) {
            rc = write_converted(&t, src, len, root, m, &p, to, a.file);
        }
    }
    if (rc == MECH_OK) {
        FILE *out = a.out ? fopen(a.out, "wb") : stdout;
        if (!out || fwrite(t.s, 1, t.n, out) != t.n || (a.out && fclose(out) != 0)) {
            fprintf(stderr, "mech convert: cannot write '%s'\n", a.out ? a.out : "-");
            rc = MECH_EIO;
        }
    }
    free(t.s);
    ytree_free(root);
    free(src);
    mech_table_free(&p.t);
    mech_model_free(&m);
    return cmd_exit_status(rc);
}
