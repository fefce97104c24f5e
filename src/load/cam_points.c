/* src/load/cam_points.c: a cam given by its profile's points (docs/cams.md,
 * section 9). The points are joined by the periodic cubic spline in their
 * chord length (GSL's cspline_periodic: a closed curve with continuous
 * curvature). The base circle is the curve's least distance from the cam's
 * centre. The follower's lift is found by contact at every 0.1 deg of the
 * cam: the follower lowered onto the curve from far out stops where its
 * contact element (roller, knife's tip, flat face) first touches it, the
 * extremum over the curve refined by GSL's Brent minimiser (a knife's tip
 * where its path crosses the curve, by GSL's Brent root finder). Those
 * lifts, joined by GSL's periodic spline, become a program of cubic
 * segments (rt_law.h's RT_SHAPE_CUBIC): the equations, the design
 * quantities, the forces, mech cam and the generated code then use it as
 * they use a program the file writes.
 *
 * GSL's error handler aborts by default: every call here is made only
 * where its preconditions hold (increasing knots, bracketing values,
 * finite function values), so it is never reached. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_min.h>
#include <gsl/gsl_roots.h>
#include <gsl/gsl_spline.h>

#include "load.h"

enum {
    MAX_POINTS = 20000,     /* 4 samples a piece at each of 3600 angles: about 3 s at most */
    LIFT_SAMPLES = 3600,    /* the lift found at every 0.1 deg of the cam */
    MIN_DENSE = 720,        /* the curve scanned at 4 places a piece, at least this often */
    MAX_ITER = 100
};
static const double PI = 3.14159265358979323846;
static const double UNDEFINED = -1e300;  /* a point the contact element cannot touch
                                            (finite: GSL's minimiser refuses NaN) */

/* ---- the closed curve ----------------------------------------------------- */

typedef struct curve {
    gsl_spline *sx, *sy;
    gsl_interp_accel *ax, *ay;
    double len;    /* the chord length around */
} curve;

static void curve_free(curve *cv)
{
    gsl_spline_free(cv->sx);
    gsl_spline_free(cv->sy);
    gsl_interp_accel_free(cv->ax);
    gsl_interp_accel_free(cv->ay);
}

/* The spline through pts[n] (closed): 0 out of memory. The caller checked
 * that no two neighbours coincide (the knots increase). */
static int curve_make(curve *cv, const double *pts, int n)
{
    memset(cv, 0, sizeof *cv);
    double *t = malloc((size_t)(n + 1) * 3 * sizeof *t);
    if (!t)
        return 0;
    double *x = t + n + 1, *y = x + n + 1;
    t[0] = 0.0;
    for (int i = 0; i <= n; i++) {
        x[i] = pts[2 * (i % n)], y[i] = pts[2 * (i % n) + 1];
        if (i > 0)
            t[i] = t[i - 1] + hypot(x[i] - x[i - 1], y[i] - y[i - 1]);
    }
    cv->len = t[n];
    cv->sx = gsl_spline_alloc(gsl_interp_cspline_periodic, (size_t)n + 1);
    cv->sy = gsl_spline_alloc(gsl_interp_cspline_periodic, (size_t)n + 1);
    cv->ax = gsl_interp_accel_alloc();
    cv->ay = gsl_interp_accel_alloc();
    int ok = cv->sx && cv->sy && cv->ax && cv->ay;
    if (ok)
        ok = gsl_spline_init(cv->sx, t, x, (size_t)n + 1) == GSL_SUCCESS &&
             gsl_spline_init(cv->sy, t, y, (size_t)n + 1) == GSL_SUCCESS;
    free(t);
    if (!ok)
        curve_free(cv);
    return ok;
}

/* The curve's point at chord length u (any u: taken around). */
static void curve_at(curve *cv, double u, double p[2])
{
    u -= cv->len * floor(u / cv->len);
    if (!(u >= 0.0 && u <= cv->len))  /* rounding at the end, or a NaN */
        u = 0.0;
    p[0] = gsl_spline_eval(cv->sx, u, cv->ax);
    p[1] = gsl_spline_eval(cv->sy, u, cv->ay);
}

