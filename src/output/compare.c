/* src/output/compare.c: a solver output CSV against a golden CSV (`mech compare`;
 * its command line is src/cli/cmd_compare.c).
 *
 * The CSV read here is what the solver writes (docs/cli.md, section mech compare):
 *   file    = { skipped } header { row | skipped }
 *   skipped = a blank line, or a comment: first non-blank character '#'
 *   header  = field { ',' field }       field = NAME [blanks] '[' UNIT ']'
 *   row     = cell { ',' cell }          as many fields as the header
 *   cell    = number, or in a column of unit '-' a word (mech sweep's status)
 *   number  = a finite decimal number: [sign] digits [. digits] [e [sign] digits]
 *             (digits before or after the point), as %.17g writes it; or
 *             nan, -nan, inf, -inf, spelled as printf writes them
 *   word    = a letter, then letters, digits, '.', '_' or '-' (compared as text)
 * A field may be quoted as RFC 4180 says ("a,b [-]", "" for a quote): mech
 * sweep quotes a metric's name that holds a comma (transmission:a,b).
 * Fields may have blanks around them; lines end with \n or \r\n. There is no
 * limit on the length of a line or the number of columns (getline grows its
 * buffer). Both files are read whole, then compared column by column. */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "output.h"
#include "base.h"

#define NO_ROW SIZE_MAX  /* col_result.first_bad when every row passes */

/* ================================================================== */
/* Reading one CSV file                                               */
/* ================================================================== */

typedef struct csv_reader {
    const char *path;
    FILE *f;
    char *line;        /* [cap] the current line without its end, NUL-terminated (getline) */
    size_t cap;
    size_t len;        /* bytes in line */
    int lineno;        /* 1-based number of the current line */
    char **fields;     /* [nfields] starts of the fields, cut in place in `line` */
    int *cols;         /* [nfields] their 1-based columns */
    size_t nfields, fields_cap;
    size_t rows_cap;   /* rows allocated in the table's values */
    int header_line;   /* line number of the header, for messages */
    mech_diag *d;      /* where errors go */
} csv_reader;

static int is_blank(char c)
{
    return c == ' ' || c == '\t';
}

static int clamp_int(size_t n)
{
    return n > INT_MAX ? INT_MAX : (int)n;
}

/* Record an error at 1-based column `col` of the current line; returns MECH_EINPUT. */
static int error_at(csv_reader *r, int col, const char *fmt, ...) MECH_PRINTF(3, 4);

static int error_at(csv_reader *r, int col, const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return diag_error(r->d, r->path, (mech_mark){r->lineno, col}, "%s", msg);
}

/* Read the next line into r->line, without its \n or \r\n. Returns 1 for a
 * line, 0 at the end of the file, MECH_EIO (recorded) or MECH_ENOMEM. */
static int read_line(csv_reader *r)
{
    errno = 0;
    ssize_t n = getline(&r->line, &r->cap, r->f);
    if (n < 0) {
        if (ferror(r->f)) {
            char ebuf[128];
            return diag_fail(r->d, MECH_FAIL_IO, r->path, (mech_mark){0, 0}, "cannot read: %s",
                             diag_strerror(errno, ebuf, sizeof ebuf));
        }
        return errno == ENOMEM ? MECH_ENOMEM : 0;  /* the caller records ENOMEM */
    }
    size_t len = (size_t)n;
    if (len > 0 && r->line[len - 1] == '\n')
        len--;
    if (len > 0 && r->line[len - 1] == '\r')
        len--;
    r->line[len] = '\0';
    r->len = len;
    if (r->lineno < INT_MAX)
        r->lineno++;
    return 1;
}

/* 1 when the current line carries no data: blank or a comment. */
static int line_is_skipped(const csv_reader *r)
{
    const char *s = r->line;
    while (is_blank(*s))
        s++;
    return (size_t)(s - r->line) == r->len || *s == '#';
}

/* 0 when the line has no NUL byte (which would hide the rest of it from
 * the string functions below); else the error, recorded. */
static int check_no_nul(csv_reader *r)
{
    size_t n = strlen(r->line);
    if (n == r->len)
        return 0;
    return error_at(r, clamp_int(n + 1), "NUL byte in the line");
}

