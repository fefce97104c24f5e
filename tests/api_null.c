/* tests/api_null.c: the C API's argument contract (include/mech.h, "NULL
 * arguments" and "Versions"), through the shared library and the public
 * header alone. Every public function is called with NULL wherever the
 * header allows it, and its result checked against the same call with the
 * pointer given; a required pointer given as NULL must be MECH_EINPUT with
 * the function's name and the argument in the message; the solve options'
 * size-checked init; mech_version(). Built and run by tests/api.sh:
 *   api_null FOURBAR.yaml SLIDER-CRANK.yaml BAD.yaml OUTDIR
 * prints "FAIL: ..." lines and "api_null: N checks, M failed"; exit 1 on a
 * failure. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mech.h>

static int checks, failures;

static void check(int ok, const char *what)
{
    checks++;
    if (!ok) {
        failures++;
        printf("FAIL: %s\n", what);
    }
}

/* d holds one error whose file is `func` and whose message contains `arg`. */
static int refused(const mech_diag *d, const char *func, const char *arg)
{
    for (size_t i = 0; i < d->count; i++)
        if (d->entries[i].severity == MECH_SEV_ERROR && strcmp(d->entries[i].file, func) == 0 &&
            strstr(d->entries[i].message, arg))
            return 1;
    return 0;
}

/* The same table: columns, rows and every value bit for bit. */
static int same_table(const mech_table *a, const mech_table *b)
{
    if (a->ncolumns != b->ncolumns || a->nrows != b->nrows || a->nrows == 0)
        return 0;
    for (int c = 0; c < a->ncolumns; c++)
        if (strcmp(a->columns[c].name, b->columns[c].name) != 0)
            return 0;
    return memcmp(a->values, b->values,
                  (size_t)a->nrows * (size_t)a->ncolumns * sizeof *a->values) == 0;
}

static char *read_all(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    char *buf = f ? malloc(1 << 16) : NULL;
    *len = buf ? fread(buf, 1, (1 << 16) - 1, f) : 0;
    if (f)
        fclose(f);
    return buf;
}

static void diags(void)
{
    mech_diag d;
    mech_diag_init(NULL);
    mech_diag_free(NULL);
    mech_diag_print(NULL, stdout);
    mech_diag_init(&d);
    check(d.count == 0 && d.max_errors == 100, "mech_diag_init");
    mech_diag_print(&d, NULL);  /* out NULL: stderr (nothing to print) */
    mech_diag_free(&d);
}

