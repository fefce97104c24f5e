/* tests/unit/test_output_h5.c: the HDF5 output (src/output/output_h5.c),
 * read back with the HDF5 library's own calls, not with mech's reader:
 * every column a float64 dataset of the table's exact doubles with its
 * unit, the root attributes in the CSV's order; then mech's reader
 * (compare_read_h5, used by mech compare) against the same table, and its
 * errors on a file that is not mech's. */
#include <criterion/criterion.h>
#include <hdf5.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "output.h"
#include "cli.h"

static char path[256];

static void setup(void)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(path, sizeof path, "%s/mech-h5-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    int fd = mkstemp(path);
    cr_assert(fd >= 0);
    close(fd);
}

static void cleanup(void) { unlink(path); }

/* 3 columns x 4 rows with values a CSV at 15 digits would round */
static mech_column cols[] = {{"q", "rad"}, {"P.x", "m"}, {"crank.torque", "N*m"}};
static double vals[] = {0.0, 0.1 + 0.2, -1e-300, 0.1, 3.141592653589793, 5e-324,
                        0.2, 1.0 / 3.0, INFINITY, 0.3, -0.0, NAN};
static mech_table table = {cols, 3, vals, 4, 4, NULL, 0};

static char *attr_string(hid_t obj, const char *name, int i)
{
    hid_t a = H5Aopen(obj, name, H5P_DEFAULT);
    cr_assert(a >= 0, "attribute %s", name);
    hid_t type = H5Tcopy(H5T_C_S1);
    H5Tset_size(type, H5T_VARIABLE);
    H5Tset_cset(type, H5T_CSET_UTF8);  /* the file's strings are UTF-8 */
    hid_t space = H5Aget_space(a);
    hssize_t n = H5Sget_simple_extent_npoints(space);
    char **v = calloc((size_t)n, sizeof *v);
    cr_assert(H5Aread(a, type, v) >= 0);
    char *out = strdup(v[i]);
    H5Dvlen_reclaim(type, space, H5P_DEFAULT, v);
    free(v);
    H5Sclose(space);
    H5Tclose(type);
    H5Aclose(a);
    return out;
}

TestSuite(output_h5, .init = setup, .fini = cleanup);

Test(output_h5, columns_units_and_manifest_read_by_the_hdf5_library)
{
    const char *keys[] = {"command", "input"}, *values[] = {"solve", "m.yaml"};
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(output_write_h5(&table, path, keys, values, 2, &d), MECH_OK);
    mech_diag_free(&d);
    cr_assert(output_file_is_h5(path));
    hid_t f = H5Fopen(path, H5F_ACC_RDONLY, H5P_DEFAULT);
    cr_assert(f >= 0);
    for (int c = 0; c < 3; c++) {
        char *name = attr_string(f, "columns", c), *unit = attr_string(f, "units", c);
        cr_assert_str_eq(name, cols[c].name);
        cr_assert_str_eq(unit, cols[c].unit);
        hid_t ds = H5Dopen2(f, cols[c].name, H5P_DEFAULT);
        cr_assert(ds >= 0, "dataset %s", name);
        char *du = attr_string(ds, "unit", 0);
        cr_assert_str_eq(du, cols[c].unit);
        double got[4];
        cr_assert(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, got) >= 0);
        for (int r = 0; r < 4; r++) {
            double want = vals[r * 3 + c];
            cr_assert(memcmp(&got[r], &want, sizeof want) == 0 || (isnan(got[r]) && isnan(want)),
                      "%s row %d: %.17g, not %.17g", name, r, got[r], want);
        }
        H5Dclose(ds);
        free(name);
        free(unit);
        free(du);
    }
    char *rows = attr_string(f, "rows", 0), *cmd = attr_string(f, "command", 0);
    cr_assert_str_eq(rows, "4");
    cr_assert_str_eq(cmd, "solve");
    free(rows);
    free(cmd);
    H5Fclose(f);
}

Test(output_h5, mech_reads_back_the_same_table)
{
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(output_write_h5(&table, path, NULL, NULL, 0, &d), MECH_OK);
    compare_table t;
    cr_assert_eq(compare_read_csv(path, &t, &d), MECH_OK);  /* by the signature */
    cr_assert_eq(t.ncols, 3);
    cr_assert_eq(t.nrows, 4);
    for (size_t i = 0; i < 12; i++)
        cr_assert(memcmp(&t.values[i], &vals[i], sizeof vals[i]) == 0 ||
                  (isnan(t.values[i]) && isnan(vals[i])), "value %zu", i);
    cr_assert_str_eq(t.names[2], "crank.torque");
    cr_assert_str_eq(t.units[2], "N*m");
    compare_table_free(&t);
    mech_diag_free(&d);
}

