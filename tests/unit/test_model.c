/* tests/unit/test_model.c: loading mechanism files (src/load/load.c) and the
 * structural check (src/equations/check.c): every shipped mechanism, Gruebler-Kutzbach
 * counts of textbook mechanisms, SI conversion of the geometry, defaults.
 *
 * Tests run from the repository root (make test does), so mechanisms/ is
 * found there.
 *
 * Tolerances: loaded values are one or two multiplications of correctly
 * rounded constants (value * unit scale), so 4 ulp relative is ample (EXACT);
 * a polar point adds a sin or cos (within 1 ulp in glibc) of a rounded angle,
 * hence 16 ulp (TRIG). */
#include <criterion/criterion.h>
#include <dirent.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "base.h"

#define PI_ 3.14159265358979323846
#define EXACT 4.0
#define TRIG 16.0

static int rel_close(double got, double want, double ulps)
{
    if (want == 0.0)
        return fabs(got) <= ulps * DBL_MIN;
    return fabs(got - want) <= ulps * DBL_EPSILON * fabs(want);
}

#define expect_close(got, want, ulps, ...) cr_expect(rel_close((got), (want), (ulps)), __VA_ARGS__)

/* All diagnostics as one string, for failure messages. */
static const char *diag_text(const mech_diag *d)
{
    static char buf[4096];
    size_t n = 0;
    buf[0] = '\0';
    for (size_t i = 0; i < d->count && n < sizeof buf; i++) {
        const mech_diag_entry *e = &d->entries[i];
        int w = snprintf(buf + n, sizeof buf - n, "\n  %d:%d: %s", e->mark.line, e->mark.col,
                         e->message);
        if (w < 0)
            break;
        n += (size_t)w;
    }
    return buf;
}

/* Index of the first diagnostic whose message contains `part`, or -1. */
static int diag_find(const mech_diag *d, const char *part)
{
    for (size_t i = 0; i < d->count; i++)
        if (strstr(d->entries[i].message, part))
            return (int)i;
    return -1;
}

/* Load YAML text that must be valid. */
static mech_model *load_ok(const char *name, const char *yaml)
{
    mech_diag d;
    mech_diag_init(&d);
    mech_model *m = NULL;
    int rc = mech_load_string(yaml, strlen(yaml), name, &m, &d);
    cr_assert_eq(rc, MECH_OK, "%s does not load:%s", name, diag_text(&d));
    cr_assert_not_null(m);
    mech_diag_free(&d);
    return m;
}

/* Load YAML text that must be rejected; d keeps the diagnostics. */
static void load_fails(const char *name, const char *yaml, mech_diag *d)
{
    mech_model *m = NULL;
    int rc = mech_load_string(yaml, strlen(yaml), name, &m, d);
    cr_expect_eq(rc, MECH_EINPUT, "%s should not load", name);
    cr_expect_null(m);
    cr_expect_gt(d->nerrors, 0);
    mech_model_free(&m);
}

typedef struct counts {
    int nlinks, nrevolute, nprismatic, npin_in_slot, nunknowns, nloops, nequations, mobility;
} counts;

/* Run mech_check and compare every count of the summary. */
static int check_counts(const char *name, const mech_model *m, counts want, mech_diag *d)
{
    mech_summary s;
    int rc = mech_check(m, &s, d);
    cr_expect_eq(s.nlinks, want.nlinks, "%s: nlinks %d, want %d", name, s.nlinks, want.nlinks);
    cr_expect_eq(s.nrevolute, want.nrevolute, "%s: nrevolute %d, want %d", name, s.nrevolute,
                 want.nrevolute);
    cr_expect_eq(s.nprismatic, want.nprismatic, "%s: nprismatic %d, want %d", name,
                 s.nprismatic, want.nprismatic);
    cr_expect_eq(s.npin_in_slot, want.npin_in_slot, "%s: npin_in_slot %d, want %d", name,
                 s.npin_in_slot, want.npin_in_slot);
    cr_expect_eq(s.nunknowns, want.nunknowns, "%s: nunknowns %d, want %d", name, s.nunknowns,
                 want.nunknowns);
    cr_expect_eq(s.nloops, want.nloops, "%s: nloops %d, want %d", name, s.nloops, want.nloops);
    cr_expect_eq(s.nequations, want.nequations, "%s: nequations %d, want %d", name,
                 s.nequations, want.nequations);
    cr_expect_eq(s.mobility, want.mobility, "%s: mobility %d, want %d", name, s.mobility,
                 want.mobility);
    cr_expect_eq(s.ndrivers, 1, "%s: one driver", name);
    return rc;
}

/* ---- every shipped mechanism --------------------------------------------- */

Test(load_files, every_file_loads_and_checks)
{
    DIR *dir = opendir("mechanisms");
    cr_assert_not_null(dir, "run the tests from the repository root (mechanisms/ not found)");
    int nfiles = 0;
    struct dirent *e;
    while ((e = readdir(dir)) != NULL) {
        size_t len = strlen(e->d_name);
        if (len < 6 || strcmp(e->d_name + len - 5, ".yaml") != 0)
            continue;
        char path[512];
        snprintf(path, sizeof path, "mechanisms/%s", e->d_name);
        nfiles++;
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        int rc = mech_load_file(path, &m, &d);
        cr_expect_eq(rc, MECH_OK, "%s does not load:%s", path, diag_text(&d));
        if (rc == MECH_OK) {
            mech_summary s;
            rc = mech_check(m, &s, &d);
            cr_expect_eq(rc, MECH_OK, "%s fails mech_check:%s", path, diag_text(&d));
            cr_expect_eq(s.mobility, s.ndrivers, "%s: mobility %d, drivers %d", path, s.mobility,
                         s.ndrivers);
            cr_expect_eq(s.nunknowns, s.nequations, "%s: %d unknowns, %d equations", path,
                         s.nunknowns, s.nequations);
            cr_expect_gt(m->driver.nvalues, 0, "%s: driver positions", path);
        }
        mech_model_free(&m);
        mech_diag_free(&d);
    }
    closedir(dir);
    cr_expect_geq(nfiles, 2, "mechanisms/ holds at least fourbar.yaml and slider-crank.yaml");
}

/* The complete examples of docs/format.md (section 15): every ```yaml block
 * after the heading "## 15." must load and check, so the documentation
 * cannot drift from the loader. */
