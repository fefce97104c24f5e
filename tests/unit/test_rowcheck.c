/* tests/unit/test_rowcheck.c: what a row read back may hold
 * (src/cli/cmd_rowcheck.c) and the digests and manifests it is tied to
 * (src/cli/cmd_manifest.c), against values worked out by hand: FNV-1a 64 of
 * known strings (the published test vectors), the cells of quoted headers,
 * rows with a field missing, one too many, a quote, a control byte; a
 * sweep row's parameters against a 3 x 4 grid (the library's, built as
 * mech sweep builds it) and every variant status; a sweep read back from
 * a manifest (its grid hash, its samples' tolerances); a batch row read
 * from the right (a name with spaces); escaped manifest arguments. */
#include <criterion/criterion.h>
#include <math.h>
#include <string.h>

#include "cli.h"
#include "study.h"

Test(rowcheck, fnv1a_test_vectors)
{
    /* FNV-1a 64: "" is the offset basis, "a" af63dc4c8601ec8c, "foobar"
     * 85944171f73967e8 (the FNV authors' test vectors) */
    cr_assert_eq(manifest_hash(MANIFEST_HASH0, "", 0), UINT64_C(0xcbf29ce484222325));
    cr_assert_eq(manifest_hash(MANIFEST_HASH0, "a", 1), UINT64_C(0xaf63dc4c8601ec8c));
    cr_assert_eq(manifest_hash(MANIFEST_HASH0, "foobar", 6), UINT64_C(0x85944171f73967e8));
}

Test(rowcheck, digest_of_lines_is_fnv_of_the_text)
{
    line_digest d;
    digest_init(&d);
    digest_line(&d, "foo", 3);
    digest_line(&d, "bar", 3);
    cr_assert_eq(d.h, manifest_hash(MANIFEST_HASH0, "foo\nbar\n", 8));
    cr_assert_eq(d.lines, 2);
    char buf[64];
    long rows;
    uint64_t h;
    digest_format(buf, sizeof buf, DIGEST_TRAILER, 12, UINT64_C(0x0123456789abcdef));
    cr_assert_str_eq(buf, "# mech-digest rows=12 fnv1a64=0123456789abcdef\n");
    buf[strlen(buf) - 1] = '\0';
    cr_assert_eq(digest_parse(buf, DIGEST_TRAILER, &rows, &h), 0);
    cr_assert_eq(rows, 12);
    cr_assert_eq(h, UINT64_C(0x0123456789abcdef));
    cr_assert_eq(digest_parse(buf, DIGEST_BLOCK, &rows, &h), -1, "another kind of line");
    cr_assert_eq(digest_parse("# mech-digest rows=12 fnv1a64=0123456789abcdef x", DIGEST_TRAILER,
                              &rows, &h), -1, "something after it");
}

Test(rowcheck, header_cells_may_be_quoted)
{
    const char *h = "variant [-],\"a,b [m]\",\"say \"\"x\"\" [-]\",status [-]";
    cr_assert_eq(csv_cells(h, strlen(h)), 4);
    cr_assert_eq(csv_cells("x", 1), 1);
    cr_assert_eq(csv_cells("x,", 2), 2);
}

Test(rowcheck, row_shape)
{
    char why[128];
    const char *ok = "7,0.0528,0.43,ok,361,0.038";
    cr_assert_eq(csv_row_shape(ok, strlen(ok), 6, why, sizeof why), 0);
    cr_assert_eq(csv_row_shape(ok, strlen(ok), 7, why, sizeof why), -1);
    cr_assert_str_eq(why, "6 fields, the header has 7 (a field missing)");
    cr_assert_eq(csv_row_shape(ok, strlen(ok), 5, why, sizeof why), -1);
    cr_assert_str_eq(why, "6 fields, the header has 5 (a field too many)");
    const char *quoted = "7,\"0.05\",0.43,ok,361,0.038";
    cr_assert_eq(csv_row_shape(quoted, strlen(quoted), 6, why, sizeof why), -1);
    cr_assert(strstr(why, "quoted"));
    const char *cr = "7,0.05,0.43,ok,361,0.038\r";
    cr_assert_eq(csv_row_shape(cr, strlen(cr), 6, why, sizeof why), -1);
    cr_assert_str_eq(why, "a control character (byte 0x0d) at byte 25");
    cr_assert_eq(csv_row_index("123,x", 5), 123);
    cr_assert_eq(csv_row_index("12a,x", 5), -1);
    cr_assert_eq(csv_row_index(",x", 2), -1);
}

