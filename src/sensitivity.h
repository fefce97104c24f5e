/* src/sensitivity.h: the sensitivity plan (sensitivity.c): the symbolic
 * derivatives of the loop equations and of the outputs by the parameters,
 * compiled once, evaluated per row and parameter (sens_row). Private to
 * sensitivity.c and sensitivity_table.c. */
#ifndef MECH_SENSITIVITY_H
#define MECH_SENSITIVITY_H

#include "param_grad.h"
#include "system.h"

/* Tangent maps (sens_plan.map): variable -> the variable of its derivative, or -1. */
enum { MAP_T, MAP_P0, MAP_P1, MAP_P2, MAP_P, NMAPS };
/* Kinds of output (sens_output_expr). */
enum { SENS_POINT, SENS_LINK, SENS_SLIDER };

typedef struct sens_plan {
    mech_system *sys;     /* SYS_CARTESIAN: coordinates are variables */
    param_grad grad;      /* d(coordinates)/d(each parameter asked for) */
    int n, npoints;       /* unknowns; points of all links */
    /* variables beyond the system's (sys->nvars): x'' [n], dC/dp [2 npoints],
       X = dx/dp [n], V = dx'/dp [n], A = dx''/dp [n] */
    int v_xdd, v_D, v_X, v_V, v_A, nvars;
    int *map[NMAPS];      /* [nvars] each */
    ex *g[3];             /* [m] P0 f, P1 T f, P2 T T f */
    ex *ox, *oy;          /* [nlinks] frame origins along the spanning tree */
    ex *out;              /* [nout] output roots: P e, P T e, P T T e per output */
    int nout, capout;
    int *vars;            /* [nvars] workspace of expr_vars */
    tape tp;              /* phases: J and P0 f; P1 T f; P2 T T f; outputs */
    double *reg;          /* [tp.nreg] */
    double *lu;           /* [n * n] LU of J, row-major */
    int *piv;             /* [n] */
    double *rhs;          /* [n] */
} sens_plan;

/* The plan for the parameters which[0..nwhich-1] of m (loaded with the
 * overrides ov). MECH_OK or an error in d. */
int sens_plan_new(sens_plan *sp, const mech_model *m, const mech_override *ov, int nov,
                  const int *which, int nwhich, mech_diag *d);
void sens_plan_free(sens_plan *sp);
/* The position expression of an output: a point (obj = name id, comp 0 x,
 * 1 y), a link's angle or a slider's displacement (obj = index). */
int sens_output_expr(sens_plan *sp, int kind, int obj, int comp, ex *e);
/* Add P e, P T e, P T T e as output roots *first_root .. + 2. */
int sens_add_output(sens_plan *sp, ex e, int *first_root);
int sens_plan_compile(sens_plan *sp, mech_diag *d);
/* state: x [n], q, x' [n], q', q'' (SYS_NVARS order), then x'' [n]. out[nout]:
 * the outputs' derivatives by parameter `param` (index into the plan's).
 * 0, or -1 when J is singular there. */
int sens_row(sens_plan *sp, const double *state, int param, double *out);

#endif
