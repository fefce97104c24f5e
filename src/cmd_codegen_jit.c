/* src/cmd_codegen_jit.c: `mech solve --jit` (docs/codegen.md, section "mech
 * solve --jit"): the code `mech codegen` writes for the file, compiled by
 * the system's C compiler ($CC, else cc) into a shared object in a private
 * temporary directory, loaded with dlopen and used for the sweep. The
 * generated code computes the interpreter's values bit for bit, so the
 * table is the interpreter's as long as every row takes the one Newton
 * solve from the predictor that the interpreter's continuation takes; a row
 * where the interpreter would do more (step halving: the predictor moves
 * too far, Newton lands far from the prediction or det J changes sign; a
 * failure: no assembly, a singular position, a branch condition, the
 * forces), an option the generated code does not follow, or no compiler,
 * and the interpreter solves the sweep instead, with a note on stderr. */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "codegen.h"
#include "commands.h"

/* What the shared object adds to the generated source (prefix jit): the
 * state's size and one row with the continuation's acceptance tests
 * (src/continuation.c cont_advance and cont_try). */
static const char *const wrapper[] = {
    "#include \"gen.c\"",
    "",
    "size_t jit_state_size(void);",
    "int jit_nout(void);",
    "const char *const *jit_names(void);",
    "int jit_row(void *vs, double q, double qd, double qdd, int first, double *out, double *info);",
    "",
    "size_t jit_state_size(void) { return sizeof(jit_state); }",
    "int jit_nout(void) { return JIT_NOUT; }",
    "const char *const *jit_names(void) { return jit_column_names; }",
    "",
    "/* Row q: 0 solved (out, info set), a status of jit_solve, or -1 where the",
    " * interpreter's continuation would not accept its first step. */",
    "int jit_row(void *vs, double q, double qd, double qdd, int first, double *out, double *info)",
    "{",
    "    jit_state *s = vs;",
    "    int st;",
    "    if (first) {",
    "        jit_init(s);",
    "        st = jit_solve(s, q, qd, qdd);",
    "    } else {",
    "        double xpred[NX + 1], move;",
    "        int det = s->det_sign;",
    "        jit_predict(s, q);",
    "        for (int i = 0; i < NX; i++) {",
    "            xpred[i] = s->x[i];",
    "            s->dx[i] = s->x[i] - s->xc[i];",
    "        }",
    "        move = step_size(s->dx);",
    "        if (move > 0.25)",
    "            return -1;",
    "        st = jit_solve(s, q, qd, qdd);",
    "        if (st == 0) {",
    "            for (int i = 0; i < NX; i++)",
    "                s->dx[i] = s->x[i] - xpred[i];",
    "            if (step_size(s->dx) > 0.5 * move + 0.05 || s->det_sign != det)",
    "                return -1;",
    "        }",
    "    }",
    "    if (st != 0)",
    "        return st;",
    "    for (int c = 0; c < JIT_NOUT; c++)",
    "        out[c] = s->out[c];",
    "    info[0] = s->iterations;",
    "    info[1] = s->residual;",
    "    /* info[2] in: the smallest rcond so far; s->rcond is a lower bound of the",
    "       interpreter's value, exact when it is not (docs/codegen.md): only one",
    "       below the smallest so far can change it */",
    "    info[2] = s->rcond < info[2] ? jit_rcond(s) : s->rcond;",
    "    info[3] = info[4] = 0.0;",
    "#ifdef NF",
    "    info[3] = fmax(fabs(s->power_residual), fabs(s->power_residual0));",
    "    info[4] = s->friction_iterations;",
    "#endif",
    "    return 0;",
    "}",
    NULL};

typedef struct jit {
    char dir[512];
    void *so;
    size_t (*state_size)(void);
    int (*nout)(void);
    const char *const *(*names)(void);
    int (*row)(void *, double, double, double, int, double *, double *);
} jit;

static double seconds_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Why the options keep the sweep with the interpreter, or NULL. */
static const char *unsupported(const mech_solve_options *o)
{
    mech_solve_options d;
    mech_solve_options_default(&d);
    return o->outputs ? "--outputs"
           : o->diagnostics ? "--diagnostics"
           : o->limit_rows ? "--range assembly"
           : o->tol != d.tol ? "--tol"
           : o->max_iter != d.max_iter ? "--max-iter"
           : o->min_rcond != d.min_rcond ? "--min-rcond"
           : o->want != d.want ? "--level"
           : o->linear_solver != d.linear_solver ? "--linear-solver"
                                                : NULL;
}

static int write_text(const char *path, const codegen *g)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    int rc = g ? codegen_emit_source(f, g) : 0;
    for (int i = 0; !g && wrapper[i]; i++)
        fprintf(f, "%s\n", wrapper[i]);
    rc |= ferror(f) ? -1 : 0;
    return fclose(f) != 0 || rc != 0 ? -1 : 0;
}

