/* tests/unit/test_pose.c: mech_pose_guess (src/solve/pose.c), the pose `mech
 * draw` draws beside the assembly: the solver's first iterate (each unknown
 * at its `initial:` guess, else 0; the driver at q) with the links placed
 * from the ground along the spanning tree. The truths are worked by hand
 * from the files' numbers: a frame's origin is its attaching point's place
 * minus the rotated local offset, points follow by rotation. */
#include <criterion/criterion.h>
#include <math.h>

#include "helpers.h"

#define DEG (3.14159265358979323846 / 180)
#define TOL 1e-15

static mech_pose guess(const mech_model *m, double q)
{
    mech_pose p;
    mech_diag d;
    mech_diag_init(&d);
    cr_assert_eq(mech_pose_guess(m, q, &p, &d), MECH_OK);
    mech_diag_free(&d);
    cr_assert_eq(p.nlinks, m->nlinks);
    return p;
}

/* Point `name` of link `link` where the pose puts it. */
static void at(const mech_model *m, const mech_pose *p, const char *link, const char *name,
               double xy[2])
{
    int l = mech_find_link(m, link);
    cr_assert_geq(l, 0, "%s", link);
    for (int k = 0; k < m->links[l].npoints; k++)
        if (strcmp(m->links[l].points[k].name, name) == 0) {
            mech_pose_point(m, p, l, k, xy);
            return;
        }
    cr_assert_fail("no point %s on %s", name, link);
}

static void expect(const mech_model *m, const mech_pose *p, const char *link, const char *name,
                   double x, double y)
{
    double xy[2];
    at(m, p, link, name, xy);
    cr_assert(fabs(xy[0] - x) < TOL && fabs(xy[1] - y) < TOL,
              "%s of %s at (%.17g, %.17g), not (%.17g, %.17g)", name, link, xy[0], xy[1], x, y);
}

/* The four-bar (mechanisms/fourbar.yaml): crank OA 20 mm, coupler AB 60 mm
 * with P 40 mm at 30 deg, rocker CB 50 mm, C = (70, 0); guesses coupler 40
 * deg, rocker 100 deg. With the crank at 30 deg: A = 20 (cos 30, sin 30);
 * the coupler hangs from A at 40 deg; the rocker from C at 100 deg, so the
 * loop is open at B (two places). */
Test(pose, fourbar_guesses)
{
    mech_model *m = load_path("mechanisms/fourbar.yaml");
    mech_pose p = guess(m, 30 * DEG);
    cr_assert_eq(p.kind, MECH_POSE_GUESSED);
    cr_assert_eq(p.q, 30 * DEG);
    double ax = 0.02 * cos(30 * DEG), ay = 0.02 * sin(30 * DEG);
    expect(m, &p, "crank", "O", 0, 0);
    expect(m, &p, "crank", "A", ax, ay);
    expect(m, &p, "coupler", "A", ax, ay);
    expect(m, &p, "coupler", "B", ax + 0.06 * cos(40 * DEG), ay + 0.06 * sin(40 * DEG));
    expect(m, &p, "coupler", "P", ax + 0.04 * cos(70 * DEG), ay + 0.04 * sin(70 * DEG));
    expect(m, &p, "rocker", "C", 0.07, 0);
    expect(m, &p, "rocker", "B", 0.07 + 0.05 * cos(100 * DEG), 0.05 * sin(100 * DEG));
    int c = mech_find_link(m, "coupler");
    cr_assert(fabs(p.frame[3 * c + 2] - 40 * DEG) < TOL);
    cr_assert_eq(p.frame[0], 0);  /* the ground */
    mech_pose_free(&p);
    mech_pose_free(&p);  /* twice: harmless */
    mech_model_free(&m);
}

/* The offset slider-crank: guesses rod 14.5 deg, x_B 156 mm along the
 * ground line through G = (0, 30 mm); the piston is a locked block (its
 * angle is the guide's, 0). The spanning tree reaches the rod from the
 * piston (through B), so the loop is open at A: the rod's A is 120 mm back
 * from B at 14.5 deg, not the crank's A. */
Test(pose, slider_guesses)
{
    mech_model *m = load_path("mechanisms/offset-slider-crank.yaml");
    mech_pose p = guess(m, 0);
    cr_assert_eq(p.kind, MECH_POSE_GUESSED);
    expect(m, &p, "crank", "A", 0.04, 0);
    expect(m, &p, "piston", "B", 0.156, 0.03);
    expect(m, &p, "rod", "B", 0.156, 0.03);
    expect(m, &p, "rod", "A", 0.156 - 0.12 * cos(14.5 * DEG), 0.03 - 0.12 * sin(14.5 * DEG));
    expect(m, &p, "piston", "K", 0.156, 0.02);
    mech_pose_free(&p);
    mech_model_free(&m);
}

/* No `initial:`: kind NONE, every unknown 0 (the coupler and rocker along
 * +x from their attaching points). */
Test(pose, no_guesses)
{
    mech_model *m = load_text("name: t\nunits: {length: mm, angle: deg}\n"
                              "ground: {O: [0, 0], C: [70, 0]}\n"
                              "links:\n"
                              "  crank: {points: {O: [0, 0], A: [20, 0]}}\n"
                              "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
                              "  rocker: {points: {C: [0, 0], B: [50, 0]}}\n"
                              "driver: {link: crank, angle: {from: 90, to: 180, steps: 2}}\n");
    mech_pose p = guess(m, 90 * DEG);
    cr_assert_eq(p.kind, MECH_POSE_NONE);
    double ax = 0.02 * cos(90 * DEG);
    expect(m, &p, "coupler", "B", ax + 0.06, 0.02);
    expect(m, &p, "rocker", "B", 0.12, 0);
    mech_pose_free(&p);
    mech_model_free(&m);
}
