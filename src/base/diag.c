/* src/base/diag.c: collect diagnostics as "file:line:col: severity: message". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"

const char *diag_strerror(int e, char *buf, size_t size)
{
    if (strerror_r(e, buf, size) != 0)  /* the POSIX (int) strerror_r */
        snprintf(buf, size, "error %d", e);
    return buf;
}

void mech_diag_init(mech_diag *d)
{
    if (!d)
        return;
    memset(d, 0, sizeof *d);
    d->max_errors = 100;
}

void mech_diag_free(mech_diag *d)
{
    if (!d)
        return;
    for (size_t i = 0; i < d->count; i++) {
        free(d->entries[i].file);
        free(d->entries[i].message);
    }
    free(d->entries);
    size_t max = d->max_errors;
    memset(d, 0, sizeof *d);
    d->max_errors = max;
}

/* Each kind's fixed name, the words its messages state it in, the library
 * status it fails with, mech sweep's status of the variant, and how
 * grave it is when several are found (mech_diag_failure): 3 out of memory
 * (what follows may be its consequence), 2 stops the sweep, 1 singular, 0
 * the others. */
static const struct fail_info {
    const char *name;
    const char *words;
    int status;
    mech_variant_status variant;
    int rank;
} fail_table[] = {
    [MECH_FAIL_NONE] = {"none", "", MECH_OK, MECH_VARIANT_OK, -1},
    [MECH_FAIL_INPUT] = {"input", "", MECH_EINPUT, MECH_VARIANT_INVALID, 0},
    [MECH_FAIL_IO] = {"io", "", MECH_EIO, MECH_VARIANT_ERROR, 0},
    [MECH_FAIL_NOMEM] = {"no-memory", "out of memory", MECH_ENOMEM, MECH_VARIANT_ERROR, 3},
    [MECH_FAIL_NO_ASSEMBLY] = {"no-assembly", "cannot assemble", MECH_ESOLVE,
                               MECH_VARIANT_NO_ASSEMBLY, 0},
    [MECH_FAIL_DEAD_POINT] = {"dead-point", "a dead point, toggle or limit position",
                              MECH_ESOLVE, MECH_VARIANT_SINGULAR, 1},
    [MECH_FAIL_CHANGE_POINT] = {"change-point", "a change point, where two assembly branches "
                                "cross", MECH_ESOLVE, MECH_VARIANT_SINGULAR, 1},
    [MECH_FAIL_BRANCH] = {"branch", "leaves the declared assembly branch", MECH_ESOLVE,
                          MECH_VARIANT_NO_ASSEMBLY, 0},
    [MECH_FAIL_JUMP] = {"jump", "the solution jumps", MECH_ESOLVE, MECH_VARIANT_NO_ASSEMBLY, 0},
    [MECH_FAIL_REDUNDANT] = {"redundant", "redundant constraints", MECH_ESOLVE,
                             MECH_VARIANT_SINGULAR, 1},
    [MECH_FAIL_NOT_CONVERGED] = {"not-converged", "does not converge", MECH_ESOLVE,
                                 MECH_VARIANT_SELF_LOCKING, 2},
    [MECH_FAIL_NON_FINITE] = {"non-finite", "not a finite number", MECH_ESOLVE,
                              MECH_VARIANT_NON_FINITE, 2},
    [MECH_FAIL_FAR_FROM_GUESS] = {"far-from-guess", "far from the guess", MECH_ESOLVE,
                                  MECH_VARIANT_NO_ASSEMBLY, 0},
    [MECH_FAIL_ON_GROUND_POINT] = {"on-ground-point", "stays on a ground point", MECH_ESOLVE,
                                   MECH_VARIANT_NO_ASSEMBLY, 0},
    [MECH_FAIL_STILL_SLIDER] = {"still-slider", "does not slide", MECH_ESOLVE,
                                MECH_VARIANT_NO_ASSEMBLY, 0},
    [MECH_FAIL_FOLDED_LOOP] = {"folded-loop", "folded onto each other", MECH_ESOLVE,
                               MECH_VARIANT_NO_ASSEMBLY, 0},
    [MECH_FAIL_STILL_OUTPUTS] = {"still-outputs", "moves none of the outputs", MECH_ESOLVE,
                                 MECH_VARIANT_NO_ASSEMBLY, 0},
};

static const struct fail_info *fail_info_of(mech_fail_kind k)
{
    return (unsigned)k < COUNT_OF(fail_table) ? &fail_table[k] : NULL;
}

const char *mech_fail_name(mech_fail_kind k)
{
    const struct fail_info *f = fail_info_of(k);
    return f ? f->name : "unknown";
}

int fail_is_suspect_assembly(mech_fail_kind k)
{
    return k >= MECH_FAIL_FAR_FROM_GUESS && k <= MECH_FAIL_STILL_OUTPUTS;  /* appended together */
}

const char *fail_words(mech_fail_kind k)
{
    const struct fail_info *f = fail_info_of(k);
    return f ? f->words : "";
}

mech_variant_status fail_variant_status(mech_fail_kind k)
{
    const struct fail_info *f = fail_info_of(k);
    return f ? f->variant : MECH_VARIANT_ERROR;
}

