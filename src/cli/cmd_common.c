/* src/cli/cmd_common.c: pieces several commands share: loading a checked
 * file, usage errors, the readers of --set, --friction, --shard and
 * --from/--to/--steps (solve, plot, animate, report; sweep, batch), the
 * progress report. */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "base.h"

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

const cmd_word cmd_friction_words[] = {
    {"on", MECH_FRICTION_ON}, {"off", MECH_FRICTION_OFF}, {"both", MECH_FRICTION_BOTH}, {NULL, 0}};

int cmd_parse_set(const char *command, void *sets, const char *val)
{
    cmd_sets *s = sets;
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

int cmd_parse_driver(const char *command, const char *opt, const char *text,
                     const mech_model *m, double *si)
{
    char err[256];
    int is_angle = m->driver.kind == MECH_DRIVE_TIME ? 2 : m->driver.kind == MECH_DRIVE_ANGLE;
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
    int code;
    if (from) {
        if ((code = cmd_parse_driver(command, "--from", from, m, &o->from)) >= 0 ||
            (code = cmd_parse_driver(command, "--to", to, m, &o->to)) >= 0)
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

const cmd_word cmd_engine_words[] = {{"auto", CMD_ENGINE_AUTO},
                                     {"compiled", CMD_ENGINE_COMPILED},
                                     {"interpreted", CMD_ENGINE_INTERPRETED}, {NULL, 0}};

int cmd_strict_assembly(mech_diag *d)
{
    int n = 0;
    for (size_t i = 0; d && i < d->count; i++) {
        mech_diag_entry *e = &d->entries[i];
        if (e->severity == MECH_SEV_WARNING && fail_is_suspect_assembly(e->kind)) {
            e->severity = MECH_SEV_ERROR;
            d->nerrors++;
            n++;
        }
    }
    return n;
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

int cmd_read_shard(const char *command, void *shard, const char *value)
{
    cmd_shard *sh = shard;
    size_t nk = strspn(value, "0123456789"), nm = strspn(value + nk + 1, "0123456789");
    long k = nk && value[nk] == '/' ? strtol(value, NULL, 10) : -1;
    long m = nk && nm && !value[nk + 1 + nm] && nm <= 7 ? strtol(value + nk + 1, NULL, 10) : 0;
    if (nk > 7 || k < 0 || m < 1 || k >= m || m > 1000000)
        return cmd_usage_error(command, "--shard needs K/M with 0 <= K < M, not '%s'", value);
    sh->k = (int)k;
    sh->m = (int)m;
    sh->given = 1;
    return -1;
}

/* ---- progress ------------------------------------------------------------- */

static pthread_mutex_t progress_lock = PTHREAD_MUTEX_INITIALIZER;

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
    p->start = p->last = clock_seconds();
}

void cmd_progress_update(cmd_progress *p, int done, int total)
{
    if (p->quiet)
        return;
    pthread_mutex_lock(&progress_lock);
    double now = clock_seconds();
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