/* ---- reading the points ---------------------------------------------------- */

/* A header cell "NAME [UNIT]" of length n: does NAME equal want? The
 * unit's text into unit (empty when none). */
static int header_cell(const char *cell, size_t n, const char *want, char *unit, size_t usize)
{
    const char *br = memchr(cell, '[', n);
    size_t name = br ? (size_t)(br - cell) : n;
    while (name > 0 && cell[name - 1] == ' ')
        name--;
    unit[0] = 0;
    if (br) {
        const char *close = memchr(br, ']', n - (size_t)(br - cell));
        size_t ul = close ? (size_t)(close - br - 1) : 0;
        if (ul < usize)
            memcpy(unit, br + 1, ul), unit[ul] = 0;
    }
    return strlen(want) == name && memcmp(cell, want, name) == 0;
}

/* The header's columns of x and y (profile.x and profile.y, as mech cam
 * writes, else x and y) and their units' scales (the file's length unit
 * when none). */
static int csv_columns(loader *ld, const ynode *f, const char *path, const char *line,
                       const mech_cam *c, int col[2], double scale[2])
{
    static const char *const names[2][2] = {{"profile.x", "x"}, {"profile.y", "y"}};
    char unit[2][64];
    col[0] = col[1] = -1;
    for (int w = 0; w < 2; w++) {
        const char *cell = line;
        for (int j = 0; *cell && *cell != '\n'; j++) {
            size_t n = strcspn(cell, ",\r\n");
            char u[64];
            for (int k = 0; k < 2; k++)
                if (col[k] < 0 && header_cell(cell, n, names[k][w], u, sizeof u))
                    col[k] = j, memcpy(unit[k], u, sizeof u);
            cell += n;
            if (*cell == ',')
                cell++;
            else
                break;
        }
    }
    if (col[0] < 0 || col[1] < 0)
        return load_err(ld, f, "cam '%s': '%s' has no columns profile.x and profile.y (mech "
                        "cam's) or x and y", c->name, path), 0;
    for (int k = 0; k < 2; k++) {
        dim d;
        const char *end;
        scale[k] = file_units_of(ld->m->units, quantity_get(Q_LENGTH)->d, NULL, 0);
        if (unit[k][0] && (!unit_parse(unit[k], &scale[k], &d, &end) || *end ||
                           !dim_equal(d, quantity_get(Q_LENGTH)->d)))
            return load_err(ld, f, "cam '%s': the profile's %s column of '%s' is in '%s', not a "
                            "length", c->name, k ? "y" : "x", path, unit[k]), 0;
    }
    return 1;
}

/* The numbers of columns col[0], col[1] of the data line at *at (advanced
 * past it). 1 read, 0 a blank line, -1 malformed (*bad: its column). */
static int csv_row(const char **at, const int col[2], double v[2], int *bad)
{
    const char *p = *at;
    int got = 0, j = 0, blank = 1;
    for (;; j++) {
        size_t n = strcspn(p, ",\r\n");
        if (n > 0)
            blank = 0;
        for (int k = 0; k < 2; k++)
            if (j == col[k]) {
                char *end;
                v[k] = strtod(p, &end);
                while (end < p + n && *end == ' ')
                    end++;
                if (end != p + n || n == 0)
                    *bad = j + 1;
                else
                    got |= 1 << k;
            }
        p += n;
        if (*p != ',')
            break;
        p++;
    }
    while (*p == '\r')
        p++;
    if (*p == '\n')
        p++;
    *at = p;
    return blank && j == 0 ? 0 : got == 3 ? 1 : -1;
}

/* 'profile: {file: CSV}' (relative to the file's folder): the columns
 * profile.x and profile.y (mech cam's) or x and y, each in its header's
 * unit, else the file's length unit. */
