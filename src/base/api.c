/* src/base/api.c: the public API's version, the options' size-checked init and
 * the helpers of the entry points' argument checks (src/base/base.h; the rules
 * are in include/mech.h and docs/api.md, section "Versions and the ABI"). */
#include <stddef.h>
#include <string.h>

#include "base.h"

const char *mech_version(void) { return MECH_VERSION; }

mech_diag *api_diag(mech_diag *d, mech_diag *own)
{
    if (d)
        return d;
    mech_diag_init(own);
    return own;
}

void api_diag_end(const mech_diag *d, mech_diag *own)
{
    if (!d)
        mech_diag_free(own);
}

int api_null(mech_diag *d, const char *func, const char *arg)
{
    return diag_error(d, func, (mech_mark){0, 0}, "%s is NULL, and it may not be (include/mech.h)",
                      arg);
}

int api_overrides(const char *func, const mech_override *ov, int nov, mech_diag *d)
{
    if (nov < 0 || (nov > 0 && !ov))
        return diag_error(d, func, (mech_mark){0, 0}, "ov is NULL or nov (%d) is negative: "
                          "give nov replacements, or NULL and 0", nov);
    for (int i = 0; i < nov; i++)
        if (!ov[i].name || !ov[i].text)
            return diag_error(d, func, (mech_mark){0, 0}, "replacement %d has a NULL %s", i,
                              ov[i].name ? "text" : "name");
    return MECH_OK;
}

/* The sizes of mech_solve_options the library accepts: its own, and once
 * fields are appended, each released layout before it, given by where it
 * ends (its last field's offset and size; the struct's alignment rounds it
 * up as the compiler does). None yet: 0.2 is the first layout with a size.
 * When 0.3 appends a field, this list gets 0.2's end:
 *     offsetof(mech_solve_options, limit_rows) + sizeof(int) */
static const size_t older_layout_ends[] = {0};

static int options_size_known(size_t size)
{
    const size_t align = _Alignof(mech_solve_options);
    if (size == sizeof(mech_solve_options))
        return 1;
    for (size_t i = 0; i < COUNT_OF(older_layout_ends); i++)
        if (older_layout_ends[i] > 0 && (older_layout_ends[i] + align - 1) / align * align == size)
            return 1;
    return 0;
}

static void options_defaults(mech_solve_options *o)
{
    memset(o, 0, sizeof *o);
    o->size = sizeof *o;
    o->tol = 1e-12;
    o->max_iter = 50;
    o->min_rcond = 1e-6;
    o->want = MECH_WANT_ALL;
}

int mech_solve_options_init(mech_solve_options *o, size_t size)
{
    if (!o)
        return MECH_EINPUT;
    if (!options_size_known(size)) {
        /* what the caller's struct surely holds; its size 0 says "not set"
           to the calls that read it */
        memset(o, 0, size < sizeof o->size ? size : sizeof o->size);
        return MECH_EINPUT;
    }
    mech_solve_options d;
    options_defaults(&d);
    d.size = size;
    memcpy(o, &d, size);
    return MECH_OK;
}

int api_options(const mech_solve_options *o, mech_solve_options *full, const char *func,
                mech_diag *d)
{
    options_defaults(full);
    if (!o)
        return MECH_OK;
    if (!options_size_known(o->size))
        return diag_error(d, func, (mech_mark){0, 0},
                          "the solve options' size is %zu, and this library (%s) knows %zu: set "
                          "them with mech_solve_options_init(&o, sizeof o) first (or the program "
                          "was built with a newer mech.h than the library it runs with)",
                          o->size, MECH_VERSION, sizeof *o);
    memcpy(full, o, o->size);
    full->size = sizeof *full;
    return MECH_OK;
}
