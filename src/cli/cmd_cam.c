/* src/cli/cmd_cam.c: `mech cam`, what it takes to make a cam of the file
 * (docs/cams.md, section 5): its design quantities with the angle where
 * each is worst, the profile and pitch curve as a table of points in the
 * cam's frame (CSV or HDF5), and the outline as SVG and DXF. The geometry is
 * src/load/cam_geometry.c's, the files src/output/cam_profile.c's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "equations.h"
#include "output.h"

typedef struct cam_args {
    const char *file, *out, *svg, *dxf, *cam, *step;
    cmd_sets set;
} cam_args;

#define AT(field) offsetof(cam_args, field)

static const cmd_opt options[] = {
    {.names = "--cam", .kind = CMD_OPT_TEXT, .at = AT(cam), .label = "--cam NAME",
     .help = "the cam pair (default: the file's only one)"},
    {.names = "--step", .kind = CMD_OPT_TEXT, .at = AT(step), .label = "--step ANGLE",
     .help = "the points at most ANGLE of the cam apart (default 1 deg;\n"
             "a bare number is in the file's angle unit)"},
    {.names = "-o|--output", .kind = CMD_OPT_TEXT, .at = AT(out), .flags = CMD_RUN_ONLY,
     .label = "-o, --output FILE",
     .help = "the profile table: CSV, or HDF5 when FILE ends in .h5"},
    {.names = "--svg", .kind = CMD_OPT_TEXT, .at = AT(svg), .flags = CMD_RUN_ONLY,
     .label = "--svg FILE", .help = "the outline as SVG, in mm"},
    {.names = "--dxf", .kind = CMD_OPT_TEXT, .at = AT(dxf), .flags = CMD_RUN_ONLY,
     .label = "--dxf FILE", .help = "the outline as DXF (R12 ASCII, mm) for CAD and CAM"},
    CMD_SET_ENTRY(AT(set), "replace the file's parameter NAME by VALUE (repeatable)"),
    CMD_HELP_ENTRY,
    {NULL}};

const cmd_spec cmd_cam_spec = {
    .name = "cam",
    .summary = "a cam's profile, pitch curve and design quantities, to make it",
    .usage = "usage: mech cam FILE [--cam NAME] [--step ANGLE] [-o PROFILE.csv]\n"
             "                [--svg OUTLINE.svg] [--dxf OUTLINE.dxf] [--set NAME=VALUE]\n",
    .about = "Print a cam pair of the file (its 'cams:', docs/cams.md) and its design\n"
             "quantities: the largest pressure angle, the least radius of curvature of\n"
             "the pitch curve and of the profile (a flat face: the face width), each\n"
             "with the cam angle where it is worst. Write the profile: a row per cam\n"
             "angle x (from the cam's 'start', at most --step apart) with the lift s and\n"
             "its derivatives ds, dds in x, the pitch curve and the profile as points in\n"
             "the cam link's own frame, the pressure angle, both radii of curvature and\n"
             "(flat face) the contact's place on the face. SI units in the table; the\n"
             "outlines in mm. An undercut cam is an error of the file (exit 2).\n",
    .opts = options,
    .column = 22,
    .exits = "exit status: 0 written, 2 invalid file or usage, 3 a file cannot be read or\n"
             "written\n",
    .max_files = 1,
    .file_at = AT(file),
    .min_files = 1,
    .no_files = "no file given (usage: mech cam FILE -o PROFILE.csv)",
};

/* The outputs: none the same, none an input. -1 to go on, else a status. */
static int check_outputs(const cam_args *a)
{
    const char *outs[3] = {a->out, a->svg, a->dxf};
    for (int i = 0; i < 3; i++) {
        if (!outs[i])
            continue;
        for (int j = 0; j < i; j++)
            if (outs[j] && strcmp(outs[i], outs[j]) == 0 && strcmp(outs[i], "-") != 0)
                return cmd_usage_error("cam", "two outputs name the same file '%s'", outs[i]);
        int code = cmd_refuse_input("cam", outs[i], &a->file, 1);
        if (code >= 0)
            return code;
    }
    return -1;
}

static void print_summary(const mech_model *m, int i, int n)
{
    char b[1024];
    cams_describe(m, i, b, sizeof b);
    printf("cam          %s\n", b);
    cams_design(m, i, b, sizeof b);
    printf("design       %s\n", b);
    printf("points       %d over a turn, %.6g deg apart\n", n, 360.0 / n);
}

static int write_outputs(const cam_args *a, const mech_model *m, int i, const mech_table *t)
{
    mech_diag d;
    mech_diag_init(&d);
    int rc = MECH_OK;
    if (a->out)
        rc = cmd_write_table(t, a->out, "cam", a->file, &d);
    if (rc == MECH_OK && a->svg)
        rc = cam_outline_svg(m, i, t, a->svg, &d);
    if (rc == MECH_OK && a->dxf)
        rc = cam_outline_dxf(m, i, t, a->dxf, &d);
    mech_diag_print(&d, stderr);
    mech_diag_free(&d);
    return cmd_exit_status(rc);
}

static int run(const cam_args *a, const mech_model *m)
{
    char err[256];
    int i = cam_find(m, a->cam, err, sizeof err);
    if (i < 0)
        return cmd_usage_error("cam", "%s", err);
    double step = cam_default_step();
    if (a->step && (output_parse_quantity(m, a->step, "rad", &step) < 0 || !(step > 0)))
        return cmd_usage_error("cam", "--step needs a positive angle, not '%s'", a->step);
    int n = cam_steps(step);
    mech_table t;
    int rc = cam_profile_table(m, i, n, &t);
    if (rc != MECH_OK) {
        mech_table_free(&t);
        fprintf(stderr, "mech cam: out of memory\n");
        return MECH_EXIT_IO;
    }
    print_summary(m, i, n);
    int code = write_outputs(a, m, i, &t);
    mech_table_free(&t);
    return code;
}

int cmd_cam(int argc, char **argv)
{
    cam_args a;
    memset(&a, 0, sizeof a);
    mech_model *m = NULL;
    int code = cmd_opts_parse(&cmd_cam_spec, argc, argv, &a);
    if (code < 0)
        code = check_outputs(&a);
    if (code < 0)
        code = cmd_load_checked_with(a.file, a.set.set, a.set.n, &m);
    cmd_sets_free(&a.set);
    if (code == MECH_EXIT_OK && m)
        code = run(&a, m);
    mech_model_free(&m);
    return code < 0 ? MECH_EXIT_OK : code;
}