Test(output_h5, an_hdf5_file_without_the_layout_is_an_error)
{
    hid_t f = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    cr_assert(f >= 0);
    H5Fclose(f);
    mech_diag d;
    mech_diag_init(&d);
    compare_table t;
    cr_assert_eq(compare_read_csv(path, &t, &d), MECH_EINPUT);
    char *text = NULL;
    size_t n = 0;
    FILE *m = open_memstream(&text, &n);
    mech_diag_print(&d, m);
    fclose(m);
    cr_assert(strstr(text, "without mech's layout"), "%s", text);
    free(text);
    mech_diag_free(&d);
}

/* mech sweep --shard 1/2 -o OUT.h5, run in this process (cmd_sweep), read
 * with the HDF5 library: the status a string dataset, the parameter and
 * index float64, and the shard's manifest as root attributes (the manifest
 * line and the digest line that mech merge reads back). */
Test(output_h5, a_sweep_shard_as_hdf5_with_its_manifest)
{
    char out[300];
    snprintf(out, sizeof out, "%s.h5", path);
    char *argv[] = {"sweep", "mechanisms/conveyor.yaml", "--vary", "l1=50mm:64mm:5", "--metric",
                    "range:E.x", "--shard", "1/2", "-q", "-j", "1", "-o", out, NULL};
    cr_assert_eq(cmd_sweep(13, argv), 0);
    hid_t f = H5Fopen(out, H5F_ACC_RDONLY, H5P_DEFAULT);
    cr_assert(f >= 0);
    static const char *const want[][2] = {
        {"command", "sweep"}, {"input", "mechanisms/conveyor.yaml"}, {"shard", "1/2"},
        {"total", "5"}, {"offset", "0"}, {"rows", "2"}, {"tol", "-"},
        {"args", "--vary l1=50mm:64mm:5 --metric range:E.x"},
        {"csv_header", "variant [-],l1 [m],status [-],rows [-],range:E.x [m]"}};
    for (size_t i = 0; i < sizeof want / sizeof want[0]; i++) {
        char *v = attr_string(f, want[i][0], 0);
        cr_assert_str_eq(v, want[i][1], "attribute %s", want[i][0]);
        free(v);
    }
    static const char *const present[] = {"mech_version", "input_digest", "grid", "manifest",
                                          "digest"};
    for (size_t i = 0; i < sizeof present / sizeof present[0]; i++) {
        char *v = attr_string(f, present[i], 0);
        cr_assert(strlen(v) > 0, "attribute %s", present[i]);
        free(v);
    }
    char *m = attr_string(f, "manifest", 0), *dg = attr_string(f, "digest", 0);
    cr_assert(strncmp(m, "# mech-manifest version=", 24) == 0, "%s", m);
    cr_assert(strncmp(dg, "# mech-digest rows=2 fnv1a64=", 29) == 0, "%s", dg);
    free(m);
    free(dg);
    char *c4 = attr_string(f, "columns", 4);
    cr_assert_str_eq(c4, "range:E.x");
    free(c4);
    hid_t st = H5Dopen2(f, "status", H5P_DEFAULT);
    cr_assert(st >= 0);
    hid_t type = H5Dget_type(st);
    cr_assert_eq(H5Tget_class(type), H5T_STRING);
    H5Tclose(type);
    char *unit = attr_string(st, "unit", 0);
    cr_assert_str_eq(unit, "-");
    free(unit);
    H5Dclose(st);
    hid_t ds = H5Dopen2(f, "variant", H5P_DEFAULT);
    double idx[2];
    cr_assert(H5Dread(ds, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, idx) >= 0);
    cr_assert(idx[0] == 1 && idx[1] == 3, "the shard's variants: %g %g", idx[0], idx[1]);
    H5Dclose(ds);
    hid_t l1 = H5Dopen2(f, "l1", H5P_DEFAULT);
    double v[2];
    cr_assert(H5Dread(l1, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, v) >= 0);
    cr_assert(v[0] == 0.0535 && v[1] == 0.0605, "l1: %.17g %.17g", v[0], v[1]);
    H5Dclose(l1);
    H5Fclose(f);
    unlink(out);
}
