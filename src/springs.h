/* src/springs.h: springs and dampers evaluated from the solved motion
 * (docs/forces.md section 7): their length or angle, its rate, the force
 * or torque, the loads they put on the links and the power they take. */
#ifndef MECH_SPRINGS_H
#define MECH_SPRINGS_H

#include "solve.h"

/* One spring at the published position of a solver. */
typedef struct spring_state {
    double length;     /* m (LINEAR) or rad (TORSION: the relative angle) */
    double rate;       /* m/s or rad/s */
    double force;      /* N, tension positive, or N*m */
    double p[2][2];    /* LINEAR: the two ends, ground frame */
    double v[2][2];    /* their velocities */
    double u[2];       /* LINEAR: unit vector from end 0 to end 1 */
} spring_state;

void springs_eval(const mech_spring *s, const solver *sv, spring_state *st);

/* What springs and the loads along a line (state_loads.c) share: point i of
 * link l at the published position (p, v: ground frame; v may be NULL); the line from
 * point[0] of link[0] to point[1] of link[1] (ends p, v, unit vector u from
 * end 0 to end 1, along x when they coincide, length and its rate); a known
 * load (force f at p, moment t) on link l moved to the right-hand side of
 * its three Newton-Euler rows (centre g[2 l], g[2 l + 1]; nothing for the
 * ground). */
void springs_point_motion(const solver *sv, int l, int i, double p[2], double v[2]);
void springs_line(const solver *sv, const int link[2], const int point[2], double p[2][2],
                  double v[2][2], double u[2], double *length, double *rate);
void springs_add_known_load(double *rhs, const double *g, int l, const double *p,
                            const double *f, double t);

/* Move every spring's loads on the moving links to the right-hand side of
 * the Newton-Euler rows (3 per moving link: x, y, moment about the centre
 * g[2 l], g[2 l + 1]). */
void springs_add_loads(const mech_model *m, const solver *sv, const double *g, double *rhs);

/* The speeds that turn a load's size into a power scale: a force times
 * `linear`, a torque times `turning` (the driver's speed, with the
 * reference length lref between them); springs_power, state_loads_power. */
void springs_power_scales(const mech_model *m, const solver *sv, double *linear,
                          double *turning);

/* Power the springs' forces deliver to the links, W (-force * rate summed:
 * negative while they store or dissipate energy); *scale gets the sum of
 * the absolute values. */
double springs_power(const mech_model *m, const solver *sv, double *scale);

/* Spring i in words, as mech check and mech report show it: its name,
 * where it acts and its coefficients (SI; angles in deg). */
void springs_describe(const mech_model *m, int i, char *buf, size_t size);

#endif