static int push_field(csv_reader *r, char *start, size_t offset)
{
    if (r->nfields == r->fields_cap) {
        size_t cap = r->fields_cap ? 2 * r->fields_cap : 16;
        char **f = xrealloc_array(r->fields, cap, sizeof *f);
        if (!f)
            return MECH_ENOMEM;
        r->fields = f;
        int *c = xrealloc_array(r->cols, cap, sizeof *c);
        if (!c)
            return MECH_ENOMEM;
        r->cols = c;
        r->fields_cap = cap;
    }
    r->fields[r->nfields] = start;
    r->cols[r->nfields] = clamp_int(offset + 1);
    r->nfields++;
    return MECH_OK;
}

/* A quoted field at s ('"' first): unquoted in place ("" is one quote);
 * *end is set after its text, and the position after the closing quote
 * returned (the line's end when there is none). */
static char *unquote(char *s, char **end)
{
    char *w = s;
    for (s++; *s; s++) {
        if (*s == '"' && s[1] != '"')
            break;
        s += *s == '"';  /* "" */
        *w++ = *s;
    }
    *end = w;
    return *s ? s + 1 : s;
}

/* Cut the current line in place at its commas into r->fields, each without
 * the blanks around it (and a quoted field without its quotes); r->cols[i]
 * is the column of field i's first non-blank character. Returns MECH_OK or
 * MECH_ENOMEM. */
static int split_fields(csv_reader *r)
{
    r->nfields = 0;
    char *s = r->line;
    for (;;) {
        while (is_blank(*s))
            s++;
        char *start = s, *end;
        if (*s == '"') {  /* a quoted field: what follows the quote up to the comma is dropped */
            s = unquote(s, &end);
            while (*s && *s != ',')
                s++;
        } else {
            while (*s && *s != ',')
                s++;
            end = s;
            while (end > start && is_blank(end[-1]))
                end--;
        }
        int more = *s == ',';
        *end = '\0';
        if (push_field(r, start, (size_t)(start - r->line)) != MECH_OK)
            return MECH_ENOMEM;
        if (!more)
            return MECH_OK;
        s++;
    }
}

/* Split a header field "NAME [UNIT]" in place: *unit points into it.
 * Returns 0, or the error (recorded). */
static int split_name_unit(csv_reader *r, size_t i, char **unit)
{
    char *f = r->fields[i];
    size_t len = strlen(f);
    char *open = strrchr(f, '[');
    if (len == 0)
        return error_at(r, r->cols[i], "empty column name in the header");
    if (!open || f[len - 1] != ']')
        return error_at(r, r->cols[i], "column '%s' has no unit (expected 'NAME [UNIT]')", f);
    f[len - 1] = '\0';
    *open = '\0';
    *unit = open + 1;
    for (char *e = open; e > f && is_blank(e[-1]); e--)
        e[-1] = '\0';  /* the blanks between the name and the '[' */
    if (*f == '\0')
        return error_at(r, r->cols[i], "column '[%s]' has no name (expected 'NAME [UNIT]')",
                        *unit);
    return 0;
}

/* Copy the names and units of the current line's fields into t; every
 * problem is recorded. Returns MECH_OK, MECH_EINPUT or MECH_ENOMEM. */
static int parse_header(csv_reader *r, compare_table *t)
{
    t->names = xcalloc(r->nfields, sizeof *t->names);
    t->units = xcalloc(r->nfields, sizeof *t->units);
    if (!t->names || !t->units)
        return MECH_ENOMEM;
    t->ncols = r->nfields;
    int rc = MECH_OK;
    name_map seen = {0};  /* name -> column, to find duplicates */
    for (size_t i = 0; i < r->nfields; i++) {
        char *unit = NULL;
        if (split_name_unit(r, i, &unit) != 0) {
            rc = MECH_EINPUT;
            continue;
        }
        t->names[i] = xstrdup(r->fields[i]);
        t->units[i] = xstrdup(unit);
        if (!t->names[i] || !t->units[i] || i > INT_MAX) {
            rc = MECH_ENOMEM;
            break;
        }
        int first = name_map_get(&seen, t->names[i]);
        if (first >= 0)
            rc = error_at(r, r->cols[i], "duplicate column '%s' (first at column %d)",
                          t->names[i], r->cols[first]);
        else if (name_map_put(&seen, t->names[i], (int)i) < 0) {
            rc = MECH_ENOMEM;
            break;
        }
    }
    name_map_free(&seen);
    return rc;
}

