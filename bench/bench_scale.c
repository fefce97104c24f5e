/* bench/bench_scale.c: how the cost grows with the mechanism. Generated
 * chains of N four-bar loops (loop k's rocker is rigidly loop k+1's crank,
 * one link with three points; crank-rocker loops alternating with their
 * mirror images, chain_text; exact guesses at the first position), N = 10
 * ... 100 000, each in a child process (fork) so that its peak memory
 * (getrusage ru_maxrss) is its own:
 *
 *   load+check  mech_load_string + mech_check of the generated text
 *   set-up      mech_solve's set-up (system, tape, blocks, klu_analyze)
 *   per step    mech_solve's sweep time per driver step (60..110 deg, 20 steps):
 *               wall time (stats.seconds, row 0 included) and CPU time
 *               (cpu_per_step: the difference of that sweep and 10 steps over
 *               60..85 deg on analyses built once, the minimum of several:
 *               the same step, so that set-up, row 0 and other processes on
 *               the machine matter less)
 *   KLU         one klu_refactor + klu_solve of the Jacobian (2N x 2N)
 *   dense       the same Jacobian by LAPACK dgetrf + dgetrs (N <= 1000; the
 *               cost grows as N^3, N = 10 000 would take ~1000 times longer)
 *
 * A child that takes longer than 150 s is stopped and reported.
 * Usage: bench-scale [SVGDIR]; bench-scale --only N measures one N; bench-scale
 * --yaml N > chain.yaml writes the chain of N loops (to run `mech solve` on
 * it, or profile). Not a test. */
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <klu.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "bench_util.h"
#include "mech.h"
#include "solve.h"
#include "equations.h"

/* LAPACK (Fortran calling convention) */
void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a, const int *lda,
             const int *ipiv, double *b, const int *ldb, int *info);

enum { NN = 5, DENSE_MAX = 1000, STEPS = 10, TIMEOUT = 150 };

typedef struct result {
    int ok, n, nnz, rows;
    double load, setup, us_step, cpu_us_step, it_step, min_rcond, rss_mb, sweep_mb, heap_mb;
    double kib_model, kib_analysis, kib_state, kib_tape, ins_loop, reg_loop, const_loop;
    double klu_factor_us, klu_re_us, dense_us;
    char msg[256];
} result;

/* ---- the chain ----------------------------------------------------------- */

/* Loop 1 is a crank-rocker four-bar: crank CH_A on L0 at G0, coupler CH_B,
 * rocker CH_C on L1 at G1, ground CH_D. Loop 2 is loop 1 reflected through
 * G1 (its input is L1's second arm, opposite the first; its output arm has
 * CH_A), so it undoes loop 1: L2 turns exactly as L0 (plus 180 deg), and
 * the pattern repeats. The odd links turn as the rocker, a nonlinear
 * function of the driver, so Newton has work at every step (the predictor
 * is not exact), and the motion neither grows nor dies out along the
 * chain. Every link L1 .. LN is a straight bar pivoted at its middle. */
#define DEG (M_PI / 180)
#define CH_A 0.3
#define CH_B 1.0
#define CH_C 0.6
#define CH_D 1.0
#define CH_Q0 60.0

/* Loop 1 at driver angle q (deg), open assembly (B above the ground line):
 * rocker angle phi and coupler angle psi, deg. */
static void chain_loop1(double q, double *phi, double *psi)
{
    double ax = CH_A * cos(q * DEG), ay = CH_A * sin(q * DEG);
    double dx = CH_D - ax, dy = -ay, L = hypot(dx, dy);
    double p = (CH_B * CH_B - CH_C * CH_C + L * L) / (2 * L), h = sqrt(CH_B * CH_B - p * p);
    double bx = ax + (p * dx - h * dy) / L, by = ay + (p * dy + h * dx) / L;
    *phi = atan2(by, bx - CH_D) / DEG;
    *psi = atan2(by - ay, bx - ax) / DEG;
}