static void loads(const char *fourbar, const char *bad)
{
    mech_diag d;
    mech_model *m = (mech_model *)1;
    /* the segfault: no diag */
    check(mech_load_file(fourbar, &m, NULL) == MECH_OK && m && m->nlinks == 4,
          "mech_load_file(path, &m, NULL)");
    mech_model_free(&m);
    check(m == NULL, "mech_model_free sets NULL");
    mech_model_free(&m);
    mech_model_free(NULL);
    m = (mech_model *)1;
    check(mech_load_file(bad, &m, NULL) == MECH_EINPUT && m == NULL,
          "mech_load_file(bad, &m, NULL): MECH_EINPUT, m NULL");
    /* out NULL: the file is checked only */
    mech_diag_init(&d);
    check(mech_load_file(fourbar, NULL, &d) == MECH_OK && d.nerrors == 0,
          "mech_load_file(path, NULL, &d)");
    check(mech_load_file(bad, NULL, &d) == MECH_EINPUT && d.nerrors > 0 &&
              strcmp(d.entries[0].file, bad) == 0 && d.entries[0].mark.line > 0,
          "mech_load_file(bad, NULL, &d): the errors with their place");
    mech_diag_free(&d);
    check(mech_load_file(bad, NULL, NULL) == MECH_EINPUT, "mech_load_file(bad, NULL, NULL)");
    mech_diag_init(&d);
    check(mech_load_file(NULL, &m, &d) == MECH_EINPUT && m == NULL &&
              refused(&d, "mech_load_file", "path is NULL"),
          "mech_load_file(NULL, ...): refused by name");
    mech_diag_free(&d);
    /* from a string: name NULL is "<string>" */
    size_t len = 0;
    char *text = read_all(fourbar, &len);
    check(text && mech_load_string(text, len, NULL, &m, NULL) == MECH_OK && m &&
              strcmp(m->file, "<string>") == 0,
          "mech_load_string(text, len, NULL, &m, NULL)");
    mech_model_free(&m);
    check(text && mech_load_string(text, len, "x", NULL, NULL) == MECH_OK,
          "mech_load_string(..., NULL, NULL)");
    free(text);
    mech_diag_init(&d);
    check(mech_load_string(NULL, 3, "x", &m, &d) == MECH_EINPUT &&
              refused(&d, "mech_load_string", "text is NULL"),
          "mech_load_string(NULL, ...): refused");
    mech_diag_free(&d);
    /* replacements: NULL with 0, not with 1 */
    check(mech_load_file_with(fourbar, NULL, 0, &m, NULL) == MECH_OK && m,
          "mech_load_file_with(path, NULL, 0, &m, NULL)");
    mech_model_free(&m);
    mech_diag_init(&d);
    check(mech_load_file_with(fourbar, NULL, 1, &m, &d) == MECH_EINPUT && !m &&
              refused(&d, "mech_load_file_with", "ov is NULL"),
          "mech_load_file_with(path, NULL, 1, ...): refused");
    mech_override noname = {NULL, "1 mm"};
    check(mech_load_file_with(fourbar, &noname, 1, NULL, &d) == MECH_EINPUT &&
              refused(&d, "mech_load_file_with", "NULL name"),
          "mech_load_file_with: an override with a NULL name refused");
    mech_diag_free(&d);
}

static void model_calls(const mech_model *m)
{
    mech_diag d;
    mech_summary s, s2;
    check(mech_find_link(NULL, "crank") == -1 && mech_find_link(m, NULL) == -1 &&
              mech_find_link(m, "crank") == 1,
          "mech_find_link with NULL");
    check(mech_find_joint(NULL, "A") == -1 && mech_find_joint(m, NULL) == -1,
          "mech_find_joint with NULL");
    check(mech_find_point(NULL, "A") == -1 && mech_find_point(m, NULL) == -1 &&
              mech_find_point(m, "A") >= 0,
          "mech_find_point with NULL");
    /* the other segfault */
    mech_diag_init(&d);
    check(mech_check(m, NULL, &d) == MECH_OK && d.nerrors == 0, "mech_check(m, NULL, &d)");
    mech_diag_free(&d);
    check(mech_check(m, &s, NULL) == MECH_OK && mech_check(m, &s2, NULL) == MECH_OK &&
              s.mobility == 1 && s.nloops == 1 && s.nunknowns == 2,
          "mech_check(m, &s, NULL): the summary");
    check(mech_check(m, NULL, NULL) == MECH_OK, "mech_check(m, NULL, NULL)");
    mech_diag_init(&d);
    check(mech_check(NULL, &s, &d) == MECH_EINPUT && refused(&d, "mech_check", "m is NULL"),
          "mech_check(NULL, ...): refused");
    check(mech_check(NULL, NULL, NULL) == MECH_EINPUT, "mech_check(NULL, NULL, NULL)");
    mech_diag_free(&d);
}

