/* src/cmd_common.c: pieces several commands share: --help, loading a
 * checked file, usage errors, --set and --from/--to/--steps (solve, plot,
 * animate), --shard, the default number of workers (the CPU affinity mask),
 * and running independent jobs on worker threads (mech batch, mech sweep). */
#define _GNU_SOURCE  /* sched_getaffinity, CPU_COUNT */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "commands.h"

int cmd_wants_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

int cmd_load_checked(const char *path, mech_model **m)
{
    return cmd_load_checked_with(path, NULL, 0, m);
}

int cmd_load_checked_with(const char *path, const mech_override *ov, int nov, mech_model **m)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_summary s;
    int rc = mech_load_file_with(path, ov, nov, m, &d);
    if (rc == MECH_OK)
        rc = mech_check(*m, &s, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    if (rc == MECH_OK)
        return MECH_EXIT_OK;
    mech_model_free(m);
    return rc == MECH_EIO ? MECH_EXIT_IO : MECH_EXIT_INPUT;
}

int cmd_usage_error(const char *command, const char *fmt, const char *arg)
{
    fprintf(stderr, "mech %s: ", command);
    fprintf(stderr, fmt, arg);
    fprintf(stderr, " (see 'mech %s --help')\n", command);
    return MECH_EXIT_INPUT;
}

int cmd_parse_int(const char *text, int lo, int hi, int *v)
{
    char *end;
    double x = strtod(text, &end);
    /* !(lo <= x <= hi) also refuses NaN: converting it (or anything out of
       int's range) to int is undefined */
    if (end == text || *end != '\0' || !(x >= lo && x <= hi) || x != (double)(int)x)
        return 0;
    *v = (int)x;
    return 1;
}

int cmd_refuse_input(const char *command, const char *out, const char *const *inputs, int n)
{
    struct stat so, si;
    if (!out || strcmp(out, "-") == 0 || stat(out, &so) != 0 || !S_ISREG(so.st_mode))
        return -1;  /* new, or not a file an input can be */
    for (int i = 0; i < n; i++)
        if (inputs[i] && stat(inputs[i], &si) == 0 && si.st_dev == so.st_dev &&
            si.st_ino == so.st_ino) {
            fprintf(stderr, "mech %s: the output %s is the input file %s; not overwriting it\n",
                    command, out, inputs[i]);
            return MECH_EXIT_INPUT;
        }
    return -1;
}

/* ---- --set, --from/--to/--steps ------------------------------------------ */

int cmd_parse_set(const char *command, const char *val, cmd_sets *s)
{
    const char *eq = strchr(val, '=');
    if (!eq || eq == val || !eq[1] || s->n == CMD_MAX_SET)
        return cmd_usage_error(command, "--set needs NAME=VALUE (at most 64), not '%s'", val);
    char *copy = malloc(strlen(val) + 1);
    if (!copy)
        return fprintf(stderr, "mech %s: out of memory\n", command), MECH_EXIT_IO;
    strcpy(copy, val);
    copy[eq - val] = '\0';
    s->copy[s->n] = copy;
    s->set[s->n].name = copy;
    s->set[s->n++].text = copy + (eq - val) + 1;
    return -1;
}

void cmd_sets_free(cmd_sets *s)
{
    for (int i = 0; i < s->n; i++)
        free(s->copy[i]);
    s->n = 0;
}

int cmd_check_range_pair(const char *command, const char *from, const char *to)
{
    if ((from != NULL) != (to != NULL))
        return cmd_usage_error(command, "%s", "--from and --to go together");
    return -1;
}

/* The largest driver position on the command line, rad or m: beyond it a
 * step of the sweep is lost in the rounding of the position itself
 * (1e6 rad = 57 million degrees, ulp 1.2e-10 rad). */
#define MAX_DRIVER 1e6

/* One end of --from/--to into *si: a finite position within MAX_DRIVER, as
 * the file's range must be finite (docs/limits.md). Returns -1 when fine,
 * else the exit status (the problem printed). */
static int parse_end(const char *command, const char *opt, const char *text, int is_angle,
                     double *si)
{
    char err[256];
    if (mech_parse_value(text, is_angle, si, err, sizeof err) != MECH_OK)
        return fprintf(stderr, "mech %s: %s '%s': %s\n", command, opt, text, err),
               MECH_EXIT_INPUT;
    if (!(fabs(*si) <= MAX_DRIVER)) {
        snprintf(err, sizeof err, "%s '%.40s' is %.3g %s: a driver %s must be within +-%s "
                 "(beyond, a step is lost in the rounding of the position)", opt, text, *si,
                 is_angle == 2 ? "s" : is_angle ? "rad" : "m",
                 is_angle == 2 ? "time" : is_angle ? "angle" : "displacement",
                 is_angle == 2 ? "1e6 s" : is_angle ? "1e6 rad (5.7e7 deg)" : "1e6 m");
        return cmd_usage_error(command, "%s", err);
    }
    return -1;
}

int cmd_apply_range(const char *command, const char *from, const char *to, int steps,
                    const mech_model *m, mech_solve_options *o)
{
    int is_angle = m->driver.kind == MECH_DRIVE_TIME ? 2 : m->driver.kind == MECH_DRIVE_ANGLE, code;
    if (from) {
        if ((code = parse_end(command, "--from", from, is_angle, &o->from)) >= 0 ||
            (code = parse_end(command, "--to", to, is_angle, &o->to)) >= 0)
            return code;
        o->has_range = 1;
        o->steps = steps > 0 ? steps : 360;
    } else if (steps > 0 && m->has_driver && m->driver.nvalues > 0) {
        /* new spacing over the file's range */
        o->has_range = 1;
        o->from = m->driver.values[0];
        o->to = m->driver.values[m->driver.nvalues - 1];
        o->steps = steps;
    }
    return -1;
}