/* Skip blank and comment lines, then read the header. Returns MECH_OK or
 * an error status (recorded). */
static int read_header(csv_reader *r, compare_table *t)
{
    int got;
    while ((got = read_line(r)) == 1 && line_is_skipped(r))
        ;
    if (got < 0)
        return got;
    if (got == 0) {
        r->lineno++;
        return error_at(r, 1, "no header line (expected 'NAME [UNIT],NAME [UNIT],...')");
    }
    if (check_no_nul(r) != 0)
        return MECH_EINPUT;
    r->header_line = r->lineno;
    if (split_fields(r) != MECH_OK)
        return MECH_ENOMEM;
    return parse_header(r, t);
}

/* Make room for one more row of t->ncols values. */
static int reserve_row(csv_reader *r, compare_table *t)
{
    if (t->nrows < r->rows_cap)
        return MECH_OK;
    size_t cap = r->rows_cap ? 2 * r->rows_cap : 64;
    if (cap > SIZE_MAX / t->ncols)
        return MECH_ENOMEM;
    double *v = xrealloc_array(t->values, cap * t->ncols, sizeof *v);
    if (!v)
        return MECH_ENOMEM;
    t->values = v;
    if (t->word) {
        int *w = xrealloc_array(t->word, cap * t->ncols, sizeof *w);
        if (!w)
            return MECH_ENOMEM;
        t->word = w;
    }
    r->rows_cap = cap;
    return MECH_OK;
}

int compare_table_intern(compare_table *t, const char *w)
{
    for (size_t i = 0; i < t->nwords; i++)
        if (strcmp(t->words[i], w) == 0)
            return (int)i;
    if (t->nwords >= INT_MAX)
        return -1;
    char **grown = xrealloc_array(t->words, t->nwords + 1, sizeof *grown);
    if (!grown)
        return -1;
    t->words = grown;
    if (!(t->words[t->nwords] = xstrdup(w)))
        return -1;
    return (int)t->nwords++;
}

const char *compare_cell_text(const compare_table *t, size_t row, size_t col)
{
    int w = t->word ? t->word[row * t->ncols + col] : -1;
    return w >= 0 ? t->words[w] : NULL;
}

/* 1 when s is a word: a letter, then letters, digits, '.', '_' or '-'. */
static int is_word(const char *s)
{
    if (!((*s >= 'a' && *s <= 'z') || (*s >= 'A' && *s <= 'Z')))
        return 0;
    return s[strspn(s, "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789._-")] ==
           '\0';
}

/* Cell `cell` (0-based) of the table a text cell holding w: the word array
 * made on the first (every cell -1 before). MECH_OK or MECH_ENOMEM. */
static int put_word(csv_reader *r, compare_table *t, size_t cell, const char *w)
{
    if (!t->word) {
        t->word = xrealloc_array(NULL, r->rows_cap * t->ncols, sizeof *t->word);
        if (!t->word)
            return MECH_ENOMEM;
        for (size_t i = 0; i < r->rows_cap * t->ncols; i++)
            t->word[i] = -1;
    }
    int k = compare_table_intern(t, w);
    if (k < 0)
        return MECH_ENOMEM;
    t->word[cell] = k;
    t->values[cell] = NAN;
    return MECH_OK;
}

/* *v = the number in cell s, when s is written as the solver writes numbers
 * (%.17g): a decimal number, or exactly nan, -nan, inf or -inf. Returns 1;
 * 0 when s is something else (hex 0x1p3, "infinity", "1OO"); -1 when a
 * decimal number overflows a double (1e999 would read as inf and then
 * match an inf). */
