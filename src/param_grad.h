/* src/param_grad.h: d(point coordinates)/d(parameter) from seeded loads
 * (param_grad.c), in the form the equation builder reads (sys_params). */
#ifndef MECH_PARAM_GRAD_H
#define MECH_PARAM_GRAD_H

#include "system.h"

typedef struct param_grad {
    sys_params view;   /* what sys_new_with(SYS_NAMED) and sensitivity.c read */
    char **names;      /* [view.nparams] owned */
    double *values;    /* [view.nparams] SI */
    double **dxy;      /* [view.nparams] -> [2 * points of all links, link by link] */
} param_grad;

/* The parameters which[0..nwhich-1] (indices into m->params), or all of
 * them (which NULL), each by one load of m->file with the same overrides
 * seeded with it; check_angles: refuse a parameter that sets a slider's
 * angle (not carried into the derivatives; one more load each). MECH_OK,
 * or the loader's status with the problem in d. */
int pgrad_build(const mech_model *m, const mech_override *ov, int nov, const int *which,
                int nwhich, int check_angles, param_grad *g, mech_diag *d);
void pgrad_free(param_grad *g);

#endif
