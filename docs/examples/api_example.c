/* api_example.c: solve a mechanism with libmech and print some columns.
 *
 *   cc api_example.c $(pkg-config --cflags --libs mech) -o api_example
 *   ./api_example mechanisms/fourbar.yaml B.x B.vx coupler.omega
 *
 * prints "q [rad],B.x [m],..." then one row per driver position, each value
 * as %.17g (which reads back as the same double, as `mech solve`'s CSV). */
#include <stdio.h>
#include <stdlib.h>

#include <mech.h>

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: %s FILE [COLUMN...]\n", argv[0]);
        return 2;
    }

    /* 1. Load: the model (SI units) or every error, with file:line:column. */
    mech_diag diag;
    mech_diag_init(&diag);
    mech_model *model = NULL;
    if (mech_load_file(argv[1], &model, &diag) != MECH_OK) {
        mech_diag_print(&diag, stderr);
        mech_diag_free(&diag);
        return 2;
    }

    /* 2. Check the structure: connectivity, mobility against the drivers. */
    mech_summary summary;
    if (mech_check(model, &summary, &diag) != MECH_OK) {
        mech_diag_print(&diag, stderr);
        mech_diag_free(&diag);
        mech_model_free(&model);
        return 2;
    }
    fprintf(stderr, "%s: %d links, %d unknowns, mobility %d\n", model->name, summary.nlinks,
            summary.nunknowns, summary.mobility);

    /* 3. Analyse once (equations, tape, pattern; read only afterwards, so
     * threads may share it), then solve the file's driver range. One call,
     * mech_solve(model, &options, &table, &stats, &diag), does both. */
    mech_solve_options options;
    mech_solve_options_init(&options, sizeof options);  /* the defaults, with its size */
    mech_analysis *analysis = NULL;
    mech_table table = {0};
    mech_solve_stats stats;
    int status = mech_analysis_new(model, &options, &analysis, &diag);
    if (status == MECH_OK)
        status = mech_analysis_solve(analysis, NULL, 0, &table, &stats, &diag);
    if (status != MECH_OK) {
        mech_diag_print(&diag, stderr); /* where and why; table holds the rows solved */
        mech_table_free(&table);
        mech_analysis_free(&analysis);
        mech_diag_free(&diag);
        mech_model_free(&model);
        return status == MECH_ESOLVE ? 1 : 2;
    }
    fprintf(stderr, "%d rows, %.2f Newton iterations per row\n", table.nrows,
            (double)stats.iterations / table.nrows);

    /* 4. Read columns by name: column 0 is the driver position q. */
    int ncols = argc - 1;
    int *col = malloc((size_t)ncols * sizeof *col);
    if (!col) {
        status = MECH_ENOMEM;
        goto done;
    }
    col[0] = 0;
    for (int i = 1; i < ncols; i++) {
        col[i] = mech_table_column(&table, argv[i + 1]);
        if (col[i] < 0) {
            fprintf(stderr, "no column '%s'\n", argv[i + 1]);
            status = MECH_EINPUT;
            goto done;
        }
    }
    for (int i = 0; i < ncols; i++)
        printf("%s%s [%s]", i ? "," : "", table.columns[col[i]].name, table.columns[col[i]].unit);
    printf("\n");
    for (int r = 0; r < table.nrows; r++) {
        for (int i = 0; i < ncols; i++)
            printf("%s%.17g", i ? "," : "", mech_table_get(&table, r, col[i]));
        printf("\n");
    }

done:
    /* 5. Free: each object with its own call (all accept NULL or an empty
     * table); the analysis borrows the model, so the model goes last. */
    free(col);
    mech_table_free(&table);
    mech_analysis_free(&analysis);
    mech_diag_free(&diag);
    mech_model_free(&model);
    return status == MECH_OK ? 0 : 2;
}