static void systems(const mech_model *m)
{
    mech_diag d;
    mech_system *s = NULL;
    check(mech_system_new(m, &s, NULL) == MECH_OK && s && mech_system_size(s) == 2,
          "mech_system_new(m, &s, NULL)");
    check(mech_system_size(NULL) == 0, "mech_system_size(NULL)");
    mech_system_print(NULL, MECH_FORMAT_TEXT, stdout);
    printf("system to stdout:\n");
    mech_system_print(s, MECH_FORMAT_TEXT, NULL);  /* stdout: tests/api.sh checks it */
    mech_system_free(&s);
    check(s == NULL, "mech_system_free sets NULL");
    mech_system_free(&s);
    mech_system_free(NULL);
    check(mech_system_new_named(m, &s, NULL) == MECH_OK && s, "mech_system_new_named(m, &s, NULL)");
    mech_system_free(&s);
    mech_diag_init(&d);
    check(mech_system_new(m, NULL, &d) == MECH_EINPUT && refused(&d, "mech_system_new", "out"),
          "mech_system_new(m, NULL, &d): refused");
    check(mech_system_new(NULL, &s, &d) == MECH_EINPUT && !s, "mech_system_new(NULL, ...)");
    check(mech_system_new_named(m, NULL, &d) == MECH_EINPUT &&
              refused(&d, "mech_system_new_named", "out"),
          "mech_system_new_named(m, NULL, &d): refused");
    mech_diag_free(&d);
}

/* The size-checked init, and the calls that read the options by it. */
static void options(const mech_model *m)
{
    mech_solve_options o;
    mech_diag d;
    mech_table t = {0};
    check(mech_solve_options_init(NULL, sizeof o) == MECH_EINPUT, "mech_solve_options_init(NULL)");
    memset(&o, 0xab, sizeof o);
    check(mech_solve_options_init(&o, sizeof o) == MECH_OK && o.size == sizeof o &&
              o.tol == 1e-12 && o.max_iter == 50 && o.min_rcond == 1e-6 &&
              o.want == MECH_WANT_ALL && o.outputs == NULL && o.log == NULL && o.steps == 0,
          "mech_solve_options_init(&o, sizeof o): the defaults");
    mech_solve_options def;
    mech_solve_options_default(&def);
    check(memcmp(&def, &o, sizeof o) == 0, "mech_solve_options_default = init(o, sizeof *o)");
    /* a struct from a newer header (larger), and sizes that are none */
    struct {
        mech_solve_options o;
        double appended[4];
    } newer;
    memset(&newer, 0xab, sizeof newer);
    check(mech_solve_options_init(&newer.o, sizeof newer) == MECH_EINPUT && newer.o.size == 0,
          "mech_solve_options_init: a larger struct refused, its size 0");
    check(mech_solve_options_init(&o, sizeof o - 8) == MECH_EINPUT && o.size == 0,
          "mech_solve_options_init: a smaller size refused");
    check(mech_solve_options_init(&o, 4) == MECH_EINPUT, "mech_solve_options_init(&o, 4)");
    /* options not set by the init are refused by name, not read */
    mech_diag_init(&d);
    memset(&o, 0, sizeof o);
    o.tol = 1e-10;
    check(mech_solve(m, &o, &t, NULL, &d) == MECH_EINPUT && t.nrows == 0 &&
              refused(&d, "mech_solve", "mech_solve_options_init"),
          "mech_solve with options not set by mech_solve_options_init: refused");
    mech_analysis *a = (mech_analysis *)1;
    check(mech_analysis_new(m, &newer.o, &a, &d) == MECH_EINPUT && a == NULL &&
              refused(&d, "mech_analysis_new", "size is 0"),
          "mech_analysis_new with a refused struct: refused");
    mech_diag_free(&d);
    mech_table_free(&t);
    /* set by the init: a field read (the range) */
    mech_solve_options_init(&o, sizeof o);
    o.has_range = 1;
    o.from = 0.1;
    o.to = 0.5;
    o.steps = 8;
    check(mech_solve(m, &o, &t, NULL, NULL) == MECH_OK && t.nrows == 9 &&
              mech_table_get(&t, 8, 0) == 0.5,
          "mech_solve with a range: 9 rows to 0.5");
    mech_table_free(&t);
}