static int points_of_csv(loader *ld, const ynode *f, mech_cam *c, double **out, int *n)
{
    char path[4096];
    const char *slash = strrchr(ld->file, '/');
    int len = f->text[0] != '/' && slash ? (int)(slash - ld->file) + 1 : 0;
    if ((size_t)snprintf(path, sizeof path, "%.*s%s", len, ld->file, f->text) >= sizeof path)
        return load_err(ld, f, "the profile's path is too long"), 0;
    size_t size;
    int rc, col[2];
    double scale[2];
    char *raw = load_read_file(path, (size_t)64 << 20, &size, ld->d, &rc);
    char *text = raw ? malloc(size + 1) : NULL;  /* a string: the reader's is not ended */
    if (text)
        memcpy(text, raw, size), text[size] = 0;
    free(raw);
    if (!text)
        return load_err(ld, f, "cam '%s': the profile '%s' cannot be read (above)", c->name,
                        path), 0;
    const char *at = strchr(text, '\n');
    size_t lines = 0;
    for (const char *q = text; *q; q++)
        lines += *q == '\n';
    double *p = lines <= MAX_POINTS ? xcalloc(2 * lines + 2, sizeof *p) : NULL;
    int ok = csv_columns(ld, f, path, text, c, col, scale);
    if (ok && lines > MAX_POINTS)
        ok = load_err(ld, f, "cam '%s': more than %d profile points in '%s'", c->name,
                      MAX_POINTS, path);
    else if (ok && !p)
        ok = (load_nomem(ld, f), 0);
    *n = 0;
    for (int line = 2; ok && at && *++at; line++) {
        double v[2];
        int bad = 0, r = csv_row(&at, col, v, &bad);
        if (r < 0)
            ok = (diag_error(ld->d, path, (mech_mark){line, bad ? bad : 1}, "not a number in "
                             "the profile's %s column", bad == col[1] + 1 ? "y" : "x"), 0);
        else if (r > 0 && *n < (int)lines)
            p[2 * *n] = v[0] * scale[0], p[2 * *n + 1] = v[1] * scale[1], ++*n;
        at--;  /* at the next line's start: the loop's ++ steps onto it */
    }
    free(text);
    *out = p;
    return ok;
}

/* 'profile: [[x, y], ...]': lengths, in the file's unit when bare. */
static int points_of_list(loader *ld, const ynode *seq, mech_cam *c, double **out, int *n)
{
    if (seq->n > MAX_POINTS)
        return load_err(ld, seq, "cam '%s': %zu profile points (at most %d)", c->name, seq->n,
                        MAX_POINTS), 0;
    double *p = xcalloc(2 * seq->n + 2, sizeof *p);
    if (!p)
        return load_nomem(ld, seq), 0;
    *out = p;
    *n = (int)seq->n;
    for (size_t i = 0; i < seq->n; i++) {
        const ynode *it = seq->items[i];
        if (!load_want_kind(ld, it, YNODE_SEQ, "a profile point [x, y]"))
            return 0;
        if (it->n != 2)
            return load_err(ld, it, "a profile point is [x, y], not %zu numbers", it->n), 0;
        if (!load_get_quantity(ld, it->items[0], Q_LENGTH, "x", &p[2 * i]) ||
            !load_get_quantity(ld, it->items[1], Q_LENGTH, "y", &p[2 * i + 1]))
            return 0;
    }
    return 1;
}

/* The points make a closed curve: enough of them, finite, no two
 * neighbours at one place. Given clockwise or counterclockwise alike. */
static int check_points(loader *ld, const ynode *n, mech_cam *c)
{
    if (c->npoints < 8)
        return load_err(ld, n, "cam '%s': a profile needs at least 8 points around the cam, "
                        "not %d", c->name, c->npoints), 0;
    double size = 0.0;
    for (int i = 0; i < 2 * c->npoints; i++) {
        if (!isfinite(c->points[i]))
            return load_err(ld, n, "cam '%s': profile point %d is not a finite number", c->name,
                            i / 2 + 1), 0;
        size = fmax(size, fabs(c->points[i]));
    }
    if (!(size < 1e6 && size > 1e-9))
        return load_err(ld, n, "cam '%s': the profile's points reach %.3g m from the origin: "
                        "not a cam's", c->name, size), 0;
    for (int i = 0; i < c->npoints; i++) {
        const double *a = &c->points[2 * i], *b = &c->points[2 * ((i + 1) % c->npoints)];
        if (hypot(b[0] - a[0], b[1] - a[1]) <= 1e-12 * size)
            return load_err(ld, n, "cam '%s': profile points %d and %d are at one place (the "
                            "curve closes by itself: do not repeat the first point at the end)",
                            c->name, i + 1, (i + 1) % c->npoints + 1), 0;
    }
    return 1;
}

