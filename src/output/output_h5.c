/* src/output/output_h5.c: a table as HDF5 (docs/cli.md, "Output files"),
 * written and read with the HDF5 library (Debian's libhdf5-dev).
 *
 * The layout, chosen so that h5py, pandas (through h5py), MATLAB's h5read
 * and Octave read it without knowing mech:
 *   /NAME             one dataset per column, float64 [rows], in SI or in
 *                     the units the header gives, with the attribute
 *                     "unit" ("m/s"); NAME is the CSV header's name (P.x),
 *                     a '/' in it written as U+2215 (HDF5 paths use '/');
 *                     a text column (mech sweep's status, mech batch's
 *                     file) is a dataset of UTF-8 strings [rows]
 *   / "columns"       the column names in the CSV's order (strings)
 *   / "units"         their units, in the same order
 *   / "rows"          the number of rows
 *   / other strings   what the caller adds: mech's version, the command,
 *                     the input file and its digest (the manifest)
 * HDF5 writes a temporary file beside the output, renamed over it when
 * complete (write_file_whole_by_name); for standard output, a FIFO or a
 * device the file is built in memory (HDF5's core driver) and its image
 * written: an HDF5 output is written whole or not at all like a CSV, and
 * never over anything else. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <hdf5.h>

#include "base.h"
#include "output.h"

/* ---- writing ------------------------------------------------------------ */

/* A column's dataset name into buf: its name, each '/' (which HDF5 takes
 * for a group: a transmission metric's "coupler/tray") written as U+2215,
 * the division slash. NULL when it does not fit. */
static const char *dataset_name(const char *name, char *buf, size_t size)
{
    size_t n = 0;
    for (; *name; name++) {
        const char *piece = *name == '/' ? "\xe2\x88\x95" : NULL;
        size_t len = piece ? 3 : 1;
        if (n + len >= size)
            return NULL;
        memcpy(buf + n, piece ? piece : name, len);
        n += len;
    }
    buf[n] = '\0';
    return buf;
}

typedef struct h5_job {
    const mech_table *t;     /* the table: a solver's, or */
    const compare_table *ct; /* one read back, which may have text cells */
    const char *const *keys, *const *values;  /* [nattrs] extra root attributes */
    int nattrs;
    void *image;  /* the file's bytes, once built */
    size_t size;
} h5_job;

/* a variable-length string type, or < 0 */
static hid_t string_type(void)
{
    hid_t s = H5Tcopy(H5T_C_S1);
    if (s >= 0 && (H5Tset_size(s, H5T_VARIABLE) < 0 || H5Tset_cset(s, H5T_CSET_UTF8) < 0)) {
        H5Tclose(s);
        return -1;
    }
    return s;
}

/* attribute `name` of `obj`: n strings (a scalar when n < 0) */
static int put_strings(hid_t obj, const char *name, const char *const *v, int n)
{
    hid_t type = string_type();
    hsize_t len = n < 0 ? 1 : (hsize_t)n;
    hid_t space = n < 0 ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &len, NULL);
    hid_t a = type >= 0 && space >= 0
                  ? H5Acreate2(obj, name, type, space, H5P_DEFAULT, H5P_DEFAULT) : -1;
    int rc = a >= 0 && H5Awrite(a, type, v) >= 0 ? 0 : -1;
    if (a >= 0)
        H5Aclose(a);
    if (space >= 0)
        H5Sclose(space);
    if (type >= 0)
        H5Tclose(type);
    return rc;
}

static int job_ncols(const h5_job *j)
{
    return j->t ? j->t->ncolumns : (int)j->ct->ncols;
}

static long job_nrows(const h5_job *j)
{
    return j->t ? j->t->nrows : (long)j->ct->nrows;
}

static const char *col_name(const h5_job *j, int c)
{
    return j->t ? j->t->columns[c].name : j->ct->names[c];
}

static const char *col_unit(const h5_job *j, int c)
{
    return j->t ? j->t->columns[c].unit : j->ct->units[c];
}

static double cell(const h5_job *j, long r, int c)
{
    return j->t ? mech_table_get(j->t, (int)r, c) : j->ct->values[(size_t)r * j->ct->ncols + (size_t)c];
}

/* 1 when column c holds a text cell (then it is written as strings) */
static int col_is_text(const h5_job *j, int c)
{
    for (size_t r = 0; j->ct && j->ct->word && r < j->ct->nrows; r++)
        if (compare_cell_text(j->ct, r, (size_t)c))
            return 1;
    return 0;
}

/* Column c's cells as strings into v[nrows]: the words, and a number as
 * the CSV writes it (fmt_double) into text[nrows * FMT_DOUBLE_MAX]. */