static void solves(const mech_model *m, const char *outdir)
{
    mech_diag d;
    mech_solve_options o;
    mech_solve_options_init(&o, sizeof o);
    mech_table ref = {0}, t = {0};
    mech_solve_stats st;
    check(mech_solve(m, &o, &ref, &st, NULL) == MECH_OK && ref.nrows == 361 && st.steps == 361,
          "mech_solve(m, &o, &t, &st, NULL)");
    check(mech_solve(m, NULL, &t, NULL, NULL) == MECH_OK && same_table(&t, &ref),
          "mech_solve(m, NULL, &t, NULL, NULL): the defaults' table");
    mech_table_free(&t);
    check(mech_solve(m, NULL, NULL, &st, NULL) == MECH_OK && st.steps == 361,
          "mech_solve(m, NULL, NULL, &st, NULL): the rows not kept, the stats");
    check(mech_solve(m, NULL, NULL, NULL, NULL) == MECH_OK, "mech_solve(m, NULL x4)");
    mech_diag_init(&d);
    check(mech_solve(NULL, &o, &t, &st, &d) == MECH_EINPUT && t.nrows == 0 &&
              refused(&d, "mech_solve", "m is NULL"),
          "mech_solve(NULL, ...): refused");
    mech_diag_free(&d);
    mech_table_free(&t);

    /* the analysis */
    mech_analysis *a = NULL;
    check(mech_analysis_new(m, NULL, &a, NULL) == MECH_OK && a, "mech_analysis_new(m, NULL, &a, NULL)");
    check(mech_analysis_columns(a) == ref.ncolumns && mech_analysis_columns(NULL) == 0,
          "mech_analysis_columns");
    check(mech_analysis_header(NULL, &t) == MECH_EINPUT && mech_analysis_header(a, NULL) == MECH_EINPUT,
          "mech_analysis_header with NULL");
    check(mech_analysis_solve(a, NULL, 0, &t, NULL, NULL) == MECH_OK && same_table(&t, &ref),
          "mech_analysis_solve(a, NULL, 0, &t, NULL, NULL): the analysis's positions");
    mech_table_free(&t);
    double q[3] = {0.0, 0.01, 0.02};
    check(mech_analysis_solve(a, q, 3, NULL, &st, NULL) == MECH_OK && st.steps == 3,
          "mech_analysis_solve(a, q, 3, NULL, &st, NULL)");
    mech_diag_init(&d);
    check(mech_analysis_solve(a, q, -1, &t, NULL, &d) == MECH_EINPUT &&
              refused(&d, "mech_analysis_solve", "nq is -1"),
          "mech_analysis_solve(a, q, -1): refused");
    check(mech_analysis_solve(NULL, q, 3, &t, NULL, &d) == MECH_EINPUT && t.nrows == 0 &&
              refused(&d, "mech_analysis_solve", "a is NULL"),
          "mech_analysis_solve(NULL, ...): refused");
    mech_analysis *none = (mech_analysis *)1;
    check(mech_analysis_new(m, NULL, NULL, &d) == MECH_EINPUT &&
              refused(&d, "mech_analysis_new", "out is NULL"),
          "mech_analysis_new(m, NULL, NULL, &d): refused");
    check(mech_analysis_new(NULL, NULL, &none, &d) == MECH_EINPUT && none == NULL,
          "mech_analysis_new(NULL, ...): refused, *out NULL");
    mech_diag_free(&d);
    mech_analysis_free(&a);
    check(a == NULL, "mech_analysis_free sets NULL");
    mech_analysis_free(&a);
    mech_analysis_free(NULL);

    /* tables */
    mech_table_free(NULL);
    check(mech_table_column(NULL, "q") == -1 && mech_table_column(&ref, NULL) == -1 &&
              mech_table_column(&ref, "B.x") > 0,
          "mech_table_column with NULL");
    char path[600];
    snprintf(path, sizeof path, "%s/api.csv", outdir);
    check(mech_table_write_csv(&ref, path, NULL) == MECH_OK, "mech_table_write_csv(t, path, NULL)");
    snprintf(path, sizeof path, "%s/no/such/dir/api.csv", outdir);
    check(mech_table_write_csv(&ref, path, NULL) == MECH_EIO, "mech_table_write_csv: EIO, no diag");
    mech_diag_init(&d);
    check(mech_table_write_csv(NULL, path, &d) == MECH_EINPUT &&
              refused(&d, "mech_table_write_csv", "t is NULL"),
          "mech_table_write_csv(NULL, ...): refused");
    check(mech_table_write_csv(&ref, NULL, &d) == MECH_EINPUT &&
              refused(&d, "mech_table_write_csv", "path is NULL"),
          "mech_table_write_csv(t, NULL): refused");
    mech_diag_free(&d);
    mech_table_free(&ref);
}

