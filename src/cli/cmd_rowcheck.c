/* src/cli/cmd_rowcheck.c: the checks of a row read back (src/cli/cli.h):
 * its shape (cells, quotes, control bytes), a sweep row's parameters
 * recomputed by the library's grid (grid_value, src/study/sweep_grid.c), a batch
 * row's fields. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "study.h"

/* An argument a manifest cannot hold (cmd_opts_each). */
static void foreign_arg(void *ctx, const cmd_opt *o, const char *name, const char *value)
{
    (void)name;
    (void)value;
    if (!o || o->kind == CMD_OPT_HELP || (o->flags & CMD_RUN_ONLY))
        *(int *)ctx = 1;
}

int manifest_args_parse(const manifest *m, const cmd_spec *spec, void *args, char ***words)
{
    int n = 0, foreign = 0;
    char **argv = NULL;
    *words = NULL;
    if (strcmp(m->command, spec->name) != 0 || manifest_args_split(m->args, words, &n) != 0 ||
        !(argv = calloc((size_t)n + 3, sizeof *argv))) {
        free(*words);
        *words = NULL;
        return -1;
    }
    argv[0] = (char *)spec->name;
    argv[1] = "FILE";  /* the file is hashed, not named */
    memcpy(argv + 2, *words, (size_t)n * sizeof *argv);
    cmd_opts_each(spec, n + 1, argv + 1, foreign_arg, &foreign);
    int code = foreign ? MECH_EXIT_INPUT : cmd_opts_parse(spec, n + 2, argv, args);
    free(argv);
    return code < 0 ? 0 : -1;
}

int sweep_tol_format(const mech_sweep *s, char *buf, size_t size)
{
    size_t n = 0;
    buf[0] = '\0';
    for (int k = s->ngrid; s->opt.nrandom > 0 && k < s->naxes; k++) {
        const sweep_axis *a = &s->axes[k];
        int w = snprintf(buf + n, size - n, "%s%a~%a", k > s->ngrid ? "," : "", a->nominal, a->tol);
        if (w < 0 || (size_t)w >= size - n)
            return -1;
        n += (size_t)w;
    }
    return 0;
}

int sweep_tol_parse(mech_sweep *s, const char *text)
{
    for (const char *p = text; *p;) {
        char *end, name[32];
        double nominal = strtod(p, &end), tol;
        if (end == p || *end != '~')
            return -1;
        p = end + 1;
        tol = strtod(p, &end);
        if (end == p || (*end && (*end != ',' || !end[1])) || !(tol > 0.0) ||
            !isfinite(tol + nominal))
            return -1;
        p = *end ? end + 1 : end;
        snprintf(name, sizeof name, "p%d", s->naxes + 1);  /* the file's names are not needed */
        if (grid_random_axis(s, name, "-", nominal, tol, NULL) != MECH_OK)
            return -1;
    }
    return s->naxes > 0 ? 0 : -1;
}

int csv_cells(const char *line, size_t len)
{
    int cells = 1, quoted = 0;
    for (size_t i = 0; i < len; i++) {
        if (line[i] == '"')
            quoted = !quoted;  /* "" inside a quoted cell toggles twice */
        else if (line[i] == ',' && !quoted)
            cells++;
    }
    return cells;
}

int csv_row_shape(const char *row, size_t len, int ncells, char *why, size_t size)
{
    int cells = 1;
    for (size_t i = 0; i < len; i++) {
        unsigned char c = (unsigned char)row[i];
        if (c == '"') {
            snprintf(why, size, "a quoted field (the rows hold numbers and words only)");
            return -1;
        }
        if (c < 32 || c == 127) {
            snprintf(why, size, "a control character (byte 0x%02x) at byte %zu", c, i + 1);
            return -1;
        }
        cells += c == ',';
    }
    if (cells != ncells) {
        snprintf(why, size, "%d fields, the header has %d (a field %s)", cells, ncells,
                 cells < ncells ? "missing" : "too many");
        return -1;
    }
    return 0;
}

long csv_row_index(const char *row, size_t len)
{
    long v = 0;
    size_t i = 0;
    for (; i < len && i < 18 && row[i] >= '0' && row[i] <= '9'; i++)
        v = 10 * v + (row[i] - '0');
    return i > 0 && (i == len || row[i] == ',') ? v : -1;
}

/* The cell that starts at *p (up to end): *p moved past it and its comma;
 * returns 1 when a cell follows (there was a comma). */
static int next_cell(const char **p, const char *end, const char **cell, size_t *n)
{
    const char *c = memchr(*p, ',', (size_t)(end - *p));
    *cell = *p;
    *n = (size_t)((c ? c : end) - *p);
    *p = c ? c + 1 : end;
    return c != NULL;
}

/* A number that is the whole cell (as %.17g and the shortest form write). */
static int cell_number(const char *cell, size_t n, double *x)
{
    char buf[64], *end;
    if (n == 0 || n >= sizeof buf || cell[0] == ' ')
        return -1;
    memcpy(buf, cell, n);
    buf[n] = '\0';
    *x = strtod(buf, &end);
    return *end ? -1 : 0;
}