static void text_cells(const h5_job *j, int c, const char **v, char *text)
{
    for (size_t r = 0; r < j->ct->nrows; r++) {
        v[r] = compare_cell_text(j->ct, r, (size_t)c);
        if (!v[r]) {
            fmt_double(cell(j, (long)r, c), text + FMT_DOUBLE_MAX * r);
            v[r] = text + FMT_DOUBLE_MAX * r;
        }
    }
}

/* Column c's dataset: float64, or strings for a text column; buf holds
 * nrows doubles (the text column's space is its own). 0 or -1. */
static int put_column(hid_t file, const h5_job *j, int c, double *buf)
{
    hsize_t n = (hsize_t)job_nrows(j);
    int text = col_is_text(j, c);
    const char **strs = text ? calloc(n + 1, sizeof *strs) : NULL;
    char *arena = text ? malloc((size_t)FMT_DOUBLE_MAX * n + 1) : NULL;
    hid_t type = text ? string_type() : H5T_IEEE_F64LE;
    if (text && (!strs || !arena || type < 0)) {
        free(strs);
        free(arena);
        if (type >= 0)
            H5Tclose(type);
        return -1;
    }
    if (text)
        text_cells(j, c, strs, arena);
    for (hsize_t r = 0; !text && r < n; r++)
        buf[r] = cell(j, (long)r, c);
    char dsname[1024];
    hid_t space = H5Screate_simple(1, &n, NULL);
    hid_t ds = space >= 0 && dataset_name(col_name(j, c), dsname, sizeof dsname)
                   ? H5Dcreate2(file, dsname, type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)
                   : -1;
    int rc = ds >= 0 && (text ? H5Dwrite(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, strs)
                              : H5Dwrite(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT,
                                         buf)) >= 0 ? 0 : -1;
    const char *unit = col_unit(j, c);
    if (rc == 0)
        rc = put_strings(ds, "unit", &unit, -1);
    if (ds >= 0)
        H5Dclose(ds);
    if (space >= 0)
        H5Sclose(space);
    if (text)
        H5Tclose(type);
    free(strs);
    free(arena);
    return rc;
}

static int put_table(hid_t file, const h5_job *j)
{
    int n = job_ncols(j);
    const char **names = calloc((size_t)n + 1, sizeof *names);
    const char **units = calloc((size_t)n + 1, sizeof *units);
    double *buf = malloc(((size_t)job_nrows(j) + 1) * sizeof *buf);
    int rc = names && units && buf ? 0 : -1;
    for (int c = 0; rc == 0 && c < n; c++) {
        names[c] = col_name(j, c);
        units[c] = col_unit(j, c);
        rc = put_column(file, j, c, buf);
    }
    if (rc == 0)
        rc = put_strings(file, "columns", names, n) | put_strings(file, "units", units, n);
    char rows[32];
    const char *rp = rows;
    snprintf(rows, sizeof rows, "%ld", job_nrows(j));
    if (rc == 0)
        rc = put_strings(file, "rows", &rp, -1);
    for (int i = 0; rc == 0 && i < j->nattrs; i++)
        rc = put_strings(file, j->keys[i], &j->values[i], -1);
    free(names);
    free(units);
    free(buf);
    return rc;
}

/* The file written by HDF5 itself at `name` (a temporary file): 0 or -1. */
static int emit_by_name(const char *name, const void *ctx)
{
    hid_t file = H5Fcreate(name, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    if (file < 0)
        return -1;
    int rc = put_table(file, ctx);
    if (H5Fclose(file) < 0)
        rc = -1;
    return rc;
}

/* The file in memory, its image copied into j->image: for standard
 * output, a FIFO or a device, which HDF5 cannot open. 0 or -1. */
static int build_image(h5_job *j)
{
    hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
    if (fapl < 0 || H5Pset_fapl_core(fapl, 1 << 20, 0) < 0) {
        if (fapl >= 0)
            H5Pclose(fapl);
        return -1;
    }
    /* the name only identifies the in-memory file: nothing is created */
    hid_t file = H5Fcreate("mech-output.h5", H5F_ACC_TRUNC, H5P_DEFAULT, fapl);
    H5Pclose(fapl);
    if (file < 0)
        return -1;
    int rc = put_table(file, j);
    if (rc == 0 && H5Fflush(file, H5F_SCOPE_LOCAL) < 0)
        rc = -1;
    ssize_t size = rc == 0 ? H5Fget_file_image(file, NULL, 0) : -1;
    if (size > 0 && (j->image = malloc((size_t)size)) &&
        H5Fget_file_image(file, j->image, (size_t)size) == size)
        j->size = (size_t)size;
    else
        rc = -1;
    H5Fclose(file);
    return rc;
}

static int emit_image(FILE *f, const void *ctx)
{
    h5_job *j = (h5_job *)ctx;
    if (!j->image && build_image(j) != 0)
        return -1;
    return fwrite(j->image, 1, j->size, f) == j->size ? 0 : -1;
}

static int write_job(h5_job *j, const char *path, mech_diag *d)
{
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);  /* failures are reported here, not printed */
    int rc = write_file_whole_by_name(path, emit_by_name, emit_image, j, d);
    free(j->image);
    return rc;
}

