/* src/cli/cmd_watch.c: `mech watch FILE`, a live page of a mechanism while its
 * file is edited (docs/cli.md, "mech watch"). It serves the page on
 * 127.0.0.1 (src/cli/cmd_http.c; the address on the first line of standard
 * output), looks at the file every WATCH_POLL_MS (its device, inode, size,
 * modification and change times: an editor's write-to-a-temporary-and-
 * rename is a new inode), and on a change that has held for one look,
 * re-reads and re-solves it as mech report does (src/cli/cli.h) into a
 * new state: the drawing, slider, values and diagnostics, or the error
 * with the last good drawing kept. SIGINT, SIGTERM and SIGHUP end it
 * cleanly, status 0. */
#include <errno.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#include "cli.h"
#include "base.h"

typedef struct watch_args {
    const char *file;
    int port;
    cmd_sets set;
    plot_anim_options anim;  /* frames, test colours */
} watch_args;

#define AT(field) offsetof(watch_args, field)

static const cmd_opt options[] = {
    {.names = "--port", .kind = CMD_OPT_INT, .at = AT(port), .lo = 0, .hi = 65535,
     .flags = CMD_RUN_ONLY, .expect = "needs a port number from 0 to 65535",
     .label = "--port N", .help = "listen on port N (default 0: a free port)"},
    CMD_SET_ENTRY(AT(set), "replace the file's parameter NAME by VALUE (repeatable)"),
    {.names = "--frames", .kind = CMD_OPT_INT, .at = AT(anim.max_frames), .lo = 2, .hi = 100000,
     .expect = "needs a whole number from 2 to 100000", .label = "--frames N",
     .help = "slider positions at most (default 1000)"},
    {.names = "--test-colours|--test-colors", .kind = CMD_OPT_FLAG, .at = AT(anim.test_colours),
     .flag = 1, .label = "--test-colours",
     .help = "draw in grey with every point a disc of its own colour"},
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_watch_spec = {
    .name = "watch",
    .summary = "serve a live page of the mechanism, solved again on every save",
    .usage = "usage: mech watch FILE [--port N] [--set NAME=VALUE] [--frames N]\n",
    .about = "Serve a live page of the mechanism on this computer only (127.0.0.1) and\n"
             "print its address (http://127.0.0.1:PORT/) as the first line of standard\n"
             "output. Open it in a browser: every time FILE is saved it is read and solved\n"
             "again and the page follows within a second: the moving mechanism with its\n"
             "traced paths, a slider over the driver positions with the values of the\n"
             "outputs there, the diagnostics and warnings (as mech report). A file with an\n"
             "error shows the error (FILE:LINE:COLUMN) above the last good drawing. The page\n"
             "loads nothing from the network. Ctrl-C (SIGINT) or SIGTERM stops it.\n"
             "Dragging a point in the page does not change the file.\n",
    .opts = options,
    .column = 22,
    .exits = "exit status: 0 stopped by a signal, 2 invalid usage, 3 FILE cannot be read or\n"
             "the port cannot be listened on\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech watch FILE)",
};

enum { WATCH_POLL_MS = 150 };

static volatile sig_atomic_t watch_stop;

static void on_stop(int sig)
{
    (void)sig;
    watch_stop = 1;
}

/* What tells one version of the file from another (ok 0: stat failed). */
typedef struct file_sig {
    int ok;
    dev_t dev;
    ino_t ino;
    off_t size;
    struct timespec mtime, ctime;
} file_sig;

static file_sig sig_of(const char *path)
{
    struct stat st;
    file_sig s;
    memset(&s, 0, sizeof s);
    if (stat(path, &st) != 0)
        return s;
    s.ok = 1;
    s.dev = st.st_dev;
    s.ino = st.st_ino;
    s.size = st.st_size;
    s.mtime = st.st_mtim;
    s.ctime = st.st_ctim;
    return s;
}

static int sig_same(const file_sig *a, const file_sig *b)
{
    return a->ok == b->ok && a->dev == b->dev && a->ino == b->ino && a->size == b->size &&
           a->mtime.tv_sec == b->mtime.tv_sec && a->mtime.tv_nsec == b->mtime.tv_nsec &&
           a->ctime.tv_sec == b->ctime.tv_sec && a->ctime.tv_nsec == b->ctime.tv_nsec;
}

/* The served state and what it is made from. */
typedef struct watch {
    const watch_args *a;
    char *page, *state;      /* the page; the state's JSON (each malloc'ed) */
    size_t page_len, state_len;
    char *good_html;         /* the last good drawing's HTML, or NULL */
    long long version, good; /* the state's version; the last good one's (0: none) */
    char name[256];          /* the mechanism's name, from the last good version */
} watch;

/* What open_memstream made, or NULL when it failed. */
static char *closed_text(FILE *f, char **text)
{
    if (fclose(f) != 0) {
        free(*text);
        *text = NULL;
    }
    return *text;
}

/* The page's part of a solved run r (report_watch_fragment), or NULL. */
static char *fragment(const report_run *r)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f)
        return NULL;
    report_input in = {
        .m = r->m, .summary = &r->summary, .t = &r->t, .stats = &r->stats, .diag = &r->d,
        .animation = r->animation, .frame_rows = r->frame_rows, .nframes = r->nframes,
        .duration = r->a.anim.duration, .gaps = r->gap_lines, .ngaps = r->t.ngaps,
    };
    report_watch_fragment(f, &in);
    return closed_text(f, &text);
}

