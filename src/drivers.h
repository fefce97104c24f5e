/* src/drivers.h: drivers as laws of time (docs/format.md section 7.3,
 * docs/solver.md section 8).
 *
 * A law is a unit-checked expression of the sweep variable t, such as
 * "30 deg + 20 deg * sin(6.2832 * t / 1 s)", parsed at load time into a
 * small tree (mech_law) with every part that does not depend on t folded
 * to a number. The system (system.c) turns each law into the expression
 * DAG with t as the driver variable q and adds one row per driver,
 *     g_i = coordinate_i - p_i(t) = 0,
 * after the loop rows; the driven coordinates are ordinary unknowns. */
#ifndef MECH_DRIVERS_H
#define MECH_DRIVERS_H

#include "expr.h"
#include "internal.h"

enum { LAW_MAX_NODES = 2048 };  /* operations in one law (law_eval's buffer) */

typedef enum { LAW_CONST, LAW_T, LAW_ADD, LAW_MUL, LAW_NEG, LAW_SIN, LAW_COS } law_op;

typedef struct law_node {
    law_op op;
    int a, b;    /* operands (node indices), -1 when unused */
    double k;    /* LAW_CONST: the value, SI */
} law_node;

struct mech_law {
    law_node *nodes;  /* [n] operands come before the node that uses them */
    int n, cap;
    int root;
};

/* Parse the law `text`, a quantity `want` (Q_ANGLE or Q_LENGTH) of the
 * time t; names are the file's parameters (env), `t`, `pi`. 0 and *out on
 * success; -1 with a message in err and its byte offset in *err_pos. */
int law_parse(const char *text, quantity want, const expr_env *env, struct mech_law **out,
              char *err, size_t errsize, size_t *err_pos);
void law_free(struct mech_law *l);
/* The law's value at time t (SI), and its first and second time derivatives
 * (by forward differentiation of the tree, independent of expr.c). */
double law_eval(const struct mech_law *l, double t, double *dt, double *dtt);
/* The law as an expression of the variable t in c. */
ex law_expr(const struct mech_law *l, expr_ctx *c, ex t);

/* ---- hooks into the other stages -------------------------------------- */

/* Rows the drivers add after the loop rows (0 for the `driver:` form). */
int drivers_rows(const mech_model *m);
/* system.c: the driver rows f[first + i] = coordinate_i - p_i(q), from the
 * link angle and slider expressions of the system. */
void drivers_residual(const mech_model *m, expr_ctx *c, const ex *link_angle, const ex *slide,
                      ex q, ex *f);
/* continuation.c: the guesses of the driven unknowns at time q (var_of:
 * the system's link_var and joint_var). */
void drivers_guess(const mech_model *m, const int *link_var, const int *joint_var, double q,
                   double *guess);
/* The name of driver i ("crank" or the slider's name). */
const char *drivers_name(const mech_model *m, int i);
/* Is link l (angle) or joint j (slider) driven by a law? */
int drivers_of_link(const mech_model *m, int l);
int drivers_of_slider(const mech_model *m, int j);

/* model.c: the error of a mechanism with `mobility` degrees of freedom and
 * a different number of drivers: the drivers in conflict, or the links
 * left free. */
void drivers_report_count(const mech_model *m, int mobility, mech_diag *d);
/* solve.c, when the system with drivers is structurally singular: an error
 * naming the drivers that over-determine their part of the mechanism and
 * the unknowns left free (a maximum matching of rows and unknowns and its
 * Dulmage-Mendelsohn parts). MECH_EINPUT, or MECH_ENOMEM. */
int drivers_report_structure(const mech_system *s, mech_diag *d);
/* model.c: free the model's motions. */
void drivers_free(mech_model *m);

#endif