int output_write_h5(const mech_table *t, const char *path, const char *const *keys,
                    const char *const *values, int nattrs, mech_diag *d)
{
    h5_job j = {t, NULL, keys, values, nattrs, NULL, 0};
    return write_job(&j, path, d);
}

int output_write_h5_table(const compare_table *t, const char *path, const char *const *keys,
                          const char *const *values, int nattrs, mech_diag *d)
{
    h5_job j = {NULL, t, keys, values, nattrs, NULL, 0};
    return write_job(&j, path, d);
}

int output_is_h5_name(const char *path)
{
    size_t n = path ? strlen(path) : 0;
    return (n > 3 && strcmp(path + n - 3, ".h5") == 0) ||
           (n > 5 && strcmp(path + n - 5, ".hdf5") == 0);
}

/* ---- reading ------------------------------------------------------------ */

int output_file_is_h5(const char *path)
{
    static const unsigned char sig[8] = {0x89, 'H', 'D', 'F', '\r', '\n', 0x1a, '\n'};
    unsigned char head[8];
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISREG(st.st_mode))
        return 0;  /* a FIFO's bytes are not read twice: only a regular file is looked at */
    FILE *f = fopen(path, "rb");
    if (!f)
        return 0;
    size_t n = fread(head, 1, sizeof head, f);
    fclose(f);
    return n == sizeof head && memcmp(head, sig, sizeof sig) == 0;
}

/* attribute `name` of obj: its strings, copied into out[n] (owned). 0 or -1. */
static int get_strings(hid_t obj, const char *name, char **out, size_t n)
{
    hid_t a = H5Aexists(obj, name) > 0 ? H5Aopen(obj, name, H5P_DEFAULT) : -1;
    hid_t space = a >= 0 ? H5Aget_space(a) : -1;
    hid_t type = string_type();
    int rc = -1;
    if (space >= 0 && type >= 0 && H5Sget_simple_extent_npoints(space) == (hssize_t)n) {
        char **v = calloc(n + 1, sizeof *v);
        if (v && H5Aread(a, type, v) >= 0) {
            rc = 0;
            for (size_t i = 0; i < n; i++)
                if (!(out[i] = xstrdup(v[i] ? v[i] : "")))
                    rc = -1;
            H5Dvlen_reclaim(type, space, H5P_DEFAULT, v);
        }
        free(v);
    }
    if (type >= 0)
        H5Tclose(type);
    if (space >= 0)
        H5Sclose(space);
    if (a >= 0)
        H5Aclose(a);
    return rc;
}

/* the number of strings of attribute `name`, or -1 */
static hssize_t count_strings(hid_t obj, const char *name)
{
    hid_t a = H5Aexists(obj, name) > 0 ? H5Aopen(obj, name, H5P_DEFAULT) : -1;
    hid_t space = a >= 0 ? H5Aget_space(a) : -1;
    hssize_t n = space >= 0 ? H5Sget_simple_extent_npoints(space) : -1;
    if (space >= 0)
        H5Sclose(space);
    if (a >= 0)
        H5Aclose(a);
    return n;
}

/* Column c of t text cells: the word array made (every cell a number,
 * -1) on the first text column. 0 or -1. */
static int make_words(compare_table *t)
{
    size_t n = t->nrows * t->ncols;
    if (t->word)
        return 0;
    if (!(t->word = malloc((n + 1) * sizeof *t->word)))
        return -1;
    for (size_t i = 0; i < n; i++)
        t->word[i] = -1;
    return 0;
}

/* A string dataset's cells as column c's words (NaN in col). 0 or -1. */
static int get_text_column(hid_t ds, hid_t space, compare_table *t, size_t c, double *col)
{
    hid_t type = string_type();
    char **v = calloc(t->nrows + 1, sizeof *v);
    int rc = type >= 0 && v && make_words(t) == 0 &&
             (t->nrows == 0 || H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0) ? 0 : -1;
    for (size_t r = 0; rc == 0 && r < t->nrows; r++) {
        int k = compare_table_intern(t, v[r] ? v[r] : "");
        t->word[r * t->ncols + c] = k;
        col[r] = NAN;
        rc = k < 0 ? -1 : 0;
    }
    if (v && type >= 0 && t->nrows > 0)
        H5Dvlen_reclaim(type, space, H5P_DEFAULT, v);
    free(v);
    if (type >= 0)
        H5Tclose(type);
    return rc;
}