static void parsing(const mech_model *m)
{
    double v = 0;
    char err[128] = "";
    check(mech_parse_value("30 deg", 1, &v, NULL, 0) == MECH_OK && fabs(v - 3.14159265358979323846 / 6) < 1e-15,
          "mech_parse_value(text, 1, &v, NULL, 0)");
    check(mech_parse_value("30", 1, NULL, NULL, 0) == MECH_OK, "mech_parse_value(..., NULL, NULL)");
    check(mech_parse_value("30 kg", 1, NULL, NULL, 64) == MECH_EINPUT,
          "mech_parse_value: an error, err NULL with a size");
    check(mech_parse_value(NULL, 1, &v, err, sizeof err) == MECH_EINPUT &&
              strstr(err, "text is NULL"),
          "mech_parse_value(NULL, ...): refused");
    mech_outputs o = {0};
    check(mech_outputs_parse(m, "B,coupler", NULL, NULL, 0) == MECH_OK,
          "mech_outputs_parse(m, list, NULL, NULL, 0)");
    check(mech_outputs_parse(m, "B,nope", NULL, NULL, 64) == MECH_EINPUT,
          "mech_outputs_parse: an unknown name, out and err NULL");
    check(mech_outputs_parse(m, "B,coupler", &o, NULL, 0) == MECH_OK && o.npoints == 1 &&
              o.nlinks == 1,
          "mech_outputs_parse(m, list, &o, NULL, 0)");
    mech_outputs_free(&o);
    mech_outputs_free(NULL);
    check(mech_outputs_parse(NULL, "B", &o, err, sizeof err) == MECH_EINPUT &&
              strstr(err, "m is NULL") && o.points == NULL,
          "mech_outputs_parse(NULL, ...): refused");
    check(mech_outputs_parse(m, NULL, &o, err, sizeof err) == MECH_EINPUT &&
              strstr(err, "list is NULL"),
          "mech_outputs_parse(m, NULL, ...): refused");
}

/* The pose a file states: d may be NULL; m and out are required; a point
 * the pose or the model does not have is NaN, never a read out of bounds. */
static void poses(const mech_model *m)
{
    mech_diag d;
    mech_pose p;
    double xy[2] = {7, 7};
    int crank = mech_find_link(m, "crank");
    check(mech_pose_guess(m, 0.0, &p, NULL) == MECH_OK && p.frame && p.nlinks == m->nlinks,
          "mech_pose_guess(m, 0, &p, NULL)");
    mech_pose_point(NULL, &p, crank, 0, xy);
    mech_pose_point(m, NULL, crank, 0, xy);
    check(xy[0] == 7 && xy[1] == 7, "mech_pose_point with m or p NULL: nothing");
    mech_pose_point(m, &p, crank, 0, NULL);
    mech_pose_point(m, &p, crank, 0, xy);
    check(isfinite(xy[0]) && isfinite(xy[1]), "mech_pose_point: a point of the pose");
    mech_pose_point(m, &p, m->nlinks, 0, xy);
    check(isnan(xy[0]) && isnan(xy[1]), "mech_pose_point: no such link: NaN");
    mech_pose_point(m, &p, crank, -1, xy);
    check(isnan(xy[0]) && isnan(xy[1]), "mech_pose_point: no such point: NaN");
    mech_pose_free(&p);
    check(p.frame == NULL && p.nlinks == 0, "mech_pose_free empties the pose");
    mech_pose_free(&p);
    mech_pose_free(NULL);
    mech_pose_point(m, &p, crank, 0, xy);
    check(isnan(xy[0]), "mech_pose_point on a freed pose: NaN");
    mech_diag_init(&d);
    check(mech_pose_guess(NULL, 0.0, &p, &d) == MECH_EINPUT && !p.frame &&
              refused(&d, "mech_pose_guess", "m is NULL"),
          "mech_pose_guess(NULL, ...): refused");
    check(mech_pose_guess(m, 0.0, NULL, &d) == MECH_EINPUT &&
              refused(&d, "mech_pose_guess", "out is NULL"),
          "mech_pose_guess(m, q, NULL, &d): refused");
    check(mech_pose_guess(NULL, 0.0, NULL, NULL) == MECH_EINPUT, "mech_pose_guess(NULL, ..., NULL)");
    mech_diag_free(&d);
}