static int parse_cell(const char *s, double *v)
{
    static const char *const special[] = {"nan", "-nan", "inf", "-inf"};
    for (size_t i = 0; i < sizeof special / sizeof special[0]; i++)
        if (strcmp(s, special[i]) == 0) {
            *v = strtod(s, NULL);
            return 1;
        }
    static const char digit[] = "0123456789";
    const char *p = s + (*s == '+' || *s == '-');
    size_t whole = strspn(p, digit), frac = 0;
    p += whole;
    if (*p == '.') {
        frac = strspn(p + 1, digit);
        p += 1 + frac;
    }
    if (whole + frac == 0)
        return 0;
    if (*p == 'e' || *p == 'E') {
        p += 1 + (p[1] == '+' || p[1] == '-');
        size_t exp = strspn(p, digit);
        if (exp == 0)
            return 0;
        p += exp;
    }
    if (*p != '\0')
        return 0;
    *v = strtod(s, NULL);  /* an underflow is a finite value near 0: kept */
    return isfinite(*v) ? 1 : -1;
}

/* The field count of the current line against the header's. Returns 0 or
 * the error (recorded), placed at the first extra field or the line's end. */
static int check_field_count(csv_reader *r, const compare_table *t)
{
    if (r->nfields == t->ncols)
        return 0;
    int col = r->nfields > t->ncols ? r->cols[t->ncols] : clamp_int(r->len + 1);
    return error_at(r, col, "row has %zu field%s, expected %zu as in the header (line %d)",
                    r->nfields, r->nfields == 1 ? "" : "s", t->ncols, r->header_line);
}

/* Parse the current line as a data row appended to t. Returns MECH_OK,
 * MECH_EINPUT (recorded; the row is dropped) or MECH_ENOMEM. */
static int parse_row(csv_reader *r, compare_table *t)
{
    if (check_no_nul(r) != 0)
        return MECH_EINPUT;
    if (split_fields(r) != MECH_OK || reserve_row(r, t) != MECH_OK)
        return MECH_ENOMEM;
    if (check_field_count(r, t) != 0)
        return MECH_EINPUT;
    size_t at = t->nrows * t->ncols;
    double *row = t->values + at;
    for (size_t i = 0; i < t->ncols; i++) {
        if (r->fields[i][0] == '\0')
            return error_at(r, r->cols[i], "empty field in column '%s' (expected a number)",
                            t->names[i]);
        int ok = parse_cell(r->fields[i], &row[i]);
        if (ok == 1 && t->word)
            t->word[at + i] = -1;
        if (ok == 0 && strcmp(t->units[i], "-") == 0 && is_word(r->fields[i])) {
            if (put_word(r, t, at + i, r->fields[i]) != MECH_OK)
                return MECH_ENOMEM;
            continue;
        }
        if (ok == 0)
            return error_at(r, r->cols[i], "'%.40s' in column '%s' is not a number",
                            r->fields[i], t->names[i]);
        if (ok < 0)
            return error_at(r, r->cols[i], "'%.40s' in column '%s' is not a finite number "
                            "(beyond the range of a double)", r->fields[i], t->names[i]);
    }
    t->nrows++;
    return MECH_OK;
}

/* Read the data rows to the end of the file. A malformed row is recorded
 * and skipped, so that every bad row is reported; I/O and memory errors
 * stop at once. */
static int read_rows(csv_reader *r, compare_table *t)
{
    int rc = MECH_OK, got;
    while ((got = read_line(r)) == 1) {
        if (line_is_skipped(r))
            continue;
        int row_rc = parse_row(r, t);
        if (row_rc == MECH_ENOMEM)
            return row_rc;
        if (row_rc != MECH_OK)
            rc = row_rc;
    }
    return got < 0 ? got : rc;
}

void compare_table_free(compare_table *t)
{
    if (!t)
        return;
    for (size_t i = 0; i < t->ncols; i++) {
        if (t->names)
            free(t->names[i]);
        if (t->units)
            free(t->units[i]);
    }
    for (size_t i = 0; i < t->nwords; i++)
        free(t->words[i]);
    free(t->names);
    free(t->units);
    free(t->values);
    free(t->word);
    free(t->words);
    memset(t, 0, sizeof *t);
}

int compare_read_csv(const char *path, compare_table *t, mech_diag *d)
{
    if (output_file_is_h5(path))  /* mech's HDF5 output (output_h5.c) */
        return compare_read_h5(path, t, d);
    memset(t, 0, sizeof *t);
    FILE *f = fopen(path, "rb");
    if (!f) {
        char ebuf[128];
        return diag_fail(d, MECH_FAIL_IO, path, (mech_mark){0, 0}, "cannot open: %s",
                         diag_strerror(errno, ebuf, sizeof ebuf));
    }
    int rc = compare_read_csv_stream(f, path, t, d);
    fclose(f);
    return rc;
}