typedef struct {
    char *s;
    size_t n, cap;
} buf;

static void put(buf *b, const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(b->s + b->n, b->cap - b->n, fmt, ap);
        va_end(ap);
        if (k < 0)
            exit(3);
        if (b->n + (size_t)k < b->cap) {
            b->n += (size_t)k;
            return;
        }
        b->cap = 2 * b->cap + (size_t)k + 1;
        if (!(b->s = realloc(b->s, b->cap)))
            exit(3);
    }
}

static char *chain_text(int n, size_t *len)
{
    buf b = {malloc(4096), 0, 4096};
    put(&b, "name: chain of %d four-bar loops\nunits: {angle: deg}\nground:\n", n);
    for (int k = 0; k <= n; k++)
        put(&b, "  G%d: [%.17g, 0]\n", k, k * CH_D);
    put(&b, "links:\n  L0: {points: {G0: [0, 0], A1: [%.17g, 0]}}\n", CH_A);
    for (int k = 1; k <= n; k++) {
        double arm = k % 2 ? CH_C : CH_A;  /* odd: a rocker; even: a crank again */
        put(&b, "  L%d: {points: {G%d: [0, 0], B%d: [%.17g, 0]", k, k, k, arm);
        if (k < n)
            put(&b, ", A%d: [%.17g, 0]", k + 1, -arm);
        put(&b, "}}\n");
    }
    for (int k = 1; k <= n; k++)
        put(&b, "  C%d: {points: {A%d: [0, 0], B%d: [%.17g, 0]}}\n", k, k, k, CH_B);
    put(&b, "driver: {link: L0, angle: {from: %g, to: 110, steps: %d}}\ninitial:\n", CH_Q0,
        STEPS);
    double phi, psi;
    chain_loop1(CH_Q0, &phi, &psi);
    for (int k = 1; k <= n; k++)  /* even loops: loop 1 reflected, couplers parallel */
        put(&b, "  L%d: %.17g\n  C%d: %.17g\n", k, k % 2 ? phi : CH_Q0 + 180.0, k, psi);
    put(&b, "outputs: {points: [B%d], links: [L%d, C%d]}\n", n, n, n);
    *len = b.n;
    return b.s;
}

/* ---- one N, in the child --------------------------------------------------- */

/* Resident memory now (not the peak), MB: /proc/self/statm's second field
 * (Linux); NAN elsewhere. */
static double rss_now_mb(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    long size = 0, res = -1;
    if (f) {
        if (fscanf(f, "%ld %ld", &size, &res) != 2)
            res = -1;
        fclose(f);
    }
    return res < 0 ? NAN : (double)res * (double)sysconf(_SC_PAGESIZE) / (1024.0 * 1024.0);
}

/* Heap in use now, MB (glibc's mallinfo2: small blocks and mmapped ones);
 * NAN elsewhere. */
static double heap_now_mb(void)
{
#ifdef __GLIBC__
    struct mallinfo2 mi = mallinfo2();
    return (double)(mi.uordblks + mi.hblkhd) / (1024.0 * 1024.0);
#else
    return NAN;
#endif
}

/* mech_solve's progress callback (after the last row, while the analysis
 * and the sweep's state are alive): the resident memory of the sweep, once
 * the set-up has given back what only it needed */
static void on_progress(void *ctx, int done, int total)
{
    (void)done, (void)total;
    double *mb = ctx, now = rss_now_mb();
    if (!(*mb >= now))
        *mb = now;
    mb[1] = heap_now_mb();
}

/* Where the heap of a sweep goes, KiB per loop (the cause column of target
 * 2): the model (measured at load), the analysis (mech_analysis_new: plan,
 * tape, pattern, columns, after solver_plan_compact), the sweep's state and
 * table (heap in use during mech_analysis_solve, less the analysis); and the
 * solver tape's share of the analysis (program and constants' image, from
 * its own solver_plan_init). */