/* A status: one of the library's names of a variant's status (whatever
 * kinds of failure it names: mech_variant_status_name gives "error" past
 * its last, which ends the look). */
static int cell_status(const char *cell, size_t n)
{
    for (int k = 0;; k++) {
        const char *name = mech_variant_status_name((mech_variant_status)k);
        if (strlen(name) == n && memcmp(name, cell, n) == 0)
            return 1;
        if (k > MECH_VARIANT_ERROR && strcmp(name, "error") == 0)
            return 0;
    }
}

static int bad_cell(char *why, size_t size, const char *what, const char *cell, size_t n)
{
    snprintf(why, size, "%s '%.*s'", what, (int)(n > 40 ? 40 : n), cell);
    return -1;
}

int sweep_row_content(const mech_sweep *s, const char *row, size_t len, char *why, size_t size)
{
    const char *p = row, *end = row + len, *cell;
    size_t n;
    long v = csv_row_index(row, len);
    if (v < 0)
        return bad_cell(why, size, "the variant is not a whole number:", row, len);
    int more = next_cell(&p, end, &cell, &n);
    for (int k = 0; k < s->naxes && more; k++) {
        double x, want = grid_value(s, v, k);
        more = next_cell(&p, end, &cell, &n);
        if (cell_number(cell, n, &x) != 0 || x != want) {
            snprintf(why, size, "parameter %d is '%.*s', the grid's value for variant %ld is "
                     "%.17g", k + 1, (int)(n > 40 ? 40 : n), cell, v, want);
            return -1;
        }
    }
    if (!more || (more = next_cell(&p, end, &cell, &n), !cell_status(cell, n)))
        return bad_cell(why, size, "the status is not a variant's status:", cell, n);
    if (!more || (more = next_cell(&p, end, &cell, &n), csv_row_index(cell, n) < 0))
        return bad_cell(why, size, "the rows are not a count:", cell, n);
    while (more) {
        double x;
        more = next_cell(&p, end, &cell, &n);
        if (cell_number(cell, n, &x) != 0)
            return bad_cell(why, size, "a metric is not a number:", cell, n);
    }
    return 0;
}

/* The last space-separated word of row[0 .. *len): its start; *len cut to
 * before it and the spaces before it. NULL when there is none. */
static const char *last_word(const char *row, size_t *len, size_t *n)
{
    size_t e = *len;
    while (e > 0 && row[e - 1] == ' ')
        e--;
    size_t s = e;
    while (s > 0 && row[s - 1] != ' ')
        s--;
    if (s == e)
        return NULL;
    *n = e - s;
    *len = s;
    return row + s;
}

static int word_to(const char *w, size_t n, char *out, size_t size)
{
    if (!w || n == 0 || n >= size)
        return -1;
    memcpy(out, w, n);
    out[n] = '\0';
    return 0;
}

int batch_row_parse(const char *row, size_t len, int indexed, batch_row *br, char *why,
                    size_t size)
{
    memset(br, 0, sizeof *br);
    br->index = -1;
    for (size_t i = 0; i < len; i++)
        if ((unsigned char)row[i] < 32 || row[i] == 127 || row[i] == '"')
            return snprintf(why, size, "a %s at byte %zu", row[i] == '"' ? "quote"
                            : "control character", i + 1), -1;
    size_t n = 0, rest = len;
    const char *w;
    char text[64], *end;
    if (indexed) {
        w = last_word(row, &rest, &n);
        if (word_to(w, n, text, sizeof text) != 0 ||
            (strcmp(text, "-") != 0 && (n != 16 || sscanf(text, "%" SCNx64, &br->csv) != 1)))
            return snprintf(why, size, "no CSV hash at its end (16 hex digits or '-')"), -1;
        br->has_csv = strcmp(text, "-") != 0;
        w = last_word(row, &rest, &n);
        if ((br->index = w ? csv_row_index(w, n) : -1) < 0)
            return snprintf(why, size, "no index before its CSV hash"), -1;
    }
    /* golden, us/step, worst residual, steps, status: from the right */
    char *words[5] = {br->golden, NULL, NULL, NULL, br->status};
    const char *names[5] = {"golden", "us/step", "worst residual", "steps", "status"};
    for (int f = 0; f < 5; f++) {
        w = last_word(row, &rest, &n);
        size_t cap = words[f] ? sizeof br->golden : sizeof text;
        int bad = word_to(w, n, words[f] ? words[f] : text, cap) != 0;
        if (!bad && (f == 1 || f == 2)) {
            *(f == 1 ? &br->us_per_step : &br->residual) = strtod(text, &end);
            bad = *end != '\0';
        } else if (!bad && f == 3) {
            bad = (br->steps = csv_row_index(text, n)) < 0;
        }
        if (bad)
            return snprintf(why, size, "its %s field is missing or malformed", names[f]), -1;
    }
    while (rest > 0 && row[rest - 1] == ' ')
        rest--;
    if (rest == 0)
        return snprintf(why, size, "no file name"), -1;
    br->name = row;
    br->name_len = (int)rest;
    return 0;
}
