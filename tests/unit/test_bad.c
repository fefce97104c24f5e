/* tests/unit/test_bad.c: the corpus of malformed mechanism files (tests/bad/).
 *
 * Every file tests/bad/NN-name.yaml starts with comment lines that give the
 * diagnostics it must produce, exactly and in order, one per line:
 *   # expect: LINE:COL: error: MESSAGE
 *   # expect: LINE:COL: note: MESSAGE
 * Each file is loaded with mech_load_file and, when that succeeds, checked
 * with mech_check; the list of "LINE:COL: severity: MESSAGE" strings of all
 * the diagnostics must equal the list of expectations (same count, same
 * order). The directory is scanned at run time (the test binary runs from
 * the repository root), so a new file is a new test. */
#include <criterion/criterion.h>
#include <criterion/parameterized.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mech.h"

#ifndef BAD_DIR
#define BAD_DIR "tests/bad"
#endif
#define MIN_FILES 30
#define EXPECT_TAG "# expect: "

typedef struct bad_file {
    char path[512];  /* fixed size: parameters are copied between processes */
} bad_file;

static int has_suffix(const char *s, const char *suffix)
{
    size_t n = strlen(s), k = strlen(suffix);
    return n >= k && strcmp(s + n - k, suffix) == 0;
}

static int cmp_name(const void *a, const void *b)
{
    return strcmp(((const bad_file *)a)->path, ((const bad_file *)b)->path);
}

/* The paths of the .yaml files in tests/bad, sorted; *count of them (0 if the directory is
 * missing). The array is from `alloc` (cr_malloc for parameters). */
static bad_file *scan_bad_dir(size_t *count, void *(*alloc)(size_t))
{
    *count = 0;
    DIR *dir = opendir(BAD_DIR);
    if (!dir)
        return NULL;
    size_t n = 0;
    for (struct dirent *e; (e = readdir(dir));)
        if (has_suffix(e->d_name, ".yaml"))
            n++;
    bad_file *files = alloc((n ? n : 1) * sizeof *files);
    if (!files) {
        closedir(dir);
        return NULL;
    }
    rewinddir(dir);
    for (struct dirent *e; (e = readdir(dir)) && *count < n;) {
        if (!has_suffix(e->d_name, ".yaml"))
            continue;
        snprintf(files[*count].path, sizeof files[*count].path, "%s/%s", BAD_DIR, e->d_name);
        (*count)++;
    }
    closedir(dir);
    qsort(files, *count, sizeof *files, cmp_name);
    return files;
}

/* A growing text of lines. */
typedef struct text {
    char *s;
    size_t len, cap;
    size_t lines;
} text;

static text text_new(void)
{
    text t = {malloc(256), 0, 256, 0};
    cr_assert_not_null(t.s, "out of memory");
    t.s[0] = '\0';
    return t;
}

static void text_add_line(text *t, const char *line, size_t n)
{
    if (t->len + n + 2 > t->cap) {
        t->cap = 2 * (t->len + n + 2);
        t->s = realloc(t->s, t->cap);
        cr_assert_not_null(t->s, "out of memory");
    }
    memcpy(t->s + t->len, line, n);
    t->len += n;
    t->s[t->len++] = '\n';
    t->s[t->len] = '\0';
    t->lines++;
}

/* The "# expect: " lines of a file, without the tag, one per line; they must
 * be in the comment lines that start the file. */
static text read_expectations(const char *path)
{
    text t = text_new();
    FILE *f = fopen(path, "r");
    cr_assert_not_null(f, "%s: cannot open", path);
    char line[2048];
    int header = 1, lineno = 0;
    while (fgets(line, sizeof line, f)) {
        size_t n = strcspn(line, "\r\n");
        lineno++;
        if (line[0] != '#')
            header = 0;
        if (strncmp(line, EXPECT_TAG, strlen(EXPECT_TAG)) != 0)
            continue;
        cr_expect(header, "%s:%d: '" EXPECT_TAG "' after the first line that is not a comment "
                  "(expectations go at the top of the file)", path, lineno);
        text_add_line(&t, line + strlen(EXPECT_TAG), n - strlen(EXPECT_TAG));
    }
    fclose(f);
    return t;
}

/* Load (and, when that succeeds, check) a file; its diagnostics as lines. */
static text run_diagnostics(const char *path)
{
    static const char *const sev[] = {"error", "warning", "note"};
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    if (mech_load_file(path, &m, &d) == MECH_OK) {
        mech_summary s;
        mech_check(m, &s, &d);
    }
    text t = text_new();
    for (size_t i = 0; i < d.count; i++) {
        const mech_diag_entry *e = &d.entries[i];
        char line[2048];
        int n = snprintf(line, sizeof line, "%d:%d: %s: %s", e->mark.line, e->mark.col,
                         sev[e->severity], e->message);
        text_add_line(&t, line, n < (int)sizeof line ? (size_t)n : sizeof line - 1);
    }
    if (d.truncated)
        text_add_line(&t, "(diagnostics truncated)", strlen("(diagnostics truncated)"));
    mech_model_free(&m);
    mech_diag_free(&d);
    return t;
}

static void free_params(struct criterion_test_params *ctp)
{
    cr_free(ctp->params);
}

ParameterizedTestParameters(bad, file)
{
    size_t n;
    bad_file *files = scan_bad_dir(&n, cr_malloc);
    return cr_make_param_array(bad_file, files, n, free_params);
}

ParameterizedTest(bad_file *f, bad, file)
{
    text want = read_expectations(f->path);
    cr_assert(want.lines > 0, "%s: no '" EXPECT_TAG "LINE:COL: error: MESSAGE' line at the top",
              f->path);
    text got = run_diagnostics(f->path);
    cr_expect(strcmp(want.s, got.s) == 0,
              "%s: diagnostics differ\n--- expected (%zu):\n%s--- actual (%zu):\n%s", f->path,
              want.lines, want.s, got.lines, got.s);
    /* line by line, so that the first difference is easy to spot */
    const char *w = want.s, *g = got.s;
    for (size_t i = 0; *w && *g; i++) {
        size_t wn = strcspn(w, "\n"), gn = strcspn(g, "\n");
        cr_expect(wn == gn && strncmp(w, g, wn) == 0,
                  "%s: diagnostic %zu differs\n  expected: %.*s\n  actual:   %.*s", f->path,
                  i + 1, (int)wn, w, (int)gn, g);
        w += wn + 1;
        g += gn + 1;
    }
    free(want.s);
    free(got.s);
}

Test(bad, corpus_size)
{
    size_t n;
    bad_file *files = scan_bad_dir(&n, malloc);
    free(files);
    cr_assert(n >= MIN_FILES, "%s: %zu malformed files found, expected at least %d (is the "
              "test run from the repository root?)", BAD_DIR, n, MIN_FILES);
}
