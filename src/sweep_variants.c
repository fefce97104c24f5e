/* src/sweep_variants.c: one variant of `mech sweep` (cmd_sweep.c calls
 * sweep_variant_solve from its worker threads): the file is read and its
 * YAML parsed once per process (the document is shared, read only, by
 * every variant and thread); each variant builds its model from the parsed
 * document with its parameter replacements, checks it, analyses it and
 * solves it. What a variant still repeats, and why, is in docs/batch.md
 * ("What a variant costs"). */
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "sweep_variants.h"

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
    if (rc == MECH_OK) {
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