int compare_read_csv_stream(FILE *f, const char *path, compare_table *t, mech_diag *d)
{
    memset(t, 0, sizeof *t);
    csv_reader r = {.path = path, .d = d, .f = f};
    int rc = read_header(&r, t);
    if (rc == MECH_OK)
        rc = read_rows(&r, t);
    if (rc == MECH_ENOMEM)
        diag_nomem(d, path, (mech_mark){0, 0});
    free(r.line);
    free(r.fields);
    free(r.cols);
    if (rc != MECH_OK)
        compare_table_free(t);
    return rc;
}

/* ================================================================== */
/* Comparing two tables                                               */
/* ================================================================== */

/* The outcome of one GOLDEN column. */
typedef struct col_result {
    size_t g;          /* column in GOLDEN */
    int o;             /* column in OUT, -1 when missing */
    int unit_differs;  /* 1: the units differ (values not compared) */
    double max_abs;    /* worst |out - golden| */
    double max_rel;    /* worst |out - golden| / |golden| over golden != 0 */
    size_t first_bad;  /* 0-based data row of the first failure, or NO_ROW */
} col_result;

void compare_options_default(compare_options *o)
{
    memset(o, 0, sizeof *o);
    o->rtol = COMPARE_RTOL;
    o->atol = COMPARE_ATOL;
    o->table = 1;
}

int compare_values_match(double out, double golden, double rtol, double atol)
{
    if (isnan(out) || isnan(golden))
        return isnan(out) && isnan(golden);
    if (isinf(out) || isinf(golden))
        return out == golden;
    return fabs(out - golden) <= atol + rtol * fabs(golden);  /* also false on overflow to inf */
}

/* Fold the error of one pair into c: a NaN or inf that does not match
 * counts as an infinite error. */
static void add_error(col_result *c, double out, double golden)
{
    double abs_err, rel_err = 0.0;
    if ((isnan(out) && isnan(golden)) || out == golden)
        abs_err = 0.0;
    else if (!isfinite(out) || !isfinite(golden))
        abs_err = rel_err = INFINITY;
    else {
        abs_err = fabs(out - golden);
        if (golden != 0.0)
            rel_err = abs_err / fabs(golden);  /* undefined at golden == 0: skipped */
    }
    if (abs_err > c->max_abs)
        c->max_abs = abs_err;
    if (rel_err > c->max_rel)
        c->max_rel = rel_err;
}

/* Compare the first nrows rows of OUT column c->o with GOLDEN column c->g. */
static void compare_column(col_result *c, const compare_table *out, const compare_table *golden,
                           size_t nrows, const compare_options *o)
{
    for (size_t row = 0; row < nrows; row++) {
        double x = out->values[row * out->ncols + (size_t)c->o];
        double y = golden->values[row * golden->ncols + c->g];
        const char *tx = compare_cell_text(out, row, (size_t)c->o);
        const char *ty = compare_cell_text(golden, row, c->g);
        if (tx || ty) {  /* text: equal or not at all */
            int same = tx && ty && strcmp(tx, ty) == 0;
            add_error(c, 0.0, same ? 0.0 : INFINITY);
            if (c->first_bad == NO_ROW && !same)
                c->first_bad = row;
            continue;
        }
        add_error(c, x, y);
        if (c->first_bad == NO_ROW && !compare_values_match(x, y, o->rtol, o->atol))
            c->first_bad = row;
    }
}

static int col_failed(const col_result *c)
{
    return c->o < 0 || c->unit_differs || c->first_bad != NO_ROW;
}

/* The state of one comparison. */
typedef struct cmp {
    const compare_table *out, *golden;
    const char *out_name, *golden_name;
    const compare_options *o;
    name_map gmap, omap;   /* column name -> index, in GOLDEN and in OUT (keys borrowed) */
    size_t nrows;          /* rows compared: the smaller of the two counts */
    col_result *cols;      /* [ncols] the selected GOLDEN columns, in GOLDEN's order */
    size_t ncols;
    size_t nfailed;        /* of cols */
} cmp;