static void remove_dir(const char *dir)
{
    static const char *const names[] = {"gen.c", "jit.c", "jit.so", "cc.err"};
    char path[600];
    for (size_t i = 0; i < COUNT_OF(names); i++) {
        snprintf(path, sizeof path, "%s/%s", dir, names[i]);
        unlink(path);
    }
    rmdir(dir);
}

/* The first line of the compiler's messages, into buf. */
static void first_line(const char *path, char *buf, size_t size)
{
    FILE *f = fopen(path, "r");
    buf[0] = '\0';
    if (f && fgets(buf, (int)size, f))
        buf[strcspn(buf, "\n")] = '\0';
    if (f)
        fclose(f);
}

/* Generate, compile and load the solver of m: 0, or -1 with why in note. */
static int jit_build(jit *j, const mech_model *m, const mech_solve_options *o,
                     mech_solve_stats *st, char *note, size_t size)
{
    const char *tmp = getenv("TMPDIR");
    if (!tmp || !*tmp || strpbrk(tmp, "'\\") || strlen(tmp) > 400)
        tmp = "/tmp";
    snprintf(j->dir, sizeof j->dir, "%s/mech-jit.XXXXXX", tmp);
    if (!mkdtemp(j->dir))
        return snprintf(note, size, "cannot make a temporary directory in %s", tmp), -1;
    codegen g;
    mech_diag d;
    mech_diag_init(&d);
    codegen_options co = {"jit", NULL, o->all_blocks, o->forces, o->friction};
    char path[600], cmd[2048];
    int rc = codegen_init(&g, m, &co, &d);
    if (rc != MECH_OK) {
        snprintf(note, size, "the code generator: %s",
                 d.count > 0 ? d.entries[d.count - 1].message : "failed");
        codegen_free(&g);
        mech_diag_free(&d);
        return -1;
    }
    mech_diag_free(&d);
    st->nunknowns = g.sp.n;  /* the plan's sizes, as mech_solve reports them */
    st->nsolved = g.sp.ns;
    st->nblocks = g.sp.nblocks;
    st->nblocks_solved = g.sp.nblocks_solved;
    snprintf(path, sizeof path, "%s/gen.c", j->dir);
    rc = write_text(path, &g);
    codegen_free(&g);
    snprintf(path, sizeof path, "%s/jit.c", j->dir);
    if (rc != 0 || write_text(path, NULL) != 0)
        return snprintf(note, size, "cannot write the generated code in %s", j->dir), -1;
    const char *cc = getenv("CC");
    if (!cc || !*cc)
        cc = "cc";
    snprintf(cmd, sizeof cmd, "%s -std=c11 -O2 -fPIC -shared -o '%s/jit.so' '%s/jit.c' -lm "
             ">'%s/cc.err' 2>&1", cc, j->dir, j->dir, j->dir);
    int status = system(cmd);
    if (status != 0) {
        char msg[300];
        snprintf(path, sizeof path, "%s/cc.err", j->dir);
        first_line(path, msg, sizeof msg);
        return snprintf(note, size, "no C compiler ran ('%s' failed%s%s)", cc, msg[0] ? ": " : "",
                        msg), -1;
    }
    snprintf(path, sizeof path, "%s/jit.so", j->dir);
    j->so = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!j->so)
        return snprintf(note, size, "dlopen: %s", dlerror()), -1;
    /* POSIX: dlsym's object pointer holds a function's address */
    void *f[4] = {dlsym(j->so, "jit_state_size"), dlsym(j->so, "jit_nout"),
                  dlsym(j->so, "jit_names"), dlsym(j->so, "jit_row")};
    memcpy(&j->state_size, &f[0], sizeof f[0]);
    memcpy(&j->nout, &f[1], sizeof f[1]);
    memcpy(&j->names, &f[2], sizeof f[2]);
    memcpy(&j->row, &f[3], sizeof f[3]);
    if (!j->state_size || !j->nout || !j->names || !j->row)
        return snprintf(note, size, "the shared object lacks its functions"), -1;
    return 0;
}

/* The interpreter's driver positions for o (sweep.c sweep_values). */
static double *positions(const mech_model *m, const mech_solve_options *o, int *n)
{
    int steps = o->has_range ? (o->steps > 0 ? o->steps : 1) : m->driver.nvalues - 1;
    double *v = xcalloc((size_t)steps + 2, sizeof *v);
    for (int i = 0; v && i <= steps; i++)
        v[i] = !o->has_range ? m->driver.values[i]
               : i == steps  ? o->to
                             : o->from + (o->to - o->from) * i / steps;
    *n = steps + 1;
    return v;
}