int cam_points_load(loader *ld, const ynode *n, mech_cam *c)
{
    static const char *const keys[] = {"points", "file"};
    const ynode *list = n, *f = NULL;
    if (n->kind != YNODE_SEQ) {
        if (!load_want_kind(ld, n, YNODE_MAP, "'profile' (a list of [x, y], {points: [...]} or "
                            "{file: CSV})") ||
            !load_check_keys(ld, n, keys, COUNT(keys), "profile"))
            return 0;
        list = ymap_get(n, "points"), f = ymap_get(n, "file");
        if (!list == !f)
            return load_err(ld, n, "a profile is '{points: [[x, y], ...]}' or '{file: CSV}' "
                            "(columns profile.x and profile.y, as mech cam writes, or x and "
                            "y)%s", list ? ", not both" : ""), 0;
        if ((list && !load_want_kind(ld, list, YNODE_SEQ, "'points'")) ||
            (f && !load_want_kind(ld, f, YNODE_SCALAR, "'file'")))
            return 0;
    }
    int ok = list ? points_of_list(ld, list, c, &c->points, &c->npoints)
                  : points_of_csv(ld, f, c, &c->points, &c->npoints);
    return ok && check_points(ld, n, c);
}

/* ---- the base circle -------------------------------------------------------- */

typedef struct contact contact;
struct contact {
    const mech_cam *c;
    curve cv;
    double oc[2];          /* the cam's centre in its frame */
    double cs, sn;         /* the cam's turn on its arm, cos and sin */
    /* translating: the line's direction u and normal n from O, the trace
       point's place along it at zero lift */
    double u[2], n[2], d0;
    /* oscillating: the follower's pivot Q from O, its contact point's
       radius L and angle al0 in the follower (roller, knife), or the face
       normal's angle be and k (flat); sigma: the side of the face the
       centre is on; far: the lift where the trace point is farthest out */
    double q[2], len, al0, be, k, sigma, far;
    gsl_min_fminimizer *mn;
    gsl_root_fsolver *rt;
};

/* What GSL's solvers are given: finite (they abort on NaN or inf). */
static double finite_or(double v, double otherwise) { return isfinite(v) ? v : otherwise; }

static double dist_from_centre(double u, void *arg)
{
    contact *k = arg;
    double p[2];
    curve_at(&k->cv, u, p);
    return finite_or(hypot(p[0] - k->oc[0], p[1] - k->oc[1]), 1e300);
}

/* The winding number of the polygon pts[n] around o: the centre inside. */
static int winds_around(const double *pts, int n, const double o[2])
{
    double turn = 0.0;
    for (int i = 0; i < n; i++) {
        const double *a = &pts[2 * i], *b = &pts[2 * ((i + 1) % n)];
        turn += atan2((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]),
                      (a[0] - o[0]) * (b[0] - o[0]) + (a[1] - o[1]) * (b[1] - o[1]));
    }
    return (int)lround(turn / (2.0 * PI));
}

/* The least of f near u, where samples h apart left f(u) the least of
 * three: Brent's method when f(u) is strictly below f(u - h) and f(u + h)
 * (recomputed here: GSL refuses a bracket that is not one), else f(u). */
static double refine_min(gsl_min_fminimizer *mn, double (*f)(double, void *), void *arg,
                         double u, double h)
{
    gsl_function F = {f, arg};
    double lo = u - h, hi = u + h, fm = f(u, arg), flo = f(lo, arg), fhi = f(hi, arg);
    if (!(fm < flo && fm < fhi) ||
        gsl_min_fminimizer_set_with_values(mn, &F, u, fm, lo, flo, hi, fhi) != GSL_SUCCESS)
        return fm;
    for (int it = 0; it < MAX_ITER; it++) {
        if (gsl_min_fminimizer_iterate(mn) != GSL_SUCCESS)
            break;
        if (gsl_min_test_interval(gsl_min_fminimizer_x_lower(mn),
                                  gsl_min_fminimizer_x_upper(mn), 1e-12 * h, 0.0) == GSL_SUCCESS)
            break;
    }
    return fmin(fm, gsl_min_fminimizer_f_minimum(mn));
}

