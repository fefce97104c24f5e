/* src/rows.h: the one description of the equation system's rows, as
 * columns.h describes the table's columns.
 *
 * Each row is a loop's x or y closure, a gear pair's rolling condition or
 * a driver's law, in that order; its descriptor says which, whose (the
 * loop, gear or driver) and where that is in the file. The system
 * (system.c) is built from the descriptors; `mech equations` (print.c),
 * the diagnostics (diagnose.c), the drivers' structure check (drivers.c)
 * and the structure counts (model.c) read them, and the force analysis
 * (forces.c) names its gear and driver columns with the same words, so
 * nothing else derives the row layout. */
#ifndef MECH_ROWS_H
#define MECH_ROWS_H

#include "internal.h"

typedef enum { ROW_LOOP_X, ROW_LOOP_Y, ROW_GEAR, ROW_DRIVER } row_kind;
enum { ROW_KINDS = 4 };

typedef struct row_desc {
    row_kind kind;
    int owner;       /* LOOP_X, LOOP_Y: the loop (of the system's loop set); GEAR: the
                        gear pair (m->gears); DRIVER: the driver (m->drivers) */
    mech_mark mark;  /* the owner's place in the file ({0, 0}: a loop found
                        automatically) */
} row_desc;

/* The rows of model m with nloops loops, per kind into count[] (may be
 * NULL): 2 per loop, 1 per gear pair, 1 per driver that is not the sweep
 * variable itself (drivers.h). Returns the total. */
int rows_count(const mech_model *m, int nloops, int *count);
/* The descriptors in row order ([rows_count] entries, at least one
 * allocated); loops_listed: the loops are the file's (their marks). NULL
 * when out of memory. */
row_desc *rows_build(const mech_model *m, int nloops, int loops_listed);

/* The owner of row r of system s in words: "loop 2 (A-B-C-D-A)",
 * "gear pair 'g12'", "driver 'crank'". */
const char *rows_owner(const mech_system *s, int r, char *buf, size_t size);
/* "gear pair 'g12'" (GEAR) or "driver 'crank'" (DRIVER): a constraint
 * that is not a loop, named from the model alone. */
const char *rows_constraint(const mech_model *m, row_kind kind, int owner, char *buf,
                            size_t size);
/* Rows a and b of s belong to one owner (a loop's x and y rows do). */
int rows_same_owner(const mech_system *s, int a, int b);

#endif