static void sensitivities(const char *slider)
{
    mech_diag d;
    mech_model *m = NULL;
    mech_table t = {0};
    const char *names[] = {"r"};
    if (mech_load_file(slider, &m, NULL) != MECH_OK) {
        check(0, "load the slider-crank");
        return;
    }
    check(mech_solve(m, NULL, &t, NULL, NULL) == MECH_OK &&
              mech_sensitivity(m, NULL, 0, NULL, names, 1, &t, NULL) == MECH_OK &&
              mech_table_column(&t, "d(B.x)/d(r)") > 0,
          "mech_sensitivity(m, NULL, 0, NULL, names, 1, &t, NULL)");
    /* d(B.x)/dr at q = 0 (dead centre, B.x = r + l): 1 */
    int c = mech_table_column(&t, "d(B.x)/d(r)");
    check(c > 0 && fabs(mech_table_get(&t, 0, c) - 1.0) < 1e-9, "d(B.x)/d(r) at q = 0 is 1");
    mech_diag_init(&d);
    check(mech_sensitivity(m, NULL, 0, NULL, NULL, 1, &t, &d) == MECH_EINPUT &&
              refused(&d, "mech_sensitivity", "names is NULL"),
          "mech_sensitivity(names NULL, 1): refused");
    check(mech_sensitivity(m, NULL, 0, NULL, names, 1, NULL, &d) == MECH_EINPUT &&
              refused(&d, "mech_sensitivity", "table is NULL"),
          "mech_sensitivity(table NULL): refused");
    check(mech_sensitivity(m, NULL, 2, NULL, names, 1, &t, &d) == MECH_EINPUT &&
              refused(&d, "mech_sensitivity", "ov is NULL"),
          "mech_sensitivity(ov NULL, nov 2): refused");
    mech_diag_free(&d);
    /* no parameter has a tolerance: an error, with or without a diag */
    check(mech_tolerances(m, NULL, 0, NULL, &t, NULL) == MECH_EINPUT,
          "mech_tolerances(m, NULL, 0, NULL, &t, NULL): no tolerance");
    mech_diag_init(&d);
    check(mech_tolerances(NULL, NULL, 0, NULL, &t, &d) == MECH_EINPUT &&
              refused(&d, "mech_tolerances", "m is NULL"),
          "mech_tolerances(NULL, ...): refused");
    mech_diag_free(&d);
    mech_table_free(&t);
    mech_model_free(&m);
}

int main(int argc, char **argv)
{
    if (argc != 5) {
        fprintf(stderr, "usage: %s FOURBAR.yaml SLIDER-CRANK.yaml BAD.yaml OUTDIR\n", argv[0]);
        return 2;
    }
    check(strcmp(mech_version(), MECH_VERSION) == 0, "mech_version() is the header's MECH_VERSION");
    printf("version %s\n", mech_version());
    diags();
    loads(argv[1], argv[3]);
    mech_model *m = NULL;
    if (mech_load_file(argv[1], &m, NULL) != MECH_OK) {
        printf("FAIL: cannot load %s\n", argv[1]);
        return 1;
    }
    model_calls(m);
    systems(m);
    options(m);
    solves(m, argv[4]);
    parsing(m);
    poses(m);
    mech_model_free(&m);
    sensitivities(argv[2]);
    printf("api_null: %d checks, %d failed\n", checks, failures);
    return failures ? 1 : 0;
}