/* A 3 x 4 grid: a in {1, 2, 3}, b in {10, 20, 30, 40}, variants from 100:
 * the library's grid (src/study/sweep_grid.c), as mech sweep builds it. */
static mech_sweep *grid_3x4(void)
{
    mech_sweep *s = NULL;
    cr_assert_eq(mech_sweep_new(&s), MECH_OK);
    cr_assert_eq(mech_sweep_list(s, "a=1,2,3", NULL), MECH_OK);
    cr_assert_eq(mech_sweep_list(s, "b=10,20,30,40", NULL), MECH_OK);
    s->opt.index_offset = 100;
    return s;
}

Test(rowcheck, grid_values_by_index)
{
    mech_sweep *s = grid_3x4();
    /* variant 100 + 4 i + j is (a_i, b_j): 109 is i = 2, j = 1 */
    cr_assert_eq(grid_value(s, 109, 0), 3.0);
    cr_assert_eq(grid_value(s, 109, 1), 20.0);
    cr_assert_eq(grid_value(s, 100, 0), 1.0);
    cr_assert_eq(grid_value(s, 111, 1), 40.0);
    mech_sweep_free(&s);
}

Test(rowcheck, sweep_row_content)
{
    mech_sweep *s = grid_3x4();
    char why[160];
    const char *good = "109,3,20,ok,361,0.5,nan";
    cr_assert_eq(sweep_row_content(s, good, strlen(good), why, sizeof why), 0, "%s", why);
    const char *param = "109,3,30,ok,361,0.5,nan";
    cr_assert_eq(sweep_row_content(s, param, strlen(param), why, sizeof why), -1);
    cr_assert_str_eq(why, "parameter 2 is '30', the grid's value for variant 109 is 20");
    static const struct { const char *row, *why; } bad[] = {
        {"109,<script>,20,ok,361,0.5,nan", "parameter 1 is '<script>'"},
        {"109,3,20,OK!,361,0.5,nan", "status"},
        {"109,3,20,okay,361,0.5,nan", "status"},
        {"109,3,20,no_assembly,361,0.5,nan", "status"},
        {"109,3,20,ok,3.5,0.5,nan", "rows"},
        {"109,3,20,ok,361,0.5x,nan", "metric"},
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cr_assert_eq(sweep_row_content(s, bad[i].row, strlen(bad[i].row), why, sizeof why), -1,
                     "%s", bad[i].row);
        cr_assert(strstr(why, bad[i].why), "%s: %s", bad[i].row, why);
    }
    const char *empty = "109,3,20,ok,361,";
    cr_assert_eq(sweep_row_content(s, empty, strlen(empty), why, sizeof why), -1, "an empty metric");
    mech_sweep_free(&s);
}

/* Every status the library names is a status a row may hold. */
Test(rowcheck, every_variant_status_is_accepted)
{
    mech_sweep *s = grid_3x4();
    char why[160], row[128];
    for (int k = MECH_VARIANT_OK; k <= MECH_VARIANT_NON_FINITE; k++) {
        snprintf(row, sizeof row, "109,3,20,%s,0,nan", mech_variant_status_name(k));
        cr_assert_eq(sweep_row_content(s, row, strlen(row), why, sizeof why), 0, "%s: %s", row, why);
    }
    mech_sweep_free(&s);
}