Test(load_files, documented_examples_load_and_check)
{
    FILE *f = fopen("docs/format.md", "rb");
    cr_assert_not_null(f, "docs/format.md not found (run from the repository root)");
    static char doc[1 << 18];
    size_t n = fread(doc, 1, sizeof doc - 1, f);
    fclose(f);
    doc[n] = '\0';
    const char *s = strstr(doc, "\n## 15.");
    cr_assert_not_null(s, "no section 15 in docs/format.md");
    const char *end = strstr(s + 1, "\n## ");
    int nexamples = 0;
    while ((s = strstr(s, "```yaml\n")) != NULL && (!end || s < end)) {
        s += strlen("```yaml\n");
        const char *close = strstr(s, "\n```");
        cr_assert_not_null(close, "unclosed ```yaml block");
        char name[64];
        snprintf(name, sizeof name, "docs/format.md example %d", ++nexamples);
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        int rc = mech_load_string(s, (size_t)(close - s) + 1, name, &m, &d);
        cr_expect_eq(rc, MECH_OK, "%s does not load:%s", name, diag_text(&d));
        if (rc == MECH_OK) {
            mech_summary sum;
            rc = mech_check(m, &sum, &d);
            cr_expect_eq(rc, MECH_OK, "%s fails mech_check:%s", name, diag_text(&d));
        }
        mech_model_free(&m);
        mech_diag_free(&d);
        s = close + 4;
    }
    cr_expect_eq(nexamples, 2, "section 15 has the four-bar and the slider-crank");
}

/* ---- Gruebler-Kutzbach counts ---------------------------------------------- */

static const char FOURBAR[] =
    "name: four-bar\n"
    "ground: {O: [0, 0], C: [0.07, 0]}\n"
    "links:\n"
    "  crank:   {points: {O: [0, 0], A: [0.02, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [0.06, 0]}}\n"
    "  rocker:  {points: {C: [0, 0], B: [0.05, 0]}}\n"
    "driver: {link: crank, angle: {from: 0 deg, to: 360 deg, steps: 360}}\n";

Test(mobility, fourbar)
{
    mech_model *m = load_ok("fourbar", FOURBAR);
    mech_diag d;
    mech_diag_init(&d);
    int rc = check_counts("fourbar", m, (counts){4, 4, 0, 0, 2, 1, 2, 1}, &d);
    cr_expect_eq(rc, MECH_OK, "%s", diag_text(&d));
    /* the four revolutes come from the shared point names, named after them */
    cr_expect_eq(m->njoints, 4);
    static const char *const pins[] = {"O", "A", "B", "C"};
    for (int i = 0; i < 4; i++) {
        int j = mech_find_joint(m, pins[i]);
        cr_assert_geq(j, 0, "joint %s", pins[i]);
        cr_expect_eq(m->joints[j].kind, MECH_JOINT_REVOLUTE);
        cr_expect_eq(m->joints[j].is_explicit, 0);
    }
    int jb = mech_find_joint(m, "B");
    int lc = mech_find_link(m, "coupler"), lr = mech_find_link(m, "rocker");
    cr_expect((m->joints[jb].link[0] == lc && m->joints[jb].link[1] == lr) ||
              (m->joints[jb].link[0] == lr && m->joints[jb].link[1] == lc));
    cr_expect_eq(m->links[0].is_ground, 1);
    cr_expect_str_eq(m->links[0].name, "ground");
    mech_diag_free(&d);
    mech_model_free(&m);
}

static const char SLIDER_PIN_IN_SLOT[] =
    "name: slider-crank, pin in slot\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0]}\n"
    "links:\n"
    "  crank: {points: {O: [0, 0], A: [40, 0]}}\n"
    "  rod:   {points: {A: [0, 0], B: [140, 0]}}\n"
    "joints:\n"
    "  - {slider: B, on: ground, through: O, angle: 0, rotation: free}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 72}}\n";

Test(mobility, slider_crank_pin_in_slot)
{
    mech_model *m = load_ok("pin-in-slot", SLIDER_PIN_IN_SLOT);
    mech_diag d;
    mech_diag_init(&d);
    /* 3 links; O, A revolute; B pin in slot: M = 3*2 - 2*2 - 1 = 1;
       unknowns: rod angle + slide x (crank angle is the driver) */
    int rc = check_counts("pin-in-slot", m, (counts){3, 2, 0, 1, 2, 1, 2, 1}, &d);
    cr_expect_eq(rc, MECH_OK, "%s", diag_text(&d));
    int js = mech_find_joint(m, "s_B");
    cr_assert_geq(js, 0, "default slider name s_B");
    const mech_joint *j = &m->joints[js];
    cr_expect_eq(j->kind, MECH_JOINT_SLIDER);
    cr_expect_eq(j->locked, 0);
    cr_expect_eq(j->link[0], mech_find_link(m, "rod"), "the one link with B slides");
    cr_expect_eq(j->link[1], 0, "guide: ground");
    cr_expect_str_eq(m->links[0].points[j->point[1]].name, "O");
    cr_expect_eq(j->angle, 0.0);
    /* default outputs include the slider */
    cr_expect_eq(m->outputs.nsliders, 1);
    mech_diag_free(&d);
    mech_model_free(&m);
}

static const char SLIDER_PISTON[] =
    "name: slider-crank, piston block\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0]}\n"
    "links:\n"
    "  crank:  {points: {O: [0, 0], A: [40, 0]}}\n"
    "  rod:    {points: {A: [0, 0], B: [140, 0]}}\n"
    "  piston: {points: {B: [0, 0]}}\n"
    "joints:\n"
    "  - {slider: B, link: piston, on: ground, through: O, angle: 0 deg, name: x_B,\n"
    "     symbol: x_B}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 72}}\n"
    "initial: {rod: -10, x_B: 180}\n";

Test(mobility, slider_crank_piston_block)
{
    mech_model *m = load_ok("piston", SLIDER_PISTON);
    mech_diag d;
    mech_diag_init(&d);
    /* 4 links; O, A, B revolute + prismatic: M = 3*3 - 2*4 = 1; the piston
       has no angle unknown (it cannot turn): unknowns rod angle + x_B */
    int rc = check_counts("piston", m, (counts){4, 3, 1, 0, 2, 1, 2, 1}, &d);
    cr_expect_eq(rc, MECH_OK, "%s", diag_text(&d));
    int js = mech_find_joint(m, "x_B");
    cr_assert_geq(js, 0);
    cr_expect_eq(m->joints[js].locked, 1, "rotation defaults to locked");
    cr_expect_eq(m->joints[js].link[0], mech_find_link(m, "piston"));
    cr_expect_str_eq(m->joints[js].symbol, "x_B");
    /* the guesses: rod angle in deg, slider displacement in mm */
    cr_assert_eq(m->nguesses, 2);
    for (int i = 0; i < 2; i++) {
        const mech_guess *g = &m->guesses[i];
        if (g->is_slider) {
            cr_expect_eq(g->index, js);
            expect_close(g->value, 0.18, EXACT, "x_B guess %g", g->value);
        } else {
            cr_expect_eq(g->index, mech_find_link(m, "rod"));
            expect_close(g->value, -PI_ / 18.0, EXACT, "rod guess %g", g->value);
        }
    }
    mech_diag_free(&d);
    mech_model_free(&m);
}