static void heap_breakdown(const mech_model *m, int N, result *r, mech_diag *d)
{
    mech_solve_options o;
    mech_solve_options_default(&o);
    double h0 = heap_now_mb(), mb[2] = {NAN, NAN};
    o.progress = on_progress;  /* copied by the analysis */
    o.progress_ctx = mb;
    mech_analysis *a = NULL;
    if (mech_analysis_new(m, &o, &a, d) != MECH_OK)
        return;
    double h1 = heap_now_mb();
    mech_table t = {0};
    mech_analysis_solve(a, NULL, 0, &t, NULL, d);
    mech_table_free(&t);
    mech_analysis_free(&a);
    r->kib_analysis = (h1 - h0) * 1024.0 / N;
    r->kib_state = (mb[1] - h1) * 1024.0 / N;
    solver_plan sp;
    mech_solve_options_default(&o);
    if (solver_plan_init(&sp, m, &o, d) == MECH_OK) {
        r->kib_tape = ((double)sp.tp.nins * sizeof(tape_ins) +
                       (double)sp.tp.nconst * (sizeof(int) + sizeof(double))) /
                      1024.0 / N;
        r->ins_loop = (double)sp.tp.nins / N;
        r->reg_loop = (double)sp.tp.nreg / N;
        r->const_loop = (double)sp.tp.nconst / N;
    }
    solver_plan_free(&sp);
}

/* CPU time per driver step, us: two analyses built once (2 STEPS steps
 * over the file's range, STEPS over its first half: the same step, so the
 * same work per step; row 0 cancels), their sweeps alternated `reps` times,
 * the difference of the two minima over STEPS. The minimum is what the
 * step costs when the other processes of a shared machine disturb it
 * least; NAN when an analysis fails. */
static double cpu_per_step(const mech_model *m, int reps)
{
    mech_analysis *a[2] = {NULL, NULL};
    double best[2] = {INFINITY, INFINITY};
    mech_diag d;
    mech_diag_init(&d);
    for (int k = 0; k < 2; k++) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.has_range = 1;
        o.from = m->driver.values[0];
        o.to = m->driver.values[m->driver.nvalues - 1];
        if (!k)
            o.to = 0.5 * (o.from + o.to);
        o.steps = STEPS * (1 + k);
        if (mech_analysis_new(m, &o, &a[k], &d) != MECH_OK)
            reps = 0;
    }
    for (int rep = 0; rep < reps; rep++)
        for (int k = 0; k < 2; k++) {
            mech_table t = {0};
            double c0 = bench_cpu();
            int rc = mech_analysis_solve(a[k], NULL, 0, &t, NULL, &d);
            double c = bench_cpu() - c0;
            mech_table_free(&t);
            if (rc != MECH_OK)
                rep = reps;
            best[k] = rc == MECH_OK && c < best[k] ? c : best[k];
        }
    mech_analysis_free(&a[0]);
    mech_analysis_free(&a[1]);
    mech_diag_free(&d);
    return reps > 0 && isfinite(best[0]) && isfinite(best[1]) ? (best[1] - best[0]) / STEPS * 1e6
                                                              : NAN;
}

