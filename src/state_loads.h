/* src/state_loads.h: loads that depend on the motion (docs/format.md
 * section 10.2, docs/forces.md section 7a). A load component written as an
 * expression of the state (B.vx, crank.angle, x_B.s, ...) is compiled at
 * load time (load_state_loads.c) into a flat register program: inputs read
 * from the solved motion, then one instruction per operation. Per step the
 * program runs once after the kinematics and before the force solve, on a
 * register file of the thread's own (forces.sl_reg): no allocation.
 *
 * Constant loads never come here: a component that reads as a constant
 * quantity stays a plain mech_load (today's code path, same numbers). */
#ifndef MECH_STATE_LOADS_H
#define MECH_STATE_LOADS_H

#include "solve.h"

/* ORDER SLOP: sl_apply switches on these. */
typedef enum {
    SLOP_ADD, SLOP_SUB, SLOP_MUL, SLOP_DIV, SLOP_NEG, SLOP_POWI, SLOP_SIN, SLOP_COS, SLOP_TAN,
    SLOP_ATAN2, SLOP_SQRT, SLOP_ABS, SLOP_MIN, SLOP_MAX, SLOP_EXP, SLOP_LOG, SLOP_TANH,
    SLOP_STEP, SLOP_SIGN, SLOP_SMOOTHSIGN
} sl_op;

/* What an input register reads from the solved motion. */
typedef enum {
    SLIN_PX, SLIN_PY, SLIN_PVX, SLIN_PVY, SLIN_PAX, SLIN_PAY,  /* point name id */
    SLIN_ANGLE, SLIN_OMEGA, SLIN_ALPHA,                          /* link index */
    SLIN_S, SLIN_SV, SLIN_SA,                                    /* slider joint index */
    SLIN_DRIVER, SLIN_DRIVER_SPEED, SLIN_DRIVER_ACCEL            /* the driver */
} sl_input_kind;

typedef struct sl_ins {
    int op;          /* sl_op */
    int d, a, b;     /* registers: d = op(a, b) (b unused: -1) */
    int k;           /* SLOP_POWI: the integer exponent */
} sl_ins;

typedef struct sl_input {
    int kind;        /* sl_input_kind */
    int index;       /* point name id, link or joint */
    int reg;
} sl_input;

typedef struct sl_load {
    int torque;      /* 0: force [fx, fy] at point `point` of `link`; 1: torque on `link`;
                        2: a force along the line from point of link to point2 of link2,
                        tension positive (pulls the two ends together) */
    int link;
    int point;       /* index of the point in the link (force, line) */
    int reg[2];      /* registers of fx, fy (force), of the torque or the tension ([0]) */
    mech_mark mark;
    int link2, point2; /* line: the other end */
} sl_load;

/* The compiled program of every motion-dependent load of a model (owned by
 * mech_model.state_loads; read only after loading: threads share it). */
typedef struct state_loads {
    double *reg0;    /* [nreg] register image: constants, zero elsewhere */
    unsigned char *fixed; /* [nreg] 1: a constant register */
    int nreg, capreg;
    sl_ins *ins;
    int nins, capins;
    sl_input *in;
    int nin, capin;
    sl_load *loads;
    int nloads, caploads;
} state_loads;

/* ---- building (load time) */
state_loads *state_loads_new(void);
void state_loads_free(state_loads *s);
int sl_const(state_loads *s, double v);              /* a register holding v, or -1 */
int sl_input_reg(state_loads *s, int kind, int index); /* one register per input, or -1 */
/* d = op(a, b): folded into a constant when a and b are constants. -1: no memory. */
int sl_emit(state_loads *s, int op, int a, int b, int k);
int sl_is_const(const state_loads *s, int reg);      /* register holds a fixed value */
int sl_add_load(state_loads *s, const sl_load *l);   /* 0, or -1 out of memory */
/* One operation on values (the evaluator's, used for folding too). */
double sl_apply(int op, double a, double b, int k);

/* ---- per step */
double *state_loads_registers(const state_loads *s);   /* a register file (free()), or NULL */
/* Run the program at the published position of sv into reg. s may be NULL. */
void state_loads_eval(const state_loads *s, const solver *sv, double *reg);
/* Move the loads to the right-hand side of the Newton-Euler rows (as
 * springs_add_loads; g: the centres of mass). */
void state_loads_add(const state_loads *s, const solver *sv, const double *reg, const double *g,
                     double *rhs);
/* Power the loads deliver, W: F . v at the point, T omega (from the solved
 * velocities); *scale gets the size terms for the relative residual. */
double state_loads_power(const state_loads *s, const solver *sv, const double *reg,
                         double *scale);
/* Load i in words, as mech check shows it: "force at T on link 'ram'". */
void state_loads_describe(const mech_model *m, int i, char *buf, size_t size);

#endif