static int map_names(const compare_table *t, name_map *m)
{
    for (size_t i = 0; i < t->ncols; i++)
        if (i > INT_MAX || name_map_put(m, t->names[i], (int)i) < 0)
            return MECH_ENOMEM;
    return MECH_OK;
}

/* Record in d why --columns name `name` is not a GOLDEN column. */
static void unknown_column(const cmp *c, const char *name, mech_diag *d)
{
    const char *near = nearest_name(name, (const char *const *)c->golden->names,
                                    c->golden->ncols);
    mech_mark none = {0, 0};
    if (name_map_get(&c->omap, name) >= 0)
        diag_error(d, c->golden_name, none, "--columns: no column '%s' (only %s has it)", name,
                   c->out_name);
    else if (near)
        diag_error(d, c->golden_name, none, "--columns: no column '%s' (did you mean '%s'?)",
                   name, near);
    else
        diag_error(d, c->golden_name, none, "--columns: no column '%s'", name);
}

/* Set selected[g] for the GOLDEN columns to compare: all of them, or those
 * o->columns names. Returns MECH_OK or MECH_EINPUT (unknown names, in d). */
static int select_columns(const cmp *c, unsigned char *selected, mech_diag *d)
{
    memset(selected, c->o->ncolumns == 0, c->golden->ncols);
    int rc = MECH_OK;
    for (size_t i = 0; i < c->o->ncolumns; i++) {
        int g = name_map_get(&c->gmap, c->o->columns[i]);
        if (g >= 0) {
            selected[g] = 1;
        } else {
            unknown_column(c, c->o->columns[i], d);
            rc = MECH_EINPUT;
        }
    }
    return rc;
}

/* Find GOLDEN column g in OUT, check its unit and compare its values. */
static void match_column(cmp *c, size_t g)
{
    col_result *r = &c->cols[c->ncols++];
    *r = (col_result){.g = g, .first_bad = NO_ROW};
    r->o = name_map_get(&c->omap, c->golden->names[g]);
    if (r->o >= 0 && strcmp(c->out->units[r->o], c->golden->units[g]) != 0)
        r->unit_differs = 1;
    if (r->o >= 0 && !r->unit_differs)
        compare_column(r, c->out, c->golden, c->nrows, c->o);
    if (col_failed(r))
        c->nfailed++;
}

/* ---- the report ---------------------------------------------------- */

static const char *plural(size_t n)
{
    return n == 1 ? "" : "s";
}

static int text_width(int w, const char *s)
{
    size_t n = strlen(s);
    return n > (size_t)w ? clamp_int(n) : w;
}

static void print_column(const cmp *c, const col_result *r, int wname, int wunit, FILE *f)
{
    char abs_err[32] = "-", rel_err[32] = "-", row[32] = "-";
    const char *name = c->golden->names[r->g], *unit = c->golden->units[r->g];
    if (r->o < 0) {
        fprintf(f, "%-*s  %-*s  %11s  %11s  %9s  FAIL (missing from OUT)\n", wname, name, wunit,
                unit, abs_err, rel_err, row);
        return;
    }
    if (r->unit_differs) {
        fprintf(f, "%-*s  %-*s  %11s  %11s  %9s  FAIL (unit [%s] in OUT)\n", wname, name, wunit,
                unit, abs_err, rel_err, row, c->out->units[r->o]);
        return;
    }
    snprintf(abs_err, sizeof abs_err, "%.3g", r->max_abs);
    snprintf(rel_err, sizeof rel_err, "%.3g", r->max_rel);
    if (r->first_bad != NO_ROW)
        snprintf(row, sizeof row, "%zu", r->first_bad + 1);
    fprintf(f, "%-*s  %-*s  %11s  %11s  %9s  %s\n", wname, name, wunit, unit, abs_err, rel_err,
            row, r->first_bad == NO_ROW ? "ok" : "FAIL");
}

/* The OUT columns GOLDEN lacks, on one line (none: nothing). */
static void print_extras(const cmp *c, FILE *f)
{
    const char *sep = "extra in OUT (not compared): ";
    for (size_t i = 0; i < c->out->ncols; i++)
        if (name_map_get(&c->gmap, c->out->names[i]) < 0) {
            fprintf(f, "%s%s [%s]", sep, c->out->names[i], c->out->units[i]);
            sep = ", ";
        }
    if (sep[0] == ',')
        fputc('\n', f);
}

