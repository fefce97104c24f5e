/* src/drivers.h: the drivers, each a law of the sweep variable
 * (docs/format.md section 7.3, docs/solver.md section 8).
 *
 * A law of time is a unit-checked expression of the sweep variable t, such
 * as "30 deg + 20 deg * sin(6.2832 * t / 1 s)", parsed at load time into a
 * small tree (mech_law) with every part that does not depend on t folded
 * to a number; `driver:` is the law q of its own value. The system
 * (system.c) turns each law into the expression DAG with q as the variable
 * and adds one row per driver that is not the sweep itself,
 *     g_i = coordinate_i - p_i(q) = 0,
 * after the loop and gear rows; the driven coordinates are ordinary
 * unknowns. */
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

/* ---- the one model of drivers ------------------------------------------
 * Driver k holds its coordinate x_k (a link angle or a slider
 * displacement, m->drivers[k]) to its law p_k(q) of the sweep variable q.
 * A driver whose law is q itself (`driver:`: the sweep variable is the
 * driver's own value) is the sweep: the system writes its coordinate as q,
 * with no unknown and no row, so it costs nothing over a fixed input.
 * Every other driver's coordinate is an unknown, and the driver adds one
 * row x_k - p_k(q) after the loop and gear rows (rows.h). */

/* Add the driver of `driver:`: the law q for the link or slider of
 * m->driver. 0, or -1 when out of memory. */
int drivers_add_sweep(mech_model *m);
/* Is driver k the one of `driver:`, whose law is the sweep variable itself? */
int drivers_is_sweep(const mech_model *m, int k);
/* The driver that is the sweep, or -1 (q is the time). */
int drivers_sweep(const mech_model *m);
/* The link whose angle, or the slider whose displacement, is the sweep
 * variable; -1 when none is. */
int drivers_sweep_link(const mech_model *m);
int drivers_sweep_slider(const mech_model *m);
/* The drivers that add a row: those that are not the sweep. */
int drivers_rows(const mech_model *m);
/* system.c: driver k's row x_k - p_k(q), from the link angle and slider
 * expressions of the system. */
ex drivers_row(const mech_model *m, int k, expr_ctx *c, const ex *link_angle, const ex *slide,
               ex q);
/* continuation.c: the guesses of the driven unknowns at q (link_var,
 * joint_var: the system's). */
void drivers_guess(const mech_model *m, const int *link_var, const int *joint_var, double q,
                   double *guess);
/* The name of driver k ("crank" or the slider's name). */
const char *drivers_name(const mech_model *m, int k);
/* The driver of link l's angle or of slider joint j, or -1. */
int drivers_of_link(const mech_model *m, int l);
int drivers_of_slider(const mech_model *m, int j);
/* Does a driver move link l (its angle, or its slide along a guide)? */
int drivers_move_link(const mech_model *m, int l);
/* Do a and b (two loads of one file) have the same drivers with the same
 * laws, every number bit for bit? (The system folds the laws' numbers.) */
int drivers_same(const mech_model *a, const mech_model *b);

/* model.c: the error of a mechanism with `mobility` degrees of freedom and
 * a different number of drivers: the drivers in conflict, or the links
 * left free. */
void drivers_report_count(const mech_model *m, int mobility, mech_diag *d);
/* solve.c, when the system with drivers is structurally singular: an error
 * naming the drivers that over-determine their part of the mechanism and
 * the unknowns left free (a maximum matching of rows and unknowns and its
 * Dulmage-Mendelsohn parts). MECH_EINPUT, or MECH_ENOMEM. */
int drivers_report_structure(const mech_system *s, mech_diag *d);
/* model.c: free the model's drivers. */
void drivers_free(mech_model *m);

#endif