int cmd_make_dir(const char *dir)
{
    char *p = malloc(strlen(dir) + 1);
    if (!p)
        return -1;
    strcpy(p, dir);
    for (char *s = p + 1;; s++) {
        if (*s == '/' || *s == '\0') {
            char c = *s;
            *s = '\0';
            if (mkdir(p, 0777) != 0 && errno != EEXIST) {
                int e = errno;
                free(p);
                errno = e;
                return -1;
            }
            *s = c;
            if (c == '\0')
                break;
        }
    }
    free(p);
    struct stat st;
    if (stat(dir, &st) != 0)
        return -1;
    if (!S_ISDIR(st.st_mode)) {
        errno = ENOTDIR;
        return -1;
    }
    return 0;
}

int cmd_parse_shard(const char *s, int *k, int *mod)
{
    char *end;
    long a = strtol(s, &end, 10);
    if (end == s || *end != '/')
        return -1;
    const char *p = end + 1;
    long b = strtol(p, &end, 10);
    if (end == p || *end != '\0' || b < 1 || a < 0 || a >= b || b > 1000000)
        return -1;
    *k = (int)a;
    *mod = (int)b;
    return 0;
}

/* The CPUs this process may run on (its affinity mask: taskset, a Slurm
 * allocation, a container's cpuset), not all those online: more workers
 * than that only take turns. */
int cmd_default_jobs(void)
{
    cpu_set_t set;
    if (sched_getaffinity(0, sizeof set, &set) == 0 && CPU_COUNT(&set) > 0)
        return CPU_COUNT(&set) < 1024 ? CPU_COUNT(&set) : 1024;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n > 0 && n < 1024 ? (int)n : 1;
}

typedef struct pool {
    int njobs;
    atomic_int next;
    void (*job)(void *ctx, int i);
    void *ctx;
} pool;

static void *worker(void *arg)
{
    pool *p = arg;
    for (int i; (i = atomic_fetch_add(&p->next, 1)) < p->njobs;)
        p->job(p->ctx, i);
    return NULL;
}

void cmd_run_parallel(int njobs, int nthreads, void (*job)(void *ctx, int i), void *ctx)
{
    pool p = {njobs, 0, job, ctx};
    if (nthreads > njobs)
        nthreads = njobs > 0 ? njobs : 1;
    pthread_t *tid = calloc((size_t)nthreads, sizeof *tid);
    int started = 0;  /* tid[0 .. started-1] are the threads created */
    for (int t = 0; tid && t < nthreads; t++)
        if (pthread_create(&tid[started], NULL, worker, &p) == 0)
            started++;
    if (started == 0)
        worker(&p);  /* no threads: do the work here */
    for (int t = 0; t < started; t++)
        pthread_join(tid[t], NULL);
    free(tid);
}

/* ---- progress ------------------------------------------------------------- */

static pthread_mutex_t progress_lock = PTHREAD_MUTEX_INITIALIZER;

static double monotonic_seconds(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cmd_progress_init(cmd_progress *p, const char *command, const char *unit, int quiet)
{
    memset(p, 0, sizeof *p);
    p->command = command;
    p->unit = unit;
    p->quiet = quiet;
    p->tty = isatty(STDERR_FILENO);
    p->interval = p->tty ? 0.1 : 5.0;
    const char *env = getenv("MECH_PROGRESS_SECONDS");
    if (env && *env && !p->tty)
        p->interval = atof(env);
    p->start = p->last = monotonic_seconds();
}

void cmd_progress_update(cmd_progress *p, int done, int total)
{
    if (p->quiet)
        return;
    pthread_mutex_lock(&progress_lock);
    double now = monotonic_seconds();
    if (now - p->last >= p->interval && done < total) {
        p->last = now;
        int pct = total > 0 ? (int)(100.0 * done / total) : 100;
        if (p->tty) {
            int width = 30, fill = total > 0 ? (int)((double)done * width / total) : width;
            fprintf(stderr, "\rmech %s: [%.*s%*s] %3d%% (%d of %d %s)", p->command, fill,
                    "##############################", width - fill, "", pct, done, total, p->unit);
            p->drawn = 1;
        } else {
            fprintf(stderr, "mech %s: %d of %d %s (%d%%), %.0f s\n", p->command, done, total,
                    p->unit, pct, now - p->start);
        }
        fflush(stderr);
    }
    pthread_mutex_unlock(&progress_lock);
}

void cmd_progress_done(cmd_progress *p)
{
    if (!p->quiet && p->drawn)
        fprintf(stderr, "\r\033[K");  /* the bar's line cleared for what follows */
    p->drawn = 0;
}

void cmd_progress_callback(void *ctx, int done, int total)
{
    cmd_progress_update(ctx, done, total);
}

/* Outputs of the animation: every point name and every moving link, no
 * forces (*all, owned by the caller). */
int cmd_select_everything(const mech_model *m, mech_outputs *all)
{
    memset(all, 0, sizeof *all);
    all->points = malloc(((size_t)m->npoint_names + 1) * sizeof *all->points);
    all->links = malloc(((size_t)m->nlinks + 1) * sizeof *all->links);
    all->sliders = malloc(sizeof *all->sliders);
    if (!all->points || !all->links || !all->sliders) {
        mech_outputs_free(all);
        return -1;
    }
    for (int p = 0; p < m->npoint_names; p++)
        all->points[p] = p;
    for (int i = 1; i < m->nlinks; i++)
        all->links[i - 1] = i;
    all->npoints = m->npoint_names;
    all->nlinks = m->nlinks - 1;
    return 0;
}