static void print_table(const cmp *c, FILE *f)
{
    int wname = 6, wunit = 4;  /* "column", "unit" */
    for (size_t i = 0; i < c->ncols; i++) {
        wname = text_width(wname, c->golden->names[c->cols[i].g]);
        wunit = text_width(wunit, c->golden->units[c->cols[i].g]);
    }
    fprintf(f, "%-*s  %-*s  %11s  %11s  %9s  %s\n", wname, "column", wunit, "unit",
            "max abs err", "max rel err", "first bad", "status");
    for (size_t i = 0; i < c->ncols; i++)
        print_column(c, &c->cols[i], wname, wunit, f);
    if (c->o->ncolumns == 0)
        print_extras(c, f);
}

/* "(first: ...)": the earliest failing row of any column (ties: the first
 * column), else the first column missing or with another unit. */
static void print_first(const cmp *c, FILE *f)
{
    const col_result *best = NULL;
    for (size_t i = 0; i < c->ncols; i++)
        if (c->cols[i].first_bad != NO_ROW && (!best || c->cols[i].first_bad < best->first_bad))
            best = &c->cols[i];
    if (best) {
        char x[FMT_DOUBLE_MAX], y[FMT_DOUBLE_MAX];  /* the fewest digits that read back */
        size_t row = best->first_bad;
        const char *tx = compare_cell_text(c->out, row, (size_t)best->o);
        const char *ty = compare_cell_text(c->golden, row, best->g);
        fmt_double(c->out->values[row * c->out->ncols + (size_t)best->o], x);
        fmt_double(c->golden->values[row * c->golden->ncols + best->g], y);
        fprintf(f, " (first: %s at row %zu: %s vs %s)", c->golden->names[best->g], row + 1,
                tx ? tx : x, ty ? ty : y);
        return;
    }
    for (size_t i = 0; i < c->ncols; i++) {
        const col_result *r = &c->cols[i];
        const char *name = c->golden->names[r->g];
        if (r->o < 0) {
            fprintf(f, " (first: %s missing from OUT)", name);
            return;
        }
        if (r->unit_differs) {
            fprintf(f, " (first: %s in [%s] in OUT, [%s] in GOLDEN)", name, c->out->units[r->o],
                    c->golden->units[r->g]);
            return;
        }
    }
}

static void print_verdict(const cmp *c, FILE *f)
{
    size_t nout = c->out->nrows, ngold = c->golden->nrows;
    fputs("compare: ", f);
    if (nout != ngold)
        fprintf(f, "row counts differ: OUT has %zu row%s, GOLDEN has %zu; ", nout, plural(nout),
                ngold);
    if (c->nfailed > 0) {
        fprintf(f, "%zu of %zu column%s differ%s", c->nfailed, c->ncols, plural(c->ncols),
                c->nfailed == 1 ? "s" : "");
        print_first(c, f);
    } else if (nout != ngold) {
        fprintf(f, "the first %zu row%s of %zu column%s are within rtol %g atol %g", c->nrows,
                plural(c->nrows), c->ncols, plural(c->ncols), c->o->rtol, c->o->atol);
    } else {
        fprintf(f, "%zu column%s, %zu row%s: all within rtol %g atol %g", c->ncols,
                plural(c->ncols), c->nrows, plural(c->nrows), c->o->rtol, c->o->atol);
    }
    fputc('\n', f);
}

int compare_tables(const compare_table *out, const compare_table *golden, const char *out_name,
                   const char *golden_name, const compare_options *o, FILE *report, mech_diag *d)
{
    compare_options defaults;
    if (!o) {
        compare_options_default(&defaults);
        o = &defaults;
    }
    cmp c = {.out = out, .golden = golden, .out_name = out_name, .golden_name = golden_name,
             .o = o, .nrows = out->nrows < golden->nrows ? out->nrows : golden->nrows};
    unsigned char *selected = xcalloc(golden->ncols, 1);  /* [golden->ncols] 1: compare */
    c.cols = xcalloc(golden->ncols, sizeof *c.cols);
    int rc = MECH_ENOMEM;
    if (!selected || !c.cols || map_names(golden, &c.gmap) != MECH_OK ||
        map_names(out, &c.omap) != MECH_OK) {
        diag_nomem(d, golden_name, (mech_mark){0, 0});
        goto done;
    }
    rc = select_columns(&c, selected, d);
    if (rc != MECH_OK)
        goto done;
    for (size_t g = 0; g < golden->ncols; g++)
        if (selected[g])
            match_column(&c, g);
    if (report && o->table)
        print_table(&c, report);
    if (report)
        print_verdict(&c, report);
    rc = c.nfailed > 0 || out->nrows != golden->nrows ? COMPARE_DIFFER : MECH_OK;
done:
    free(selected);
    free(c.cols);
    name_map_free(&c.gmap);
    name_map_free(&c.omap);
    return rc;
}