int cam_points_base(loader *ld, mech_cam *c)
{
    const mech_model *m = ld->m;
    const mech_point *o = &m->links[c->cam].points[c->cam_pivot[0]];
    contact k = {.c = c, .oc = {o->x, o->y}};
    int turns = winds_around(c->points, c->npoints, k.oc);
    if (turns == 0)
        return diag_error(ld->d, ld->file, c->mark, "cam '%s': the cam's centre (its pivot %s "
                          "at %.6g, %.6g mm) is not inside its profile", c->name, o->name,
                          o->x * 1e3, o->y * 1e3), 0;
    if (turns != 1 && turns != -1)
        return diag_error(ld->d, ld->file, c->mark, "cam '%s': the profile's points go %d times "
                          "around the cam's centre: a profile goes around once", c->name,
                          abs(turns)), 0;
    if (!curve_make(&k.cv, c->points, c->npoints))
        return diag_error(ld->d, ld->file, c->mark, "out of memory"), 0;
    k.mn = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
    int dense = 4 * c->npoints > MIN_DENSE ? 4 * c->npoints : MIN_DENSE;
    double h = k.cv.len / dense, best = INFINITY;
    int at = 0;
    for (int j = 0; j < dense; j++) {
        double r = dist_from_centre(j * h, &k);
        if (r < best)
            best = r, at = j;
    }
    c->base = k.mn ? fmin(best, refine_min(k.mn, dist_from_centre, &k, at * h, h)) : best;
    gsl_min_fminimizer_free(k.mn);
    curve_free(&k.cv);
    if (!(c->base > 0.0))
        return diag_error(ld->d, ld->file, c->mark, "cam '%s': the profile passes through the "
                          "cam's centre", c->name), 0;
    return 1;
}

/* ---- the lift at a cam angle ---------------------------------------------- */

/* The profile's point at u seen from the arm (from O, the cam turned). */
static void arm_point(contact *k, double u, double p[2])
{
    double v[2];
    curve_at(&k->cv, u, v);
    v[0] -= k->oc[0], v[1] -= k->oc[1];
    p[0] = k->cs * v[0] - k->sn * v[1];
    p[1] = k->sn * v[0] + k->cs * v[1];
}

/* An oscillating follower's angle psi as its lift, the turn that is
 * nearest below the farthest-out lift. */
static double lift_of_angle(const contact *k, double psi)
{
    double s = k->c->rise * (psi - k->c->c0);
    return s - 2.0 * PI * ceil((s - k->far) / (2.0 * PI));
}

/* The lift at which the contact element, coming down, leaves point P
 * (roller, flat face); UNDEFINED when it never touches P. */
static double lift_leaving(const contact *k, const double P[2])
{
    const mech_cam *c = k->c;
    if (c->motion == CAM_TRANSLATING) {
        double a = P[0] * k->n[0] + P[1] * k->n[1] - c->offset, b = P[0] * k->u[0] + P[1] * k->u[1];
        if (c->contact == CAM_FLAT_FACED)
            return b - c->base;
        double r2 = c->roller * c->roller - a * a;
        return r2 >= 0.0 ? b + sqrt(r2) - k->d0 : UNDEFINED;
    }
    double D[2] = {P[0] - k->q[0], P[1] - k->q[1]}, dl = hypot(D[0], D[1]), de = atan2(D[1], D[0]);
    if (c->contact == CAM_FLAT_FACED) {  /* the face's line through P: D . nu = k; P cuts
                                            into the face while beyond it, away from O */
        if (!(dl > fabs(k->k)))
            return UNDEFINED;
        return lift_of_angle(k, de - k->be + k->sigma * c->rise * acos(k->k / dl));
    }
    double cs = (k->len * k->len + dl * dl - c->roller * c->roller) / (2.0 * dl * k->len);
    if (!(fabs(cs) <= 1.0))
        return UNDEFINED;
    return lift_of_angle(k, de - k->al0 + c->rise * acos(cs));
}

