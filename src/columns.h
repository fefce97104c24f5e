/* src/columns.h: the one description of a result table's columns.
 *
 * A layout lists every column once: its name, its unit and where its value
 * comes from (a source and the object it belongs to). The same layout
 * names the table's columns, sizes its rows and fills them, so the three
 * can never disagree. It is built with the analysed system and read only
 * afterwards. */
#ifndef MECH_COLUMNS_H
#define MECH_COLUMNS_H

#include "forces.h"

/* ORDER SRC: columns_fill switches on these. */
typedef enum {
    SRC_DRIVER,          /* the driver position q */
    SRC_POINT,           /* obj: point name id; comp 0..5: x, y, vx, vy, ax, ay */
    SRC_LINK,            /* obj: link; comp 0..2: angle, omega, alpha */
    SRC_SLIDER,          /* obj: joint; comp 0..2: s, v, a */
    SRC_REACTION,        /* obj: joint; comp 0..3: Fx, Fy, F or N, M; set: 1 with
                            friction, 0 frictionless */
    SRC_DRIVE_LOAD,      /* the driver torque or force; set as above */
    SRC_POWER_RESIDUAL,  /* set as above */
    SRC_FRICTION_POWER,
    SRC_FRICTION_ITERATIONS,
    SRC_ITERATIONS,      /* diagnostics: Newton iterations of the row */
    SRC_RESIDUAL,
    SRC_RCOND,
    SRC_SUBSTEPS,
    SRC_SPRING,          /* obj: spring; comp 0..2: length (angle), rate, force (torque) */
    SRC_GEAR             /* obj: gear pair; the tooth force along the line of action */
} column_source;

typedef struct column_desc {
    column_source src;
    int obj;             /* point id, link or joint (see column_source) */
    int comp;            /* component (see column_source) */
    int set;             /* reactions: 1 with friction, 0 frictionless */
    char *name;          /* owned */
    const char *unit;    /* static */
} column_desc;

/* Consecutive columns of one source object, filled together: the source
 * is evaluated once (a point's six motion values, a joint's reaction) and
 * the wanted components copied. Derived from the descriptors. */
typedef struct column_group {
    column_source src;
    int obj, set;
    int first;           /* first column */
    int n;               /* columns: components 0 .. n-1 of the source (the rates come
                            after the positions, the levels are nested) */
    int direct;          /* n is every component: the source writes into the row */
} column_group;

typedef struct column_layout {
    column_desc *cols;   /* [ncols] */
    int ncols;
    int cap;
    column_group *groups; /* [ngroups] the columns in runs of one source object */
    int ngroups;
} column_layout;

/* What a layout must hold. */
typedef struct column_request {
    const mech_outputs *outputs; /* the points, links and sliders */
    int level;           /* MECH_WANT_* bits: rates of points, links, sliders */
    int forces;          /* reactions, driver load, power residual */
    int friction;        /* 0 none, 1 friction columns, 2 also the frictionless set */
    int diagnostics;     /* iterations, residual, rcond, substeps */
} column_request;

/* The columns of the request's outputs. MECH_OK or MECH_ENOMEM. */
int columns_build(column_layout *cl, const mech_model *m, const column_request *rq);
void columns_free(column_layout *cl);
/* Give the table the layout's names and units (owned copies) and room for
 * nrows rows. MECH_OK or MECH_ENOMEM. */
int columns_make_table(const column_layout *cl, mech_table *t, int nrows);

/* What one row is filled from: the published solver state, the forces
 * (NULL without forces), and the row's diagnostics. */
typedef struct row_sources {
    const solver *sv;
    const forces *fc;
    int iterations;
    int substeps;
} row_sources;

/* Fill one row (ncols values) from the sources. */
void columns_fill(const column_layout *cl, const row_sources *rs, double *row);

#endif
