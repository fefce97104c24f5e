/* src/sweep_variants.c: one variant of `mech sweep` (cmd_sweep.c calls
 * sweep_variant_solve from its worker threads): the file is read and its
 * YAML parsed once per process (the document is shared, read only, by
 * every variant and thread); each variant builds its model from the parsed
 * document with its parameter replacements and checks it. The file's own
 * model is analysed once with the varied parameters' lengths and angles as
 * registers (variant_regs.c), and a variant of the same structure is
 * solved through that analysis; one that is not (or fails there) is
 * analysed on its own. What a variant still repeats, and why, is in
 * docs/batch.md ("What a variant costs", "One analysis per sweep"). */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "sweep_variants.h"
#include "variant_regs.h"

/* The parsed document of the first file asked for (a sweep has one), kept
 * until the process exits; NULL when it could not be read: every variant
 * then loads the file itself and reports why, as before. */
static struct {
    pthread_mutex_t lock;
    int tried;
    char *path;
    load_doc *doc;
} cache = {PTHREAD_MUTEX_INITIALIZER, 0, NULL, NULL};

static void release_cache(void)
{
    load_doc_free(&cache.doc);
    free(cache.path);
    cache.path = NULL;
}

/* The analysed base of the first sweep asked for (one file, one set of
 * varied names, one forces flag), or NULL: variants then analysed alone. */
enum { MAX_BASE_NAMES = 64 };
static struct {
    pthread_mutex_t lock;
    int tried;
    char *names[MAX_BASE_NAMES];
    int nnames, forces;
    variant_base *base;
} fast = {PTHREAD_MUTEX_INITIALIZER, 0, {NULL}, 0, 0, NULL};

static atomic_long count_shared, count_alone;

static void release_fast(void)
{
    vbase_free(&fast.base);
    for (int i = 0; i < fast.nnames; i++)
        free(fast.names[i]);
    fast.nnames = 0;
}

static int same_names(const mech_override *ov, int nov)
{
    if (nov != fast.nnames)
        return 0;
    for (int i = 0; i < nov; i++)
        if (strcmp(ov[i].name, fast.names[i]) != 0)
            return 0;
    return 1;
}

static const load_doc *document_of(const char *path);

/* The base for this file, these names and forces: built by the first
 * variant (from the file's own parameter values), then shared. */
static const variant_base *base_of(const char *path, const mech_override *ov, int nov, int forces)
{
    const load_doc *doc = document_of(path);
    const variant_base *b = NULL;
    if (!doc || nov > MAX_BASE_NAMES || getenv("MECH_SWEEP_REANALYSE"))
        return NULL;
    pthread_mutex_lock(&fast.lock);
    if (!fast.tried) {
        fast.tried = 1;
        mech_diag quiet;  /* no base: every variant is analysed alone, as before */
        mech_diag_init(&quiet);
        mech_model *m = NULL;
        mech_summary sum;
        const char *names[MAX_BASE_NAMES];
        int ok = 1;
        for (int i = 0; i < nov && ok; i++) {
            names[i] = fast.names[i] = xstrdup(ov[i].name);
            ok = names[i] != NULL;
            fast.nnames += ok;
        }
        fast.forces = forces;
        if (ok && load_doc_model(doc, NULL, 0, &m, &quiet) == MECH_OK &&
            mech_check(m, &sum, &quiet) == MECH_OK &&
            vbase_new(m, names, nov, forces, &fast.base, &quiet) == MECH_OK)
            m = NULL;  /* the base's */
        mech_model_free(&m);
        mech_diag_free(&quiet);
        atexit(release_fast);
    }
    if (fast.base && forces == fast.forces && same_names(ov, nov) &&
        strcmp(vbase_model(fast.base)->file, path) == 0)
        b = fast.base;
    pthread_mutex_unlock(&fast.lock);
    return b;
}

void sweep_variant_counts(long *shared, long *alone)
{
    *shared = atomic_load(&count_shared);
    *alone = atomic_load(&count_alone);
}

/* The messages of d (a solve through the base) appended to out. */
static void append_diag(mech_diag *out, const mech_diag *d)
{
    for (size_t i = 0; i < d->count; i++) {
        const mech_diag_entry *e = &d->entries[i];
        if (e->severity == MECH_SEV_ERROR)
            diag_error(out, e->file, e->mark, "%s", e->message);
        else if (e->severity == MECH_SEV_WARNING)
            diag_warning(out, e->file, e->mark, "%s", e->message);
        else
            diag_note(out, e->file, e->mark, "%s", e->message);
    }
}

static const load_doc *document_of(const char *path)
{
    const load_doc *doc = NULL;
    pthread_mutex_lock(&cache.lock);
    if (!cache.tried) {
        cache.tried = 1;
        mech_diag quiet;  /* a problem is reported by each variant's own load */
        mech_diag_init(&quiet);
        if (!getenv("MECH_SWEEP_REPARSE") &&
            load_doc_read(path, &cache.doc, &quiet) == MECH_OK &&
            (cache.path = xstrdup(path)) != NULL)
            atexit(release_cache);
        else
            load_doc_free(&cache.doc);
        mech_diag_free(&quiet);
    }
    if (cache.doc && strcmp(cache.path, path) == 0)
        doc = cache.doc;
    pthread_mutex_unlock(&cache.lock);
    return doc;
}

int sweep_variant_solve(const char *file, const mech_override *ov, int nov, int forces,
                        mech_table *t, mech_model **model, mech_diag *d)
{
    const load_doc *doc = document_of(file);
    mech_model *m = NULL;
    mech_summary sum;
    int rc = doc ? load_doc_model(doc, ov, nov, &m, d) : mech_load_file_with(file, ov, nov, &m, d);
    if (rc == MECH_OK)
        rc = mech_check(m, &sum, d);
    const variant_base *b = rc == MECH_OK ? base_of(file, ov, nov, forces) : NULL;
    int shared = 0;
    if (b) {  /* through the shared analysis; re-analysed when it cannot be, or fails */
        mech_diag local;
        mech_diag_init(&local);
        int rs = vbase_solve(b, m, t, &local);
        if ((shared = rs == MECH_OK))
            append_diag(d, &local);
        else
            mech_table_free(t);
        mech_diag_free(&local);
    }
    if (shared)
        atomic_fetch_add(&count_shared, 1);
    else if (rc == MECH_OK)
        atomic_fetch_add(&count_alone, 1);
    if (rc == MECH_OK && !shared) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.forces = forces;
        rc = mech_solve(m, &o, t, NULL, d);
    }
    if (model)
        *model = m;  /* the caller's now, also when NULL or not solved */
    else
        mech_model_free(&m);
    return rc;
}