static const char FIVEBAR[] =
    "name: five-bar\n"
    "ground: {O: [0, 0], E: [0.1, 0]}\n"
    "links:\n"
    "  l1: {points: {O: [0, 0], A: [0.03, 0]}}\n"
    "  l2: {points: {A: [0, 0], B: [0.08, 0]}}\n"
    "  l3: {points: {B: [0, 0], C: [0.08, 0]}}\n"
    "  l4: {points: {C: [0, 0], E: [0.03, 0]}}\n"
    "driver: {link: l1, angle: 0}\n";

Test(mobility, fivebar_is_under_constrained)
{
    mech_model *m = load_ok("fivebar", FIVEBAR);
    mech_diag d;
    mech_diag_init(&d);
    /* M = 3*4 - 2*5 = 2 with one driver: 3 unknowns for 2 equations */
    int rc = check_counts("fivebar", m, (counts){5, 5, 0, 0, 3, 1, 2, 2}, &d);
    cr_expect_eq(rc, MECH_EINPUT);
    int k = diag_find(&d, "under-constrained");
    cr_expect_geq(k, 0, "no under-constrained error:%s", diag_text(&d));
    if (k >= 0) {
        cr_expect_eq(d.entries[k].severity, MECH_SEV_ERROR);
        cr_expect_eq(d.entries[k].mark.line, 8, "the error points at the driver");
    }
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* Watt: the two ternary links (ground O-C-F and rocker C-B-D) are joined. */
static const char WATT[] =
    "name: Watt six-bar\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0], C: [80, 0], F: [200, 0]}\n"
    "links:\n"
    "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [70, 0]}}\n"
    "  rocker:  {points: {C: [0, 0], B: [60, 0], D: {length: 40, angle: 60, from: B}}}\n"
    "  link4:   {points: {D: [0, 0], E: [90, 0]}}\n"
    "  link5:   {points: {F: [0, 0], E: [70, 0]}}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 36}}\n";

/* Stephenson: the ternary links (ground O-C-F and coupler A-B-D) are not. */
static const char STEPHENSON[] =
    "name: Stephenson six-bar\n"
    "units: {length: mm, angle: deg}\n"
    "ground: {O: [0, 0], C: [80, 0], F: [160, -40]}\n"
    "links:\n"
    "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [90, 0], D: [40, 30]}}\n"
    "  rocker:  {points: {C: [0, 0], B: [60, 0]}}\n"
    "  link4:   {points: {D: [0, 0], E: [90, 0]}}\n"
    "  link5:   {points: {F: [0, 0], E: [70, 0]}}\n"
    "driver: {link: crank, angle: {from: 0, to: 360, steps: 36}}\n";

Test(mobility, six_bars_have_two_loops)
{
    static const struct {
        const char *name, *yaml;
    } six[] = {{"watt", WATT}, {"stephenson", STEPHENSON}};
    for (int i = 0; i < 2; i++) {
        mech_model *m = load_ok(six[i].name, six[i].yaml);
        mech_diag d;
        mech_diag_init(&d);
        /* 6 links, 7 revolutes: M = 15 - 14 = 1; 2 loops, 4 equations,
           5 angles - driver = 4 unknowns */
        int rc = check_counts(six[i].name, m, (counts){6, 7, 0, 0, 4, 2, 4, 1}, &d);
        cr_expect_eq(rc, MECH_OK, "%s:%s", six[i].name, diag_text(&d));
        cr_expect_eq(m->nloops, 0, "loops are not listed: found automatically");
        mech_diag_free(&d);
        mech_model_free(&m);
    }
}

/* A point on three links pins them with two revolutes (a double joint):
 * B joins coupler, rocker and link4. */
static const char COMPOUND_HINGE[] =
    "name: six-bar with a double joint\n"
    "ground: {O: [0, 0], C: [3, 0], E: [5, 1]}\n"
    "links:\n"
    "  crank:   {points: {O: [0, 0], A: [1, 0]}}\n"
    "  coupler: {points: {A: [0, 0], B: [3, 0]}}\n"
    "  rocker:  {points: {C: [0, 0], B: [2, 0]}}\n"
    "  link4:   {points: {B: [0, 0], D: [2, 0]}}\n"
    "  link5:   {points: {E: [0, 0], D: [2, 0]}}\n"
    "driver: {link: crank, angle: 0}\n";

Test(mobility, double_joint_counts_twice)
{
    mech_model *m = load_ok("double joint", COMPOUND_HINGE);
    mech_diag d;
    mech_diag_init(&d);
    /* O, C, E, A, D, and B twice: 7 revolutes, M = 15 - 14 = 1 */
    int rc = check_counts("double joint", m, (counts){6, 7, 0, 0, 4, 2, 4, 1}, &d);
    cr_expect_eq(rc, MECH_OK, "%s", diag_text(&d));
    int b1 = mech_find_joint(m, "B"), b2 = mech_find_joint(m, "B_2");
    cr_expect_geq(b1, 0, "first joint at B is named B");
    cr_expect_geq(b2, 0, "second joint at B is named B_2");
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* With an explicit joint the pairs at a shared point are chosen by the file. */
Test(mobility, explicit_revolute_with_friction)
{
    static const char yaml[] =
        "name: four-bar, explicit joint\n"
        "units: {length: mm}\n"
        "ground: {O: [0, 0], C: [70, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
        "joints:\n"
        "  - {revolute: B, links: [rocker, coupler], name: pinB, friction: 0.15,\n"
        "     pin_radius: 4}\n"
        "driver: {link: crank, angle: 0}\n";
    mech_model *m = load_ok("explicit", yaml);
    mech_diag d;
    mech_diag_init(&d);
    int rc = check_counts("explicit", m, (counts){4, 4, 0, 0, 2, 1, 2, 1}, &d);
    cr_expect_eq(rc, MECH_OK, "%s", diag_text(&d));
    cr_expect_eq(mech_find_joint(m, "B"), -1, "no implicit joint doubles pinB");
    int j = mech_find_joint(m, "pinB");
    cr_assert_geq(j, 0);
    cr_expect_eq(m->joints[j].is_explicit, 1);
    cr_expect_eq(m->joints[j].link[0], mech_find_link(m, "rocker"));
    cr_expect_eq(m->joints[j].link[1], mech_find_link(m, "coupler"));
    expect_close(m->joints[j].friction, 0.15, EXACT, "friction");
    expect_close(m->joints[j].pin_radius, 0.004, EXACT, "pin radius in mm");
    mech_diag_free(&d);
    mech_model_free(&m);
}

static const char TRIANGLE[] =
    "name: triangle\n"
    "ground: {O: [0, 0], B: [1, 0]}\n"
    "links:\n"
    "  a: {points: {O: [0, 0], A: [1, 0]}}\n"
    "  b: {points: {A: [0, 0], B: [1, 0]}}\n"
    "driver: {link: a, angle: 60 deg}\n";

Test(mobility, triangle_is_rigid)
{
    mech_model *m = load_ok("triangle", TRIANGLE);
    mech_diag d;
    mech_diag_init(&d);
    /* 3 links, 3 revolutes: M = 6 - 6 = 0, a structure; 1 unknown, 2 equations */
    int rc = check_counts("triangle", m, (counts){3, 3, 0, 0, 1, 1, 2, 0}, &d);
    cr_expect_eq(rc, MECH_EINPUT);
    cr_expect_geq(diag_find(&d, "over-constrained"), 0, "%s", diag_text(&d));
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* The over-constrained error is followed by a note naming the rigid
 * triangle (src/equations/check.c report_rigid). */
Test(mobility, triangle_is_named_as_rigid)
{
    mech_model *m = load_ok("triangle", TRIANGLE);
    mech_diag d;
    mech_diag_init(&d);
    mech_summary s;
    mech_check(m, &s, &d);
    int k = diag_find(&d, "triangle");
    cr_expect_geq(k, 0, "no note names the rigid triangle:%s", diag_text(&d));
    if (k >= 0) {
        cr_expect_eq(d.entries[k].severity, MECH_SEV_NOTE);
        cr_expect(strstr(d.entries[k].message, "'ground'") && strstr(d.entries[k].message, "'a'") &&
                      strstr(d.entries[k].message, "'b'"),
                  "%s", d.entries[k].message);
    }
    mech_diag_free(&d);
    mech_model_free(&m);
}

Test(mobility, links_joined_twice)
{
    static const char yaml[] =
        "name: double-jointed pair\n"
        "ground: {O: [0, 0], C: [3, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [1, 0], A2: [1, 1]}}\n"
        "  coupler: {points: {A: [0, 0], A2: [0, 1], B: [2, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [2, 0]}}\n"
        "driver: {link: crank, angle: 0}\n";
    mech_model *m = load_ok("pair", yaml);
    mech_diag d;
    mech_diag_init(&d);
    /* crank and coupler pinned at A and A2 are one body: M = 9 - 10 = -1 */
    int rc = check_counts("pair", m, (counts){4, 5, 0, 0, 2, 2, 4, -1}, &d);
    cr_expect_eq(rc, MECH_EINPUT);
    cr_expect_geq(diag_find(&d, "over-constrained"), 0, "%s", diag_text(&d));
    int k = diag_find(&d, "joined twice");
    cr_expect_geq(k, 0, "no note about the pair:%s", diag_text(&d));
    if (k >= 0) {
        cr_expect_eq(d.entries[k].severity, MECH_SEV_NOTE);
        cr_expect(strstr(d.entries[k].message, "'crank'") &&
                      strstr(d.entries[k].message, "'coupler'"),
                  "%s", d.entries[k].message);
    }
    mech_diag_free(&d);
    mech_model_free(&m);
}

Test(mobility, slider_driver)
{
    static const char yaml[] =
        "name: slider-driven\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  crank:  {points: {O: [0, 0], A: [40, 0]}}\n"
        "  rod:    {points: {A: [0, 0], B: [140, 0]}}\n"
        "  piston: {points: {B: [0, 0]}}\n"
        "joints:\n"
        "  - {slider: B, link: piston, on: ground, through: O, angle: 0}\n"
        "driver: {slider: s_B, displacement: {from: 110, to: 170, steps: 6}}\n";
    mech_model *m = load_ok("slider driver", yaml);
    mech_diag d;
    mech_diag_init(&d);
    /* unknowns: crank and rod angles (the displacement is the driver) */
    int rc = check_counts("slider driver", m, (counts){4, 3, 1, 0, 2, 1, 2, 1}, &d);
    cr_expect_eq(rc, MECH_OK, "%s", diag_text(&d));
    cr_expect_eq(m->driver.kind, MECH_DRIVE_SLIDER);
    cr_expect_eq(m->driver.index, mech_find_joint(m, "s_B"));
    cr_assert_eq(m->driver.nvalues, 7);
    expect_close(m->driver.values[0], 0.11, EXACT, "from 110 mm");
    expect_close(m->driver.values[6], 0.17, EXACT, "to 170 mm");
    cr_expect_eq(m->driver.speed, 1.0, "default 1 m/s");
    mech_diag_free(&d);
    mech_model_free(&m);
}

Test(mobility, dangling_link)
{
    static const char yaml[] =
        "name: dangling\n"
        "ground: {O: [0, 0], C: [0.07, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [0.02, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [0.06, 0]}}\n"
        "driver: {link: crank, angle: 0}\n";
    mech_model *m = load_ok("dangling", yaml);
    mech_diag d;
    mech_diag_init(&d);
    mech_summary s;
    cr_expect_eq(mech_check(m, &s, &d), MECH_EINPUT);
    int k = diag_find(&d, "single joint");
    cr_expect_geq(k, 0, "%s", diag_text(&d));
    if (k >= 0)
        cr_expect(strstr(d.entries[k].message, "'coupler'") != NULL);
    mech_diag_free(&d);
    mech_model_free(&m);
}

/* ---- geometry in SI ---------------------------------------------------------- */

static const mech_point *point_of(const mech_model *m, const char *link, const char *point)
{
    int li = mech_find_link(m, link);
    cr_assert_geq(li, 0, "link %s", link);
    int id = mech_find_point(m, point);
    cr_assert_geq(id, 0, "point %s", point);
    int p = model_point_in_link(&m->links[li], id);
    cr_assert_geq(p, 0, "point %s on link %s", point, link);
    return &m->links[li].points[p];
}

Test(load_geometry, polar_points_in_si)
{
    static const char yaml[] =
        "name: polar\n"
        "units: {length: mm, angle: deg}\n"
        "parameters:\n"
        "  r: 40 mm\n"
        "  gamma: 30\n"
        "ground: {O: [0, 0], C: [70, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: {length: 50 mm, angle: 30 deg}}}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0],\n"
        "                     P: {length: r, angle: gamma + 60, from: B}}}\n"
        "  rocker:  {points: {C: [0, 0], B: [2 in, -1 cm]}}\n"
        "driver: {link: crank, angle: 0}\n";
    mech_model *m = load_ok("polar", yaml);
    const mech_point *a = point_of(m, "crank", "A");
    expect_close(a->x, 0.05 * cos(PI_ / 6.0), TRIG, "A.x = %.17g", a->x);
    expect_close(a->y, 0.05 * sin(PI_ / 6.0), TRIG, "A.y = %.17g", a->y);
    /* from B = (60 mm, 0), 40 mm at 90 deg in the coupler's frame */
    const mech_point *p = point_of(m, "coupler", "P");
    cr_expect(fabs(p->x - 0.06) <= 1e-17, "P.x = %.17g (cos 90 deg is ~6e-17)", p->x);
    expect_close(p->y, 0.04, TRIG, "P.y = %.17g", p->y);
    const mech_point *b = point_of(m, "rocker", "B");
    expect_close(b->x, 0.0508, EXACT, "2 in");
    expect_close(b->y, -0.01, EXACT, "-1 cm");
    const mech_point *c = point_of(m, "ground", "C");
    expect_close(c->x, 0.07, EXACT, "bare 70 in a mm file");
    /* shared names are one pin: one id */
    cr_expect_eq(point_of(m, "crank", "A")->id, point_of(m, "coupler", "A")->id);
    cr_expect_eq(m->nparams, 2);
    expect_close(m->params[0].value, 0.04, EXACT, "r");
    cr_expect_str_eq(m->params[1].name, "gamma");
    cr_expect_eq(m->params[1].value, 30.0, "a bare parameter is stored as the plain number");
    mech_model_free(&m);
}

Test(load_geometry, mass_properties_in_si)
{
    static const char yaml[] =
        "name: masses\n"
        "units: {length: mm, angle: deg, mass: g}\n"
        "gravity: [0, -9.81]\n"
        "ground: {O: [0, 0], C: [70, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [20, 0]}, mass: 50, center: [10, 0],\n"
        "            inertia: 2e-6 kg*m^2}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0]}, mass: 0.1 kg, center: B,\n"
        "            inertia: 3 g*cm^2, symbol: phi2}\n"
        "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
        "driver: {link: crank, angle: 0}\n";
    mech_model *m = load_ok("masses", yaml);
    const mech_link *cr = &m->links[mech_find_link(m, "crank")];
    cr_expect_eq(cr->has_mass, 1);
    expect_close(cr->mass, 0.05, EXACT, "50 g");
    expect_close(cr->center[0], 0.01, EXACT, "10 mm");
    cr_expect_eq(cr->center[1], 0.0);
    expect_close(cr->inertia, 2e-6, EXACT, "inertia");
    const mech_link *co = &m->links[mech_find_link(m, "coupler")];
    expect_close(co->mass, 0.1, EXACT, "0.1 kg");
    expect_close(co->center[0], 0.06, EXACT, "center at point B");
    expect_close(co->inertia, 3e-7, EXACT, "3 g*cm^2");
    cr_expect_str_eq(co->symbol, "phi2");
    cr_expect_eq(m->links[mech_find_link(m, "rocker")].has_mass, 0);
    cr_expect_eq(m->gravity[0], 0.0);
    expect_close(m->gravity[1], -9.81, EXACT, "gravity in m/s^2");
    mech_model_free(&m);
}

Test(load_geometry, gravity_defaults_to_zero)
{
    mech_model *m = load_ok("fourbar", FOURBAR);
    cr_expect_eq(m->gravity[0], 0.0);
    cr_expect_eq(m->gravity[1], 0.0);
    mech_model_free(&m);
}

/* ---- driver ------------------------------------------------------------------ */

Test(load_driver, steps_give_steps_plus_one_positions)
{
    static const char *const ranges[] = {
        "{from: 0, to: 90, steps: 4}",
        "{from: 90 deg, to: 0, steps: 1}",
        "{from: -30, to: 330, steps: 360}",
    };
    static const double from[] = {0.0, PI_ / 2.0, -PI_ / 6.0};
    static const double to[] = {PI_ / 2.0, 0.0, 11.0 * PI_ / 6.0};
    static const int steps[] = {4, 1, 360};
    for (int i = 0; i < 3; i++) {
        char yaml[1024];
        snprintf(yaml, sizeof yaml,
                 "name: steps\n"
                 "units: {angle: deg}\n"
                 "ground: {O: [0, 0], C: [0.07, 0]}\n"
                 "links:\n"
                 "  crank:   {points: {O: [0, 0], A: [0.02, 0]}}\n"
                 "  coupler: {points: {A: [0, 0], B: [0.06, 0]}}\n"
                 "  rocker:  {points: {C: [0, 0], B: [0.05, 0]}}\n"
                 "driver: {link: crank, angle: %s}\n",
                 ranges[i]);
        mech_model *m = load_ok(ranges[i], yaml);
        const mech_driver *dr = &m->driver;
        cr_expect_eq(dr->kind, MECH_DRIVE_ANGLE);
        cr_expect_eq(dr->index, mech_find_link(m, "crank"));
        cr_assert_eq(dr->nvalues, steps[i] + 1, "%s: %d positions", ranges[i], dr->nvalues);
        /* both ends included; the last is from + (to - from) * 1, within 4 ulp of to */
        expect_close(dr->values[0], from[i], EXACT, "%s: first %.17g", ranges[i], dr->values[0]);
        expect_close(dr->values[steps[i]], to[i], EXACT, "%s: last %.17g", ranges[i],
                     dr->values[steps[i]]);
        double h = (to[i] - from[i]) / steps[i];
        for (int k = 1; k < steps[i]; k++)
            cr_expect(fabs(dr->values[k] - (from[i] + k * h)) <= 8 * DBL_EPSILON * 2 * PI_,
                      "%s: value %d evenly spaced", ranges[i], k);
        mech_model_free(&m);
    }
}

Test(load_driver, lists_single_values_and_defaults)
{
    static const char yaml[] =
        "name: list\n"
        "units: {angle: deg}\n"
        "ground: {O: [0, 0], C: [0.07, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [0.02, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [0.06, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [0.05, 0]}}\n"
        "driver: {link: crank, angle: [0, 45, 1 rad, 135]}\n";
    mech_model *m = load_ok("list", yaml);
    cr_assert_eq(m->driver.nvalues, 4);
    expect_close(m->driver.values[1], PI_ / 4.0, EXACT, "45 deg");
    cr_expect_eq(m->driver.values[2], 1.0, "1 rad");
    cr_expect_eq(m->driver.speed, 1.0, "default speed 1 rad/s");
    cr_expect_eq(m->driver.accel, 0.0, "default acceleration 0");
    mech_model_free(&m);

    m = load_ok("single", FOURBAR);
    cr_expect_eq(m->driver.nvalues, 361);
    mech_model_free(&m);

    static const char one[] =
        "name: one position\n"
        "ground: {O: [0, 0], C: [0.07, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [0.02, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [0.06, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [0.05, 0]}}\n"
        "driver: {link: crank, angle: 2.0864, speed: 120 rpm, acceleration: 2 rad/s^2}\n";
    m = load_ok("one", one);
    cr_assert_eq(m->driver.nvalues, 1);
    cr_expect_eq(m->driver.values[0], 2.0864, "a bare angle in an SI file is in rad");
    expect_close(m->driver.speed, 4.0 * PI_, EXACT, "120 rpm");
    cr_expect_eq(m->driver.accel, 2.0);
    mech_model_free(&m);
}

/* Bare driver angles are radians: 'to: 360' without 'units: {angle: deg}'
 * is 57 revolutions. A warning (the file still loads) at the range when bare
 * numbers span more than a revolution or step by more than 30 deg; none when
 * the unit is written, in 'units:' or on the number. */
Test(load_driver, bare_angles_in_radians_warn)
{
    static const char head[] =
        "name: four-bar\n"
        "%s"
        "ground: {O: [0, 0], C: [0.07, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [0.02, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [0.06, 0]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [0.05, 0]}}\n"
        "parameters: {full: 360 deg}\n"
        "driver: {link: crank, angle: %s}\n";
    static const struct {
        const char *units, *angle, *message;  /* message NULL: no warning */
    } cases[] = {
        {"", "{from: 0, to: 360, steps: 360}",
         "driver angle numbers without a unit are radians: this range spans 57.3 revolutions "
         "in steps of up to 57.3 deg; for degrees write 'units: {angle: deg}' or '360 deg'"},
        {"", "{from: 0 deg, to: 720, steps: 720}", "spans 115 revolutions"},
        {"", "{from: 0, to: 6.2832, steps: 4}", "in steps of up to 90 deg"},
        {"", "[0, 1, 2]", "this range spans 0.318 revolutions in steps of up to 57.3 deg"},
        {"", "{from: 0, to: 6.283185307179586, steps: 360}", NULL},
        {"", "{from: 0, to: 2*pi, steps: 12}", NULL},
        {"", "{from: 0, to: 360 deg, steps: 360}", NULL},
        {"", "{from: 0, to: 2*full, steps: 720}", NULL},
        {"", "[0, 0.1, 0.2]", NULL},
        {"units: {angle: deg}\n", "{from: 0, to: 360, steps: 360}", NULL},
        {"units: {angle: rad}\n", "{from: 0, to: 60, steps: 10}", NULL},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char yaml[1024];
        snprintf(yaml, sizeof yaml, head, cases[i].units, cases[i].angle);
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        int rc = mech_load_string(yaml, strlen(yaml), "bare.yaml", &m, &d);
        cr_expect_eq(rc, MECH_OK, "%s loads:%s", cases[i].angle, diag_text(&d));
        if (cases[i].message) {
            cr_expect_eq(d.count, 1, "%s: one warning:%s", cases[i].angle, diag_text(&d));
            int k = diag_find(&d, cases[i].message);
            cr_expect_geq(k, 0, "%s: want '%s':%s", cases[i].angle, cases[i].message,
                          diag_text(&d));
            int line = cases[i].units[0] ? 9 : 8;
            int col = (int)strlen("driver: {link: crank, angle: ") + 1;
            if (k >= 0)
                cr_expect(d.entries[k].severity == MECH_SEV_WARNING &&
                              d.entries[k].mark.line == line && d.entries[k].mark.col == col,
                          "%s: a warning at %d:%d, got severity %d at %d:%d", cases[i].angle,
                          line, col, (int)d.entries[k].severity, d.entries[k].mark.line,
                          d.entries[k].mark.col);
        } else {
            cr_expect_eq(d.count, 0, "%s (%s): no warning:%s", cases[i].angle, cases[i].units,
                         diag_text(&d));
        }
        mech_model_free(&m);
        mech_diag_free(&d);
    }
}

/* Control characters in a link name or a description are refused (they
 * would reach the terminal, SVG and LaTeX raw); the message writes them
 * \xNN. A description may span lines. */
Test(load_names, control_characters)
{
    static const char link_bell[] =
        "name: four-bar\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  \"cr\\aank\": {points: {O: [0, 0], A: [0.02, 0]}}\n"
        "driver: {link: crank, angle: {from: 0 deg, to: 90 deg, steps: 3}}\n";
    mech_diag d;
    mech_diag_init(&d);
    load_fails("link name with a bell", link_bell, &d);
    int k = diag_find(&d, "link name 'cr\\x07ank' contains a control character (byte 0x07 at "
                          "character 3)");
    cr_expect_geq(k, 0, "got:%s", diag_text(&d));
    if (k >= 0)
        cr_expect(d.entries[k].mark.line == 4 && d.entries[k].mark.col == 3, "at 4:3, not %d:%d",
                  d.entries[k].mark.line, d.entries[k].mark.col);
    for (size_t i = 0; i < d.count; i++)
        cr_expect_null(strchr(d.entries[i].message, '\a'), "a raw bell in: %s",
                       d.entries[i].message);
    mech_diag_free(&d);

    char yaml[1024];
    snprintf(yaml, sizeof yaml, "%sdescription: \"two\\nlines\\tand a tab\"\n", FOURBAR);
    mech_model *m = load_ok("description on two lines", yaml);
    cr_expect_str_eq(m->description, "two\nlines\tand a tab");
    mech_model_free(&m);
    snprintf(yaml, sizeof yaml, "%sdescription: \"red \\e[31m\"\n", FOURBAR);
    mech_diag_init(&d);
    load_fails("description with an escape", yaml, &d);
    cr_expect_geq(diag_find(&d, "'description' contains a control character (byte 0x1b at "
                                "character 5); write printable characters only"), 0, "got:%s",
                  diag_text(&d));
    mech_diag_free(&d);
}

Test(load_driver, bad_steps)
{
    static const char *const bad[] = {"0", "1.5", "1000001", "2*180", "many"};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        char yaml[1024];
        snprintf(yaml, sizeof yaml,
                 "name: steps\n"
                 "ground: {O: [0, 0], C: [0.07, 0]}\n"
                 "links:\n"
                 "  crank:   {points: {O: [0, 0], A: [0.02, 0]}}\n"
                 "  coupler: {points: {A: [0, 0], B: [0.06, 0]}}\n"
                 "  rocker:  {points: {C: [0, 0], B: [0.05, 0]}}\n"
                 "driver: {link: crank, angle: {from: 0, to: 1, steps: %s}}\n",
                 bad[i]);
        mech_diag d;
        mech_diag_init(&d);
        load_fails(bad[i], yaml, &d);
        cr_expect_geq(diag_find(&d, "steps"), 0, "steps: %s:%s", bad[i], diag_text(&d));
        mech_diag_free(&d);
    }
}

/* ---- outputs, loops, branches, loads ------------------------------------------ */

Test(load_outputs, defaults_when_absent)
{
    mech_model *m = load_ok("piston", SLIDER_PISTON);
    const mech_outputs *o = &m->outputs;
    cr_expect_eq(o->npoints, m->npoint_names, "every point name, ground's too");
    for (int i = 0; i < o->npoints; i++)
        cr_expect_eq(o->points[i], i);
    cr_expect_eq(o->nlinks, m->nlinks - 1, "every moving link");
    for (int i = 0; i < o->nlinks; i++)
        cr_expect_eq(o->links[i], i + 1, "not the ground");
    cr_expect_eq(o->nsliders, 1);
    cr_expect_eq(o->sliders[0], mech_find_joint(m, "x_B"));
    cr_expect_eq(o->forces, 0, "no forces unless asked");
    mech_model_free(&m);
}

Test(load_outputs, only_what_is_listed)
{
    static const char yaml[] =
        "name: outputs\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  crank:  {points: {O: [0, 0], A: [40, 0]}}\n"
        "  rod:    {points: {A: [0, 0], B: [140, 0]}}\n"
        "  piston: {points: {B: [0, 0]}}\n"
        "joints:\n"
        "  - {slider: B, link: piston, on: ground, through: O, angle: 0}\n"
        "driver: {link: crank, angle: 0}\n"
        "outputs: {points: [B, A], forces: true}\n";
    mech_model *m = load_ok("outputs", yaml);
    const mech_outputs *o = &m->outputs;
    cr_assert_eq(o->npoints, 2);
    cr_expect_eq(o->points[0], mech_find_point(m, "B"), "in the order given");
    cr_expect_eq(o->points[1], mech_find_point(m, "A"));
    cr_expect_eq(o->nlinks, 0, "links not listed: none");
    cr_expect_eq(o->nsliders, 0, "sliders not listed: none");
    cr_expect_eq(o->forces, 1);
    mech_model_free(&m);
}

Test(load_loops, the_written_forms_agree)
{
    static const char *const forms[] = {
        "[[O, A, B, C, O]]", "[\"O A B C O\"]", "[O-A-B-C-O]", "[OABCO]", "[\"O, A, B, C, O\"]",
    };
    for (size_t i = 0; i < sizeof forms / sizeof forms[0]; i++) {
        char yaml[1024];
        snprintf(yaml, sizeof yaml, "%sloops: %s\n", FOURBAR, forms[i]);
        mech_model *m = load_ok(forms[i], yaml);
        cr_assert_eq(m->nloops, 1, "%s", forms[i]);
        const mech_loop *lp = &m->loops[0];
        cr_assert_eq(lp->npoints, 5, "%s: %d names", forms[i], lp->npoints);
        static const char *const want[] = {"O", "A", "B", "C", "O"};
        for (int k = 0; k < 5; k++)
            cr_expect_eq(lp->points[k], mech_find_point(m, want[k]), "%s: name %d", forms[i], k);
        mech_model_free(&m);
    }
}

Test(load_loops, must_close)
{
    static const char *const bad[] = {"[[O, A, B, C]]", "[\"O A O\"]", "[OAXO]"};
    static const char *const why[] = {"does not close", "at least three", "unknown point 'X'"};
    for (int i = 0; i < 3; i++) {
        char yaml[1024];
        snprintf(yaml, sizeof yaml, "%sloops: %s\n", FOURBAR, bad[i]);
        mech_diag d;
        mech_diag_init(&d);
        load_fails(bad[i], yaml, &d);
        cr_expect_geq(diag_find(&d, why[i]), 0, "%s:%s", bad[i], diag_text(&d));
        mech_diag_free(&d);
    }
}

Test(load_branch, turn_signs)
{
    char yaml[1024];
    snprintf(yaml, sizeof yaml,
             "%sbranch:\n  - {points: [A, B, C], turn: cw}\n  - {points: [O, A, B], turn: ccw}\n",
             FOURBAR);
    mech_model *m = load_ok("branch", yaml);
    cr_assert_eq(m->nbranches, 2);
    cr_expect_eq(m->branches[0].sign, -1);
    cr_expect_eq(m->branches[0].point[1], mech_find_point(m, "B"));
    cr_expect_eq(m->branches[1].sign, 1);
    mech_model_free(&m);
}

Test(load_loads, kinds_and_defaults)
{
    static const char yaml[] =
        "name: loads\n"
        "units: {length: mm, angle: deg, force: kN}\n"
        "ground: {O: [0, 0], C: [70, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [20, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [60, 0], P: [30, 10]}}\n"
        "  rocker:  {points: {C: [0, 0], B: [50, 0]}}\n"
        "driver: {link: crank, angle: 0}\n"
        "loads:\n"
        "  - {force: [0, -2], at: P}\n"
        "  - {force: [10 N, 0], at: B, link: rocker}\n"
        "  - {torque: -3 N*m, link: rocker}\n"
        "  - {distributed: 500 N/m, from: A, to: B, link: coupler}\n"
        "  - {distributed: 1 N/mm, from: P, to: B, direction: 0}\n";
    mech_model *m = load_ok("loads", yaml);
    cr_assert_eq(m->nloads, 5);
    const mech_load *l = m->loads;
    cr_expect_eq(l[0].kind, MECH_LOAD_FORCE);
    cr_expect_eq(l[0].link, mech_find_link(m, "coupler"), "the only link with P");
    expect_close(l[0].force[1], -2000.0, EXACT, "-2 kN");
    cr_expect_eq(l[1].link, mech_find_link(m, "rocker"));
    expect_close(l[1].force[0], 10.0, EXACT, "10 N");
    cr_expect_eq(l[2].kind, MECH_LOAD_TORQUE);
    expect_close(l[2].torque, -3.0, EXACT, "clockwise 3 N*m");
    cr_expect_eq(l[3].kind, MECH_LOAD_DISTRIBUTED);
    expect_close(l[3].intensity, 500.0, EXACT, "500 N/m");
    expect_close(l[3].direction, -PI_ / 2.0, EXACT, "default: straight down");
    expect_close(l[4].intensity, 1000.0, EXACT, "1 N/mm");
    cr_expect_eq(l[4].direction, 0.0);
    mech_model_free(&m);
}

/* A key that belongs to another kind of load is an error, at the key:
 * {torque: 5, link: crank, at: A} loads the whole crank with 5 N*m, and an
 * 'at' would let a reader think the torque acts at A; a force with
 * 'direction' or 'from' likewise. (It used to be accepted and ignored.) */
Test(load_loads, keys_of_another_kind_are_errors)
{
    static const struct {
        const char *load, *key, *message;  /* the error is at `key` in the load */
    } cases[] = {
        {"{torque: 5, link: crank, at: A}", " at:", "'at' does not apply to a torque"},
        {"{force: [0, 1], at: A, direction: 90}", " direction:",
         "'direction' does not apply to a force"},
        {"{force: [0, 1], at: A, from: A}", " from:", "'from' does not apply to a force"},
        {"{distributed: 5, link: coupler, from: A, to: B, at: A}", " at:",
         "'at' does not apply to a distributed load"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        char yaml[1024];
        snprintf(yaml, sizeof yaml, "%sloads:\n  - %s\n", FOURBAR, cases[i].load);
        mech_diag d;
        mech_diag_init(&d);
        load_fails(cases[i].load, yaml, &d);
        int k = diag_find(&d, cases[i].message);
        cr_expect_geq(k, 0, "%s: want '%s', got:%s", cases[i].load, cases[i].message,
                      diag_text(&d));
        /* line 9, after the 7 of FOURBAR and 'loads:'; "  - " precedes the load */
        int col = 4 + (int)(strstr(cases[i].load, cases[i].key) - cases[i].load) + 2;
        if (k >= 0)
            cr_expect(d.entries[k].mark.line == 9 && d.entries[k].mark.col == col,
                      "%s: at %d:%d, want 9:%d", cases[i].load, d.entries[k].mark.line,
                      d.entries[k].mark.col, col);
        cr_expect_eq(d.nerrors, 1, "%s: one error:%s", cases[i].load, diag_text(&d));
        mech_diag_free(&d);
    }
}

/* `initial:` rejects a guess for the driving link ("its angle comes from
 * 'driver'") and likewise one for the driving slider (it used to be
 * accepted and then ignored). */
Test(load_initial, guess_for_the_driving_slider_is_an_error)
{
    static const char yaml[] =
        "name: slider-driven\n"
        "units: {length: mm, angle: deg}\n"
        "ground: {O: [0, 0]}\n"
        "links:\n"
        "  crank:  {points: {O: [0, 0], A: [40, 0]}}\n"
        "  rod:    {points: {A: [0, 0], B: [140, 0]}}\n"
        "  piston: {points: {B: [0, 0]}}\n"
        "joints:\n"
        "  - {slider: B, link: piston, on: ground, through: O, angle: 0}\n"
        "driver: {slider: s_B, displacement: {from: 110, to: 170, steps: 6}}\n"
        "initial: {s_B: 120}\n";
    mech_diag d;
    mech_diag_init(&d);
    load_fails("initial driver slider", yaml, &d);
    int k = diag_find(&d, "'s_B' is the driver; its displacement comes from 'driver'");
    cr_expect_geq(k, 0, "got:%s", diag_text(&d));
    if (k >= 0)
        cr_expect(d.entries[k].mark.line == 11 && d.entries[k].mark.col == 11,
                  "at the key 's_B' (11:11), not %d:%d", d.entries[k].mark.line,
                  d.entries[k].mark.col);
    cr_expect_eq(d.nerrors, 1, "one error:%s", diag_text(&d));
    mech_diag_free(&d);
}

/* ---- error positions ----------------------------------------------------------- */

/* Column (1-based) of `needle` on line `line` (1-based) of text. */
static int column_of(const char *text, int line, const char *needle)
{
    const char *s = text;
    for (int l = 1; l < line && s; l++) {
        s = strchr(s, '\n');
        if (s)
            s++;
    }
    const char *hit = s ? strstr(s, needle) : NULL;
    return hit ? (int)(hit - s) + 1 : -1;
}

Test(load_errors, file_line_column)
{
    static const char yaml[] =
        "name: bad\n"
        "units: {length: mm}\n"
        "ground: {O: [0, 0], C: [70, 0]}\n"
        "links:\n"
        "  crank:   {points: {O: [0, 0], A: [5 kg, 0]}}\n"
        "  coupler: {points: {A: [0, 0], B: [\"2 m + 3 s\", 0]}}\n"
        "  rocker:  {pionts: {C: [0, 0], B: [50, 0]}}\n"
        "driver: {link: crank, angle: 0}\n";
    mech_diag d;
    mech_diag_init(&d);
    load_fails("bad.yaml", yaml, &d);
    int k = diag_find(&d, "expected a length, got a mass (kg)");
    cr_expect_geq(k, 0, "%s", diag_text(&d));
    if (k >= 0) {
        cr_expect_str_eq(d.entries[k].file, "bad.yaml");
        cr_expect_eq(d.entries[k].mark.line, 5);
        cr_expect_eq(d.entries[k].mark.col, column_of(yaml, 5, "5 kg"));
        cr_expect(strstr(d.entries[k].message, "point 'A' of link 'crank'") != NULL,
                  "%s", d.entries[k].message);
    }
    /* inside a quoted value the column points at the operator */
    k = diag_find(&d, "cannot add a length (m) and a time (s)");
    cr_expect_geq(k, 0, "%s", diag_text(&d));
    if (k >= 0) {
        cr_expect_eq(d.entries[k].mark.line, 6);
        cr_expect_eq(d.entries[k].mark.col, column_of(yaml, 6, "+ 3 s"));
    }
    k = diag_find(&d, "unknown key 'pionts'");
    cr_expect_geq(k, 0, "%s", diag_text(&d));
    if (k >= 0) {
        cr_expect_eq(d.entries[k].mark.line, 7);
        cr_expect_eq(d.entries[k].mark.col, column_of(yaml, 7, "pionts"));
        cr_expect(strstr(d.entries[k].message, "did you mean 'points'") != NULL);
    }
    mech_diag_free(&d);
}

Test(load_errors, missing_required_keys)
{
    static const char yaml[] = "description: nothing else\n";
    mech_diag d;
    mech_diag_init(&d);
    load_fails("empty", yaml, &d);
    static const char *const keys[] = {"'name'", "'ground'", "'links'", "'driver'"};
    for (int i = 0; i < 4; i++)
        cr_expect_geq(diag_find(&d, keys[i]), 0, "missing %s:%s", keys[i], diag_text(&d));
    mech_diag_free(&d);
}
