/* tests/unit/test_golden.c: the golden CSV files tests/golden/NAME.csv
 * (written by `mech solve mechanisms/NAME.yaml -o tests/golden/NAME.csv`,
 * `make golden`) checked by means independent of the solver: only the CSV
 * numbers (read with compare_read_csv) and the geometry of the model (read
 * with mech_load_file) are used; mech_solve is never called.
 *
 * Every tests/golden/NAME.csv that has a mechanisms/NAME.yaml is checked,
 * and every mechanisms/NAME.yaml must have its golden file. The directories can be
 * changed for a test run with the environment variables MECH_GOLDEN_DIR
 * (default tests/golden) and MECH_GOLDEN_MECHANISMS (default mechanisms),
 * e.g. to see a check fail on a corrupted copy of the files;
 * MECH_GOLDEN_REPORT=1 prints the worst deviation of each check and file to
 * standard error. The checks and their tolerances (tests/golden/README.md):
 *
 * - columns: q is the file's driver range; every column is a point, link or
 *   slider of the model with the right unit, every output of the model has
 *   its columns, every value is finite; the driver's own columns are q and
 *   its speed and acceleration.
 * - rigid links: every pair of known points of one link (output points, and
 *   ground points, whose positions are the ground coordinates) keeps its
 *   link-frame distance (2e-12 of the mechanism's size); their relative
 *   velocity and acceleration are those of a rigid body (1e-10 of the
 *   largest speed / acceleration); output link angles, angular speeds and
 *   accelerations agree with the points; output sliders lie on their guide;
 *   spreading the known motions along links (by their angle columns) and
 *   sliders, every point reached along two chains is at the same place with
 *   the same velocity and acceleration (loop closure); the file's branch
 *   conditions hold at every row.
 * - finite differences: velocities are qd times the derivative of the
 *   positions in q, accelerations qd times that of the velocities plus
 *   qdd / qd times the velocity (5-point central differences, tolerance from
 *   the step, below).
 * - periodicity: over a full crank revolution the last row is the first
 *   (angles modulo 2 pi), 1e-9 of each column kind's largest value.
 * - closed forms: mechanisms/fourbar.yaml (circle intersection) and
 *   mechanisms/slider-crank.yaml (x = r cos q + sqrt(l^2 - r^2 sin^2 q)),
 *   every column to 1e-10 relative (tests/unit/closed_forms.h, shared with
 *   test_solve.c; the dimensions are written here from the YAML text, not
 *   read through the loader); mechanisms/five-bar.yaml (drivers as laws of
 *   time: the coupler point P by circle-circle intersection, its rates from
 *   the differentiated distance constraints). */
#include <criterion/criterion.h>
#include <dirent.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "closed_forms.h"
#include "output.h"
#include "mech.h"

/* src/load/drivers.c: a law of time and its first two derivatives, evaluated on
 * the law's tree by forward differentiation (src/load/load.h; declared here
 * because drivers.h brings in the library's internal.h) */
double law_eval(const struct mech_law *l, double t, double *dt, double *dtt);

#define PI 3.14159265358979323846
#define TWO_PI (2.0 * PI)
#define DEG (PI / 180.0)

/* ---- tolerances --------------------------------------------------------- */

/* Positions of points of one link, of sliders on their guides, relative to
 * the mechanism's size lref (the largest distance between two points of one
 * link or of the ground). Newton accepts a position when every loop equation
 * (a length) is within 1e-12 lref (docs/solver.md), and a point reached along
 * one chain of links sits off the other chains by about that residual: up to
 * sqrt(2) 1e-12 lref for the two components of one loop. In practice Newton
 * converges quadratically and the files show at most 5e-13 lref
 * (tests/golden/README.md). */
#define TOL_RIGID 2e-12
/* Rates of a rigid body (r.dv = 0, r.da + |dv|^2 = 0, omega and alpha from
 * two points, slider rates along the guide), relative to the largest speed
 * or acceleration of the file: the velocity and acceleration solves reuse
 * the converged factors, their relative error is about eps / rcond (rcond >=
 * 0.015 in these files, 1.5e-14) plus the position error times a derivative
 * of order one; 1e-10 leaves room for a rebuild and is still far below any
 * wrong term of a formula (order one). */
#define TOL_RIGID_RATE 1e-10
/* A full revolution returns to its start; the two ends are solved by
 * continuation from opposite sides of the sweep and differ by the Newton
 * tolerance times the derivatives (1e-12 lref, amplified by 1/rcond for the
 * rates). */
#define TOL_PERIOD 1e-9
/* Against the closed forms, as in test_solve.c. */
#define TOL_CLOSED 1e-10

/* ---- small helpers ------------------------------------------------------ */

/* snprintf that may cut a long text short (names in messages). */
__attribute__((format(printf, 3, 4))) static void say(char *buf, size_t size, const char *fmt,
                                                      ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, size, fmt, ap);
    va_end(ap);
}

