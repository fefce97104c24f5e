/* src/cli/cmd_codegen_jit.c: `mech solve --jit` (docs/codegen.md, section "mech
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
 * and the interpreter solves the sweep instead, with a note on stderr. A
 * row with a value that is not finite stops the sweep with the
 * interpreter's error (its check, sweep.c), as the interpreter does; the
 * assembly's checks run on the rows' positions, as the interpreter's.
 * mech sweep (cmd_jit_variants, at the end): one solver for all the
 * variants through the sweep's one analysis, its source reading their
 * numbers from the state (docs/codegen.md, "One solver for a sweep's
 * variants"). */
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "codegen.h"
#include "cli.h"

extern char **environ;  /* the compiler's environment: ours (POSIX) */

/* What the shared object adds to the generated source (prefix jit): the
 * state's size and one row with the continuation's acceptance tests
 * (src/solve/continuation.c cont_advance and cont_try). */
static const char *const wrapper[] = {
    "#include \"gen.c\"",
    "",
    "size_t jit_state_size(void);",
    "int jit_nout(void);",
    "int jit_nx(void);",
    "const char *const *jit_names(void);",
    "int jit_row(void *vs, const void *num, double q, double qd, double qdd, int first,",
    "            double *out, double *info, double *x);",
    "",
    "size_t jit_state_size(void) { return sizeof(jit_state); }",
    "int jit_nout(void) { return JIT_NOUT; }",
    "int jit_nx(void) { return NX; }",
    "const char *const *jit_names(void) { return jit_column_names; }",
    "",
    "/* Row q: 0 solved (out, info and, unless NULL, x set), a status of",
    " * jit_solve, or -1 where the interpreter's continuation would not accept",
    " * its first step. num: a sweep's",
    " * variant's numbers (struct rt_numbers) for the first row of a solver built",
    " * for them, else unused. */",
    "int jit_row(void *vs, const void *num, double q, double qd, double qdd, int first,",
    "            double *out, double *info, double *x)",
    "{",
    "    jit_state *s = vs;",
    "    int st;",
    "    (void)num;",
    "    if (first) {",
    "        jit_init(s);",
    "#if CG_NUMBERS",
    "        jit_numbers(s, (const struct rt_numbers *)num);",
    "#endif",
    "        st = jit_solve(s, q, qd, qdd);",
    "    } else {",
    "        double xpred[NX + 1], move;",
    "        int det = s->det_sign;",
    "        jit_predict(s, q);",
    "        for (int i = 0; i < NX; i++) {",
    "            xpred[i] = s->x[i];",
    "            s->dx[i] = s->x[i] - s->xc[i];",
    "        }",
    "        move = rt_step_size(s->dx, unit, NX);",
    "        if (move > 0.25)",
    "            return -1;",
    "        st = jit_solve(s, q, qd, qdd);",
    "        if (st == 0) {",
    "            for (int i = 0; i < NX; i++)",
    "                s->dx[i] = s->x[i] - xpred[i];",
    "            if (rt_step_size(s->dx, unit, NX) > 0.5 * move + 0.05 || s->det_sign != det)",
    "                return -1;",
    "        }",
    "    }",
    "    if (st != 0)",
    "        return st;",
    "    for (int c = 0; c < JIT_NOUT; c++)",
    "        out[c] = s->out[c];",
    "    for (int i = 0; x && i < NX; i++)",
    "        x[i] = s->x[i];",
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

/* How the last sweep of this thread ran (cmd_jit_how): mech batch solves
 * its files on several threads. */
static _Thread_local char how[700];

/* One build at a time in the process (mech batch's threads): the guard
 * below (the private directory, the compiler's pid, the signal actions) is
 * the process's, and a second file of the same structure then finds the
 * first one's solver in the cache instead of compiling it again. */
static pthread_mutex_t build_lock = PTHREAD_MUTEX_INITIALIZER;

const char *cmd_jit_how(void)
{
    return how;
}

typedef struct jit {
    void *so;
    size_t (*state_size)(void);
    int (*nout)(void);
    int (*nx)(void);           /* the unknowns solved: x of jit_row */
    const char *const *(*names)(void);
    int (*row)(void *, const void *, double, double, double, int, double *, double *,
               double *);
} jit;

/* Why the options or the file keep the sweep with the interpreter, or
 * NULL. q0: the first driver position. A drawn file is assembled at its
 * drawing's driver value and followed from there to q0 (continuation.c
 * cont_start), which the generated code does not do. */
static const char *unsupported(const mech_model *m, const mech_solve_options *o, double q0)
{
    mech_solve_options d;
    mech_solve_options_default(&d);
    return m->has_start && m->start_q != q0 ? "a drawing's driver value other than the first"
           : o->outputs ? "--outputs"
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

/* ---- the private directory and the compiler, undone on a signal ---------
 * From mkdtemp to the directory's removal, SIGTERM, SIGINT and SIGHUP stop
 * the compiler's process group (SIGTERM, SIGKILL after a second), remove
 * the directory, then take the action they had before (src/output/output.c's
 * handler, which removes the outputs being written, or the default): mech
 * dies of the signal and leaves neither files nor a compiler behind. The
 * compiler runs in a process group of its own, so that it is stopped as a
 * whole (its driver and the cc1, as, ld it starts). One build at a time:
 * mech solve is one thread. */
enum { F_GEN, F_JIT, F_SO, F_ERR, JIT_FILES };
static const char *const jit_file_names[JIT_FILES] = {"gen.c", "jit.c", "jit.so", "cc.err"};
static const int guarded_signals[] = {SIGTERM, SIGINT, SIGHUP};

static struct {
    volatile sig_atomic_t live;      /* the directory exists: remove it */
    volatile sig_atomic_t compiler;  /* the compiler's pid, its process group too; 0: none */
    char dir[512];
    char files[JIT_FILES][600];      /* the directory's files, built before they exist */
    struct sigaction old[COUNT_OF(guarded_signals)];
    int installed[COUNT_OF(guarded_signals)];
} guard;

static void guarded_set(sigset_t *set)
{
    sigemptyset(set);
    for (size_t i = 0; i < COUNT_OF(guarded_signals); i++)
        sigaddset(set, guarded_signals[i]);
}

/* Async-signal-safe: SIGTERM to the compiler's group, a second for its
 * first process to end, then SIGKILL to what is left of the group. */
static void stop_compiler(pid_t pid)
{
    struct timespec tick = {0, 10000000};
    int reaped = 0;
    kill(-pid, SIGTERM);
    for (int i = 0; i < 100 && !reaped; i++) {
        pid_t w = waitpid(pid, NULL, WNOHANG);
        reaped = w == pid || (w < 0 && errno != EINTR);
        if (!reaped)
            nanosleep(&tick, NULL);
    }
    kill(-pid, SIGKILL);
    while (!reaped && waitpid(pid, NULL, 0) < 0 && errno == EINTR)
        ;
}

/* Async-signal-safe: the directory's files and the directory. */
static void remove_guarded_dir(void)
{
    if (!guard.live)
        return;
    for (int i = 0; i < JIT_FILES; i++)
        unlink(guard.files[i]);
    rmdir(guard.dir);
    guard.live = 0;
}

static void restore_actions(void)
{
    for (size_t i = 0; i < COUNT_OF(guarded_signals); i++)
        if (guard.installed[i])
            sigaction(guarded_signals[i], &guard.old[i], NULL);
}

static void on_guarded_signal(int sig)
{
    int e = errno;
    if (guard.compiler > 0)
        stop_compiler((pid_t)guard.compiler);
    remove_guarded_dir();
    restore_actions();
    errno = e;
    raise(sig);  /* blocked until the handler returns, then the former action's */
}

static void guard_begin(void)
{
    for (size_t i = 0; i < COUNT_OF(guarded_signals); i++) {
        struct sigaction sa;
        guard.installed[i] = 0;
        if (sigaction(guarded_signals[i], NULL, &guard.old[i]) != 0 ||
                guard.old[i].sa_handler == SIG_IGN)
            continue;  /* nohup: an ignored signal stays ignored */
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = on_guarded_signal;
        guarded_set(&sa.sa_mask);
        guard.installed[i] = sigaction(guarded_signals[i], &sa, NULL) == 0;
    }
}

/* The directory removed (the loaded object stays mapped), the former
 * actions back; a signal meanwhile waits for them. */
static void guard_end(void)
{
    sigset_t set, old;
    guarded_set(&set);
    pthread_sigmask(SIG_BLOCK, &set, &old);
    remove_guarded_dir();
    restore_actions();
    pthread_sigmask(SIG_SETMASK, &old, NULL);
}

/* mkdtemp in tmp, its file names set for the handler in the same step. */
static int guard_mkdtemp(const char *tmp)
{
    sigset_t set, old;
    guarded_set(&set);
    pthread_sigmask(SIG_BLOCK, &set, &old);
    snprintf(guard.dir, sizeof guard.dir, "%s/mech-jit.XXXXXX", tmp);
    int ok = mkdtemp(guard.dir) != NULL;
    for (int i = 0; ok && i < JIT_FILES; i++)
        snprintf(guard.files[i], sizeof guard.files[i], "%s/%s", guard.dir, jit_file_names[i]);
    guard.live = ok;
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    return ok ? 0 : -1;
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

/* The compiler's command line: $CC split on blanks (the compiler and its
 * own flags, no shell: no quoting, no expansion), then ours. */
enum { CC_MAX_WORDS = 32 };
typedef struct cc_command {
    char words[1024];  /* $CC with NULs for its blanks */
    char *argv[CC_MAX_WORDS + 9];
} cc_command;

static int cc_command_init(cc_command *c, const char *cc)
{
    static const char *const ours[] = {"-std=c11", "-O2", "-fPIC", "-shared", "-o"};
    if (strlen(cc) >= sizeof c->words)
        return -1;
    strcpy(c->words, cc);
    int n = 0;
    char *save = NULL;
    for (char *w = strtok_r(c->words, " \t\n", &save); w; w = strtok_r(NULL, " \t\n", &save)) {
        if (n == CC_MAX_WORDS)
            return -1;
        c->argv[n++] = w;
    }
    if (n == 0)
        c->argv[n++] = (char *)"cc";
    for (size_t i = 0; i < COUNT_OF(ours); i++)
        c->argv[n++] = (char *)ours[i];
    c->argv[n++] = guard.files[F_SO];
    c->argv[n++] = guard.files[F_JIT];
    c->argv[n++] = (char *)"-lm";
    c->argv[n] = NULL;
    return 0;
}

/* Start the compiler in its own process group, its output in cc.err: its
 * pid, or -1 with errno. The signals are blocked from the spawn until the
 * handler knows the pid. */
static pid_t spawn_compiler(cc_command *c)
{
    posix_spawn_file_actions_t fa;
    posix_spawnattr_t at;
    sigset_t set, old;
    pid_t pid = -1;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 1, guard.files[F_ERR], O_WRONLY | O_CREAT | O_TRUNC,
                                     0600);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    posix_spawnattr_init(&at);
    guarded_set(&set);
    pthread_sigmask(SIG_BLOCK, &set, &old);
    posix_spawnattr_setsigmask(&at, &old);
    posix_spawnattr_setpgroup(&at, 0);
    posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP | POSIX_SPAWN_SETSIGMASK);
    int e = posix_spawnp(&pid, c->argv[0], &fa, &at, c->argv, environ);
    if (e == 0)
        guard.compiler = pid;
    pthread_sigmask(SIG_SETMASK, &old, NULL);
    posix_spawnattr_destroy(&at);
    posix_spawn_file_actions_destroy(&fa);
    errno = e;
    return e == 0 ? pid : -1;
}

/* $CC, else cc. */
static const char *compiler_words(void)
{
    const char *cc = getenv("CC");
    return cc && *cc ? cc : "cc";
}

/* The compiler's file as "PATH bytes=N mtime=S.NS inode=I" (the program
 * $CC names, found in $PATH as posix_spawnp finds it), so that another
 * compiler, or the same one upgraded, makes another key. */
static void compiler_identity(const char *word, char *buf, size_t size)
{
    char path[1024];
    struct stat s;
    const char *dirs = strchr(word, '/') ? "" : getenv("PATH");
    snprintf(buf, size, "%s (not found)", word);
    for (const char *d = dirs ? dirs : "/usr/bin:/bin"; d;) {
        const char *end = strchr(d, ':');
        int len = end ? (int)(end - d) : (int)strlen(d);
        if (!strchr(word, '/'))
            snprintf(path, sizeof path, "%.*s/%s", len, len ? d : ".", word);
        else
            snprintf(path, sizeof path, "%s", word);
        if (stat(path, &s) == 0 && S_ISREG(s.st_mode) && access(path, X_OK) == 0) {
            snprintf(buf, size, "%.1000s bytes=%lld mtime=%lld.%09ld inode=%llu",
                     path, (long long)s.st_size,
                     (long long)s.st_mtim.tv_sec, s.st_mtim.tv_nsec,
                     (unsigned long long)s.st_ino);
            return;
        }
        d = end && !strchr(word, '/') ? end + 1 : NULL;
    }
}

/* What the compiled object depends on, as text (the cache's key): mech's
 * version, the compiler (its file and its command line but the
 * directory's paths), the generated source and the wrapper; NULL when it
 * cannot be read. */
static char *cache_key(const cc_command *c, size_t *n)
{
    char *text = NULL;
    FILE *f = open_memstream(&text, n);
    if (!f)
        return NULL;
    char id[1200];
    compiler_identity(c->argv[0], id, sizeof id);
    fprintf(f, "mech %s\ncompiler %s\ncommand", MECH_VERSION, id);
    for (int i = 0; c->argv[i]; i++)
        if (c->argv[i] != guard.files[F_SO] && c->argv[i] != guard.files[F_JIT])
            fprintf(f, " %s", c->argv[i]);
    fputs("\n", f);
    FILE *g = fopen(guard.files[F_GEN], "r");
    char buf[8192];
    for (size_t r; g && (r = fread(buf, 1, sizeof buf, g)) > 0;)
        fwrite(buf, 1, r, f);
    int bad = !g || ferror(g);
    if (g)
        fclose(g);
    for (int i = 0; wrapper[i]; i++)
        fprintf(f, "%s\n", wrapper[i]);
    bad |= ferror(f);
    bad |= fclose(f) != 0;
    if (bad) {
        free(text);
        return NULL;
    }
    return text;
}

/* Compile the directory's jit.c into jit.so with the command c: 0, or -1
 * with why (after "no C compiler ran") in note. */
static int compile(cc_command *cp, char *note, size_t size)
{
    const char *cc = compiler_words();
    char buf[128];
    pid_t pid = spawn_compiler(cp);
    if (pid < 0)
        return snprintf(note, size, "no C compiler ran ('%s': %s)", cp->argv[0],
                        diag_strerror(errno, buf, sizeof buf)), -1;
    int status = 0;
    pid_t w;
    while ((w = waitpid(pid, &status, 0)) < 0 && errno == EINTR)
        ;
    guard.compiler = 0;
    if (w == pid && WIFEXITED(status) && WEXITSTATUS(status) == 0)
        return 0;
    char msg[300];
    first_line(guard.files[F_ERR], msg, sizeof msg);
    if (msg[0])
        return snprintf(note, size, "no C compiler ran ('%s' failed: %s)", cc, msg), -1;
    if (w == pid && WIFSIGNALED(status))
        return snprintf(note, size, "no C compiler ran ('%s' was killed by signal %d)", cc,
                        WTERMSIG(status)), -1;
    return snprintf(note, size, "no C compiler ran ('%s' exited with status %d)", cc,
                    w == pid && WIFEXITED(status) ? WEXITSTATUS(status) : -1), -1;
}

/* What a build is of: model m with options o; with leaves (a sweep's
 * variants), the generated code reads their numbers (codegen_options). */
typedef struct jit_spec {
    const mech_model *m;
    const mech_solve_options *o;
    const sys_leaves *leaves;
    codegen *keep;             /* non-NULL: the code generator's analysis is kept here
                                  (codegen_numbers_fill), else freed */
} jit_spec;

/* Generate, compile and load the solver of sp in the private directory:
 * 0, or -1 with why in note. */
static int build_in_dir(jit *j, const jit_spec *sp, mech_solve_stats *st, int cached_only,
                        char *note, size_t size)
{
    codegen local, *g = sp->keep ? sp->keep : &local;
    mech_diag d;
    mech_diag_init(&d);
    const mech_solve_options *o = sp->o;
    codegen_options co = {"jit", NULL, o->all_blocks, o->forces, o->friction, 1, sp->leaves};
    int rc = codegen_init(g, sp->m, &co, &d);
    if (rc != MECH_OK) {
        snprintf(note, size, "the code generator: %s",
                 d.count > 0 ? d.entries[d.count - 1].message : "failed");
        codegen_free(g);
        mech_diag_free(&d);
        return -1;
    }
    mech_diag_free(&d);
    st->nunknowns = g->sp.n;  /* the plan's sizes, as mech_solve reports them */
    st->nsolved = g->sp.ns;
    st->nblocks = g->sp.nblocks;
    st->nblocks_solved = g->sp.nblocks_solved;
    rc = write_text(guard.files[F_GEN], g);
    if (!sp->keep)
        codegen_free(g);
    if (rc != 0 || write_text(guard.files[F_JIT], NULL) != 0)
        return snprintf(note, size, "cannot write the generated code in %s", guard.dir), -1;
    cc_command c;
    if (cc_command_init(&c, compiler_words()) != 0)
        return snprintf(note, size, "no C compiler ran ($CC has more than %d words or %zu "
                        "characters)", CC_MAX_WORDS, sizeof c.words - 1), -1;
    size_t klen = 0;
    char *key = cache_key(&c, &klen);
    char cached[600];
    jit_cache cache;
    jit_cache_open(&cache);
    int hit = key && jit_cache_find(&cache, key, klen, cached, sizeof cached);
    if (cached_only && !hit) {  /* --engine auto: a short run does not compile */
        jit_cache_close(&cache);
        free(key);
        return snprintf(note, size, "no compiled solver of this structure in the cache"), -2;
    }
    double t0 = clock_seconds();
    rc = hit ? 0 : compile(&c, note, size);
    if (rc == 0 && !hit) {
        int stored = key && jit_cache_put(&cache, key, klen, guard.files[F_SO]) == 0;
        snprintf(how, sizeof how, "compiled in %.2f s; %s%s", clock_seconds() - t0,
                 stored ? "stored in the cache " : "not cached: ",
                 stored ? cache.dir : cache.usable ? "cannot write the cache" : cache.why);
    } else if (hit) {
        snprintf(how, sizeof how, "from the cache, %s", cached);
    }
    jit_cache_close(&cache);
    free(key);
    if (rc != 0)
        return -1;
    j->so = dlopen(hit ? cached : guard.files[F_SO], RTLD_NOW | RTLD_LOCAL);
    if (!j->so)
        return snprintf(note, size, "dlopen: %s", dlerror()), -1;
    /* POSIX: dlsym's object pointer holds a function's address */
    void *f[5] = {dlsym(j->so, "jit_state_size"), dlsym(j->so, "jit_nout"),
                  dlsym(j->so, "jit_names"), dlsym(j->so, "jit_row"), dlsym(j->so, "jit_nx")};
    memcpy(&j->state_size, &f[0], sizeof f[0]);
    memcpy(&j->nout, &f[1], sizeof f[1]);
    memcpy(&j->names, &f[2], sizeof f[2]);
    memcpy(&j->row, &f[3], sizeof f[3]);
    memcpy(&j->nx, &f[4], sizeof f[4]);
    if (!j->state_size || !j->nout || !j->names || !j->row || !j->nx)
        return snprintf(note, size, "the shared object lacks its functions"), -1;
    return 0;
}

/* Build the solver of m in a private directory of $TMPDIR (else /tmp),
 * removed before returning, also on a signal meanwhile: 0, or -1 with why
 * in note (-2: cached_only and the cache has none). */
static int jit_build(jit *j, const jit_spec *sp, mech_solve_stats *st, int cached_only,
                     char *note, size_t size)
{
    const char *tmp = getenv("TMPDIR");
    if (!tmp || !*tmp || strlen(tmp) > 400)
        tmp = "/tmp";
    pthread_mutex_lock(&build_lock);
    guard_begin();
    int rc = guard_mkdtemp(tmp) == 0 ? build_in_dir(j, sp, st, cached_only, note, size)
             : (snprintf(note, size, "cannot make a temporary directory in %s", tmp), -1);
    guard_end();
    pthread_mutex_unlock(&build_lock);
    return rc;
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

/* One sweep by the loaded code: of model m's analysis a (the driver's
 * speed and acceleration are m's) at the positions q[nq]; num: a sweep
 * variant's numbers (codegen_numbers), or NULL. smp keeps the positions
 * the interpreter keeps for the assembly's checks (analysis_assembly_check). */
typedef struct jit_run {
    const jit *j;
    const void *num;
    const mech_model *m;
    const mech_analysis *a;
    const double *q;
    int nq;
    assembly_samples smp;
} jit_run;

static const char *row_failure(int rc)
{
    return rc < 0    ? "would take another step than the interpreter's continuation"
           : rc == 1 ? "found no assembly"
           : rc == 2 ? "found a singular position"
           : rc == 3 ? "found a branch condition false"
                     : "could not solve the forces";
}

static void row_stats(mech_solve_stats *st, const double *info, double q)
{
    st->iterations += (long)info[0];
    st->max_iterations = (int)info[0] > st->max_iterations ? (int)info[0] : st->max_iterations;
    st->worst_residual = fmax(st->worst_residual, info[1]);
    if (info[2] < st->min_rcond) {
        st->min_rcond = info[2];
        st->worst_rcond_q = q;
    }
    st->worst_power_residual = fmax(st->worst_power_residual, info[3]);
    if ((int)info[4] > st->max_friction_iterations)
        st->max_friction_iterations = (int)info[4];
}

/* The sweep r into t (its header already made): 0, or -1 with why in note
 * (t's rows are then to be discarded). A row with a value that is not
 * finite ends the sweep before it, as in the interpreter: *bad is its
 * index (else -1) and t holds the rows before it. */
static int jit_sweep(jit_run *r, mech_table *t, mech_solve_stats *st, int *bad, char *note,
                     size_t size)
{
    const jit *j = r->j;
    int nout = j->nout(), ns = analysis_solver_plan(r->a)->ns;
    const char *const *names = j->names();
    *bad = -1;
    if (nout != t->ncolumns)
        return snprintf(note, size, "the generated code has %d columns, mech solve %d", nout,
                        t->ncolumns), -1;
    if (j->nx() != ns)  /* x holds ns */
        return snprintf(note, size, "the generated code solves %d unknowns, mech solve %d",
                        j->nx(), ns), -1;
    for (int c = 0; c < nout; c++)
        if (strcmp(names[c], t->columns[c].name) != 0)
            return snprintf(note, size, "column %d is %s, mech solve's %s", c + 1, names[c],
                            t->columns[c].name), -1;
    void *s = calloc(1, j->state_size());
    double *x = xcalloc((size_t)ns + 1, sizeof *x);
    free(t->values);  /* the header's room for no rows */
    t->values = xcalloc((size_t)r->nq * (size_t)nout + 1, sizeof *t->values);
    int rc = !s || !x || !t->values || assembly_samples_init(&r->smp, ns, r->nq) != 0;
    if (rc)
        snprintf(note, size, "out of memory");
    double info[5];
    for (int i = 0; !rc && i < r->nq; i++) {
        double *out = t->values + (size_t)i * (size_t)nout;
        info[2] = st->min_rcond;
        double *keep = i >= r->smp.next_row ? x : NULL;  /* only the assembly's samples */
        rc = j->row(s, r->num, r->q[i], r->m->driver.speed, r->m->driver.accel, i == 0, out,
                    info, keep);
        if (rc != 0) {
            snprintf(note, size, "the generated code %s at row %d", row_failure(rc), i + 1);
            break;
        }
        if (analysis_check_finite(r->a, r->q[i], out, NULL) != MECH_OK) {
            *bad = i;  /* sweep.c's fill_row: the row is not added, the sweep stops */
            break;
        }
        if (keep)
            assembly_take(&r->smp, i, r->q[i], x);
        row_stats(st, info, r->q[i]);
        t->nrows = i + 1;
    }
    free(s);
    free(x);
    return rc ? -1 : 0;
}

long cmd_jit_auto_rows(void)
{
    const char *off = getenv("MECH_JIT_AUTO"), *rows = getenv("MECH_JIT_AUTO_ROWS");
    if (off && strcmp(off, "off") == 0)
        return -1;
    char *end;
    long n = rows && *rows ? strtol(rows, &end, 10) : 0;
    return rows && *rows && !*end && n > 0 ? n : 2000000;
}

/* --engine auto, a run of nq rows: 1 (why in how) to keep the
 * interpreter: options the generated code does not follow (opt, from
 * unsupported), or a run too short to pay for the compiler while the
 * cache holds no solver; 0 to go on. *worth: the run is long enough to
 * compile. */
static int auto_keeps_interpreter(const char *opt, long nq, int *worth)
{
    long at = cmd_jit_auto_rows();
    *worth = at > 0 && nq >= at;
    long hit_at = at / 100 > 1 ? at / 100 : 1;  /* loading a cached solver: about 3 ms */
    if (opt)
        return snprintf(how, sizeof how, "interpreted (auto: the compiled solver does not "
                        "follow %s)", opt), 1;
    if (at < 0)
        return snprintf(how, sizeof how, "interpreted (auto: MECH_JIT_AUTO=off)"), 1;
    jit_cache cache;
    jit_cache_open(&cache);
    int empty = jit_cache_empty(&cache);
    jit_cache_close(&cache);
    if (!*worth && (empty || nq < hit_at))
        return snprintf(how, sizeof how, "interpreted (auto: %ld rows, fewer than the %ld from "
                        "which compiling pays off%s)", nq, at, nq < hit_at ? ""
                        : "; no compiled solver in the cache"), 1;
    return 0;
}

int cmd_jit_solve(const mech_model *m, const mech_solve_options *o, mech_table *t,
                  mech_solve_stats *st, mech_diag *d, int engine, FILE *notes,
                  const char *who)
{
    char note[700] = "";
    int worth = 1, nq = 0, bad = -1, automatic = engine == CMD_ENGINE_AUTO;
    if (engine == CMD_ENGINE_INTERPRETED) {
        snprintf(how, sizeof how, "interpreted (--engine interpreted)");
        return mech_solve(m, o, t, st, d);
    }
    how[0] = '\0';
    double *q = positions(m, o, &nq);
    const char *opt = q ? unsupported(m, o, q[0]) : NULL;
    if (automatic && auto_keeps_interpreter(opt, nq, &worth)) {
        free(q);
        return mech_solve(m, o, t, st, d);
    }
    if (opt) {
        free(q);
        snprintf(how, sizeof how, "interpreted (--jit does not follow %s)", opt);
        fprintf(notes, "%s: note: --jit does not follow %s: the interpreter solves the "
                "sweep\n", who, opt);
        return mech_solve(m, o, t, st, d);
    }
    double t0 = clock_seconds();
    mech_analysis *a = NULL;
    mech_diag ad;  /* the analysis's notes: d's when the generated code solves */
    mech_diag_init(&ad);
    if (mech_analysis_new(m, o, &a, &ad) != MECH_OK) {
        snprintf(how, sizeof how, "interpreted (the analysis failed)");
        mech_diag_free(&ad);
        free(q);
        return mech_solve(m, o, t, st, d);  /* it says what is wrong */
    }
    jit j;
    memset(&j, 0, sizeof j);
    memset(st, 0, sizeof *st);
    st->min_rcond = INFINITY;  /* as the interpreter (sweep.c): row 0 sets it */
    st->failure_q = NAN;       /* no failure (a failing sweep is the interpreter's) */
    jit_spec spec = {m, o, NULL, NULL};
    int ok = q && jit_build(&j, &spec, st, automatic && !worth, note, sizeof note) == 0;
    double t1 = clock_seconds();
    jit_run run = {&j, NULL, m, a, q, nq, {0}};
    if (ok && mech_analysis_header(a, t) == MECH_OK) {
        t->nrequested = nq;
        ok = jit_sweep(&run, t, st, &bad, note, sizeof note) == 0;
    } else if (ok) {
        ok = 0;
        snprintf(note, sizeof note, "out of memory");
    }
    if (ok) {
        st->steps = t->nrows;
        st->seconds = clock_seconds() - t1;
        st->setup_seconds = t1 - t0;
    }
    for (size_t i = 0; ok && i < ad.count; i++)  /* warnings and notes: it was built */
        diag_copy(d, &ad.entries[i]);
    mech_diag_free(&ad);
    /* the interpreter's error for the row that is not finite, after its notes,
       then the assembly's warnings */
    int status = ok && bad >= 0
                 ? analysis_check_finite(a, q[bad], t->values + (size_t)bad * (size_t)t->ncolumns, d)
                 : MECH_OK;
    if (ok && analysis_assembly_check(a, &run.smp, d) != 0)
        status = diag_nomem(d, m->file, (mech_mark){0, 0});
    assembly_samples_free(&run.smp);
    free(q);
    if (j.so)
        dlclose(j.so);
    mech_analysis_free(&a);
    if (ok) {
        char built[sizeof how];
        snprintf(built, sizeof built, "%s", how);
        snprintf(how, sizeof how, "compiled (%s%.660s)", automatic ? "auto: " : "", built);
        return status;
    }
    mech_table_free(t);
    memset(t, 0, sizeof *t);
    if (automatic && !worth) {  /* a short run: the cache had none, or it cannot */
        snprintf(how, sizeof how, "interpreted (auto: %d rows, fewer than the %ld from which "
                 "compiling pays off; %.400s)", nq, cmd_jit_auto_rows(), note);
        return mech_solve(m, o, t, st, d);
    }
    snprintf(how, sizeof how, "interpreted (%s: %.600s)", automatic ? "auto" : "--jit", note);
    fprintf(notes, "%s: note: %s: %s; the interpreter solves the sweep\n", who,
            automatic ? "the compiled solver" : "--jit", note);
    return mech_solve(m, o, t, st, d);
}

/* ---- one compiled solver for a sweep's variants (mech sweep) ------------- */

struct cmd_jit_variants {
    sweep_engine ops;          /* what mech_sweep_run calls (sweep_set_engine) */
    pthread_mutex_t lock;
    int engine;                /* CMD_ENGINE_AUTO or CMD_ENGINE_COMPILED */
    long variants;             /* in this run */
    FILE *notes;
    int decided, ready;        /* the first variant decided; the solver is loaded */
    jit j;
    codegen g;                 /* the solver's analysis (codegen_numbers_fill) */
    char how[700];
    atomic_long compiled, interpreted;
};

/* The first variant through the base decides, for all: compiled when the
 * sweep's rows in all pay for it (as cmd_jit_solve, the rows of every
 * variant), the base built with its leaves into one solver that reads each
 * variant's numbers. Under v->lock. */
static void variants_decide(cmd_jit_variants *v, const variant_base *b, const mech_analysis *view)
{
    int nq = 0, worth = 1, automatic = v->engine == CMD_ENGINE_AUTO;
    const double *q = analysis_positions(view, &nq);
    const mech_model *m = vbase_model(b);
    mech_solve_options o;
    mech_solve_options_default(&o);
    o.forces = vbase_forces(b);
    const char *opt = nq > 0 ? unsupported(m, &o, q[0]) : NULL;
    v->decided = 1;
    if (automatic && auto_keeps_interpreter(opt, v->variants * nq, &worth)) {
        snprintf(v->how, sizeof v->how, "%s", how);
        return;
    }
    if (opt) {
        snprintf(v->how, sizeof v->how, "interpreted (--engine compiled does not follow %s)",
                 opt);
        fprintf(v->notes, "mech sweep: note: --engine compiled does not follow %s: the "
                "interpreter solves the variants\n", opt);
        return;
    }
    char note[700] = "";
    mech_solve_stats st;
    memset(&st, 0, sizeof st);
    jit_spec spec = {m, &o, vbase_leaves(b), &v->g};
    v->ready = jit_build(&v->j, &spec, &st, automatic && !worth, note, sizeof note) == 0;
    char built[sizeof how];
    snprintf(built, sizeof built, "%s", v->ready ? how : note);
    snprintf(v->how, sizeof v->how, "%s (%s%.640s)", v->ready ? "compiled" : "interpreted",
             automatic ? "auto: " : "", built);
    if (!v->ready && !(automatic && !worth))
        fprintf(v->notes, "mech sweep: note: the compiled solver: %s; the interpreter solves "
                "the variants\n", note);
}

/* sweep_engine.solve: variant mv through view by the compiled solver, or
 * VBASE_INTERPRET where it cannot follow the interpreter's rows (the
 * interpreter then solves that variant, and says what it finds). */
static int variants_solve(void *ctx, const variant_base *b, const mech_analysis *view,
                          const mech_model *mv, mech_table *t, mech_diag *d)
{
    cmd_jit_variants *v = ctx;
    pthread_mutex_lock(&v->lock);
    if (!v->decided)
        variants_decide(v, b, view);
    pthread_mutex_unlock(&v->lock);
    codegen_numbers num;
    if (!v->ready || codegen_numbers_fill(&v->g, view, mv, &num) != 0) {
        atomic_fetch_add(&v->interpreted, 1);
        return VBASE_INTERPRET;
    }
    mech_solve_stats st;
    memset(&st, 0, sizeof st);
    st.min_rcond = INFINITY;
    int nq = 0, bad = -1;
    const double *q = analysis_positions(view, &nq);
    jit_run run = {&v->j, &num.n, mv, view, q, nq, {0}};
    char note[200];
    int ok = mech_analysis_header(view, t) == MECH_OK &&
             jit_sweep(&run, t, &st, &bad, note, sizeof note) == 0 && bad < 0;
    codegen_numbers_free(&num);
    if (ok) {
        t->nrequested = nq;
        ok = analysis_assembly_check(view, &run.smp, d) == 0;
    }
    assembly_samples_free(&run.smp);
    if (!ok) {  /* the interpreter's rows, errors and notes instead */
        mech_table_free(t);
        memset(t, 0, sizeof *t);
        atomic_fetch_add(&v->interpreted, 1);
        return VBASE_INTERPRET;
    }
    atomic_fetch_add(&v->compiled, 1);
    return MECH_OK;
}

cmd_jit_variants *cmd_jit_variants_new(int engine, long variants, FILE *notes)
{
    cmd_jit_variants *v = xcalloc(1, sizeof *v);
    if (!v)
        return NULL;
    v->ops = (sweep_engine){variants_solve, v};
    pthread_mutex_init(&v->lock, NULL);
    v->engine = engine;
    v->variants = variants;
    v->notes = notes;
    snprintf(v->how, sizeof v->how, "interpreted (no variant went through the sweep's one "
             "analysis)");
    return v;
}

const sweep_engine *cmd_jit_variants_engine(cmd_jit_variants *v) { return &v->ops; }

const char *cmd_jit_variants_how(cmd_jit_variants *v, long *compiled, long *interpreted)
{
    *compiled = atomic_load(&v->compiled);
    *interpreted = atomic_load(&v->interpreted);
    return v->how;
}

void cmd_jit_variants_free(cmd_jit_variants **pv)
{
    cmd_jit_variants *v = pv ? *pv : NULL;
    if (!v)
        return;
    if (v->j.so)
        dlclose(v->j.so);
    codegen_free(&v->g);
    pthread_mutex_destroy(&v->lock);
    free(v);
    *pv = NULL;
}