const char *mech_variant_status_name(mech_variant_status s)
{
    static const char *const names[] = {  /* ORDER mech_variant_status */
        "ok", "no-assembly", "singular", "self-locking", "invalid", "error", "non-finite"};
    return (unsigned)s < COUNT_OF(names) ? names[s] : "error";
}

int fail_kind_status(mech_fail_kind k)
{
    const struct fail_info *f = fail_info_of(k);
    return f ? f->status : MECH_ESOLVE;
}

mech_fail_kind fail_of_status(int status)
{
    return status == MECH_OK ? MECH_FAIL_NONE
           : status == MECH_EINPUT ? MECH_FAIL_INPUT
           : status == MECH_ENOMEM ? MECH_FAIL_NOMEM
           : status == MECH_EIO ? MECH_FAIL_IO : MECH_FAIL_NO_ASSEMBLY;
}

mech_fail_kind fail_graver(mech_fail_kind now, mech_fail_kind found)
{
    const struct fail_info *a = fail_info_of(now), *b = fail_info_of(found);
    if (!b || found == MECH_FAIL_NONE)
        return now;
    return !a || now == MECH_FAIL_NONE || b->rank > a->rank ? found : now;
}

mech_fail_kind diag_failure_since(const mech_diag *d, size_t first)
{
    mech_fail_kind k = MECH_FAIL_NONE;
    for (size_t i = first; d && i < d->count; i++)
        if (d->entries[i].severity == MECH_SEV_ERROR)
            k = fail_graver(k, d->entries[i].kind);
    return k;
}

int diag_status_since(const mech_diag *d, size_t first, int otherwise)
{
    mech_fail_kind k = diag_failure_since(d, first);
    return k == MECH_FAIL_NONE ? otherwise : fail_kind_status(k);
}

mech_fail_kind mech_diag_failure(const mech_diag *d)
{
    return diag_failure_since(d, 0);
}

static void record(mech_diag *d, mech_severity sev, mech_fail_kind kind, const char *file,
                   mech_mark at, const char *fmt, va_list ap)
{
    if (!d)
        return;
    size_t max = d->max_errors ? d->max_errors : 100;
    if (sev == MECH_SEV_ERROR)
        d->nerrors++;
    if (d->nerrors > max) {  /* keep counting, stop storing */
        d->truncated = 1;
        return;
    }
    if (d->count == d->capacity) {
        size_t cap = d->capacity ? 2 * d->capacity : 16;
        mech_diag_entry *e = xrealloc_array(d->entries, cap, sizeof *e);
        if (!e)
            return;
        d->entries = e;
        d->capacity = cap;
    }
    char buf[1024];
    vsnprintf(buf, sizeof buf, fmt, ap);
    mech_diag_entry *e = &d->entries[d->count];
    e->severity = sev;
    e->kind = kind;
    e->file = xstrdup(file ? file : "<input>");
    e->mark = at;
    e->message = xstrdup(buf);
    if (!e->file || !e->message) {
        free(e->file);
        free(e->message);
        return;
    }
    d->count++;
}

int diag_error(mech_diag *d, const char *file, mech_mark at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    record(d, MECH_SEV_ERROR, MECH_FAIL_INPUT, file, at, fmt, ap);
    va_end(ap);
    return MECH_EINPUT;
}

int diag_fail(mech_diag *d, mech_fail_kind kind, const char *file, mech_mark at,
              const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    record(d, MECH_SEV_ERROR, kind, file, at, fmt, ap);
    va_end(ap);
    return fail_kind_status(kind);
}

int diag_nomem(mech_diag *d, const char *file, mech_mark at)
{
    return diag_fail(d, MECH_FAIL_NOMEM, file, at, "%s", fail_words(MECH_FAIL_NOMEM));
}

void diag_warning(mech_diag *d, const char *file, mech_mark at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    record(d, MECH_SEV_WARNING, MECH_FAIL_NONE, file, at, fmt, ap);
    va_end(ap);
}

void diag_note(mech_diag *d, const char *file, mech_mark at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    record(d, MECH_SEV_NOTE, MECH_FAIL_NONE, file, at, fmt, ap);
    va_end(ap);
}

void diag_add(mech_diag *d, mech_severity sev, mech_fail_kind kind, const char *file,
              mech_mark at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    record(d, sev, kind, file, at, fmt, ap);
    va_end(ap);
}

void diag_copy(mech_diag *d, const mech_diag_entry *e)
{
    diag_add(d, e->severity, e->kind, e->file, e->mark, "%s", e->message);
}

void mech_diag_print(const mech_diag *d, FILE *out)
{
    static const char *const sev_name[] = {"error", "warning", "note"};
    if (!d)
        return;
    if (!out)
        out = stderr;
    for (size_t i = 0; i < d->count; i++) {
        const mech_diag_entry *e = &d->entries[i];
        if (e->mark.line > 0)
            fprintf(out, "%s:%d:%d: %s: %s\n", e->file, e->mark.line, e->mark.col,
                    sev_name[e->severity], e->message);
        else
            fprintf(out, "%s: %s: %s\n", e->file, sev_name[e->severity], e->message);
    }
    if (d->truncated)
        fprintf(out, "(%zu errors in all; only the first %zu are shown)\n", d->nerrors,
                d->max_errors ? d->max_errors : (size_t)100);
}