static double lift_leaving_at(double u, void *arg)
{
    contact *k = arg;
    double P[2];
    arm_point(k, u, P);
    return finite_or(-lift_leaving(k, P), -UNDEFINED);  /* minimised */
}

/* A knife's tip on its path: the signed distance of P from the path, and
 * the lift where the tip is at P. */
static double knife_gap(const contact *k, const double P[2])
{
    if (k->c->motion == CAM_TRANSLATING)
        return P[0] * k->n[0] + P[1] * k->n[1] - k->c->offset;
    return hypot(P[0] - k->q[0], P[1] - k->q[1]) - k->len;
}

static double knife_gap_at(double u, void *arg)
{
    contact *k = arg;
    double P[2];
    arm_point(k, u, P);
    return finite_or(knife_gap(k, P), 0.0);
}

static double knife_lift(const contact *k, const double P[2])
{
    if (k->c->motion == CAM_TRANSLATING)
        return P[0] * k->u[0] + P[1] * k->u[1] - k->d0;
    return lift_of_angle(k, atan2(P[1] - k->q[1], P[0] - k->q[0]) - k->al0);
}

/* The tip's path crosses the curve between u and u + h (gaps ga, gb of
 * opposite signs): the crossing's lift. */
static double knife_crossing(contact *k, double u, double h, double ga, double gb)
{
    double P[2], at = fabs(ga) <= fabs(gb) ? u : u + h;
    ga = knife_gap_at(u, k), gb = knife_gap_at(u + h, k);  /* as the solver sees them */
    if ((ga < 0.0 && gb > 0.0) || (ga > 0.0 && gb < 0.0)) {
        gsl_function F = {knife_gap_at, k};
        if (gsl_root_fsolver_set(k->rt, &F, u, u + h) == GSL_SUCCESS) {
            for (int it = 0; it < MAX_ITER; it++) {
                if (gsl_root_fsolver_iterate(k->rt) != GSL_SUCCESS)
                    break;
                if (gsl_root_test_interval(gsl_root_fsolver_x_lower(k->rt),
                                           gsl_root_fsolver_x_upper(k->rt), 1e-13 * h,
                                           0.0) == GSL_SUCCESS)
                    break;
            }
            at = gsl_root_fsolver_root(k->rt);
        }
    }
    arm_point(k, at, P);
    return knife_lift(k, P);
}

/* The lift at the program's x: the follower, coming down, stops at the
 * greatest lift where it touches the curve. */
static double lift_at(contact *k, double x, const double *dense, int ndense)
{
    const mech_cam *c = k->c;
    double th = c->start + c->sense * x, h = k->cv.len / ndense, best = UNDEFINED;
    k->cs = cos(th), k->sn = sin(th);
    int at = -1;
    double prev_gap = 0.0, first_gap = 0.0;
    for (int j = 0; j <= ndense; j++) {
        const double *v = &dense[2 * (j % ndense)];
        double P[2] = {k->cs * v[0] - k->sn * v[1], k->sn * v[0] + k->cs * v[1]};
        if (c->contact == CAM_KNIFE_EDGE) {
            double g = j < ndense ? knife_gap(k, P) : first_gap;
            if (j == 0)
                first_gap = g;
            else if ((prev_gap < 0.0) != (g < 0.0) || prev_gap == 0.0) {
                double s = knife_crossing(k, (j - 1) * h, h, prev_gap, g);
                if (s > best)
                    best = s;
            }
            prev_gap = g;
        } else if (j < ndense) {
            double s = lift_leaving(k, P);
            if (s > best)
                best = s, at = j;
        }
    }
    if (at >= 0)
        best = fmax(best, -refine_min(k->mn, lift_leaving_at, k, at * h, h));
    return best;
}

/* ---- the program of the lifts ---------------------------------------------- */

