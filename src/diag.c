/* src/diag.c: collect diagnostics as "file:line:col: severity: message". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"

const char *diag_strerror(int e, char *buf, size_t size)
{
    if (strerror_r(e, buf, size) != 0)  /* the POSIX (int) strerror_r */
        snprintf(buf, size, "error %d", e);
    return buf;
}

void mech_diag_init(mech_diag *d)
{
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

static void record(mech_diag *d, mech_severity sev, const char *file,
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
    record(d, MECH_SEV_ERROR, file, at, fmt, ap);
    va_end(ap);
    return MECH_EINPUT;
}

void diag_warning(mech_diag *d, const char *file, mech_mark at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    record(d, MECH_SEV_WARNING, file, at, fmt, ap);
    va_end(ap);
}

void diag_note(mech_diag *d, const char *file, mech_mark at, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    record(d, MECH_SEV_NOTE, file, at, fmt, ap);
    va_end(ap);
}

void mech_diag_print(const mech_diag *d, FILE *out)
{
    static const char *const sev_name[] = {"error", "warning", "note"};
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