static void measure(int N, result *r)
{
    size_t len;
    char *text = chain_text(N, &len);
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    mech_summary sum;
    double h0 = heap_now_mb() - (double)len / (1024.0 * 1024.0);  /* the text is freed below */
    double t0 = bench_now();
    if (mech_load_string(text, len, "chain.yaml", &m, &d) != MECH_OK ||
        mech_check(m, &sum, &d) != MECH_OK) {
        snprintf(r->msg, sizeof r->msg, "load: %s", d.count ? d.entries[0].message : "?");
        return;
    }
    r->load = bench_now() - t0;
    free(text);
    r->kib_model = (heap_now_mb() - h0) * 1024.0 / N;
    /* the sweep: the best of up to 5 runs (fewer for large N); wall time per
       step from mech_solve's stats of 2*STEPS steps over the file's range
       (row 0 included), CPU time per step from the difference between that
       sweep and one of STEPS steps over the first half of the range: the
       same step, so the same Newton work per step, and the set-up and row 0
       cancel; robust when other processes share the machine */
    int reps = N <= 1000 ? 5 : N <= 10000 ? 3 : 1;
    double best = INFINITY, cpu[2] = {INFINITY, INFINITY};
    mech_solve_stats st, full = {0};
    for (int k = 0; k < reps; k++)
        for (int twice = 1; twice >= 0; twice--) {
            mech_solve_options o;
            mech_solve_options_default(&o);
            o.has_range = 1;
            o.from = m->driver.values[0];
            o.to = m->driver.values[m->driver.nvalues - 1];
            if (!twice)
                o.to = 0.5 * (o.from + o.to);
            o.steps = STEPS * (1 + twice);
            double sweep_mb[2] = {NAN, NAN};
            o.progress = on_progress;
            o.progress_ctx = sweep_mb;
            mech_table t = {0};
            double c0 = bench_cpu();
            if (mech_solve(m, &o, &t, &st, &d) != MECH_OK) {
                snprintf(r->msg, sizeof r->msg, "solve: %s",
                         d.count ? d.entries[0].message : "?");
                return;
            }
            cpu[twice] = fmin(cpu[twice], bench_cpu() - c0);
            mech_table_free(&t);
            if (twice && (k == 0 || sweep_mb[0] < r->sweep_mb))
                r->sweep_mb = sweep_mb[0], r->heap_mb = sweep_mb[1];
            if (twice && st.seconds < best)
                best = st.seconds, r->setup = st.setup_seconds, full = st;
        }
    r->us_step = best / full.steps * 1e6;
    r->cpu_us_step = (cpu[1] - cpu[0]) / STEPS * 1e6;
    r->rows = full.steps;
    r->it_step = (double)full.iterations / full.steps;
    r->min_rcond = full.min_rcond;
    /* the Jacobian at the first position (exact guesses) */
    mech_system *s = NULL;
    if (mech_system_new(m, &s, &d) != MECH_OK) {
        snprintf(r->msg, sizeof r->msg, "system: %s", d.count ? d.entries[0].message : "?");
        return;
    }
    int n = s->n;
    r->n = n, r->nnz = s->nnz;
    double *x = calloc((size_t)n, sizeof *x), *f = calloc((size_t)s->m, sizeof *f);
    double *J = calloc((size_t)s->nnz, sizeof *J), *b = calloc((size_t)n, sizeof *b);
    for (int g = 0; g < m->nguesses; g++)
        if (!m->guesses[g].is_slider && s->link_var[m->guesses[g].index] >= 0)
            x[s->link_var[m->guesses[g].index]] = m->guesses[g].value;
    sys_eval_position(s, x, m->driver.values[0], f, J);
    klu_common c;
    klu_defaults(&c);
    c.scale = 0, c.tol = 0.1; /* as src/solve/solve.c */
    klu_symbolic *sym = klu_analyze(n, s->Jp, s->Ji, &c);
    double tf = bench_now();
    klu_numeric *num = sym ? klu_factor(s->Jp, s->Ji, J, sym, &c) : NULL;
    r->klu_factor_us = (bench_now() - tf) * 1e6;
    if (!num) {
        snprintf(r->msg, sizeof r->msg, "klu_factor failed (status %d)", c.status);
        return;
    }
    int kreps = N <= 1000 ? 200 : N <= 10000 ? 20 : 5;
    double tk[200];
    for (int k = 0; k < kreps; k++) {
        memcpy(b, f, sizeof *b * (size_t)n);
        double t1 = bench_now();
        klu_refactor(s->Jp, s->Ji, J, sym, num, &c);
        klu_solve(sym, num, n, 1, b, &c);
        tk[k] = bench_now() - t1;
    }
    r->klu_re_us = bench_median(tk, kreps) * 1e6;
    klu_free_numeric(&num, &c);
    klu_free_symbolic(&sym, &c);
    /* peak memory so far: before the dense matrix */
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    r->rss_mb = (double)ru.ru_maxrss / 1024.0;
    r->dense_us = NAN;
    if (N <= DENSE_MAX) {
        double *A = malloc(sizeof *A * (size_t)n * (size_t)n), *A0 = calloc((size_t)n * (size_t)n, sizeof *A0);
        int *ipiv = malloc(sizeof *ipiv * (size_t)n), info, one = 1, dreps = N <= 100 ? 50 : 1;
        double td[50];
        for (int j = 0; j < n; j++)
            for (int p = s->Jp[j]; p < s->Jp[j + 1]; p++)
                A0[(size_t)j * (size_t)n + (size_t)s->Ji[p]] = J[p];
        for (int k = 0; k < dreps; k++) {
            memcpy(A, A0, sizeof *A * (size_t)n * (size_t)n);
            memcpy(b, f, sizeof *b * (size_t)n);
            double t1 = bench_now();
            dgetrf_(&n, &n, A, &n, ipiv, &info);
            dgetrs_("N", &n, &one, A, &n, ipiv, b, &n, &info);
            td[k] = bench_now() - t1;
        }
        r->dense_us = bench_median(td, dreps) * 1e6;
        free(A), free(A0), free(ipiv);
    }
    free(x), free(f), free(J), free(b);
    mech_system_free(&s);
    /* after the peak is read (two analyses at once): the CPU time of a step
       with the set-up out of the timed sweeps, and more of them */
    double cps = cpu_per_step(m, N <= 1000 ? 15 : N <= 10000 ? 9 : 5);
    if (cps == cps)
        r->cpu_us_step = cps;
    heap_breakdown(m, N, r, &d);
    mech_model_free(&m);
    mech_diag_free(&d);
    r->ok = 1;
}