static int contact_init(contact *k, const mech_model *m, const mech_cam *c)
{
    const mech_point *oc = &m->links[c->cam].points[c->cam_pivot[0]];
    *k = (contact){.c = c, .oc = {oc->x, oc->y}};
    if (c->motion == CAM_TRANSLATING) {
        double a = m->joints[c->slider].angle;
        k->u[0] = cos(a), k->u[1] = sin(a), k->n[0] = -k->u[1], k->n[1] = k->u[0];
        k->d0 = c->contact == CAM_FLAT_FACED
                    ? c->base
                    : sqrt((c->base + c->roller) * (c->base + c->roller) - c->offset * c->offset);
    } else {
        const mech_link *fl = &m->links[c->follower];
        const mech_point *pf = &fl->points[c->follower_pivot[0]];
        const mech_point *pa = &m->links[c->arm].points[c->follower_pivot[1]];
        const mech_point *o = &m->links[c->arm].points[c->cam_pivot[1]];
        k->q[0] = pa->x - o->x, k->q[1] = pa->y - o->y;
        double qa = atan2(k->q[1], k->q[0]);
        if (c->contact == CAM_FLAT_FACED) {
            double w[2];
            k->k = cam_face(m, c, w);
            k->be = atan2(w[0], -w[1]);  /* the angle of J w */
            double d = hypot(k->q[0], k->q[1]) * cos(c->c0 + k->be - qa) + k->k;
            k->sigma = d < 0.0 ? -1.0 : 1.0;
            k->far = c->rise * ((k->sigma > 0 ? qa : qa + PI) - k->be - c->c0);
        } else {
            const mech_point *r = &fl->points[c->at];
            k->len = hypot(r->x - pf->x, r->y - pf->y);
            k->al0 = atan2(r->y - pf->y, r->x - pf->x);
            k->far = c->rise * (qa - k->al0 - c->c0);
        }
        k->far -= 2.0 * PI * floor(k->far / (2.0 * PI));  /* in [0, 2 pi) */
    }
    k->mn = gsl_min_fminimizer_alloc(gsl_min_fminimizer_brent);
    k->rt = gsl_root_fsolver_alloc(gsl_root_fsolver_brent);
    if (!k->mn || !k->rt || !curve_make(&k->cv, c->points, c->npoints)) {
        gsl_min_fminimizer_free(k->mn);
        gsl_root_fsolver_free(k->rt);
        return 0;
    }
    return 1;
}

static void contact_free(contact *k)
{
    gsl_min_fminimizer_free(k->mn);
    gsl_root_fsolver_free(k->rt);
    curve_free(&k->cv);
}

/* The lifts s[0..n-1] at x = 2 pi i / n: 0 with the error reported. */
static int sample_lifts(loader *ld, mech_cam *c, contact *k, double *s, int n)
{
    int ndense = 4 * c->npoints > MIN_DENSE ? 4 * c->npoints : MIN_DENSE;
    double *dense = xcalloc(2 * (size_t)ndense, sizeof *dense), scale = c->base + c->roller;
    if (!dense)
        return diag_error(ld->d, ld->file, c->mark, "out of memory"), 0;
    for (int j = 0; j < ndense; j++) {
        double p[2];
        curve_at(&k->cv, k->cv.len * j / ndense, p);
        dense[2 * j] = p[0] - k->oc[0], dense[2 * j + 1] = p[1] - k->oc[1];
    }
    int ok = 1;
    for (int i = 0; ok && i < n; i++) {
        double x = 2.0 * PI * i / n;
        s[i] = lift_at(k, x, dense, ndense);
        double tol = c->motion == CAM_TRANSLATING ? 1e-9 * scale : 1e-9;
        if (!(s[i] > UNDEFINED / 2) || !isfinite(s[i]))
            ok = !diag_error(ld->d, ld->file, c->mark, "cam '%s': at %.4g deg of the cam the "
                            "follower does not touch the profile", c->name, x * 180.0 / PI);
        else if (c->motion == CAM_OSCILLATING && s[i] > k->far - 1e-9)
            ok = !diag_error(ld->d, ld->file, c->mark, "cam '%s': at %.4g deg of the cam the "
                             "follower cannot clear the profile: it would have to swing past "
                             "its farthest reach from the cam's centre (%.6g deg from its base "
                             "position)", c->name, x * 180.0 / PI, k->far * 180.0 / PI);
        else if (s[i] < -tol)
            ok = !diag_error(ld->d, ld->file, c->mark, "cam '%s': at %.4g deg of the cam the "
                            "follower touches the profile inside its base circle (the profile "
                            "cannot be followed)", c->name, x * 180.0 / PI);
        else if (s[i] < 0.0)
            s[i] = 0.0;
    }
    free(dense);
    return ok;
}