static int ends_with(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

static int cmp_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static int is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

static const char *env_or(const char *var, const char *def)
{
    const char *v = getenv(var);
    return v && *v ? v : def;
}

static const char *golden_dir(void) { return env_or("MECH_GOLDEN_DIR", "tests/golden"); }
static const char *mechanisms_dir(void)
{
    return env_or("MECH_GOLDEN_MECHANISMS", "mechanisms");
}
static int reporting(void) { return getenv("MECH_GOLDEN_REPORT") != NULL; }

/* The names (without `ext`) of the regular files of `dir` ending in `ext`,
 * sorted; *n of them. */
static char **list_names(const char *dir, const char *ext, int *n)
{
    DIR *dp = opendir(dir);
    cr_assert_not_null(dp, "cannot open the directory %s", dir);
    char **names = NULL;
    int count = 0, cap = 0;
    struct dirent *e;
    while ((e = readdir(dp))) {
        char path[1024];
        size_t len = strlen(e->d_name), k = strlen(ext);
        if (len <= k || strcmp(e->d_name + len - k, ext) != 0)
            continue;
        say(path, sizeof path, "%s/%s", dir, e->d_name);
        if (!is_file(path))
            continue;
        if (count == cap) {
            cap = cap ? 2 * cap : 16;
            names = realloc(names, (size_t)cap * sizeof *names);
            cr_assert_not_null(names);
        }
        names[count] = strndup(e->d_name, len - k);
        cr_assert_not_null(names[count]);
        count++;
    }
    closedir(dp);
    if (count)
        qsort(names, (size_t)count, sizeof *names, cmp_names);
    *n = count;
    return names;
}

static void free_names(char **names, int n)
{
    for (int i = 0; i < n; i++)
        free(names[i]);
    free(names);
}

/* Column kinds: 0 length, 1 speed, 2 acceleration, 3 angle, 4 angular
 * speed, 5 angular acceleration; -1 for q. */
enum { K_LEN, K_VEL, K_ACC, K_ANG, K_OMEGA, K_ALPHA, NKINDS };
static const char *const KIND_UNIT[NKINDS] = {"m", "m/s", "m/s^2", "rad", "rad/s", "rad/s^2"};

/* The column suffixes, their kind, and for a position its velocity and
 * acceleration suffixes. */
static const struct {
    const char *suffix;
    int kind;
    const char *rate1, *rate2;
} SUFFIXES[] = {
    {".x", K_LEN, ".vx", ".ax"},         {".y", K_LEN, ".vy", ".ay"},
    {".vx", K_VEL, NULL, NULL},          {".vy", K_VEL, NULL, NULL},
    {".ax", K_ACC, NULL, NULL},          {".ay", K_ACC, NULL, NULL},
    {".angle", K_ANG, ".omega", ".alpha"}, {".omega", K_OMEGA, NULL, NULL},
    {".alpha", K_ALPHA, NULL, NULL},     {".s", K_LEN, ".v", ".a"},
    {".v", K_VEL, NULL, NULL},           {".a", K_ACC, NULL, NULL},
};
#define NSUFFIXES ((int)(sizeof SUFFIXES / sizeof *SUFFIXES))

/* The entry of SUFFIXES the column name ends with (the longest), or -1. */
static int suffix_of(const char *name)
{
    int best = -1;
    for (int i = 0; i < NSUFFIXES; i++)
        if (ends_with(name, SUFFIXES[i].suffix) &&
            (best < 0 || strlen(SUFFIXES[i].suffix) > strlen(SUFFIXES[best].suffix)))
            best = i;
    return best;
}

/* ---- one golden file ---------------------------------------------------- */

typedef struct golden {
    char name[256];            /* NAME */
    char csv[1024], yaml[1024];
    compare_table t;
    mech_model *m;
    int qc;                    /* the q column */
    int *kind;                 /* [ncols] column kinds, -1 for q */
    double kind_max[NKINDS];   /* largest |value| of each kind over the file */
    double lref;               /* largest distance between two points of one link, m */
} golden;

static double val(const golden *g, size_t row, int col)
{
    return g->t.values[row * g->t.ncols + (size_t)col];
}

static double qval(const golden *g, size_t row) { return val(g, row, g->qc); }

static int col(const golden *g, const char *name)
{
    for (size_t j = 0; j < g->t.ncols; j++)
        if (strcmp(g->t.names[j], name) == 0)
            return (int)j;
    return -1;
}

static int colf(const golden *g, const char *fmt, ...)
{
    char name[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(name, sizeof name, fmt, ap);
    va_end(ap);
    return col(g, name);
}

static double largest_length(const mech_model *m)
{
    double l = 0;
    for (int k = 0; k < m->nlinks; k++) {
        const mech_link *L = &m->links[k];
        for (int i = 0; i < L->npoints; i++)
            for (int j = i + 1; j < L->npoints; j++)
                l = fmax(l, hypot(L->points[j].x - L->points[i].x,
                                  L->points[j].y - L->points[i].y));
    }
    return l;
}

/* Columns of the force analysis (reactions, torque, friction, power
 * balance): N, N*m, W, or pure numbers. */
static int is_force_unit(const char *unit)
{
    return strcmp(unit, "N") == 0 || strcmp(unit, "N*m") == 0 || strcmp(unit, "W") == 0 ||
           strcmp(unit, "-") == 0;
}

/* Columns of a spring or damper (NAME.length, .rate, .force, .angle,
 * .torque): checked against truths in tests/unit/test_springs.c and, with
 * the forces, by the power balance. */
static int is_spring_column(const mech_model *m, const char *col)
{
    for (int i = 0; i < m->nsprings; i++) {
        size_t n = strlen(m->springs[i].name);
        if (strncmp(col, m->springs[i].name, n) == 0 && col[n] == '.')
            return 1;
    }
    return 0;
}

static void load_golden(golden *g, const char *name)
{
    memset(g, 0, sizeof *g);
    say(g->name, sizeof g->name, "%s", name);
    say(g->csv, sizeof g->csv, "%s/%s.csv", golden_dir(), name);
    say(g->yaml, sizeof g->yaml, "%s/%s.yaml", mechanisms_dir(), name);

    mech_diag d;
    mech_diag_init(&d);
    int rc = compare_read_csv(g->csv, &g->t, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK, "%s: cannot be read as a CSV table (status %d)", g->csv, rc);

    mech_diag_init(&d);
    mech_summary s;
    rc = mech_load_file(g->yaml, &g->m, &d);
    if (rc == MECH_OK)
        rc = mech_check(g->m, &s, &d);
    if (rc != MECH_OK)
        mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    cr_assert_eq(rc, MECH_OK, "%s: does not load or check (status %d)", g->yaml, rc);
    cr_assert(g->m->has_driver, "%s: no driver", g->yaml);

    cr_assert_geq(g->t.nrows, 1, "%s: no data rows", g->csv);
    /* q, or t when the drivers are laws of time (docs/format.md 7.3) */
    g->qc = col(g, g->m->driver.kind == MECH_DRIVE_TIME ? "t" : "q");
    cr_assert_eq(g->qc, 0, "%s: the first column is not q (or t)", g->csv);
    g->kind = malloc(g->t.ncols * sizeof *g->kind);
    cr_assert_not_null(g->kind);
    for (size_t j = 0; j < g->t.ncols; j++) {
        if ((int)j == g->qc) {
            g->kind[j] = -1;
            continue;
        }
        if (is_force_unit(g->t.units[j]) || is_spring_column(g->m, g->t.names[j])) {
            /* forces and springs: checked by the power balance */
            g->kind[j] = -2;
            continue;
        }
        int sf = suffix_of(g->t.names[j]);
        cr_assert_geq(sf, 0, "%s: column %s is of no known kind", g->csv, g->t.names[j]);
        int k = SUFFIXES[sf].kind;
        g->kind[j] = k;
        for (size_t i = 0; i < g->t.nrows; i++)
            g->kind_max[k] = fmax(g->kind_max[k], fabs(val(g, i, (int)j)));
    }
    g->lref = largest_length(g->m);
    cr_assert_gt(g->lref, 0, "%s: no two distinct points on any link", g->yaml);
}

static void free_golden(golden *g)
{
    compare_table_free(&g->t);
    mech_model_free(&g->m);
    free(g->kind);
    g->kind = NULL;
}

/* Every golden CSV with a mechanism file; at least one. */
static golden *load_all(int *n)
{
    int ncsv;
    char **names = list_names(golden_dir(), ".csv", &ncsv);
    golden *g = calloc((size_t)(ncsv ? ncsv : 1), sizeof *g);
    cr_assert_not_null(g);
    int count = 0;
    for (int i = 0; i < ncsv; i++) {
        char yaml[1024];
        say(yaml, sizeof yaml, "%s/%s.yaml", mechanisms_dir(), names[i]);
        if (!is_file(yaml))
            continue;  /* a CSV that is not the golden file of a mechanism */
        load_golden(&g[count++], names[i]);
    }
    free_names(names, ncsv);
    cr_assert_gt(count, 0, "no golden CSV file in %s has a mechanism in %s", golden_dir(),
                 mechanisms_dir());
    *n = count;
    return g;
}

static void free_goldens(golden *g, int n)
{
    for (int i = 0; i < n; i++)
        free_golden(&g[i]);
    free(g);
}

/* ---- checking one value, recording the worst ----------------------------- */

typedef struct worst {
    const char *check;
    double rel;       /* worst |got - expected| / scale */
    double tol;       /* the tolerance on that ratio (the largest, if it varies) */
    double frac;      /* worst |got - expected| / allowed */
    char column[128];
    size_t row;
    int count;        /* values checked */
} worst;

static void worst_init(worst *w, const char *check, double tol)
{
    memset(w, 0, sizeof *w);
    w->check = check;
    w->tol = tol;
    w->rel = -1;
}

static void worst_report(const golden *g, const worst *w)
{
    if (!reporting())
        return;
    if (w->count == 0)
        fprintf(stderr, "golden: %-34s %-24s nothing to check\n", g->csv, w->check);
    else
        fprintf(stderr,
                "golden: %-34s %-24s %6d values, worst %.3g (tolerance %.3g; %.2g of allowed) "
                "at %s, row %zu\n",
                g->csv, w->check, w->count, w->rel, w->tol, w->frac, w->column, w->row + 1);
}

/* Check |got - expected| <= tol * scale for the column described by
 * `column` at data row `row` (0-based; printed 1-based, as mech compare). */
static void check_value(const golden *g, worst *w, const char *column, size_t row,
                        double expected, double got, double scale, double tol)
{
    double err = fabs(got - expected);
    double rel = scale > 0 ? err / scale : err;
    w->count++;
    if (!(err / (tol * scale) <= w->frac))
        w->frac = err / (tol * scale);
    if (!(rel <= w->rel)) {
        w->rel = rel;
        say(w->column, sizeof w->column, "%s", column);
        w->row = row;
    }
    cr_assert(err <= tol * scale,
              "%s: %s: column %s, data row %zu (q = %.17g): expected %.17g, got %.17g "
              "(error %.3g, allowed %.3g = %.3g x %.3g)",
              g->csv, w->check, column, row + 1, qval(g, row), expected, got, err, tol * scale,
              tol, scale);
}

/* ---- every mechanism has its golden file -------------------------------- */

Test(golden, every_mechanism_has_a_golden_file)
{
    int n;
    char **names = list_names(mechanisms_dir(), ".yaml", &n);
    cr_assert_gt(n, 0, "no mechanism in %s", mechanisms_dir());
    for (int i = 0; i < n; i++) {
        char csv[1024];
        say(csv, sizeof csv, "%s/%s.csv", golden_dir(), names[i]);
        cr_assert(is_file(csv),
                  "%s/%s.yaml has no golden file %s (make golden, then review the new file)",
                  mechanisms_dir(), names[i], csv);
    }
    free_names(names, n);
}

/* ---- the columns -------------------------------------------------------- */

/* Which model object a column belongs to: 0 point, 1 link, 2 slider. */
static int column_owner(const golden *g, const char *column, int s)
{
    char base[256];
    size_t len = strlen(column) - strlen(SUFFIXES[s].suffix);
    cr_assert_lt(len, sizeof base);
    memcpy(base, column, len);
    base[len] = '\0';
    int k = SUFFIXES[s].kind;
    if (k == K_ANG || k == K_OMEGA || k == K_ALPHA) {
        int l = mech_find_link(g->m, base);
        cr_assert(l > 0, "%s: column %s: no moving link '%s' in %s", g->csv, column, base,
                  g->yaml);
        return 1;
    }
    if (!strcmp(SUFFIXES[s].suffix, ".s") || !strcmp(SUFFIXES[s].suffix, ".v") ||
        !strcmp(SUFFIXES[s].suffix, ".a")) {
        int j = mech_find_joint(g->m, base);
        cr_assert(j >= 0 && g->m->joints[j].kind == MECH_JOINT_SLIDER,
                  "%s: column %s: no slider '%s' in %s", g->csv, column, base, g->yaml);
        return 2;
    }
    cr_assert_geq(mech_find_point(g->m, base), 0, "%s: column %s: no point '%s' in %s", g->csv,
                  column, base, g->yaml);
    return 0;
}

Test(golden, columns_and_driver_range)
{
    int n;
    golden *gs = load_all(&n);
    for (int f = 0; f < n; f++) {
        golden *g = &gs[f];
        const mech_model *m = g->m;
        const mech_driver *dr = &m->driver;
        worst w;
        worst_init(&w, "driver", 1e-12);
        cr_assert_str_eq(g->t.units[g->qc], dr->kind == MECH_DRIVE_TIME ? "s"
                                            : dr->kind == MECH_DRIVE_ANGLE ? "rad" : "m",
                         "%s: column q has unit [%s]", g->csv, g->t.units[g->qc]);
        cr_assert_eq(g->t.nrows, (size_t)dr->nvalues,
                     "%s: %zu data rows, but %s has %d driver positions", g->csv, g->t.nrows,
                     g->yaml, dr->nvalues);
        for (size_t i = 0; i < g->t.nrows; i++)
            check_value(g, &w, "q", i, dr->values[i], qval(g, i), fmax(1.0, fabs(dr->values[i])),
                        1e-12);
        for (size_t j = 0; j < g->t.ncols; j++) {
            if ((int)j == g->qc || g->kind[j] < 0)
                continue;
            const char *name = g->t.names[j];
            int s = suffix_of(name);
            column_owner(g, name, s);
            cr_assert_str_eq(g->t.units[j], KIND_UNIT[SUFFIXES[s].kind],
                             "%s: column %s has unit [%s], expected [%s]", g->csv, name,
                             g->t.units[j], KIND_UNIT[SUFFIXES[s].kind]);
            for (size_t i = 0; i < g->t.nrows; i++)
                cr_assert(isfinite(val(g, i, (int)j)), "%s: column %s, data row %zu: %g", g->csv,
                          name, i + 1, val(g, i, (int)j));
        }
        /* every output of the model has its columns */
        static const char *const pc[] = {"x", "y", "vx", "vy", "ax", "ay"};
        static const char *const lc[] = {"angle", "omega", "alpha"};
        static const char *const sc[] = {"s", "v", "a"};
        for (int i = 0; i < m->outputs.npoints; i++)
            for (int k = 0; k < 6; k++)
                cr_assert_geq(colf(g, "%s.%s", m->point_names[m->outputs.points[i]], pc[k]), 0,
                              "%s: no column %s.%s for an output of %s", g->csv,
                              m->point_names[m->outputs.points[i]], pc[k], g->yaml);
        for (int i = 0; i < m->outputs.nlinks; i++)
            for (int k = 0; k < 3; k++)
                cr_assert_geq(colf(g, "%s.%s", m->links[m->outputs.links[i]].name, lc[k]), 0,
                              "%s: no column %s.%s for an output of %s", g->csv,
                              m->links[m->outputs.links[i]].name, lc[k], g->yaml);
        for (int i = 0; i < m->outputs.nsliders; i++)
            for (int k = 0; k < 3; k++)
                cr_assert_geq(colf(g, "%s.%s", m->joints[m->outputs.sliders[i]].name, sc[k]), 0,
                              "%s: no column %s.%s for an output of %s", g->csv,
                              m->joints[m->outputs.sliders[i]].name, sc[k], g->yaml);
        /* laws of time: each driven coordinate is its law at t, its rates the
           law's derivatives (forward differentiation of the law's tree,
           drivers.c, not the solver's symbolic derivatives) */
        for (int k = 0; dr->kind == MECH_DRIVE_TIME && k < m->nmotions; k++) {
            const mech_motion *mo = &m->motions[k];
            int angle = mo->kind == MECH_DRIVE_ANGLE;
            const char *mn = angle ? m->links[mo->index].name : m->joints[mo->index].name;
            int cc[3] = {colf(g, "%s.%s", mn, angle ? "angle" : "s"),
                         colf(g, "%s.%s", mn, angle ? "omega" : "v"),
                         colf(g, "%s.%s", mn, angle ? "alpha" : "a")};
            for (size_t i = 0; i < g->t.nrows; i++) {
                double want[3];
                want[0] = law_eval(mo->law, qval(g, i), &want[1], &want[2]);
                for (int c = 0; c < 3; c++)
                    if (cc[c] >= 0)
                        check_value(g, &w, g->t.names[cc[c]], i, want[c], val(g, i, cc[c]),
                                    fmax(1.0, fabs(want[c])), 1e-12);
            }
        }
        /* the driver's own columns: its position is q, its rates the file's */
        const char *dname = dr->kind == MECH_DRIVE_TIME ? "(none)"
                            : dr->kind == MECH_DRIVE_ANGLE ? m->links[dr->index].name
                                                           : m->joints[dr->index].name;
        int c0 = colf(g, "%s.%s", dname, dr->kind == MECH_DRIVE_ANGLE ? "angle" : "s");
        int c1 = colf(g, "%s.%s", dname, dr->kind == MECH_DRIVE_ANGLE ? "omega" : "v");
        int c2 = colf(g, "%s.%s", dname, dr->kind == MECH_DRIVE_ANGLE ? "alpha" : "a");
        for (size_t i = 0; i < g->t.nrows; i++) {
            if (c0 >= 0)
                check_value(g, &w, g->t.names[c0], i, qval(g, i), val(g, i, c0),
                            fmax(1.0, fabs(qval(g, i))), 1e-12);
            if (c1 >= 0)
                check_value(g, &w, g->t.names[c1], i, dr->speed, val(g, i, c1),
                            fmax(fabs(dr->speed), 1e-300), 1e-12);
            if (c2 >= 0)
                check_value(g, &w, g->t.names[c2], i, dr->accel, val(g, i, c2),
                            fmax(fabs(dr->accel), 1e-300), 1e-12);
        }
        worst_report(g, &w);
    }
    free_goldens(gs, n);
}

/* ---- rigid links, loop closure, sliders ---------------------------------- */

/* What is known of a point or a link over the sweep, and how. */
enum { KN_UNKNOWN, KN_GROUND, KN_CSV, KN_DERIVED };

typedef struct pmotion {
    int state;
    char via[160];    /* "ground", "CSV", "from D on link2", ... */
    double *v[6];     /* [nrows] x y vx vy ax ay */
} pmotion;

typedef struct lmotion {
    int state;        /* KN_GROUND: the ground; KN_CSV: its columns; KN_DERIVED: two points */
    char via[160];
    double *v[3];     /* [nrows] angle omega alpha */
} lmotion;

typedef struct motions {
    pmotion *p;       /* [npoint_names] */
    lmotion *l;       /* [nlinks] */
} motions;

static const char *const POINT_COLS[6] = {"x", "y", "vx", "vy", "ax", "ay"};
static const char *const LINK_COLS[3] = {"angle", "omega", "alpha"};

static double *new_array(size_t n)
{
    double *a = calloc(n ? n : 1, sizeof *a);
    cr_assert_not_null(a);
    return a;
}

/* The ground's points at their coordinates, at rest; the output points,
 * links (angle, omega, alpha) from the CSV; everything else unknown. */
static motions motions_init(const golden *g)
{
    const mech_model *m = g->m;
    size_t nr = g->t.nrows;
    motions mo;
    mo.p = calloc((size_t)m->npoint_names, sizeof *mo.p);
    mo.l = calloc((size_t)m->nlinks, sizeof *mo.l);
    cr_assert(mo.p && mo.l);
    for (int id = 0; id < m->npoint_names; id++) {
        pmotion *pm = &mo.p[id];
        for (int j = 0; j < 6; j++)
            pm->v[j] = new_array(nr);
        const mech_link *G = &m->links[0];
        for (int i = 0; i < G->npoints; i++)
            if (G->points[i].id == id) {
                pm->state = KN_GROUND;
                say(pm->via, sizeof pm->via, "ground");
                for (size_t r = 0; r < nr; r++) {
                    pm->v[0][r] = G->points[i].x;
                    pm->v[1][r] = G->points[i].y;
                }
            }
        if (pm->state == KN_UNKNOWN && colf(g, "%s.x", m->point_names[id]) >= 0) {
            pm->state = KN_CSV;
            say(pm->via, sizeof pm->via, "CSV");
            for (int j = 0; j < 6; j++) {
                int c = colf(g, "%s.%s", m->point_names[id], POINT_COLS[j]);
                cr_assert_geq(c, 0, "%s: no column %s.%s", g->csv, m->point_names[id],
                              POINT_COLS[j]);
                for (size_t r = 0; r < nr; r++)
                    pm->v[j][r] = val(g, r, c);
            }
        }
    }
    for (int l = 0; l < m->nlinks; l++) {
        lmotion *lm = &mo.l[l];
        for (int j = 0; j < 3; j++)
            lm->v[j] = new_array(nr);
        if (l == 0) {
            lm->state = KN_GROUND;
            say(lm->via, sizeof lm->via, "ground");
        } else if (colf(g, "%s.angle", m->links[l].name) >= 0) {
            lm->state = KN_CSV;
            say(lm->via, sizeof lm->via, "CSV");
            for (int j = 0; j < 3; j++) {
                int c = colf(g, "%s.%s", m->links[l].name, LINK_COLS[j]);
                cr_assert_geq(c, 0, "%s: no column %s.%s", g->csv, m->links[l].name,
                              LINK_COLS[j]);
                for (size_t r = 0; r < nr; r++)
                    lm->v[j][r] = val(g, r, c);
            }
        }
    }
    return mo;
}

static void motions_free(const golden *g, motions *mo)
{
    for (int id = 0; id < g->m->npoint_names; id++)
        for (int j = 0; j < 6; j++)
            free(mo->p[id].v[j]);
    for (int l = 0; l < g->m->nlinks; l++)
        for (int j = 0; j < 3; j++)
            free(mo->l[l].v[j]);
    free(mo->p);
    free(mo->l);
}

/* The worst deviations of the rigid-body and closure checks. */
typedef struct rigid_worst {
    worst pos, vel, acc;
} rigid_worst;

static void rigid_worst_init(rigid_worst *w, const char *pos, const char *vel, const char *acc)
{
    worst_init(&w->pos, pos, TOL_RIGID);
    worst_init(&w->vel, vel, TOL_RIGID_RATE);
    worst_init(&w->acc, acc, TOL_RIGID_RATE);
}

/* Compare a point's motion obtained another way (d[6][nrows], described by
 * `how`) with what is known of it; or, when nothing is, record it. */
static void meet_point(const golden *g, motions *mo, rigid_worst *w, int id, double *const d[6],
                       const char *how)
{
    pmotion *pm = &mo->p[id];
    if (pm->state == KN_UNKNOWN) {
        pm->state = KN_DERIVED;
        say(pm->via, sizeof pm->via, "%s", how);
        for (int j = 0; j < 6; j++)
            memcpy(pm->v[j], d[j], g->t.nrows * sizeof *d[j]);
        return;
    }
    double scale[3] = {g->lref, g->kind_max[K_VEL], g->kind_max[K_ACC]};
    worst *wk[3] = {&w->pos, &w->vel, &w->acc};
    for (int j = 0; j < 6; j++) {
        char what[512];
        say(what, sizeof what, "%s.%s %s vs %s", g->m->point_names[id], POINT_COLS[j], how,
                 pm->via);
        for (size_t r = 0; r < g->t.nrows; r++)
            check_value(g, wk[j / 2], what, r, pm->v[j][r], d[j][r],
                        scale[j / 2] > 0 ? scale[j / 2] : 1, wk[j / 2]->tol);
    }
}

/* Every point of link l from its known point `base` and the link's motion:
 *     p = p_b + R r,  v = v_b + w k x (R r),  a = a_b + al k x (R r) - w^2 R r. */
static void derive_link(const golden *g, motions *mo, rigid_worst *w, int l, int base)
{
    const mech_link *L = &g->m->links[l];
    const lmotion *lm = &mo->l[l];
    const pmotion *b = &mo->p[L->points[base].id];
    size_t nr = g->t.nrows;
    double *d[6];
    for (int j = 0; j < 6; j++)
        d[j] = new_array(nr);
    for (int q = 0; q < L->npoints; q++) {
        if (q == base)
            continue;
        double rx0 = L->points[q].x - L->points[base].x, ry0 = L->points[q].y - L->points[base].y;
        for (size_t r = 0; r < nr; r++) {
            double th = lm->v[0][r], om = lm->v[1][r], al = lm->v[2][r];
            double rx = cos(th) * rx0 - sin(th) * ry0, ry = sin(th) * rx0 + cos(th) * ry0;
            d[0][r] = b->v[0][r] + rx;
            d[1][r] = b->v[1][r] + ry;
            d[2][r] = b->v[2][r] - om * ry;
            d[3][r] = b->v[3][r] + om * rx;
            d[4][r] = b->v[4][r] - al * ry - om * om * rx;
            d[5][r] = b->v[5][r] + al * rx - om * om * ry;
        }
        char how[160];
        say(how, sizeof how, "from %s on %s (angle: %s)", L->points[base].name, L->name,
                 lm->via);
        meet_point(g, mo, w, L->points[q].id, d, how);
    }
    for (int j = 0; j < 6; j++)
        free(d[j]);
}

/* The motion of link l from two of its known points p and q:
 *     angle = direction of pq - its direction in the link frame,
 *     omega = (d x dv) / |d|^2, alpha = (d x da) / |d|^2. */
static void link_from_points(const golden *g, motions *mo, int l, int p, int q)
{
    const mech_link *L = &g->m->links[l];
    lmotion *lm = &mo->l[l];
    const pmotion *a = &mo->p[L->points[p].id], *b = &mo->p[L->points[q].id];
    double frame = atan2(L->points[q].y - L->points[p].y, L->points[q].x - L->points[p].x);
    for (size_t r = 0; r < g->t.nrows; r++) {
        double dx = b->v[0][r] - a->v[0][r], dy = b->v[1][r] - a->v[1][r];
        double d2 = dx * dx + dy * dy;
        lm->v[0][r] = atan2(dy, dx) - frame;
        lm->v[1][r] = (dx * (b->v[3][r] - a->v[3][r]) - dy * (b->v[2][r] - a->v[2][r])) / d2;
        lm->v[2][r] = (dx * (b->v[5][r] - a->v[5][r]) - dy * (b->v[4][r] - a->v[4][r])) / d2;
    }
    lm->state = KN_DERIVED;
    say(lm->via, sizeof lm->via, "points %s, %s", L->points[p].name, L->points[q].name);
}

/* The sliding point M of slider joint j from the guide's `through` point T,
 * the guide's motion and the slider's s, v, a columns: with u the guide's
 * direction and n = k x u,
 *     M = T + s u,  v_M = v_T + s' u + s w n,
 *     a_M = a_T + s'' u + (2 s' w + s al) n - s w^2 u. */
static void derive_slider(const golden *g, motions *mo, rigid_worst *w, int j, const int c[3])
{
    const mech_joint *J = &g->m->joints[j];
    const mech_point *P = &g->m->links[J->link[0]].points[J->point[0]];
    const mech_point *T = &g->m->links[J->link[1]].points[J->point[1]];
    const lmotion *lm = &mo->l[J->link[1]];
    const pmotion *t = &mo->p[T->id];
    size_t nr = g->t.nrows;
    double *d[6];
    for (int k = 0; k < 6; k++)
        d[k] = new_array(nr);
    for (size_t r = 0; r < nr; r++) {
        double th = lm->v[0][r] + J->angle, om = lm->v[1][r], al = lm->v[2][r];
        double ux = cos(th), uy = sin(th), nx = -uy, ny = ux;
        double s = val(g, r, c[0]), sv = val(g, r, c[1]), sa = val(g, r, c[2]);
        d[0][r] = t->v[0][r] + s * ux;
        d[1][r] = t->v[1][r] + s * uy;
        d[2][r] = t->v[2][r] + sv * ux + s * om * nx;
        d[3][r] = t->v[3][r] + sv * uy + s * om * ny;
        d[4][r] = t->v[4][r] + sa * ux + (2 * sv * om + s * al) * nx - s * om * om * ux;
        d[5][r] = t->v[5][r] + sa * uy + (2 * sv * om + s * al) * ny - s * om * om * uy;
    }
    char how[160];
    say(how, sizeof how, "from %s + %s.s along the guide of %s", T->name, J->name,
             g->m->links[J->link[1]].name);
    meet_point(g, mo, w, P->id, d, how);
    for (int k = 0; k < 6; k++)
        free(d[k]);
}

/* Spread what is known along the links and sliders until nothing changes:
 * a link with a known motion (its CSV columns, or two known points) and one
 * known point gives all its points; a slider whose s is in the CSV gives its
 * sliding point from the guide. A point reached a second way is compared
 * with the first: a loop closes (positions, velocities, accelerations). */
static void spread(const golden *g, motions *mo, rigid_worst *w)
{
    const mech_model *m = g->m;
    int *done_l = calloc((size_t)m->nlinks, sizeof *done_l);
    int *done_j = calloc((size_t)(m->njoints ? m->njoints : 1), sizeof *done_j);
    cr_assert(done_l && done_j);
    for (int progress = 1; progress;) {
        progress = 0;
        for (int l = 1; l < m->nlinks; l++) {
            const mech_link *L = &m->links[l];
            if (done_l[l])
                continue;
            if (mo->l[l].state == KN_UNKNOWN) {  /* two known points farthest apart */
                int bp = -1, bq = -1;
                double best = 1e-9 * g->lref;
                for (int p = 0; p < L->npoints; p++)
                    for (int q = p + 1; q < L->npoints; q++) {
                        double r = hypot(L->points[q].x - L->points[p].x,
                                         L->points[q].y - L->points[p].y);
                        if (mo->p[L->points[p].id].state && mo->p[L->points[q].id].state &&
                            r > best) {
                            best = r;
                            bp = p;
                            bq = q;
                        }
                    }
                if (bp < 0)
                    continue;
                link_from_points(g, mo, l, bp, bq);
            }
            int base = -1;  /* the known point nearest the source: ground, CSV, derived */
            for (int p = 0; p < L->npoints; p++) {
                int s = mo->p[L->points[p].id].state;
                if (s != KN_UNKNOWN && (base < 0 || s < mo->p[L->points[base].id].state))
                    base = p;
            }
            if (base < 0)
                continue;
            derive_link(g, mo, w, l, base);
            done_l[l] = progress = 1;
        }
        for (int j = 0; j < m->njoints; j++) {
            const mech_joint *J = &m->joints[j];
            if (done_j[j] || J->kind != MECH_JOINT_SLIDER)
                continue;
            int c[3] = {colf(g, "%s.s", J->name), colf(g, "%s.v", J->name),
                        colf(g, "%s.a", J->name)};
            if (c[0] < 0)
                continue;
            cr_assert(c[1] >= 0 && c[2] >= 0, "%s: slider %s without its .v or .a column",
                      g->csv, J->name);
            const mech_point *T = &m->links[J->link[1]].points[J->point[1]];
            if (mo->l[J->link[1]].state == KN_UNKNOWN || mo->p[T->id].state == KN_UNKNOWN)
                continue;
            derive_slider(g, mo, w, j, c);
            done_j[j] = progress = 1;
        }
    }
    free(done_l);
    free(done_j);
}

Test(golden, rigid_links_and_loop_closure)
{
    int n;
    golden *gs = load_all(&n);
    for (int f = 0; f < n; f++) {
        golden *g = &gs[f];
        const mech_model *m = g->m;
        motions mo = motions_init(g);
        rigid_worst wr, wc;
        worst wang, wom, wal, wgr;
        rigid_worst_init(&wr, "rigid distance", "rigid velocity", "rigid acceleration");
        rigid_worst_init(&wc, "loop closure", "closure velocity", "closure acceleration");
        worst_init(&wang, "link angle", TOL_RIGID);
        worst_init(&wom, "link omega", TOL_RIGID_RATE);
        worst_init(&wal, "link alpha", TOL_RIGID_RATE);
        worst_init(&wgr, "ground points", TOL_RIGID);
        double vmax = g->kind_max[K_VEL], amax = g->kind_max[K_ACC];
        char what[256];

        /* output points on the ground stay at their ground coordinates, at rest */
        const mech_link *G = &m->links[0];
        for (int p = 0; p < G->npoints; p++) {
            double want[6] = {G->points[p].x, G->points[p].y, 0, 0, 0, 0};
            for (int j = 0; j < 6; j++) {
                int c = colf(g, "%s.%s", G->points[p].name, POINT_COLS[j]);
                if (c < 0)
                    continue;
                double scale = j < 2 ? g->lref : j < 4 ? vmax : amax;
                for (size_t i = 0; i < g->t.nrows; i++)
                    check_value(g, &wgr, g->t.names[c], i, want[j], val(g, i, c),
                                scale > 0 ? scale : 1, TOL_RIGID);
            }
        }

        /* pairs of points of one link given by the CSV or the ground: distance
         * kept, d.dv = 0, d.da + |dv|^2 = 0 (divided by |d|); the link's
         * columns against the pair farthest apart */
        for (int l = 1; l < m->nlinks; l++) {
            const mech_link *L = &m->links[l];
            int bi = -1, bj = -1;
            double best = 1e-9 * g->lref;
            for (int p = 0; p < L->npoints; p++)
                for (int q = p + 1; q < L->npoints; q++) {
                    const pmotion *a = &mo.p[L->points[p].id], *b = &mo.p[L->points[q].id];
                    if (a->state == KN_UNKNOWN || b->state == KN_UNKNOWN ||
                        (a->state == KN_GROUND && b->state == KN_GROUND))
                        continue;
                    double r = hypot(L->points[q].x - L->points[p].x,
                                     L->points[q].y - L->points[p].y);
                    say(what, sizeof what, "|%s%s| on %s", L->points[p].name,
                             L->points[q].name, L->name);
                    for (size_t i = 0; i < g->t.nrows; i++) {
                        double dx = b->v[0][i] - a->v[0][i], dy = b->v[1][i] - a->v[1][i];
                        check_value(g, &wr.pos, what, i, r, hypot(dx, dy), g->lref, TOL_RIGID);
                        if (r <= 1e-9 * g->lref)
                            continue;
                        double dvx = b->v[2][i] - a->v[2][i], dvy = b->v[3][i] - a->v[3][i];
                        double dax = b->v[4][i] - a->v[4][i], day = b->v[5][i] - a->v[5][i];
                        check_value(g, &wr.vel, what, i, 0, (dx * dvx + dy * dvy) / r,
                                    vmax > 0 ? vmax : 1, TOL_RIGID_RATE);
                        check_value(g, &wr.acc, what, i, 0,
                                    (dx * dax + dy * day + dvx * dvx + dvy * dvy) / r,
                                    amax > 0 ? amax : 1, TOL_RIGID_RATE);
                    }
                    if (r > best) {
                        best = r;
                        bi = p;
                        bj = q;
                    }
                }
            if (mo.l[l].state != KN_CSV || bi < 0)
                continue;
            /* the link's own columns against the direction of the pair */
            double frame = atan2(L->points[bj].y - L->points[bi].y,
                                 L->points[bj].x - L->points[bi].x);
            const pmotion *a = &mo.p[L->points[bi].id], *b = &mo.p[L->points[bj].id];
            for (size_t i = 0; i < g->t.nrows; i++) {
                double dx = b->v[0][i] - a->v[0][i], dy = b->v[1][i] - a->v[1][i];
                double d2 = dx * dx + dy * dy;
                double got = mo.l[l].v[0][i], want = atan2(dy, dx) - frame;
                want = got - remainder(got - want, TWO_PI);  /* the CSV's turn */
                say(what, sizeof what, "%s.angle vs direction %s%s", L->name,
                         L->points[bi].name, L->points[bj].name);
                /* an angle error e moves the far point by e |pq|: allow TOL_RIGID lref */
                check_value(g, &wang, what, i, want, got, g->lref / best, TOL_RIGID);
                double om = (dx * (b->v[3][i] - a->v[3][i]) - dy * (b->v[2][i] - a->v[2][i])) / d2;
                double al = (dx * (b->v[5][i] - a->v[5][i]) - dy * (b->v[4][i] - a->v[4][i])) / d2;
                say(what, sizeof what, "%s.omega vs points %s, %s", L->name,
                         L->points[bi].name, L->points[bj].name);
                check_value(g, &wom, what, i, om, mo.l[l].v[1][i],
                            g->kind_max[K_OMEGA] > 0 ? g->kind_max[K_OMEGA] : 1, TOL_RIGID_RATE);
                say(what, sizeof what, "%s.alpha vs points %s, %s", L->name,
                         L->points[bi].name, L->points[bj].name);
                check_value(g, &wal, what, i, al, mo.l[l].v[2][i],
                            g->kind_max[K_ALPHA] > 0 ? g->kind_max[K_ALPHA] : 1, TOL_RIGID_RATE);
            }
        }

        /* loops: every point reached along two chains of links and sliders */
        spread(g, &mo, &wc);

        /* the assembly branch the file declares: the turn P0 -> P1 -> P2 is
         * counter-clockwise (sign +1) or clockwise (-1) at every row */
        int nbranch = 0;
        for (int b = 0; b < m->nbranches; b++) {
            const mech_branch *B = &m->branches[b];
            const pmotion *p0 = &mo.p[B->point[0]], *p1 = &mo.p[B->point[1]],
                          *p2 = &mo.p[B->point[2]];
            if (!p0->state || !p1->state || !p2->state)
                continue;
            nbranch++;
            for (size_t i = 0; i < g->t.nrows; i++) {
                double cross = (p1->v[0][i] - p0->v[0][i]) * (p2->v[1][i] - p1->v[1][i]) -
                               (p1->v[1][i] - p0->v[1][i]) * (p2->v[0][i] - p1->v[0][i]);
                cr_assert(cross * B->sign > 0,
                          "%s: branch: data row %zu (q = %.17g): the turn %s -> %s -> %s is %s, "
                          "%s declares it %s",
                          g->csv, i + 1, qval(g, i), m->point_names[B->point[0]],
                          m->point_names[B->point[1]], m->point_names[B->point[2]],
                          cross > 0 ? "counter-clockwise" : cross < 0 ? "clockwise" : "flat",
                          g->yaml, B->sign > 0 ? "counter-clockwise" : "clockwise");
            }
        }
        if (reporting())
            fprintf(stderr, "golden: %-34s %-24s %d of %d conditions hold at every row\n", g->csv,
                    "branch", nbranch, m->nbranches);

        worst_report(g, &wgr);
        worst_report(g, &wr.pos);
        worst_report(g, &wr.vel);
        worst_report(g, &wr.acc);
        worst_report(g, &wang);
        worst_report(g, &wom);
        worst_report(g, &wal);
        worst_report(g, &wc.pos);
        worst_report(g, &wc.vel);
        worst_report(g, &wc.acc);
        motions_free(g, &mo);
    }
    free_goldens(gs, n);
}

/* ---- finite differences ------------------------------------------------- */

/* The velocity of a position column x is qd x'(q), its acceleration
 * qd v'(q) + qdd / qd v (a = x'' qd^2 + x' qdd, v = x' qd); qd = 0 leaves
 * a = qdd x'(q). The derivatives in q are the fourth-order central
 * difference over the rows (2 <= i < n - 2, equal steps h):
 *     f'(q_i) = (f[i-2] - 8 f[i-1] + 8 f[i+1] - f[i+2]) / (12 h) - h^4 f^(5)(xi) / 30.
 *
 * Tolerance, from the step. The truncation term h^4 |f^(5)| / 30 is the
 * whole budget; with 1 degree steps (h = 0.01745 rad) h^4 / 30 = 3.1e-9, with
 * the 5 degree steps of slider-crank.yaml 1.9e-6. How large f^(5) is depends
 * on the mechanism, not on the step: a term of order k in the crank angle
 * (k turns per crank turn) has |f^(5)| = k^4 |f'|, and a linkage near a toggle
 * has large high orders (the conveyor's rocker 5: f^(5) about 200 f'). So
 * |f^(5)| is bounded by the data: the largest |seven-point fifth central
 * difference| of the column being differentiated over the sweep,
 *     f^(5) ~ (f[i+3] - 4 f[i+2] + 5 f[i+1] - 5 f[i-1] + 4 f[i-2] - f[i-3]) / (2 h^5),
 * times FD_SAFETY = 2 (the sampled maximum can miss the true one between
 * rows; the seven-point estimate itself is off by O(h^2 f^(7))). The
 * allowed error of a velocity is then
 *     FD_SAFETY * h^4 / 30 * |qd| * max |x^(5)|  +  TOL_FD_FLOOR * (largest |velocity| of the kind)
 * and likewise for an acceleration with the velocity column. The estimate
 * comes from the column being differentiated, never from the column being
 * checked, so a wrong velocity cannot widen its own tolerance; an error e
 * in one position widens it by at most FD_SAFETY * 2.5 e / (30 h) = e / (6 h)
 * (times qd), while it moves the difference by 2 e / (3 h): it still shows.
 * TOL_FD_FLOOR = 1e-9 covers rounding: a position error e ~ 1e-12 lref
 * becomes 18 e / (12 h) ~ 9e-11 lref of the derivative at 1 degree.
 * A bound that is itself large says the step is too coarse for the check to
 * mean anything: it must stay below FD_MAX_TOL (1e-3) of the kind's largest
 * value. Measured worst deviations and the tolerances they used are in
 * tests/golden/README.md; a wrong term of a rate formula is of the order of
 * the rate itself. */
#define FD_SAFETY 2.0
#define TOL_FD_FLOOR 1e-9
#define FD_MAX_TOL 1e-3

static double d5(const golden *g, int c, size_t i, double h)
{
    return (val(g, i - 2, c) - 8 * val(g, i - 1, c) + 8 * val(g, i + 1, c) - val(g, i + 2, c)) /
           (12 * h);
}

/* The largest |fifth derivative| of column c over the sweep, from seven-point
 * fifth central differences. */
static double max_fifth(const golden *g, int c, double h)
{
    double m = 0, h5 = h * h * h * h * h;
    for (size_t i = 3; i + 3 < g->t.nrows; i++) {
        double d = (val(g, i + 3, c) - 4 * val(g, i + 2, c) + 5 * val(g, i + 1, c) -
                    5 * val(g, i - 1, c) + 4 * val(g, i - 2, c) - val(g, i - 3, c)) /
                   (2 * h5);
        m = fmax(m, fabs(d));
    }
    return m;
}

Test(golden, rates_match_differences)
{
    int n;
    golden *gs = load_all(&n);
    for (int f = 0; f < n; f++) {
        golden *g = &gs[f];
        const mech_driver *dr = &g->m->driver;
        size_t nrows = g->t.nrows;
        worst wv, wa;
        cr_assert_geq(nrows, 7, "%s: %zu rows, too few for the differences", g->csv, nrows);
        double q0 = qval(g, 0), h = (qval(g, nrows - 1) - q0) / (double)(nrows - 1);
        cr_assert(h != 0, "%s: the driver does not move", g->csv);
        /* the differences need equal steps in q */
        for (size_t i = 0; i < nrows; i++)
            cr_assert(fabs(qval(g, i) - (q0 + h * (double)i)) <= 1e-9 * fabs(h),
                      "%s: data row %zu: q = %.17g, not on the uniform grid %.17g + %zu * %.17g "
                      "(finite differences need a uniform driver range)",
                      g->csv, i + 1, qval(g, i), q0, i, h);
        double h4 = h * h * h * h;
        worst_init(&wv, "velocity differences", 0);
        worst_init(&wa, "acceleration differences", 0);
        double qd = dr->speed, qdd = dr->accel;
        for (size_t j = 0; j < g->t.ncols; j++) {
            if ((int)j == g->qc || g->kind[j] < 0)
                continue;
            int s = suffix_of(g->t.names[j]);
            if (!SUFFIXES[s].rate1)
                continue;  /* not a position */
            char base[256];
            size_t len = strlen(g->t.names[j]) - strlen(SUFFIXES[s].suffix);
            memcpy(base, g->t.names[j], len);
            base[len] = '\0';
            int cx = (int)j, cv = colf(g, "%s%s", base, SUFFIXES[s].rate1),
                ca = colf(g, "%s%s", base, SUFFIXES[s].rate2);
            cr_assert(cv >= 0 && ca >= 0, "%s: %s without its rate columns", g->csv,
                      g->t.names[j]);
            int kv = SUFFIXES[s].kind + 1, ka = SUFFIXES[s].kind + 2;
            double vscale = g->kind_max[kv] > 0 ? g->kind_max[kv] : 1;
            double ascale = g->kind_max[ka] > 0 ? g->kind_max[ka] : 1;
            /* the truncation bounds, relative to the scales */
            double tv = FD_SAFETY * h4 / 30 * fabs(qd) * max_fifth(g, cx, h) / vscale + TOL_FD_FLOOR;
            double ta = (qd != 0 ? FD_SAFETY * h4 / 30 * fabs(qd) * max_fifth(g, cv, h)
                                 : FD_SAFETY * h4 / 30 * fabs(qdd) * max_fifth(g, cx, h)) /
                            ascale + TOL_FD_FLOOR;
            cr_assert(tv <= FD_MAX_TOL && ta <= FD_MAX_TOL,
                      "%s: %s: the truncation bound of the differences is %.3g (velocity), %.3g "
                      "(acceleration) of the largest value: the step %.3g is too coarse",
                      g->csv, g->t.names[j], tv, ta, h);
            wv.tol = fmax(wv.tol, tv);
            wa.tol = fmax(wa.tol, ta);
            for (size_t i = 2; i + 2 < nrows; i++) {
                double v = val(g, i, cv);
                double v_fd = qd * d5(g, cx, i, h);
                check_value(g, &wv, g->t.names[cv], i, v_fd, v, vscale, tv);
                double a_fd = qd != 0 ? qd * d5(g, cv, i, h) + qdd / qd * v
                                      : qdd * d5(g, cx, i, h);
                check_value(g, &wa, g->t.names[ca], i, a_fd, val(g, i, ca), ascale, ta);
            }
        }
        worst_report(g, &wv);
        worst_report(g, &wa);
    }
    free_goldens(gs, n);
}

/* ---- periodicity -------------------------------------------------------- */

static int full_revolution(const golden *g)
{
    double span = fabs(qval(g, g->t.nrows - 1) - qval(g, 0));
    return g->m->driver.kind == MECH_DRIVE_ANGLE && fabs(span - TWO_PI) <= 1e-12 * TWO_PI;
}

Test(golden, full_revolution_returns_to_start)
{
    int n;
    golden *gs = load_all(&n);
    for (int f = 0; f < n; f++) {
        golden *g = &gs[f];
        worst w;
        worst_init(&w, "periodicity", TOL_PERIOD);
        if (full_revolution(g)) {
            size_t last = g->t.nrows - 1;
            for (size_t j = 0; j < g->t.ncols; j++) {
                if ((int)j == g->qc || g->kind[j] < 0)
                    continue;
                double first = val(g, 0, (int)j), end = val(g, last, (int)j);
                double want = first;
                if (g->kind[j] == K_ANG)  /* whole turns apart */
                    want = end - remainder(end - first, TWO_PI);
                double scale = g->kind_max[g->kind[j]];
                if (g->kind[j] == K_ANG)
                    scale = PI;  /* angles are compared modulo 2 pi */
                check_value(g, &w, g->t.names[j], last, want, end, scale > 0 ? scale : 1,
                            TOL_PERIOD);
            }
        }
        worst_report(g, &w);
    }
    free_goldens(gs, n);
}

/* ---- closed forms ------------------------------------------------------- */

/* The golden file of mechanisms/NAME.yaml, or NULL (with a failure) when the
 * mechanism exists but its golden file does not. */
static int find_golden(golden *gs, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (!strcmp(gs[i].name, name))
            return i;
    return -1;
}

/* Every column of the golden file against the closed form f over the
 * range from..to degrees in `steps` steps, to tol relative to max(|expected|,
 * the largest |expected| of the column's kind over the sweep); angles after
 * unwrapping the closed form along the sweep and aligning it to the CSV's
 * first value by whole turns, relative to the largest |angle| in (-pi, pi]. */
static void check_closed_form(golden *g, const char *const *names, int ncol, ref_fn f,
                              const void *geom, double w, double al, double from, double to,
                              int steps, double tol)
{
    worst wk;
    worst_init(&wk, "closed form", tol);
    cr_assert_eq(g->t.nrows, (size_t)steps + 1,
                 "%s: %zu data rows; the closed form is written for %g..%g deg in %d steps "
                 "(did %s change?)",
                 g->csv, g->t.nrows, from, to, steps, g->yaml);
    cr_assert(fabs(g->m->driver.speed - w) <= 1e-12 * fabs(w) &&
                  fabs(g->m->driver.accel - al) <= 1e-12 * fmax(1, fabs(al)),
              "%s: driver speed %.17g, acceleration %.17g; the closed form is written for %.17g, "
              "%.17g",
              g->yaml, g->m->driver.speed, g->m->driver.accel, w, al);
    int *cols = malloc((size_t)ncol * sizeof *cols);
    int *kinds = malloc((size_t)ncol * sizeof *kinds);
    double *ref = malloc((g->t.nrows * (size_t)ncol) * sizeof *ref);
    double *tmp = malloc((size_t)ncol * sizeof *tmp);
    cr_assert(cols && kinds && ref && tmp);
    double kind_max[NKINDS] = {0};
    for (int k = 0; k < ncol; k++) {  /* the file's outputs: not every column need be there */
        cols[k] = col(g, names[k]);
        kinds[k] = SUFFIXES[suffix_of(names[k])].kind;
    }
    for (size_t j = 0; j < g->t.ncols; j++) {
        int found = (int)j == g->qc;
        for (int k = 0; k < ncol && !found; k++)
            found = cols[k] == (int)j;
        cr_assert(found, "%s: column %s has no closed form", g->csv, g->t.names[j]);
    }
    for (size_t i = 0; i < g->t.nrows; i++) {
        double q = (from + (to - from) * (double)i / steps) * DEG;
        check_value(g, &wk, "q", i, q, qval(g, i), fmax(1, fabs(q)), 1e-12);
        f(geom, q, w, al, tmp);
        for (int k = 0; k < ncol; k++) {
            double *r = &ref[i * (size_t)ncol + (size_t)k];
            *r = tmp[k];
            if (kinds[k] == K_ANG && cols[k] >= 0) {
                if (i > 0)
                    *r = r[-ncol] + remainder(*r - r[-ncol], TWO_PI);
                else
                    *r += TWO_PI * round((val(g, 0, cols[k]) - *r) / TWO_PI);
            }
            kind_max[kinds[k]] = fmax(kind_max[kinds[k]], fabs(kinds[k] == K_ANG ? tmp[k] : *r));
        }
    }
    for (size_t i = 0; i < g->t.nrows; i++)
        for (int k = 0; k < ncol; k++) {
            if (cols[k] < 0)
                continue;
            double want = ref[i * (size_t)ncol + (size_t)k];
            double scale = kinds[k] == K_ANG ? kind_max[K_ANG] : fmax(fabs(want), kind_max[kinds[k]]);
            check_value(g, &wk, names[k], i, want, val(g, i, cols[k]), scale, tol);
        }
    worst_report(g, &wk);
    free(cols);
    free(kinds);
    free(ref);
    free(tmp);
}

/* The golden file NAME.csv, which must exist when mechanisms/NAME.yaml does
 * (every_mechanism_has_a_golden_file); -1 when the mechanism is gone. */
static int closed_form_file(golden *gs, int n, const char *name)
{
    int i = find_golden(gs, n, name);
    char yaml[1024];
    say(yaml, sizeof yaml, "%s/%s.yaml", mechanisms_dir(), name);
    cr_assert(i >= 0 || !is_file(yaml), "no golden file %s/%s.csv for %s", golden_dir(), name,
              yaml);
    return i;
}

/* mechanisms/fourbar.yaml, from its text: O = (0, 0), C = (70, 0) mm; crank
 * OA 20 mm, coupler AB 60 mm with P 40 mm at 30 deg from AB, rocker CB
 * 50 mm; B above AC (turn A -> B -> C clockwise: sign +1); 10 rad/s, no
 * acceleration; 0..360 deg in 360 steps. */
Test(golden, fourbar_matches_closed_form)
{
    int n;
    golden *gs = load_all(&n);
    int i = closed_form_file(gs, n, "fourbar");
    if (i >= 0) {
        const fourbar geom = {.a = 0.020, .b = 0.060, .c = 0.050, .d = 0.070,
                              .px = 0.040 * cos(30 * DEG), .py = 0.040 * sin(30 * DEG),
                              .sign = +1};
        check_closed_form(&gs[i], FOURBAR_COLS, NFOURBAR, fourbar_ref, &geom, 10, 0, 0, 360, 360,
                          TOL_CLOSED);
    }
    free_goldens(gs, n);
}

/* mechanisms/double-crank.yaml, from its text: O = (0, 0), C = (20, 0) mm;
 * crank OA 60, coupler AB 75 with P 40 mm at 30 deg from AB, follower CB 70
 * (the closed form's rocker); turn A -> B -> C counter-clockwise (sign -1);
 * 10 rad/s, no acceleration; 0..360 deg in 360 steps. */
Test(golden, double_crank_matches_closed_form)
{
    int n;
    golden *gs = load_all(&n);
    int i = closed_form_file(gs, n, "double-crank");
    if (i >= 0) {
        const fourbar geom = {.a = 0.060, .b = 0.075, .c = 0.070, .d = 0.020,
                              .px = 0.040 * cos(30 * DEG), .py = 0.040 * sin(30 * DEG),
                              .sign = -1};
        char names[NFOURBAR][64];
        const char *ptr[NFOURBAR];
        for (int k = 0; k < NFOURBAR; k++) {  /* the rocker is called follower here */
            if (!strncmp(FOURBAR_COLS[k], "rocker.", 7))
                say(names[k], sizeof names[k], "follower.%s", FOURBAR_COLS[k] + 7);
            else
                say(names[k], sizeof names[k], "%s", FOURBAR_COLS[k]);
            ptr[k] = names[k];
        }
        check_closed_form(&gs[i], ptr, NFOURBAR, fourbar_ref, &geom, 10, 0, 0, 360, 360,
                          TOL_CLOSED);
    }
    free_goldens(gs, n);
}

/* mechanisms/slider-crank.yaml, from its text: in line (e = 0), r = 40 mm,
 * l = 140 mm, 3000 rpm = 100 pi rad/s, no acceleration; 0..360 deg in 72
 * steps. */
Test(golden, slider_crank_matches_closed_form)
{
    int n;
    golden *gs = load_all(&n);
    int i = closed_form_file(gs, n, "slider-crank");
    if (i >= 0) {
        const slidercrank geom = {.r = 0.040, .l = 0.140, .e = 0};
        check_closed_form(&gs[i], SLIDER_COLS, NSLIDER, slider_ref, &geom, 100 * PI, 0, 0, 360,
                          72, TOL_CLOSED);
    }
    free_goldens(gs, n);
}

/* mechanisms/offset-slider-crank.yaml, from its text: the line of stroke
 * through G = (0, 30) mm at 0 deg, r = 40 mm, l = 120 mm, B right of A,
 * 3000 rpm, no acceleration; 0..360 deg in 360 steps. Its outputs are A, B,
 * rod and x_B (no crank columns). */
Test(golden, offset_slider_crank_matches_closed_form)
{
    int n;
    golden *gs = load_all(&n);
    int i = closed_form_file(gs, n, "offset-slider-crank");
    if (i >= 0) {
        const slidercrank geom = {.r = 0.040, .l = 0.120, .e = 0.030};
        check_closed_form(&gs[i], SLIDER_COLS, NSLIDER, slider_ref, &geom, 100 * PI, 0, 0, 360,
                          360, TOL_CLOSED);
    }
    free_goldens(gs, n);
}

/* The force analysis's own proof (docs/forces.md): driver power, load and
 * gravity power, friction losses and the rate of kinetic energy balance to
 * 1e-9 relative at every row, with and without friction. */
Test(golden, forces_power_balance)
{
    int n;
    golden *gs = load_all(&n);
    for (int f = 0; f < n; f++) {
        golden *g = &gs[f];
        for (size_t j = 0; j < g->t.ncols; j++) {
            if (strncmp(g->t.names[j], "power.residual", 14) != 0)
                continue;
            for (size_t i = 0; i < g->t.nrows; i++)
                cr_assert(fabs(val(g, i, (int)j)) <= 1e-9, "%s: %s = %g at data row %zu", g->csv,
                          g->t.names[j], val(g, i, (int)j), i + 1);
        }
    }
    free_goldens(gs, n);
}

/* mechanisms/five-bar.yaml, from its text: O = (0, 0), E = (50, 0) mm;
 * cranks OA = EB = 25 mm, arms AP = BP = 60 mm, P on the clockwise side of
 * A -> B; crank1 = 90 deg + 360 deg/s t, crank2 = 60 deg + 20 deg sin(2 pi t
 * / 1 s), t from 0 to 1 s in 100 steps (drivers as laws of time). P by the
 * intersection of the circles (A, 60 mm) and (B, 60 mm); its velocity and
 * acceleration from the time derivatives of |P - A|^2 = |P - B|^2 = l^2,
 * with the laws' rates written out here. */
Test(golden, five_bar_matches_closed_form)
{
    int n;
    golden *gs = load_all(&n);
    int gi = closed_form_file(gs, n, "five-bar");
    for (int f = gi; f >= 0 && f == gi; f++) {
        golden *g = &gs[f];
        worst w;
        worst_init(&w, "five-bar closed form", TOL_CLOSED);
        const double r = 0.025, l = 0.060, ex = 0.050, tw = 2 * PI, h = 20 * DEG;
        cr_assert_eq(g->t.nrows, (size_t)101, "%s: %zu rows", g->csv, g->t.nrows);
        static const char *const pc[] = {"P.x", "P.y", "P.vx", "P.vy", "P.ax", "P.ay"};
        for (size_t i = 0; i < g->t.nrows; i++) {
            double t = (double)i / 100.0;
            check_value(g, &w, "t", i, t, qval(g, i), 1.0, 1e-15);
            double t1 = 90 * DEG + tw * t, w1 = tw, a1 = 0.0;
            double t2 = 60 * DEG + h * sin(tw * t), w2 = h * tw * cos(tw * t),
                   a2 = -h * tw * tw * sin(tw * t);
            double A[2] = {r * cos(t1), r * sin(t1)}, B[2] = {ex + r * cos(t2), r * sin(t2)};
            double Av[2] = {-r * sin(t1) * w1, r * cos(t1) * w1};
            double Bv[2] = {-r * sin(t2) * w2, r * cos(t2) * w2};
            double Aa[2] = {-r * (cos(t1) * w1 * w1 + sin(t1) * a1),
                            -r * (sin(t1) * w1 * w1 - cos(t1) * a1)};
            double Ba[2] = {-r * (cos(t2) * w2 * w2 + sin(t2) * a2),
                            -r * (sin(t2) * w2 * w2 - cos(t2) * a2)};
            double dx = B[0] - A[0], dy = B[1] - A[1], d = hypot(dx, dy);
            double along = d / 2, hh = sqrt(l * l - along * along);  /* equal arms */
            double P[2] = {A[0] + along * dx / d - hh * dy / d, A[1] + along * dy / d + hh * dx / d};
            double u[2] = {P[0] - A[0], P[1] - A[1]}, v[2] = {P[0] - B[0], P[1] - B[1]};
            double det = u[0] * v[1] - u[1] * v[0];
            double r1 = u[0] * Av[0] + u[1] * Av[1], r2 = v[0] * Bv[0] + v[1] * Bv[1];
            double Pv[2] = {(r1 * v[1] - u[1] * r2) / det, (u[0] * r2 - r1 * v[0]) / det};
            double du[2] = {Pv[0] - Av[0], Pv[1] - Av[1]}, dv[2] = {Pv[0] - Bv[0], Pv[1] - Bv[1]};
            double s1 = u[0] * Aa[0] + u[1] * Aa[1] - (du[0] * du[0] + du[1] * du[1]);
            double s2 = v[0] * Ba[0] + v[1] * Ba[1] - (dv[0] * dv[0] + dv[1] * dv[1]);
            double Pa[2] = {(s1 * v[1] - u[1] * s2) / det, (u[0] * s2 - s1 * v[0]) / det};
            double want[6] = {P[0], P[1], Pv[0], Pv[1], Pa[0], Pa[1]};
            for (int k = 0; k < 6; k++) {
                int c = col(g, pc[k]);
                cr_assert_geq(c, 0, "%s: no column %s", g->csv, pc[k]);
                double scale = k < 2 ? l : k < 4 ? 1.0 : 10.0;  /* m, m/s, m/s^2 */
                check_value(g, &w, pc[k], i, want[k], val(g, i, c), scale, TOL_CLOSED);
            }
        }
        worst_report(g, &w);
    }
    free_goldens(gs, n);
}
