/* tests/unit/test_assembly.c: the comparison of an assembled position with a
 * stated pose (assembly_check_pose, src/solve/assembly.c), which the drawn
 * form of a file calls: the crank's point A of mechanisms/fourbar.yaml at
 * its closed form (20 mm at the driver angle) is not reported; moved 1 mm,
 * it is, by name, as a far-from-guess warning; a point not stated is not
 * looked at. */
#include <math.h>

#include "helpers.h"
#include "solve.h"

Test(assembly, pose_against_closed_form)
{
    mech_model *m = test_load(NULL, "mechanisms/fourbar.yaml");
    mech_solve_options o;
    mech_solve_options_default(&o);
    mech_diag d;
    mech_diag_init(&d);
    solver_plan sp;
    cr_assert_eq(solver_plan_init(&sp, m, &o, &d), MECH_OK);
    cont c;
    mech_solve_stats st = {0};
    cr_assert_eq(cont_init(&c, &sp, &d, &st), 0);
    double q = 0.7;  /* rad */
    cr_assert_eq(cont_start(&c, q), MECH_OK);
    int a = mech_find_point(m, "A"), np = m->npoint_names;
    double *pose = malloc((size_t)np * 2 * sizeof *pose);
    cr_assert(pose);
    for (int i = 0; i < 2 * np; i++)
        pose[i] = NAN;
    pose[2 * a] = 0.020 * cos(q);
    pose[2 * a + 1] = 0.020 * sin(q);
    size_t before = d.count;
    cr_expect_eq(assembly_check_pose(&c.sv, q, c.sv.x, pose, 1e-9, &d), 0);
    cr_expect_eq(d.count, before);
    pose[2 * a + 1] += 0.001;  /* 1 mm off */
    cr_expect_eq(assembly_check_pose(&c.sv, q, c.sv.x, pose, 1e-4, &d), 1);
    cr_assert_eq(d.count, before + 1);
    cr_expect_eq(d.entries[before].kind, MECH_FAIL_FAR_FROM_GUESS);
    cr_expect_eq(d.entries[before].severity, MECH_SEV_WARNING);
    cr_expect(strstr(d.entries[before].message, "point 'A' (link 'crank')") != NULL, "%s",
              d.entries[before].message);
    cr_expect(strstr(d.entries[before].message, "1 mm far from the guess") != NULL, "%s",
              d.entries[before].message);
    free(pose);
    cont_free(&c);
    solver_plan_free(&sp);
    mech_diag_free(&d);
    mech_model_free(&m);
}