Test(rowcheck, random_tolerances_round_trip)
{
    mech_sweep *s = NULL, *back = NULL;
    cr_assert_eq(mech_sweep_new(&s), MECH_OK);
    cr_assert_eq(mech_sweep_new(&back), MECH_OK);
    s->opt.nrandom = back->opt.nrandom = 40;
    cr_assert_eq(grid_random_axis(s, "r", "m", 0.04, 5e-5, NULL), MECH_OK);
    cr_assert_eq(grid_random_axis(s, "l", "m", 0.12, 1e-4, NULL), MECH_OK);
    char text[256];
    cr_assert_eq(sweep_tol_format(s, text, sizeof text), 0);
    cr_assert_eq(sweep_tol_parse(back, text), 0, "%s", text);
    cr_assert_eq(back->naxes, 2);
    for (int k = 0; k < 2; k++) {  /* hexadecimal floats: exact */
        cr_assert_eq(back->axes[k].nominal, s->axes[k].nominal);
        cr_assert_eq(back->axes[k].tol, s->axes[k].tol);
        for (long v = 0; v < 40; v++)
            cr_assert_eq(grid_value(back, v, k), grid_value(s, v, k));
    }
    mech_sweep_free(&back);
    static const char *const bad[] = {"", "0x1p-3", "0x1p-3~", "0x1p-3~0,0x1p-2~0x1p-9",
                                      "0x1p-3~-0x1p-9", "0x1p-3~0x1p-9,"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        cr_assert_eq(mech_sweep_new(&back), MECH_OK);
        cr_assert_eq(sweep_tol_parse(back, bad[i]), -1, "'%s'", bad[i]);
        mech_sweep_free(&back);
    }
    mech_sweep_free(&s);
}

/* FNV-1a 64 of the NUL-terminated strings, one after the other. */
static uint64_t hash_texts(const char *const *t, size_t n)
{
    uint64_t h = MANIFEST_HASH0;
    for (size_t i = 0; i < n; i++)
        h = manifest_hash(h, t[i], strlen(t[i]) + 1);
    return h;
}

/* A shard's manifest read back as mech sweep's options (its own table):
 * the grid that hashes to grid=, the offset, the samples from tol=. */
Test(rowcheck, sweep_of_a_manifest)
{
    static const char *const texts[] = {"a", "1", "2", "3", "b", "10", "20", "30", "40"};
    manifest m = {.command = "sweep", .offset = 100,
                  .args = "--list a=1,2,3 --list b=10,20,30,40 --metric range:x"};
    m.grid = hash_texts(texts, 9);
    mech_sweep *s = NULL;
    cr_assert_eq(sweep_of_manifest(&m, &s), 0);
    cr_assert_eq(mech_sweep_nparams(s), 2);
    cr_assert_eq(grid_value(s, 109, 0), 3.0);
    cr_assert_eq(grid_value(s, 109, 1), 20.0);
    mech_sweep_free(&s);
    manifest edited = m;
    snprintf(edited.args, sizeof edited.args, "--list a=1,2,3 --list b=10,20,30,41");
    cr_assert_eq(sweep_of_manifest(&edited, &s), -1, "the grid hash no longer matches");
    cr_assert_null(s);
    static const char *const foreign[] = {"--list a=1,2,3 --list b=10,20,30,40 --help",
                                          "--list a=1,2,3 --list b=10,20,30,40 -o x.csv",
                                          "--list a=1,2,3 --list b=10,20,30,40 file.yaml",
                                          "--list a=1,2,3 --list b=10,20,30,40 --nope"};
    for (size_t i = 0; i < sizeof foreign / sizeof foreign[0]; i++) {
        snprintf(edited.args, sizeof edited.args, "%s", foreign[i]);
        cr_assert_eq(sweep_of_manifest(&edited, &s), -1, "%s", foreign[i]);
    }
    snprintf(edited.command, sizeof edited.command, "batch");
    snprintf(edited.args, sizeof edited.args, "%s", m.args);
    cr_assert_eq(sweep_of_manifest(&edited, &s), -1, "a batch's manifest");

    static const char *const sample[] = {"random 40 seed 7"};
    manifest r = {.command = "sweep", .offset = 3, .args = "--random 40 --seed 7",
                  .tol = "0x1.47ae147ae147bp-5~0x1.a36e2eb1c432dp-15"};
    r.grid = hash_texts(sample, 1);
    cr_assert_eq(sweep_of_manifest(&r, &s), 0);
    cr_assert_eq(mech_sweep_nparams(s), 1);
    for (long v = 3; v < 43; v++)  /* bit for bit what mech sweep writes */
        cr_assert_eq(grid_value(s, v, 0), 0.04 + 5e-5 * sweep_random_unit(7, v, 0));
    mech_sweep_free(&s);
    r.tol[0] = '\0';
    cr_assert_eq(sweep_of_manifest(&r, &s), -1, "--random without tol=");
    static const char *const both[] = {"a", "1", "2", "random 40 seed 7"};
    manifest rg = r;  /* a grid and samples: mech sweep refuses them together */
    snprintf(rg.args, sizeof rg.args, "--list a=1,2 --random 40 --seed 7");
    snprintf(rg.tol, sizeof rg.tol, "0x1p-3~0x1p-9");
    rg.grid = hash_texts(both, 4);
    cr_assert_eq(sweep_of_manifest(&rg, &s), -1, "--list with --random");
}
Test(rowcheck, batch_row_from_the_right)
{
    batch_row br;
    char why[128];
    const char *row = "my file  name                 kept       361     4.44e-16          nan - 12 b6e651d7d06f224b";
    cr_assert_eq(batch_row_parse(row, strlen(row), 1, &br, why, sizeof why), 0, "%s", why);
    cr_assert_eq(br.name_len, 13);
    cr_assert_eq(strncmp(br.name, "my file  name", 13), 0);
    cr_assert_str_eq(br.status, "kept");
    cr_assert_eq(br.steps, 361);
    cr_assert_eq(br.residual, 4.44e-16);
    cr_assert(isnan(br.us_per_step));
    cr_assert_str_eq(br.golden, "-");
    cr_assert_eq(br.index, 12);
    cr_assert(br.has_csv);
    cr_assert_eq(br.csv, UINT64_C(0xb6e651d7d06f224b));
    const char *plain = "fourbar                      ok         361     2.78e-17         1.42 match";
    cr_assert_eq(batch_row_parse(plain, strlen(plain), 0, &br, why, sizeof why), 0, "%s", why);
    cr_assert_eq(br.index, -1);
    cr_assert_str_eq(br.golden, "match");
    const char *missing = "fourbar ok 361 2.78e-17 - 4 -";  /* no us/step */
    cr_assert_eq(batch_row_parse(missing, strlen(missing), 1, &br, why, sizeof why), -1);
    const char *nohash = "fourbar ok 361 2.78e-17 1.4 - 4";
    cr_assert_eq(batch_row_parse(nohash, strlen(nohash), 1, &br, why, sizeof why), -1);
    cr_assert(strstr(why, "CSV hash"));
}

