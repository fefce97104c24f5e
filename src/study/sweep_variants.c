/* src/study/sweep_variants.c: one variant of a sweep (mech_sweep_run, in
 * sweep_run.c, calls sweep_variant_solve from its worker threads): the file
 * is read and its YAML parsed once per sweep (the document is shared, read
 * only, by every variant and thread); each variant builds its model from the parsed
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

#include "base.h"
#include "study.h"

/* One sweep's shared parts: its file parsed once (NULL when it could not
 * be read: every variant then loads the file itself and reports why, as
 * before), and the analysed base built by its first variant (its varied
 * names and forces flag; NULL: the variants are analysed alone). */
enum { MAX_BASE_NAMES = 64 };
struct sweep_shared {
    char *path;
    int forces;
    pthread_mutex_t lock;
    int read_tried, base_tried;
    load_doc *doc;
    char *names[MAX_BASE_NAMES];
    int nnames;
    variant_base *base;
    const sweep_engine *engine;  /* NULL: the interpreter */
    atomic_long count_shared, count_alone;
};

sweep_shared *sweep_shared_new(const char *file, int with_forces)
{
    sweep_shared *sh = xcalloc(1, sizeof *sh);
    if (!sh || !(sh->path = xstrdup(file))) {
        free(sh);
        return NULL;
    }
    sh->forces = with_forces;
    pthread_mutex_init(&sh->lock, NULL);
    return sh;
}

void sweep_shared_free(sweep_shared **shp)
{
    sweep_shared *sh = *shp;
    if (!sh)
        return;
    vbase_free(&sh->base);
    for (int i = 0; i < sh->nnames; i++)
        free(sh->names[i]);
    load_doc_free(&sh->doc);
    pthread_mutex_destroy(&sh->lock);
    free(sh->path);
    free(sh);
    *shp = NULL;
}

static int same_names(const sweep_shared *sh, const mech_override *ov, int nov)
{
    if (nov != sh->nnames)
        return 0;
    for (int i = 0; i < nov; i++)
        if (strcmp(ov[i].name, sh->names[i]) != 0)
            return 0;
    return 1;
}

static const load_doc *document_of(sweep_shared *sh);

/* The base for these names: built by the first variant (from the file's
 * own parameter values), then shared by those with the same names. */
static const variant_base *base_of(sweep_shared *sh, const mech_override *ov, int nov)
{
    const load_doc *doc = document_of(sh);
    const variant_base *b = NULL;
    if (!doc || nov > MAX_BASE_NAMES || getenv("MECH_SWEEP_REANALYSE"))
        return NULL;
    pthread_mutex_lock(&sh->lock);
    if (!sh->base_tried) {
        sh->base_tried = 1;
        mech_diag quiet;  /* no base: every variant is analysed alone, as before */
        mech_diag_init(&quiet);
        mech_model *m = NULL;
        mech_summary sum;
        const char *names[MAX_BASE_NAMES];
        int ok = 1;
        for (int i = 0; i < nov && ok; i++) {
            names[i] = sh->names[i] = xstrdup(ov[i].name);
            ok = names[i] != NULL;
            sh->nnames += ok;
        }
        if (ok && load_doc_model(doc, NULL, 0, &m, &quiet) == MECH_OK &&
            mech_check(m, &sum, &quiet) == MECH_OK &&
            vbase_new(m, names, nov, sh->forces, &sh->base, &quiet) == MECH_OK)
            m = NULL;  /* the base's */
        mech_model_free(&m);
        mech_diag_free(&quiet);
    }
    if (sh->base && same_names(sh, ov, nov))
        b = sh->base;
    pthread_mutex_unlock(&sh->lock);
    return b;
}

void sweep_shared_set_engine(sweep_shared *sh, const sweep_engine *e) { sh->engine = e; }

void sweep_variant_counts(const sweep_shared *sh, long *shared, long *alone)
{
    *shared = atomic_load(&sh->count_shared);
    *alone = atomic_load(&sh->count_alone);
}

/* The messages of d (a solve through the base) appended to out, with their
 * severities and kinds. */
static void append_diag(mech_diag *out, const mech_diag *d)
{
    for (size_t i = 0; i < d->count; i++)
        diag_copy(out, &d->entries[i]);
}

static const load_doc *document_of(sweep_shared *sh)
{
    pthread_mutex_lock(&sh->lock);
    if (!sh->read_tried) {
        sh->read_tried = 1;
        mech_diag quiet;  /* a problem is reported by each variant's own load */
        mech_diag_init(&quiet);
        if (getenv("MECH_SWEEP_REPARSE") || load_doc_read(sh->path, &sh->doc, &quiet) != MECH_OK)
            load_doc_free(&sh->doc);
        mech_diag_free(&quiet);
    }
    const load_doc *doc = sh->doc;
    pthread_mutex_unlock(&sh->lock);
    return doc;
}

int sweep_variant_solve(sweep_shared *sh, const mech_override *ov, int nov, mech_table *t,
                        mech_model **model, mech_diag *d)
{
    const char *file = sh->path;
    const load_doc *doc = document_of(sh);
    mech_model *m = NULL;
    mech_summary sum;
    int rc = doc ? load_doc_numbers(doc, ov, nov, &m, d) : mech_load_file_with(file, ov, nov, &m, d);
    if (rc == MECH_OK)
        rc = mech_check(m, &sum, d);
    const variant_base *b = rc == MECH_OK ? base_of(sh, ov, nov) : NULL;
    int shared = 0;
    if (b) {  /* through the shared analysis; re-analysed when it cannot be, or fails */
        mech_diag local;
        mech_diag_init(&local);
        int rs = vbase_solve(b, m, sh->engine, t, &local);
        if ((shared = rs == MECH_OK))
            append_diag(d, &local);
        else
            mech_table_free(t);
        mech_diag_free(&local);
    }
    if (shared)
        atomic_fetch_add(&sh->count_shared, 1);
    else if (rc == MECH_OK)
        atomic_fetch_add(&sh->count_alone, 1);
    if (rc == MECH_OK && !shared) {
        mech_solve_options o;
        mech_solve_options_default(&o);
        o.forces = sh->forces;
        rc = mech_solve(m, &o, t, NULL, d);
    }
    if (model)
        *model = m;  /* the caller's now, also when NULL or not solved */
    else
        mech_model_free(&m);
    return rc;
}