/* The worse of two read statuses: malformed, then out of memory, then unreadable. */
static int worse(int a, int b)
{
    static const int order[] = {MECH_EINPUT, MECH_ENOMEM, MECH_EIO};
    for (size_t i = 0; i < sizeof order / sizeof order[0]; i++)
        if (a == order[i] || b == order[i])
            return order[i];
    return MECH_OK;
}

/* Compare a (read with status ra, problems in d) against the golden file,
 * print the problems, free both. */
static int compare_with_golden(compare_table *a, int ra, const char *out_name,
                               const char *golden, const compare_options *o, FILE *report,
                               FILE *errors, mech_diag *d)
{
    compare_table b;
    int rb = compare_read_csv(golden, &b, d);
    int rc = worse(ra, rb);
    if (rc == MECH_OK)
        rc = compare_tables(a, &b, out_name, golden, o, report, d);
    if (errors)
        mech_diag_print(d, errors);
    mech_diag_free(d);
    compare_table_free(a);
    compare_table_free(&b);
    return rc;
}

int compare_csv_files(const char *out, const char *golden, const compare_options *o,
                      FILE *report, FILE *errors)
{
    mech_diag d;
    mech_diag_init(&d);
    compare_table a;
    int ra = compare_read_csv(out, &a, &d);
    return compare_with_golden(&a, ra, out, golden, o, report, errors, &d);
}

/* *c = a copy of the solver's table t, as compare_read_csv would read its
 * CSV (%.17g reads back as the same double). MECH_OK or MECH_ENOMEM. */
static int table_of_result(const mech_table *t, compare_table *c)
{
    memset(c, 0, sizeof *c);
    size_t nc = (size_t)t->ncolumns, nr = (size_t)t->nrows, nv = nc * nr;  /* t holds nv */
    c->names = xcalloc(nc ? nc : 1, sizeof *c->names);
    c->units = xcalloc(nc ? nc : 1, sizeof *c->units);
    c->values = xcalloc(nv ? nv : 1, sizeof *c->values);
    int bad = !c->names || !c->units || !c->values;
    c->ncols = c->names && c->units ? nc : 0;
    for (size_t i = 0; i < c->ncols; i++) {
        c->names[i] = strdup(t->columns[i].name);
        c->units[i] = strdup(t->columns[i].unit);
        bad |= !c->names[i] || !c->units[i];
    }
    if (bad) {
        compare_table_free(c);
        return MECH_ENOMEM;
    }
    if (nv)
        memcpy(c->values, t->values, nv * sizeof *c->values);
    c->nrows = nr;
    return MECH_OK;
}

int compare_result_file(const mech_table *out, const char *out_name, const char *golden,
                        const compare_options *o, FILE *report, FILE *errors)
{
    mech_diag d;
    mech_diag_init(&d);
    compare_table a;
    int ra = table_of_result(out, &a);
    if (ra != MECH_OK)
        diag_nomem(&d, out_name, (mech_mark){0, 0});
    return compare_with_golden(&a, ra, out_name, golden, o, report, errors, &d);
}

int compare_exit_status(int status)
{
    switch (status) {
    case MECH_OK:
        return MECH_EXIT_OK;
    case COMPARE_DIFFER:
        return 1;  /* both files valid, some value or column differs */
    case MECH_EIO:
    case MECH_ENOMEM:  /* "out of memory" is recorded; not the files' fault */
        return MECH_EXIT_IO;
    default:
        return MECH_EXIT_INPUT;
    }
}