/* The sweep by the loaded code into t (its header already made): 0, or -1
 * with why in note (t's rows are then to be discarded). */
static int jit_sweep(const jit *j, const mech_model *m, const double *q, int nq, mech_table *t,
                     mech_solve_stats *st, char *note, size_t size)
{
    int nout = j->nout();
    const char *const *names = j->names();
    if (nout != t->ncolumns)
        return snprintf(note, size, "the generated code has %d columns, mech solve %d", nout,
                        t->ncolumns), -1;
    for (int c = 0; c < nout; c++)
        if (strcmp(names[c], t->columns[c].name) != 0)
            return snprintf(note, size, "column %d is %s, mech solve's %s", c + 1, names[c],
                            t->columns[c].name), -1;
    void *s = calloc(1, j->state_size());
    free(t->values);  /* the header's room for no rows */
    t->values = xcalloc((size_t)nq * (size_t)nout + 1, sizeof *t->values);
    if (!s || !t->values) {
        free(s);
        return snprintf(note, size, "out of memory"), -1;
    }
    double info[5];
    for (int i = 0; i < nq; i++) {
        info[2] = st->min_rcond;
        int rc = j->row(s, q[i], m->driver.speed, m->driver.accel, i == 0,
                        t->values + (size_t)i * (size_t)nout, info);
        if (rc != 0) {
            free(s);
            return snprintf(note, size, "the generated code %s at row %d", rc < 0
                            ? "would take another step than the interpreter's continuation"
                            : rc == 1 ? "found no assembly" : rc == 2 ? "found a singular position"
                            : rc == 3 ? "found a branch condition false"
                                      : "could not solve the forces", i + 1), -1;
        }
        st->iterations += (long)info[0];
        st->max_iterations = (int)info[0] > st->max_iterations ? (int)info[0] : st->max_iterations;
        st->worst_residual = fmax(st->worst_residual, info[1]);
        if (info[2] < st->min_rcond) {
            st->min_rcond = info[2];
            st->worst_rcond_q = q[i];
        }
        st->worst_power_residual = fmax(st->worst_power_residual, info[3]);
        if ((int)info[4] > st->max_friction_iterations)
            st->max_friction_iterations = (int)info[4];
        t->nrows = i + 1;
    }
    free(s);
    return 0;
}

int cmd_jit_solve(const mech_model *m, const mech_solve_options *o, mech_table *t,
                  mech_solve_stats *st, mech_diag *d)
{
    char note[700] = "";
    const char *opt = unsupported(o);
    if (opt) {
        fprintf(stderr, "mech solve: note: --jit does not follow %s: the interpreter solves the "
                "sweep\n", opt);
        return mech_solve(m, o, t, st, d);
    }
    double t0 = seconds_now();
    mech_analysis *a = NULL;
    mech_diag ad;  /* the analysis's notes: d's when the generated code solves */
    mech_diag_init(&ad);
    if (mech_analysis_new(m, o, &a, &ad) != MECH_OK) {
        mech_diag_free(&ad);
        return mech_solve(m, o, t, st, d);  /* it says what is wrong */
    }
    jit j;
    memset(&j, 0, sizeof j);
    int nq = 0;
    double *q = positions(m, o, &nq);
    memset(st, 0, sizeof *st);
    st->min_rcond = INFINITY;  /* as the interpreter (sweep.c): row 0 sets it */
    int ok = q && jit_build(&j, m, o, st, note, sizeof note) == 0;
    if (j.dir[0])
        remove_dir(j.dir);  /* the loaded object stays mapped */
    double t1 = seconds_now();
    if (ok && mech_analysis_header(a, t) == MECH_OK) {
        t->nrequested = nq;
        ok = jit_sweep(&j, m, q, nq, t, st, note, sizeof note) == 0;
    } else if (ok) {
        ok = 0;
        snprintf(note, sizeof note, "out of memory");
    }
    if (ok) {
        st->steps = t->nrows;
        st->seconds = seconds_now() - t1;
        st->setup_seconds = t1 - t0;
    }
    free(q);
    if (j.so)
        dlclose(j.so);
    mech_analysis_free(&a);
    for (size_t i = 0; ok && i < ad.count; i++) {
        const mech_diag_entry *e = &ad.entries[i];
        if (e->severity == MECH_SEV_WARNING)
            diag_warning(d, e->file, e->mark, "%s", e->message);
        else
            diag_note(d, e->file, e->mark, "%s", e->message);
    }
    mech_diag_free(&ad);
    if (ok)
        return MECH_OK;
    mech_table_free(t);
    memset(t, 0, sizeof *t);
    fprintf(stderr, "mech solve: note: --jit: %s; the interpreter solves the sweep\n", note);
    return mech_solve(m, o, t, st, d);
}