static result run_child(int N)
{
    result r;
    memset(&r, 0, sizeof r);
    int fd[2];
    if (pipe(fd))
        exit(3);
    fflush(stdout);
    pid_t pid = fork();
    if (pid == 0) {
        close(fd[0]);
        /* the alarm must end the child even if SIGALRM came ignored or
         * blocked from the parent (both survive fork and exec) */
        sigset_t alrm;
        sigemptyset(&alrm);
        sigaddset(&alrm, SIGALRM);
        signal(SIGALRM, SIG_DFL);
        sigprocmask(SIG_UNBLOCK, &alrm, NULL);
        alarm(TIMEOUT);
        measure(N, &r);
        if (write(fd[1], &r, sizeof r) != (ssize_t)sizeof r)
            _exit(3);
        _exit(0);
    }
    close(fd[1]);
    ssize_t got = read(fd[0], &r, sizeof r);
    close(fd[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (got != (ssize_t)sizeof r) {
        memset(&r, 0, sizeof r);
        snprintf(r.msg, sizeof r.msg, "%s",
                 WIFSIGNALED(status) && WTERMSIG(status) == SIGALRM
                     ? "stopped after 150 s"
                     : "the child process failed");
    }
    return r;
}

/* least-squares slope of log y against log x over the points with y > 0 */
static double slope(const int *x, const double *y, int n)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int k = 0;
    for (int i = 0; i < n; i++)
        if (svg_ok(y[i])) {
            double lx = log((double)x[i]), ly = log(y[i]);
            sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly, k++;
        }
    return k < 2 ? NAN : (k * sxy - sx * sy) / (k * sxx - sx * sx);
}

static void print_header(void)
{
    printf("%7s %7s %8s %8s %8s %10s %10s %7s %9s %8s %8s %11s %11s %12s %8s\n", "N", "unknowns",
           "nnz", "load s", "setup s", "us/step", "CPU us/st", "it/step", "min rcond", "peak MB",
           "sweep MB", "KLU fact us", "KLU re+sol", "dense LU us", "dense/KLU");
}

static void print_row(int N, result *r)
{
    if (!r->ok) {
        printf("%7d  not measured: %s\n", N, r->msg);
        r->us_step = r->rss_mb = r->sweep_mb = r->klu_re_us = r->load = r->cpu_us_step = NAN;
        r->dense_us = NAN;
        return;
    }
    printf("%7d %7d %8d %8.3f %8.3f %10.1f %10.1f %7.2f %9.2e %8.1f %8.1f %11.1f %11.1f %12.1f "
           "%8.1f\n", N, r->n, r->nnz, r->load, r->setup, r->us_step, r->cpu_us_step, r->it_step,
           r->min_rcond, r->rss_mb, r->sweep_mb, r->klu_factor_us, r->klu_re_us, r->dense_us,
           r->dense_us / r->klu_re_us);
    fflush(stdout);
}

/* The load average over the last minute (/proc/loadavg), or NAN. */
static double load_average(void)
{
    FILE *f = fopen("/proc/loadavg", "r");
    double l = NAN;
    if (f) {
        if (fscanf(f, "%lf", &l) != 1)
            l = NAN;
        fclose(f);
    }
    return l;
}

static void target_row(const char *what, const char *goal, const char *measured, int met,
                       const char *cause)
{
    printf("%-42s %-10s %-11s %-8s %s\n", what, goal, measured, met ? "met" : "not met",
           met ? "" : cause);
}

/* target_row with the measured value printed by fmt (one double). */
static void target_value(const char *what, const char *goal, const char *fmt, double value,
                         int met, const char *cause)
{
    char m[64];
    snprintf(m, sizeof m, fmt, value);
    target_row(what, goal, m, met, cause);
}

/* A target table's title and head, and its rows of CPU per loop and step
 * at N = 10^4 (cpu4) and 10^5 (cpu5) against goal (us), with their cause. */
static void cpu_targets(const char *title, double goal, double cpu4, double cpu5)
{
    const char *cause = "per loop 2 tape evaluations, 2 block factorisations, 4 block solves "
                        "(Newton, rates) and the whole-matrix condition estimate; instructions "
                        "and their kinds: bench_ratio.sh's chain row; CPU time moves with the "
                        "load; 0.17-0.22 us by hand";
    char g[32];
    snprintf(g, sizeof g, "<= %.2g us", goal);
    printf("%s\n%-42s %-10s %-11s %-8s %s\n", title, "target", "goal", "measured", "", "cause");
    target_value("CPU per loop and step, N = 10 000", g, "%.3f us", cpu4, cpu4 <= goal, cause);
    target_value("CPU per loop and step, N = 100 000", g, "%.3f us", cpu5, cpu5 <= goal, cause);
}

/* issue 21, target 2, per loop: CPU time (what this process used, not the
 * other processes of a loaded machine), its growth with N, and the resident
 * memory of the sweep; for a target not met, the cause from what this run
 * measured (heap per part; the machine's load) and the instruction profile
 * of bench_ratio.sh's chain row (docs/performance.md, "Target 2"). */
static void target_table(const int *Ns, const result *r)
{
    const result *r3 = &r[2], *r4 = &r[3], *r5 = &r[4];
    double cpu3 = r3->cpu_us_step / Ns[2], cpu4 = r4->cpu_us_step / Ns[3],
           cpu5 = r5->cpu_us_step / Ns[4];
    double kib5 = r5->sweep_mb * 1024.0 / Ns[4], heap5 = r5->heap_mb * 1024.0 / Ns[4];
    char m[64], cause[512], title[160];
    snprintf(title, sizeof title, "issue 21, target 2: chains of N four-bars, per loop (load "
             "average now %.1f on %ld processors)", load_average(),
             sysconf(_SC_NPROCESSORS_ONLN));
    cpu_targets(title, 0.25, cpu4, cpu5);
    snprintf(cause, sizeof cause, "beyond the caches: the tape, registers, factors and "
             "frames of every loop stream from memory each step (%.1f KiB per loop)", heap5);
    target_value("linear: CPU per loop, 10^5 over 10^3", "<= 1.25", "%.2f", cpu5 / cpu3,
                 cpu5 / cpu3 <= 1.25, cause);
    snprintf(cause, sizeof cause, "heap %.2f KiB: model %.2f (the file's links, points, joints, "
             "names), analysis %.2f (solver tape %.2f: %.0f instructions; pattern, BTF, spanning "
             "tree, unknowns' names), sweep state %.2f (%.0f registers, x and 6 rate/work "
             "vectors, 2x2 factors, link frames, predictor history)", heap5, r5->kib_model,
             r5->kib_analysis, r5->kib_tape, r5->ins_loop, r5->kib_state, r5->reg_loop);
    target_value("resident in the sweep, N = 100 000", "<= 1 KiB", "%.2f KiB", kib5,
                 kib5 <= 1.0, cause);
    snprintf(m, sizeof m, "%.2f KiB", r5->rss_mb * 1024.0 / Ns[4]);
    printf("%-42s %-10s %-11s %-8s %s\n", "(peak resident, N = 100 000: set-up)", "-", m, "",
           "the loader's tree, the expression DAG and the solver's tape until it is "
           "compiled, freed after (plan_compact.c)");
}

/* issue 33, target 4: at most 0.3 us of CPU per loop per step at N = 10^4
 * and 10^5, linear in N, and a peak resident set of at most 2 KiB per loop
 * at N = 10^5, set-up included; the causes from this run's measurements and
 * the profiles of docs/performance.md section 4. */
static void target_table_33(const int *Ns, const result *r)
{
    const result *r4 = &r[3], *r5 = &r[4];
    double cpu4 = r4->cpu_us_step / Ns[3], cpu5 = r5->cpu_us_step / Ns[4];
    double peak5 = r5->rss_mb * 1024.0 / Ns[4], held5 = r5->sweep_mb * 1024.0 / Ns[4];
    char cause[600];
    cpu_targets("issue 33, target 4: chains of N four-bars, per loop", 0.3, cpu4, cpu5);
    snprintf(cause, sizeof cause, "beyond the caches at 10^5 (%.1f KiB held per loop)", held5);
    target_value("linear: CPU per loop, 10^5 over 10^4", "<= 1.25", "%.2f", cpu5 / cpu4,
                 cpu5 / cpu4 <= 1.25, cause);
    snprintf(cause, sizeof cause, "the set-up's peak: the loader's tree and the model, then "
             "the expression DAG's nodes and hash table and the solver's tape until it is "
             "compiled (massif); %.2f KiB per loop held in the sweep", held5);
    target_value("peak resident, N = 100 000, set-up included", "<= 2 KiB", "%.2f KiB", peak5,
                 peak5 <= 2.0, cause);
}

int main(int argc, char **argv)
{
    if (argc > 2 && strcmp(argv[1], "--only") == 0) {  /* one N (to profile or compare) */
        int N = atoi(argv[2]);
        result r = run_child(N);
        print_header();
        print_row(N, &r);
        if (r.ok)
            printf("per loop: CPU %.3f us per step, sweep resident %.2f KiB (heap in use %.2f KiB), "
                   "peak %.2f KiB\n", r.cpu_us_step / N, r.sweep_mb * 1024.0 / N,
                   r.heap_mb * 1024.0 / N, r.rss_mb * 1024.0 / N);
        if (r.ok)
            printf("heap per loop: model %.2f KiB, analysis %.2f KiB (solver tape %.2f KiB: %.1f "
                   "instructions, %.1f constants; %.1f registers per state), sweep state and "
                   "table %.2f KiB\n", r.kib_model, r.kib_analysis, r.kib_tape, r.ins_loop,
                   r.const_loop, r.reg_loop, r.kib_state);
        return r.ok ? 0 : 1;
    }
    if (argc > 2 && strcmp(argv[1], "--yaml") == 0) {
        size_t len;
        char *text = chain_text(atoi(argv[2]), &len);
        fwrite(text, 1, len, stdout);
        free(text);
        return 0;
    }
    const char *svgdir = argc > 1 ? argv[1] : NULL;
    static const int Ns[NN] = {10, 100, 1000, 10000, 100000};
    result r[NN];
    printf("scaling: chains of N four-bar loops (2N unknowns), %d driver steps (2.5 deg); each N in its own\n"
           "process; KLU and dense: one factorisation + solve of the same 2N x 2N Jacobian\n", 2 * STEPS);
    print_header();
    for (int i = 0; i < NN; i++) {
        r[i] = run_child(Ns[i]);
        print_row(Ns[i], &r[i]);
    }
    double y[7][NN];
    for (int i = 0; i < NN; i++) {
        y[6][i] = r[i].cpu_us_step;
        y[0][i] = r[i].us_step, y[1][i] = r[i].klu_re_us, y[2][i] = r[i].dense_us;
        y[3][i] = r[i].load * 1e6, y[4][i] = r[i].rss_mb, y[5][i] = r[i].setup * 1e6;
    }
    /* slopes over N >= 100 (N = 10 is dominated by constant costs) */
    printf("log-log slopes for N >= 100 (1 = linear): time per step %.2f (CPU %.2f), KLU refactor+solve %.2f, "
           "load+check %.2f, set-up %.2f, peak RSS %.2f; dense LU (N = 100..1000) %.2f\n",
           slope(Ns + 1, y[0] + 1, NN - 1), slope(Ns + 1, y[6] + 1, NN - 1),
           slope(Ns + 1, y[1] + 1, NN - 1),
           slope(Ns + 1, y[3] + 1, NN - 1), slope(Ns + 1, y[5] + 1, NN - 1),
           slope(Ns + 1, y[4] + 1, NN - 1), slope(Ns + 1, y[2] + 1, 2));
    target_table(Ns, r);
    target_table_33(Ns, r);
    if (!svgdir)
        return 0;
    double xs[NN];
    for (int i = 0; i < NN; i++)
        xs[i] = Ns[i];
    svg_series s[] = {
        {"mech_solve, per step", xs, y[0], NN, SVG_COLORS[0], NULL},
        {"same, CPU time", xs, y[6], NN, SVG_COLORS[0], "2,3"},
        {"KLU refactor+solve", xs, y[1], NN, SVG_COLORS[2], NULL},
        {"dense LU (LAPACK)", xs, y[2], NN, SVG_COLORS[1], NULL},
        {"load+check (once)", xs, y[3], NN, SVG_COLORS[3], "6,3"},
        {"set-up (once)", xs, y[5], NN, SVG_COLORS[4], "6,3"},
    };
    char path[600];
    snprintf(path, sizeof path, "%s/scaling-time.svg", svgdir);
    svg_loglog(path, "chain of N four-bar loops: time", "N (loops; 2N unknowns)",
               "time [us]", s, (int)(sizeof s / sizeof s[0]));
    svg_series sm[] = {{"peak RSS", xs, y[4], NN, SVG_COLORS[0], NULL}};
    snprintf(path, sizeof path, "%s/scaling-memory.svg", svgdir);
    svg_loglog(path, "chain of N four-bar loops: peak memory (ru_maxrss)",
               "N (loops; 2N unknowns)", "peak RSS [MB]", sm, 1);
    printf("wrote %s/scaling-time.svg, %s/scaling-memory.svg\n", svgdir, svgdir);
    return 0;
}