/* The periodic spline of the lifts as n cubic segments. */
static int lift_program(const double *s, int n, mech_program *p)
{
    double *x = malloc(2 * ((size_t)n + 1) * sizeof *x);
    gsl_spline *sp = gsl_spline_alloc(gsl_interp_cspline_periodic, (size_t)n + 1);
    gsl_interp_accel *acc = gsl_interp_accel_alloc();
    p->seg = xcalloc((size_t)n, sizeof *p->seg);
    int ok = x && sp && acc && p->seg;
    if (ok) {
        double *y = x + n + 1;
        for (int i = 0; i <= n; i++)
            x[i] = 2.0 * PI * i / n, y[i] = s[i % n];
        ok = gsl_spline_init(sp, x, y, (size_t)n + 1) == GSL_SUCCESS;
    }
    for (int i = 0; ok && i < n; i++) {
        prog_segment *sg = &p->seg[i];
        double hh = x[i + 1] - x[i];
        double b = gsl_spline_eval_deriv(sp, x[i], acc), c2 = gsl_spline_eval_deriv2(sp, x[i], acc),
               c2n = gsl_spline_eval_deriv2(sp, x[i + 1], acc);
        double ds = s[(i + 1) % n] - s[i];
        sg->kind = ds > 0 ? PROG_RISE : ds < 0 ? PROG_RETURN : PROG_DWELL;
        sg->shape = SHAPE_CUBIC;
        sg->x0 = x[i], sg->span = hh, sg->s0 = s[i], sg->lift = 1.0;
        sg->piece[0] = (rt_piece){0.0, 0.0, b * hh, c2 * hh * hh, (c2n - c2) * hh * hh, 0.0, 0.0};
        sg->npieces = 1;
        sg->user.root = -1;
    }
    p->n = n;
    p->start = 0.0, p->period = 2.0 * PI, p->net = 0.0, p->continuity = 2;
    p->rt = (rt_program){p->seg, p->n, p->start, p->period, p->net};
    free(x);
    gsl_spline_free(sp);
    gsl_interp_accel_free(acc);
    return ok;
}

/* A law of the cam's angle (the law's variable) that is program p (owned
 * by it from then on, also when NULL is returned out of memory). */
static struct mech_law *law_of_program(mech_program *p)
{
    struct mech_law *l = law_new('t');
    if (!l || !law_take_program(l, p)) {
        law_free(l);
        program_free(p);
        return NULL;
    }
    int t = law_add_node(l, LAW_T, -1, -1, 0.0);
    l->root = t >= 0 ? law_add_node(l, LAW_PROGRAM, t, 0, 0.0) : -1;
    if (l->root < 0) {
        law_free(l);
        return NULL;
    }
    return l;
}

int cam_points_program(loader *ld, mech_cam *c)
{
    contact k;
    double *s = xcalloc(LIFT_SAMPLES, sizeof *s);
    mech_program *p = xcalloc(1, sizeof *p);
    if (!s || !p || !contact_init(&k, ld->m, c)) {
        free(s);
        free(p);
        return diag_error(ld->d, ld->file, c->mark, "out of memory"), 0;
    }
    int ok = sample_lifts(ld, c, &k, s, LIFT_SAMPLES);
    contact_free(&k);
    if (ok && !lift_program(s, LIFT_SAMPLES, p))
        ok = (diag_error(ld->d, ld->file, c->mark, "out of memory"), 0);
    free(s);
    if (!ok) {
        program_free(p);
        return 0;
    }
    if (!(c->program = law_of_program(p)))  /* p is the law's, or freed */
        return diag_error(ld->d, ld->file, c->mark, "out of memory"), 0;
    snprintf(c->program->name, sizeof c->program->name, "s_%s", c->name);
    return 1;
}