/* The error of a failed run: its messages as mech prints them. */
static char *error_text(const report_run *r, int code)
{
    char *text = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&text, &len);
    if (!f)
        return NULL;
    mech_diag_print(&r->d, f);
    if (r->d.nerrors == 0)
        fprintf(f, "%s: the mechanism could not be solved (exit status %d; the terminal "
                "running mech watch says why)\n", r->a.file, code);
    return closed_text(f, &text);
}

/* The state's JSON: version, the last good version, file, name, time,
 * error (or null) and the last good drawing's HTML. */
static int put_state(watch *w, const char *error)
{
    char *text = NULL, when[32];
    size_t len = 0;
    time_t now = time(NULL);
    struct tm tm;
    strftime(when, sizeof when, "%H:%M:%S", localtime_r(&now, &tm));
    FILE *f = open_memstream(&text, &len);
    if (!f)
        return -1;
    fprintf(f, "{\"version\":%lld,\"good\":%lld,\"file\":", w->version, w->good);
    report_put_json_string(f, w->a->file);
    fputs(",\"name\":", f);
    report_put_json_string(f, w->name[0] ? w->name : w->a->file);
    fprintf(f, ",\"time\":\"%s\",\"error\":", when);
    if (error)
        report_put_json_string(f, error);
    else
        fputs("null", f);
    fputs(",\"html\":", f);
    report_put_json_string(f, w->good_html ? w->good_html : "");
    fputs("}\n", f);
    if (!closed_text(f, &text))
        return -1;
    free(w->state);
    w->state = text;
    w->state_len = strlen(text);
    return 0;
}