Test(rowcheck, manifest_arguments_unescaped)
{
    manifest m;
    memset(&m, 0, sizeof m);
    manifest_add_arg(&m, "--list");
    manifest_add_arg(&m, "l=1 mm,2\\x");
    manifest_add_arg(&m, "a\tb");
    cr_assert_str_eq(m.args, "--list l=1\\ mm,2\\\\x a\\x09b");
    char **argv;
    int argc;
    cr_assert_eq(manifest_args_split(m.args, &argv, &argc), 0);
    cr_assert_eq(argc, 3);
    cr_assert_str_eq(argv[0], "--list");
    cr_assert_str_eq(argv[1], "l=1 mm,2\\x");
    cr_assert_str_eq(argv[2], "a\tb");
    cr_assert_null(argv[3]);
    free(argv);
}

Test(rowcheck, manifest_line_round_trip)
{
    manifest m, back;
    memset(&m, 0, sizeof m);
    snprintf(m.version, sizeof m.version, "0.1.0");
    snprintf(m.command, sizeof m.command, "sweep");
    m.shard_k = 1;
    m.shard_m = 3;
    m.rows = 10;
    m.total = 30;
    m.input = 1;
    m.grid = 2;
    manifest_add_arg(&m, "--vary");
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    manifest_write(&m, f);
    fclose(f);
    text[strlen(text) - 1] = '\0';
    cr_assert(strstr(text, " tol=- args=--vary"), "%s", text);
    cr_assert_eq(manifest_parse(text, &back), 0);
    cr_assert(manifest_same_run(&m, &back));
    cr_assert_eq(back.tol[0], '\0');
    free(text);
    m.total = MANIFEST_MAX_TOTAL + 1;  /* forged beyond what a run can be */
    text = NULL;
    f = open_memstream(&text, &size);
    manifest_write(&m, f);
    fclose(f);
    text[strlen(text) - 1] = '\0';
    cr_assert_eq(manifest_parse(text, &back), -1);
    free(text);
}