/* column c's dataset into t->values (row-major); 0, or -1 with a reason */
static int get_column(hid_t file, compare_table *t, size_t c, double *col, const char **why)
{
    char dsname[1024];
    const char *dn = dataset_name(t->names[c], dsname, sizeof dsname);
    hid_t ds = dn && H5Lexists(file, dn, H5P_DEFAULT) > 0 ? H5Dopen2(file, dn, H5P_DEFAULT) : -1;
    hid_t space = ds >= 0 ? H5Dget_space(ds) : -1;
    hid_t dtype = ds >= 0 ? H5Dget_type(ds) : -1;
    int rc = -1;
    *why = "no dataset of that name";
    if (space >= 0 && H5Sget_simple_extent_ndims(space) == 1 &&
        H5Sget_simple_extent_npoints(space) == (hssize_t)t->nrows &&
        dtype >= 0 && H5Tget_class(dtype) == H5T_STRING) {
        *why = "cannot read it as text";
        rc = get_text_column(ds, space, t, c, col);
    } else if (space >= 0 && H5Sget_simple_extent_ndims(space) == 1 &&
        H5Sget_simple_extent_npoints(space) == (hssize_t)t->nrows) {
        *why = "cannot read it as numbers";
        if (t->nrows == 0 ||
            H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, col) >= 0)
            rc = 0;
    } else if (space >= 0)
        *why = "not one value per row";
    for (size_t r = 0; rc == 0 && r < t->nrows; r++)
        t->values[r * t->ncols + c] = col[r];
    if (dtype >= 0)
        H5Tclose(dtype);
    if (space >= 0)
        H5Sclose(space);
    if (ds >= 0)
        H5Dclose(ds);
    return rc;
}

static int read_h5(hid_t file, const char *path, compare_table *t, mech_diag *d)
{
    hssize_t n = count_strings(file, "columns");
    char *rows_text = NULL;
    if (n <= 0 || count_strings(file, "units") != n || get_strings(file, "rows", &rows_text, 1))
        return diag_fail(d, MECH_FAIL_INPUT, path, (mech_mark){0, 0},
                         "an HDF5 file without mech's layout (root attributes 'columns', "
                         "'units' and 'rows'; docs/cli.md, Output files)");
    char *end;
    long rows = strtol(rows_text, &end, 10);
    int bad_rows = *end || rows < 0 || rows > (1L << 40);
    free(rows_text);
    if (bad_rows)
        return diag_fail(d, MECH_FAIL_INPUT, path, (mech_mark){0, 0},
                         "the attribute 'rows' is not a row count");
    t->ncols = (size_t)n;
    t->nrows = (size_t)rows;
    t->names = calloc(t->ncols, sizeof *t->names);
    t->units = calloc(t->ncols, sizeof *t->units);
    t->values = malloc((t->nrows * t->ncols + 1) * sizeof *t->values);
    double *col = malloc((t->nrows + 1) * sizeof *col);
    if (!t->names || !t->units || !t->values || !col ||
        get_strings(file, "columns", t->names, t->ncols) ||
        get_strings(file, "units", t->units, t->ncols)) {
        free(col);
        return diag_nomem(d, path, (mech_mark){0, 0});
    }
    for (size_t c = 0; c < t->ncols; c++) {
        const char *why;
        if (get_column(file, t, c, col, &why) != 0) {
            free(col);
            return diag_fail(d, MECH_FAIL_INPUT, path, (mech_mark){0, 0},
                             "column '%s': %s (%zu rows)", t->names[c], why, t->nrows);
        }
    }
    free(col);
    return MECH_OK;
}

int compare_read_h5(const char *path, compare_table *t, mech_diag *d)
{
    memset(t, 0, sizeof *t);
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0)
        return diag_fail(d, MECH_FAIL_IO, path, (mech_mark){0, 0},
                         "cannot open the HDF5 file (damaged or cut short?)");
    int rc = read_h5(file, path, t, d);
    H5Fclose(file);
    if (rc != MECH_OK)
        compare_table_free(t);
    return rc;
}

int output_h5_attrs(const char *path, const char *const *names, char **values, int n)
{
    for (int i = 0; i < n; i++)
        values[i] = NULL;
    H5Eset_auto2(H5E_DEFAULT, NULL, NULL);
    hid_t file = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    if (file < 0)
        return -1;
    for (int i = 0; i < n; i++)
        if (count_strings(file, names[i]) == 1)
            get_strings(file, names[i], &values[i], 1);
    H5Fclose(file);
    return 0;
}