/* Read and solve the file again (mech report's steps) into a new state. */
static void rebuild(watch *w)
{
    report_run r;
    memset(&r, 0, sizeof r);
    r.cmd = "watch";
    r.a.file = w->a->file;
    r.a.friction = -1;
    r.a.anim = w->a->anim;
    r.a.set.n = w->a->set.n;  /* borrowed: r.a.set.copy stays NULL (nothing to free) */
    memcpy(r.a.set.set, w->a->set.set, sizeof r.a.set.set);
    mech_diag_init(&r.d);
    int code = report_run_load(&r);
    if (code == MECH_EXIT_OK)
        code = report_run_solve(&r);
    if (code == MECH_EXIT_OK)
        code = report_run_animation(&r);
    if (code == MECH_EXIT_OK)
        code = report_run_gaps(&r);
    char *html = code == MECH_EXIT_OK ? fragment(&r) : NULL, *error = NULL;
    w->version++;
    if (html) {
        free(w->good_html);
        w->good_html = html;
        w->good = w->version;
        snprintf(w->name, sizeof w->name, "%s", r.m->name ? r.m->name : w->a->file);
        mech_diag_print(&r.d, stderr);
        fprintf(stderr, "mech watch: version %lld: %d of %d positions solved\n", w->version,
                r.t.nrows, r.t.nrequested);
    } else {
        error = error_text(&r, code);
        if (r.m)  /* a failed load has printed its messages already */
            mech_diag_print(&r.d, stderr);
        fprintf(stderr, "mech watch: version %lld: not solved; the page shows why\n",
                w->version);
    }
    if (put_state(w, error ? error : html ? NULL : "out of memory") != 0)
        fprintf(stderr, "mech watch: out of memory; the page keeps the state before\n");
    free(error);
    report_run_free(&r);
}

static int make_page(watch *w)
{
    FILE *f = open_memstream(&w->page, &w->page_len);
    if (!f)
        return -1;
    report_watch_page(f, w->a->file);
    return closed_text(f, &w->page) ? 0 : -1;
}

/* SIGINT, SIGTERM and SIGHUP stop the loop (poll returns, interrupted);
 * a closed connection is no signal (SIGPIPE ignored). */
static void catch_stops(void)
{
    static const int sigs[] = {SIGINT, SIGTERM, SIGHUP};
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sigemptyset(&sa.sa_mask);
    sa.sa_handler = on_stop;  /* no SA_RESTART: poll() is interrupted */
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++)
        sigaction(sigs[i], &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
}

/* Serve, and rebuild when the file has changed and held still for one look. */
static void serve(watch *w, http_server *srv, file_sig loaded)
{
    file_sig seen = loaded;
    double next_look = clock_seconds() + WATCH_POLL_MS / 1e3;
    while (!watch_stop) {
        http_site site = {w->page, w->page_len, w->state, w->state_len, w->version};
        double left = (next_look - clock_seconds()) * 1e3;
        http_serve(srv, &site, left > 0 ? (int)left + 1 : 0);
        if (watch_stop || clock_seconds() < next_look)
            continue;
        next_look = clock_seconds() + WATCH_POLL_MS / 1e3;
        file_sig now = sig_of(w->a->file);
        if (!sig_same(&now, &loaded) && sig_same(&now, &seen)) {
            rebuild(w);
            loaded = now;
        }
        seen = now;
    }
}

int cmd_watch(int argc, char **argv)
{
    watch_args a;
    memset(&a, 0, sizeof a);
    plot_anim_options_default(&a.anim);
    int code = cmd_opts_parse(&cmd_watch_spec, argc, argv, &a);
    if (code >= 0) {
        cmd_sets_free(&a.set);
        return code;
    }
    file_sig first = sig_of(a.file);
    char err[300];
    http_server srv;
    watch w;
    memset(&w, 0, sizeof w);
    w.a = &a;
    if (!first.ok) {
        fprintf(stderr, "%s: error: cannot read the file: %s\n", a.file, strerror(errno));
        code = MECH_EXIT_IO;
    } else if (http_open(&srv, a.port, err, sizeof err) != 0) {
        fprintf(stderr, "mech watch: %s\n", err);
        code = MECH_EXIT_IO;
    } else if (make_page(&w) != 0) {
        fprintf(stderr, "mech watch: out of memory\n");
        http_close(&srv);
        code = MECH_EXIT_IO;
    }
    if (code < 0) {
        catch_stops();
        printf("http://127.0.0.1:%d/\n", srv.port);
        fflush(stdout);
        rebuild(&w);
        serve(&w, &srv, first);
        http_close(&srv);
        fprintf(stderr, "mech watch: stopped\n");
        code = MECH_EXIT_OK;
    }
    free(w.page);
    free(w.state);
    free(w.good_html);
    cmd_sets_free(&a.set);
    return code;
}
