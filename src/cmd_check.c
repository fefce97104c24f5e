/* src/cmd_check.c: `mech check`, validate mechanism files and print a
 * summary of each one's structure (docs/cli.md, section mech check). */
#include <stdio.h>
#include <string.h>

#include "commands.h"
#include "drivers.h"
#include "gears.h"
#include "springs.h"
#include "state_loads.h"

const char cmd_check_help[] =
    "usage: mech check [-q] FILE...\n"
    "\n"
    "Load each mechanism file, report every error as FILE:LINE:COLUMN: error: MESSAGE,\n"
    "and print a summary: links, joints, unknowns, independent loops, and the\n"
    "mobility (Gruebler-Kutzbach count) against the number of drivers.\n"
    "\n"
    "options:\n"
    "  -q, --quiet   print only errors, no summary\n"
    "  -h, --help    show this help\n"
    "\n"
    "exit status: 0 all files valid, 2 some file invalid, 3 a file cannot be read\n";

static const char *drive_text(const mech_model *m, char *buf, size_t size)
{
    if (!m->has_driver)
        return "none";
    const mech_driver *dr = &m->driver;
    if (dr->kind == MECH_DRIVE_ANGLE)
        snprintf(buf, size, "angle of link '%s', %d position%s", m->links[dr->index].name,
                 dr->nvalues, dr->nvalues == 1 ? "" : "s");
    else
        snprintf(buf, size, "displacement of slider '%s', %d position%s",
                 m->joints[dr->index].name, dr->nvalues, dr->nvalues == 1 ? "" : "s");
    return buf;
}

/* One line per spring or damper (springs_describe: mech report shows the
 * same lines). */
static void print_springs(const mech_model *m)
{
    char buf[512];
    for (int i = 0; i < m->nsprings; i++) {
        springs_describe(m, i, buf, sizeof buf);
        printf("  spring     %s\n", buf);
    }
}

static void print_summary(const mech_model *m, const mech_summary *s)
{
    char buf[512];
    int nsliders = s->nprismatic + s->npin_in_slot;
    printf("%s: %s\n", m->file, m->name ? m->name : "(unnamed)");
    printf("  links      %d (ground + %d moving)\n", s->nlinks, s->nlinks - 1);
    printf("  joints     %d (%d revolute, %d prismatic slider, %d pin-in-slot slider)\n",
           s->nrevolute + nsliders, s->nrevolute, s->nprismatic, s->npin_in_slot);
    printf("  unknowns   %d (%d link angles + %d slider displacements - %d driver%s)\n",
           s->nunknowns, s->nlinks - 1 - s->nprismatic, nsliders, s->ndrivers,
           s->ndrivers == 1 ? "" : "s");
    printf("  loops      %d independent%s, %d equations\n", s->nloops,
           m->nloops ? " (listed in the file)" : " (found automatically)", s->nequations);
    if (s->ngears)  /* each mesh removes one freedom (gears.c) */
        printf("  mobility   %d = 3*(%d-1) - 2*%d - %d - %d gear%s, drivers %d\n", s->mobility,
               s->nlinks, s->nrevolute + s->nprismatic, s->npin_in_slot, s->ngears,
               s->ngears == 1 ? "" : "s", s->ndrivers);
    else
        printf("  mobility   %d = 3*(%d-1) - 2*%d - %d, drivers %d\n", s->mobility, s->nlinks,
               s->nrevolute + s->nprismatic, s->npin_in_slot, s->ndrivers);
    if (m->has_driver && m->driver.kind == MECH_DRIVE_TIME) {
        const mech_driver *dr = &m->driver;
        printf("  sweep      time t from %g s to %g s, %d position%s\n", dr->values[0],
               dr->values[dr->nvalues - 1], dr->nvalues, dr->nvalues == 1 ? "" : "s");
        for (int i = 0; i < m->nmotions; i++)
            printf("  driver     %s of %s '%s' = %s\n",
                   m->motions[i].kind == MECH_DRIVE_ANGLE ? "angle" : "displacement",
                   m->motions[i].kind == MECH_DRIVE_ANGLE ? "link" : "slider",
                   drivers_name(m, i), m->motions[i].text);
    } else {
        printf("  driver     %s\n", drive_text(m, buf, sizeof buf));
    }
    printf("  outputs    %d points, %d links, %d sliders%s\n", m->outputs.npoints,
           m->outputs.nlinks, m->outputs.nsliders, m->outputs.forces ? ", forces" : "");
    print_springs(m);
    for (int i = 0; m->state_loads && i < m->state_loads->nloads; i++) {
        state_loads_describe(m, i, buf, sizeof buf);
        printf("  load       %s\n", buf);
    }
    for (int i = 0; i < m->ngears; i++) {
        gears_describe(m, i, buf, sizeof buf);
        printf("  gears      %s\n", buf);
    }
}

int cmd_check(int argc, char **argv)
{
    int quiet = 0, nfiles = 0, status = MECH_EXIT_OK;
    for (int i = 1; i < argc; i++) {
        if (cmd_wants_help(argv[i])) {
            fputs(cmd_check_help, stdout);
            return MECH_EXIT_OK;
        }
        if (strcmp(argv[i], "-q") == 0 || strcmp(argv[i], "--quiet") == 0)
            quiet = 1;
        else if (argv[i][0] == '-' && argv[i][1] != '\0') {
            fprintf(stderr, "mech check: unknown option '%s' (see 'mech check --help')\n", argv[i]);
            return MECH_EXIT_INPUT;
        } else
            nfiles++;
    }
    if (nfiles == 0) {
        fprintf(stderr, "mech check: no files given (usage: mech check [-q] FILE...)\n");
        return MECH_EXIT_INPUT;
    }
    for (int i = 1; i < argc; i++) {
        if (argv[i][0] == '-' && argv[i][1] != '\0')
            continue;
        mech_diag d;
        mech_diag_init(&d);
        mech_model *m = NULL;
        mech_summary s;
        int rc = mech_load_file(argv[i], &m, &d);
        if (rc == MECH_OK)
            rc = mech_check(m, &s, &d);
        mech_diag_print(&d, stderr);
        if (rc == MECH_OK && !quiet)
            print_summary(m, &s);
        if (rc == MECH_EIO && status == MECH_EXIT_OK)
            status = MECH_EXIT_IO;
        else if (rc != MECH_OK)
            status = MECH_EXIT_INPUT;
        mech_model_free(&m);
        mech_diag_free(&d);
    }
    return status;
}
