/* include/mech.h: public API of libmech, a declarative planar-mechanism
 * interpreter (YAML file -> model -> loop equations -> solutions).
 *
 * Three kinds of data are kept apart (see docs/architecture.md):
 *   the model    (this header: what the file says, in SI units, fixed after load),
 *   the analysis (equations, tape, sparsity pattern, columns; built once, then
 *                 read only and shared by threads: mech_analysis below),
 *   the state    (positions, velocities, factors...; changes every crank step,
 *                 one per thread, inside mech_analysis_solve).
 *
 * Ownership: every mech_*_new / mech_load_* result is released by the matching
 * mech_*_free, which accepts NULL.
 *
 * Pointers: which arguments may be NULL, function by function, is the list
 * "NULL arguments" at the end of this header; a required one given as NULL
 * is MECH_EINPUT (with the message in the mech_diag, when there is one),
 * never a crash. Versions, sizes and the ABI: "Versions" at the end. */
#ifndef MECH_H
#define MECH_H

#include <stddef.h>
#include <stdio.h>

/* The version of this header; the library's is mech_version(). */
#define MECH_VERSION "0.2.0"

/* Status codes returned by library calls: 0 success, < 0 failure. */
enum {
    MECH_OK = 0,
    MECH_EINPUT = -1,  /* the file or the mechanism is invalid */
    MECH_ENOMEM = -2,  /* out of memory */
    MECH_EIO = -3,     /* cannot read or write a file */
    MECH_ESOLVE = -4   /* numerical failure (no assembly, singular position) */
};

/* ------------------------------------------------------------------ */
/* Diagnostics: every problem found, with its place in the input.      */

typedef enum { MECH_SEV_ERROR, MECH_SEV_WARNING, MECH_SEV_NOTE } mech_severity;

/* What kind of problem a diagnostic reports, and what made a solve fail
 * (mech_diag_entry.kind, mech_solve_stats.failure): the failure as data, so
 * that no program has to read the messages' words (docs/api.md, "Failure
 * kinds"). New kinds are appended; the values never change. */
typedef enum {
    MECH_FAIL_NONE = 0,      /* no failure: notes, and warnings that report none */
    MECH_FAIL_INPUT,         /* the file or the mechanism is invalid: syntax, names, units,
                                topology, mobility, a structurally singular system */
    MECH_FAIL_IO,            /* a file cannot be read or written */
    MECH_FAIL_NOMEM,         /* out of memory */
    MECH_FAIL_NO_ASSEMBLY,   /* cannot assemble: the loops do not close (links that cannot
                                reach each other, a position past an assembly limit) */
    MECH_FAIL_DEAD_POINT,    /* a singular position the driver cannot pass: dead point,
                                toggle, limit position */
    MECH_FAIL_CHANGE_POINT,  /* a singular position where two assembly branches cross */
    MECH_FAIL_BRANCH,        /* not on the declared assembly branch (at the first position,
                                or leaving it) */
    MECH_FAIL_JUMP,          /* the solution jumps even with a tiny step */
    MECH_FAIL_REDUNDANT,     /* redundant constraints: equations implied by the others (a
                                warning), reactions that are then not unique (an error) */
    MECH_FAIL_NOT_CONVERGED, /* an iteration does not converge: joint friction's fixed point
                                (the mechanism may be self-locking there) */
    MECH_FAIL_NON_FINITE,    /* a result is not a finite number (the data overflow) */
    /* a suspect assembly (warnings; errors under `--strict`, docs/solver.md section 9):
       the sweep solved, but not the mechanism the file seems to mean */
    MECH_FAIL_FAR_FROM_GUESS, /* the first position far from an `initial:` guess (or a
                                stated pose) */
    MECH_FAIL_ON_GROUND_POINT, /* a moving point on a ground point over the whole sweep */
    MECH_FAIL_STILL_SLIDER,  /* a slider whose travel is zero over the whole sweep */
    MECH_FAIL_FOLDED_LOOP,   /* two pinned links of a loop folded onto each other over
                                the whole sweep */
    MECH_FAIL_STILL_OUTPUTS  /* the driver's motion moves none of the outputs */
} mech_fail_kind;

/* A place in an input file; line and col are 1-based, 0 means "unknown". */
typedef struct mech_mark {
    int line;
    int col;
} mech_mark;

typedef struct mech_diag_entry {
    mech_severity severity;
    char *file;          /* file name as given, owned */
    mech_mark mark;
    char *message;       /* one sentence, no trailing newline, owned */
    mech_fail_kind kind; /* what it reports (MECH_FAIL_NONE for most notes and warnings) */
} mech_diag_entry;

typedef struct mech_diag {
    mech_diag_entry *entries; /* [count] in the order found */
    size_t count;
    size_t capacity;
    size_t nerrors;           /* entries with severity ERROR */
    size_t max_errors;        /* stop recording errors after this many (0 = 100) */
    int truncated;            /* 1 when errors were dropped */
} mech_diag;

void mech_diag_init(mech_diag *d);
void mech_diag_free(mech_diag *d);
/* Print "file:line:col: error: message" lines, one per entry. */
void mech_diag_print(const mech_diag *d, FILE *out);
/* The failure d's errors report: MECH_FAIL_NONE when it holds no error, else
 * the gravest of their kinds (NOMEM first, whatever followed it; then those
 * that stop a sweep: NOT_CONVERGED, NON_FINITE; then the singular ones:
 * DEAD_POINT, CHANGE_POINT, REDUNDANT; else the first error's), the same
 * rule as mech_solve_stats.failure. */
mech_fail_kind mech_diag_failure(const mech_diag *d);
/* A fixed word for each kind: "none", "input", "io", "no-memory",
 * "no-assembly", "dead-point", "change-point", "branch", "jump", "redundant",
 * "not-converged", "non-finite", "far-from-guess", "on-ground-point",
 * "still-slider", "folded-loop", "still-outputs"; "unknown" for a value out
 * of range. */
const char *mech_fail_name(mech_fail_kind k);

/* ------------------------------------------------------------------ */
/* The model: everything in SI units (m, rad, kg, s, N).               */

typedef struct mech_point {
    char *name;     /* owned */
    int id;         /* index into mech_model.point_names (shared names = same pin) */
    double x, y;    /* in the link's own frame, m */
    mech_mark mark;
    double dxy[2];  /* unused, 0 (kept for the layout): d(x, y)/d(parameter) comes from the
                       model's parameter expressions (mech_model.pexpr) */
} mech_point;

typedef struct mech_link {
    char *name;          /* owned; the ground link is always links[0], named "ground" */
    char *symbol;        /* printing symbol of the link angle, or NULL */
    int is_ground;
    mech_point *points;  /* [npoints] */
    int npoints;
    int has_mass;        /* mass/center/inertia were given */
    double mass;         /* kg */
    double center[2];    /* centre of mass in the link frame, m */
    double inertia;      /* about the centre of mass, kg*m^2 */
    mech_mark mark;
} mech_link;

typedef enum { MECH_JOINT_REVOLUTE, MECH_JOINT_SLIDER } mech_joint_kind;

typedef struct mech_joint {
    mech_joint_kind kind;
    char *name;        /* owned; default: point name (revolute), "s_<point>" (slider) */
    char *symbol;      /* printing symbol of the slider displacement, or NULL */
    int link[2];       /* revolute: the two links; slider: [0] sliding link, [1] guide */
    int point[2];      /* point index in link[0] and link[1]; for a slider, [1] is the
                          guide's `through` point */
    double angle;      /* slider: line direction in the guide's frame, rad */
    int locked;        /* slider: 1 = prismatic (no relative rotation), 0 = pin in slot */
    double friction;   /* Coulomb coefficient, 0 if none */
    double pin_radius; /* revolute: pin radius for the friction moment, m */
    int is_explicit;   /* listed under joints: (else implied by a shared point name) */
    mech_mark mark;
} mech_joint;

/* The kind of a driven coordinate (MECH_DRIVE_ANGLE: a link angle,
 * MECH_DRIVE_SLIDER: a slider displacement), and of the sweep variable q:
 * a driver's own angle or displacement (`driver:`), or MECH_DRIVE_TIME, the
 * time t of the laws of `drivers:` (docs/format.md section 7.3). */
typedef enum { MECH_DRIVE_ANGLE, MECH_DRIVE_SLIDER, MECH_DRIVE_TIME } mech_drive_kind;

/* The sweep: the variable q every row of a table is solved at. */
typedef struct mech_driver {
    mech_drive_kind kind; /* q's kind: its unit (rad, m, s), column name and words */
    int index;         /* ANGLE, SLIDER: the link or joint whose coordinate q is (a view
                          of drivers[0].index); TIME: 0 */
    double *values;    /* [nvalues] sweep positions, rad, m or s */
    int nvalues;
    double speed;      /* rad/s or m/s (1 for the time) */
    double accel;      /* rad/s^2 or m/s^2 (0 for the time) */
    mech_mark mark;
} mech_driver;

/* One driver (docs/format.md section 7.3): a link angle (MECH_DRIVE_ANGLE,
 * link index) or a slider displacement (MECH_DRIVE_SLIDER, joint index)
 * held to a law of the sweep variable q, compiled symbolically
 * (src/load/load.h). `driver:` is the driver whose law is q itself; each
 * entry of `drivers:` is a law of the time. */
typedef struct mech_motion {
    mech_drive_kind kind; /* MECH_DRIVE_ANGLE: link index; MECH_DRIVE_SLIDER: joint index */
    int index;
    char *text;           /* owned: the law as written; NULL for `driver:` (the law q) */
    struct mech_law *law; /* its expression tree (src/load/load.h): owned, but for the law q
                             of `driver:`, one tree shared by all models */
    mech_mark mark;
} mech_motion;

typedef struct mech_guess {
    int is_slider;     /* 0: link angle, 1: slider displacement */
    int index;         /* link or joint index */
    double value;      /* rad or m */
    mech_mark mark;
} mech_guess;

/* What an assembly branch condition compares (docs/format.md 8.2). */
typedef enum {
    MECH_BRANCH_TURN,   /* the turn point[0] -> point[1] -> point[2]: ccw (+1) or cw (-1) */
    MECH_BRANCH_X,      /* x of point[0] - x of point[1]: right of (+1) or left of (-1) */
    MECH_BRANCH_Y,      /* y of point[0] - y of point[1]: above (+1) or below (-1) */
    MECH_BRANCH_SLIDER  /* the displacement of slider joint `slider`: positive (+1) or
                           negative (-1) */
} mech_branch_kind;

/* Assembly branch condition: the quantity of `kind` has the sign `sign`;
 * points are name ids (X, Y: point[2] == point[1]; SLIDER: none, -1).
 * first_only: it selects the assembly at the first position (and at each
 * re-assembly after a gap); the continuation then follows by continuity. */
typedef struct mech_branch {
    mech_branch_kind kind;
    int point[3];
    int slider;        /* joint index (SLIDER), else -1 */
    int sign;
    int first_only;
    mech_mark mark;
} mech_branch;

typedef struct mech_loop {
    int *points;       /* [npoints] name ids, first == last */
    int npoints;
    mech_mark mark;
    mech_mark *marks;  /* [npoints] place of each name */
} mech_loop;

typedef enum { MECH_LOAD_FORCE, MECH_LOAD_TORQUE, MECH_LOAD_DISTRIBUTED } mech_load_kind;

typedef struct mech_load {
    mech_load_kind kind;
    int link;
    int point[2];      /* FORCE: [0] point of application; DISTRIBUTED: from, to */
    double force[2];   /* FORCE: N, in the ground frame */
    double torque;     /* TORQUE: N*m, counter-clockwise positive */
    double intensity;  /* DISTRIBUTED: N/m along the segment */
    double direction;  /* DISTRIBUTED: direction of the load in the ground frame, rad */
    mech_mark mark;
} mech_load;

typedef struct mech_param {
    char *name;
    double value;      /* SI, or a pure number */
    mech_mark mark;
    char unit[32];     /* SI unit of the value ("m", "rad", "kg/m^3"), "" for a bare number */
    double tol;        /* tolerance: the value is value +- tol (same unit); 0 when none */
} mech_param;

/* A spring and/or viscous damper (docs/forces.md section 7). LINEAR: between
 * point[0] of link[0] and point[1] of link[1], the force along the line
 * joining them, tension positive: preload + stiffness (L - free) + damping
 * dL/dt. TORSION: at the revolute joint `joint`, between its receiving link
 * link[0] (the later in the file) and link[1]: the relative angle
 * phi = th[link[0]] - th[link[1]], torque preload + stiffness (phi - free)
 * + damping dphi/dt acting on link[1], its opposite on link[0]. */
typedef enum { MECH_SPRING_LINEAR, MECH_SPRING_TORSION } mech_spring_kind;

typedef struct mech_spring {
    mech_spring_kind kind;
    char *name;        /* owned; column base name */
    int link[2];
    int point[2];      /* LINEAR: point index in link[0], link[1]; TORSION: -1 */
    int joint;         /* TORSION: revolute joint index; LINEAR: -1 */
    double stiffness;  /* N/m or N*m/rad, >= 0 (0: a damper only) */
    double free;       /* free length (m) or free angle (rad) */
    double preload;    /* N or N*m at the free length or angle */
    double damping;    /* N*s/m or N*m*s/rad, >= 0 */
    mech_mark mark;
} mech_spring;

/* A gear pair or a rack and pinion (docs/format.md section gears,
 * docs/forces.md): one higher pair, one constraint row after the loop rows.
 * PAIR: gears link[0] (a, 'gear') and link[1] (b, 'with') turn about pivots
 * fixed in the arm `arm` (the ground or a carrier); with phi_k = th[link[k]]
 * - th[arm] - offset[k]:  radius[0] phi_0 + sign radius[1] phi_1 = 0, sign
 * +1 external, -1 internal. RACK: pinion link[0] pivoted on the guide `arm`
 * of the locked slider `rack` (its moving link is link[1]):
 * s - offset[1] - side radius[0] phi_0 = 0. */
typedef enum { MECH_GEAR_PAIR, MECH_GEAR_RACK } mech_gear_kind;

typedef struct mech_gear {
    mech_gear_kind kind;
    char *name;        /* owned; column base name */
    int link[2];       /* PAIR: gear a, gear b; RACK: pinion, the rack's moving link */
    int arm;           /* link carrying both pivots (PAIR) or the pinion's pivot (RACK) */
    int pivot[2];      /* point index of each pivot in link[k] (RACK: [1] = -1) */
    int arm_pivot[2];  /* the same pivots as point indices in the arm (RACK: [1] = -1) */
    int rack;          /* RACK: the slider joint; PAIR: -1 */
    double radius[2];  /* pitch radii, m (RACK: [1] = 0) */
    int teeth[2];      /* tooth counts when given, else 0 */
    int internal;      /* PAIR: 1 = internal (a ring gear meshes inside) */
    int side;          /* RACK: +1 or -1, the side of the rack's line the pinion is on */
    double offset[2];  /* PAIR: angles th - th_arm where the pair meshes as drawn, rad;
                          RACK: [0] pinion angle, [1] rack displacement there, m */
    double pressure_angle; /* rad */
    mech_mark mark;
} mech_gear;

typedef struct mech_outputs {
    int *points;       /* [npoints] name ids */
    int npoints;
    int *links;        /* [nlinks] link indices */
    int nlinks;
    int *sliders;      /* [nsliders] joint indices */
    int nsliders;
    int forces;        /* joint reactions and driver torque wanted */
    int *cams;         /* [ncams] cam pairs whose design quantities are columns (the cam's
                          angle on its arm, pressure angle, radii of curvature;
                          docs/cams.md); appended: the fields before keep their places */
    int ncams;
} mech_outputs;

typedef struct mech_model {
    char *file;           /* path as given */
    char *name;
    char *description;    /* or NULL */
    double gravity[2];    /* m/s^2 */
    mech_param *params;   /* [nparams] */
    int nparams;
    mech_link *links;     /* [nlinks]; links[0] is the ground */
    int nlinks;
    mech_joint *joints;   /* [njoints] */
    int njoints;
    char **point_names;   /* [npoint_names] distinct point names */
    int npoint_names;
    int has_driver;
    mech_driver driver;
    mech_guess *guesses;  /* [nguesses] */
    int nguesses;
    mech_branch *branches;/* [nbranches] */
    int nbranches;
    mech_loop *loops;     /* [nloops] explicit loops (may be 0: found automatically) */
    int nloops;
    mech_load *loads;     /* [nloads] */
    int nloads;
    mech_outputs outputs;
    mech_spring *springs; /* [nsprings] springs and dampers (last: the fields before
                             keep their places) */
    int nsprings;
    struct state_loads *state_loads; /* owned: the loads that depend on the motion
                                        (src/load/load.h), NULL when there are none */
    mech_gear *gears;     /* [ngears] gear pairs and racks (docs/format.md) */
    int ngears;
    mech_motion *motions; /* [nmotions] a view of `drivers` for the callers of 0.1: the
                             drivers when they are laws of time (driver.kind ==
                             MECH_DRIVE_TIME), else NULL and 0; not owned */
    int nmotions;
    mech_motion *drivers; /* [ndrivers] every driver, whichever form the file used:
                             `driver:` is one (the law q), `drivers:` one per law */
    int ndrivers;
    struct param_exprs *pexpr; /* owned: what the parameters move, as expressions over
                                  them (src/load/load.h); NULL without parameters */
    int has_start;        /* the drawn form (docs/format.md 5.4): the guesses hold at the */
    double start_q;       /* driver value start_q (the drawing's), and row 0 is reached
                             from there by continuation */
    struct file_units *units; /* owned: the file's `units:` as written, for results in
                                 them (src/base/base.h); NULL when it gives none */
    struct model_fit *fit; /* owned: the file's `fit:` section, mech fit's problem
                              (src/base/base.h, docs/synthesis.md); NULL when none */
    struct free_drivers *free_drivers; /* owned: the drivers of `drivers:` marked
                                 `free: true` (docs/dynamics.md; src/load/load.h), moved by
                                 their loads in `mech simulate`; NULL when none is */
    struct model_cams *cams; /* owned: the file's `cams:` (cam-follower pairs,
                                docs/cams.md; src/load/load.h); NULL when none */
} mech_model;

/* Read and validate a mechanism file. On success *out is the model and the
 * result is MECH_OK; otherwise *out is NULL and d holds every error found. */
int mech_load_file(const char *path, mech_model **out, mech_diag *d);
/* Same, from memory; `name` is used in messages. */
int mech_load_string(const char *text, size_t len, const char *name,
                     mech_model **out, mech_diag *d);
void mech_model_free(mech_model **m);

/* A replacement for one of the file's `parameters:`: its definition text
 * ("135 mm", "l1 + 2 mm"), evaluated where the file's would have been. */
typedef struct mech_override {
    const char *name;
    const char *text;
} mech_override;

/* mech_load_file with some parameters replaced (mech sweep). Naming a
 * parameter the file does not define is an error. */
int mech_load_file_with(const char *path, const mech_override *ov, int nov, mech_model **out,
                        mech_diag *d);

int mech_find_link(const mech_model *m, const char *name);   /* index or -1 */
int mech_find_joint(const mech_model *m, const char *name);  /* index or -1 */
int mech_find_point(const mech_model *m, const char *name);  /* name id or -1 */

/* ------------------------------------------------------------------ */
/* Structure: counts and the Gruebler-Kutzbach mobility.               */

typedef struct mech_summary {
    int nlinks;           /* including the ground */
    int nrevolute;
    int nprismatic;       /* locked sliders: 2 constraints each */
    int npin_in_slot;     /* free sliders: 1 constraint each */
    int nunknowns;        /* link angles + slider displacements, driver excluded */
    int nloops;           /* independent loops = joints - links + 1 */
    int nequations;       /* 2 * nloops + ngears + ncams */
    int mobility;         /* 3 (n - 1) - 2 j_full - j_half - ngears - ncams */
    int ndrivers;
    int ngears;           /* gear pairs and racks: higher pairs, 1 constraint each (in
                             mobility and nequations) */
    int ncams;            /* cam-follower pairs: higher pairs, 1 constraint each (in
                             mobility and nequations) */
} mech_summary;

/* Check the topology (connectivity, mobility, unknowns against equations).
 * Fills *s even on failure; errors name the links or joints involved. */
int mech_check(const mech_model *m, mech_summary *s, mech_diag *d);

/* ------------------------------------------------------------------ */
/* The equation system: unknowns, loop equations, symbolic derivatives */
/* and their compiled evaluator, built once per mechanism.             */

typedef struct mech_system mech_system;

/* Build the system of a checked model (the model must outlive it). */
int mech_system_new(const mech_model *m, mech_system **out, mech_diag *d);
/* The same equations for printing (mech equations): lengths and angles
 * that depend on the file's parameters appear as the parameters (`r`) or
 * as named lengths |AB| and angles <AB; what depends on what comes from the
 * model's parameter expressions (no file read: a model from memory too;
 * numbers are printed with more than 200 parameters). Not for solving. */
int mech_system_new_named(const mech_model *m, mech_system **out, mech_diag *d);
void mech_system_free(mech_system **s);
int mech_system_size(const mech_system *s);   /* number of unknowns */

typedef enum { MECH_FORMAT_TEXT, MECH_FORMAT_LATEX } mech_format;
/* Print unknowns, loops, position equations, Jacobian nonzeros and the
 * velocity and acceleration right-hand sides. */
void mech_system_print(const mech_system *s, mech_format fmt, FILE *out);

/* ------------------------------------------------------------------ */
/* Solving: positions, velocities, accelerations over the driver sweep */
/* (src/solve/solve.c; the numerical method is in docs/solver.md).           */

/* What to compute (bits). Accelerations need velocities, velocities need
 * positions; asking for more implies the lower levels. */
enum {
    MECH_WANT_POSITION = 1,
    MECH_WANT_VELOCITY = 2,
    MECH_WANT_ACCELERATION = 4,
    MECH_WANT_ALL = 7
};

typedef struct mech_solve_options {
    size_t size;       /* sizeof the struct the caller was compiled with, set by
                          mech_solve_options_init: the library reads no field past it */
    double tol;        /* Newton tolerance relative to the largest length (default 1e-12) */
    int max_iter;      /* Newton iterations per step before giving up (default 50) */
    double min_rcond;  /* a converged position with a smaller reciprocal condition
                          (of the column-equilibrated Jacobian's diagonal blocks) is
                          singular (default 1e-6) */
    int want;          /* MECH_WANT_* bits (default MECH_WANT_ALL) */
    int all_blocks;    /* 1: solve every unknown, also those no output needs */
    int diagnostics;   /* 1: add the columns iterations, residual, rcond */
    int has_range;     /* 1: sweep from..to in `steps` intervals instead of the file's */
    double from, to;   /* driver positions, SI (rad or m) */
    int steps;
    FILE *log;         /* when not NULL: which blocks are solved, and why (--verbose) */
    int forces;        /* 0: joint reactions and driver torque when the outputs ask
                          for them (outputs: forces: true); 1: also when they do not;
                          -1: not even when they do */
    const mech_outputs *outputs; /* what to output instead of the file's outputs
                          (mech_outputs_parse), or NULL; borrowed for the analysis */
    int friction;      /* MECH_FRICTION_*: how joint friction enters the forces */
    int linear_solver; /* MECH_LINEAR_*: how the Jacobians are factored */
    void (*progress)(void *ctx, int done, int total); /* when not NULL: called every 4096
                          driver positions (and after the last) with the rows done
                          and requested, from the solving thread */
    void *progress_ctx;
    int limit_rows;    /* 1: a partial sweep also gets a row at each limit of a gap
                          found (mech_gap.from/to with from_limit/to_limit), where
                          the position is not singular (mech solve --range assembly) */
} mech_solve_options;

enum {
    MECH_LINEAR_AUTO = 0, /* dense LU of each block of the block triangular form when
                             every block is at most 16x16, else KLU (default) */
    MECH_LINEAR_KLU       /* SuiteSparse KLU always */
};

enum {
    MECH_FRICTION_ON = 0,  /* the joints' friction coefficients are applied (default) */
    MECH_FRICTION_OFF,     /* frictionless reactions only */
    MECH_FRICTION_BOTH     /* both, the frictionless columns suffixed ".nofriction" */
};

/* The defaults in *o, a struct of `size` bytes (sizeof *o, as the caller was
 * compiled): MECH_OK, or MECH_EINPUT when the library does not know that
 * size (a header newer than the library; then o->size is 0 and every call
 * given o refuses it). Call it before setting any field. */
int mech_solve_options_init(mech_solve_options *o, size_t size);
/* mech_solve_options_init(o, sizeof *o): inline, so that the size is the
 * caller's. */
static inline void mech_solve_options_default(mech_solve_options *o)
{
    (void)mech_solve_options_init(o, sizeof *o);
}

/* A table of results: named columns with units, one row per driver step. */
typedef struct mech_column {
    char *name;        /* "q", "B.x", "coupler.omega", "x_B.s", ...; owned */
    char *unit;        /* "m", "rad/s", "-", ...; owned */
} mech_column;

/* Why requested rows of a sweep are missing (mech_gap.kind). */
typedef enum {
    MECH_GAP_NO_ASSEMBLY,  /* the loops do not close there: past a limit position */
    MECH_GAP_DEAD_POINT,   /* a singular position the driver cannot pass: dead point,
                              toggle, limit position (rows on or past it) */
    MECH_GAP_CHANGE_POINT, /* a singular position where two assembly branches cross */
    MECH_GAP_BRANCH,       /* the continuation leaves the declared branch */
    MECH_GAP_JUMP          /* the solution jumps even with a tiny step */
} mech_gap_kind;

/* A run of requested rows that were not solved. from/to bound it: the last
 * driver position solved before it and the first after it (when from_limit /
 * to_limit: a limit of the assembly, found to about 1e-12 of the row
 * spacing; otherwise the requested position itself, as when the gap starts
 * at the first requested row or runs to the last). */
typedef struct mech_gap {
    mech_gap_kind kind;    /* why its first row failed */
    int first_row, last_row; /* requested rows (indices into the driver positions) */
    double from, to;       /* rad or m */
    int from_limit, to_limit;
} mech_gap;

typedef struct mech_table {
    mech_column *columns;  /* [ncolumns] */
    int ncolumns;
    double *values;        /* [nrows * ncolumns], row-major */
    int nrows;             /* rows solved (the q column says which positions) */
    int nrequested;        /* driver positions asked for (a solver's table) */
    mech_gap *gaps;        /* [ngaps] requested rows not solved, in order; owned */
    int ngaps;
} mech_table;

void mech_table_free(mech_table *t);
/* Index of the column called `name`, or -1. */
int mech_table_column(const mech_table *t, const char *name);
/* Value of column `col` in row `row`. */
static inline double mech_table_get(const mech_table *t, int row, int col)
{
    return t->values[(size_t)row * (size_t)t->ncolumns + (size_t)col];
}

/* How a sweep went. */
typedef struct mech_solve_stats {
    int steps;               /* rows solved */
    long iterations;         /* Newton iterations, all steps */
    int max_iterations;      /* worst step */
    double worst_residual;   /* largest converged closure residual, m */
    double min_rcond;        /* smallest reciprocal condition (the rcond column) */
    double worst_rcond_q;    /* driver position where min_rcond occurred */
    int factorizations;      /* full factorisations (klu_factor, or dense blocks) */
    int refactorizations;    /* klu_refactor calls (KLU only) */
    int nunknowns;           /* unknowns of the mechanism */
    int nsolved;             /* unknowns actually solved (the needed blocks) */
    int nblocks;             /* blocks of the block triangular form */
    int nblocks_solved;
    double worst_power_residual; /* forces: largest relative power-balance residual */
    int max_friction_iterations; /* forces: worst step of the friction fixed point */
    double setup_seconds;    /* wall time to build the system, choose blocks, analyse */
    double seconds;          /* wall time of the sweep itself (all rows) */
    mech_fail_kind failure;  /* why requested rows are missing or the solve failed: the
                                gravest kind found (mech_diag_failure's rule);
                                MECH_FAIL_NONE when every row was solved */
    double failure_q;        /* driver position where that failure was found (rad, m or s);
                                NaN when none, or not at a position (the analysis) */
} mech_solve_stats;

/* Solve the driver sweep of a checked model. On success *out holds one row
 * per driver position with the outputs the model asks for (points: x, y, vx,
 * vy, ax, ay; links: angle, omega, alpha; sliders: s, v, a; with forces,
 * joint reactions, driver torque or force, power balance; SI units).
 *
 * Partial sweeps: when a row cannot be reached (past a limit position, at a
 * dead point, off the declared branch) d says why and where (driver
 * position, loop, unknowns, the assembly interval), the sweep looks for
 * re-assembly at each following requested row (Newton from the last
 * position, the guesses and scattered starts, with the declared `branch:`
 * conditions) and goes on from there; *out holds every row solved, in order,
 * and out->gaps lists the runs of requested rows that are missing, with their
 * limits and kind. The status is then MECH_ESOLVE (some requested row is
 * missing). A failure of the force analysis stops the sweep there (no gap).
 * MECH_EINPUT for an invalid system. `stats` may be NULL. */
int mech_solve(const mech_model *m, const mech_solve_options *o, mech_table *out,
               mech_solve_stats *stats, mech_diag *d);

/* ---- Poses: where the file puts the mechanism (src/solve/pose.c) ----------
 * A pose places every link: its frame's origin (m) and angle (rad) in the
 * ground's frame at the driver position q. `mech draw` draws the pose the
 * file states beside the assembled one (docs/plots.md, "mech draw"). */
typedef enum {
    MECH_POSE_NONE = 0,  /* the file states no pose (the frames are the solver's
                            default first iterate: every unknown 0) */
    MECH_POSE_GUESSED,   /* from the `initial:` guesses */
    MECH_POSE_DRAWN      /* from the file's drawing */
} mech_pose_kind;

typedef struct mech_pose {
    mech_pose_kind kind;
    double q;            /* the driver position, SI (rad, m or s) */
    double *frame;       /* [3 nlinks] origin x, y and angle of each link; the ground's
                            0, 0, 0; NaN for a link not connected to the ground */
    int nlinks;
} mech_pose;

/* The pose the file states at driver position q, for a checked model: the
 * solver's first Newton iterate at a sweep's first row (each unknown at
 * its `initial:` guess, else 0; the drivers at q), the links placed along
 * the spanning tree from the ground, so a loop the guesses do not close is
 * drawn open. kind says whether the file stated it (MECH_POSE_GUESSED) or
 * not. MECH_OK, or an error in d. Free with mech_pose_free. */
int mech_pose_guess(const mech_model *m, double q, mech_pose *out, mech_diag *d);
/* Where the pose puts point k of link `link`, m (NaN, NaN when the pose
 * is empty or not of m, or m has no such point). */
void mech_pose_point(const mech_model *m, const mech_pose *p, int link, int k, double xy[2]);
void mech_pose_free(mech_pose *p);

/* ---- Forward dynamics (src/study/simulate.c, docs/dynamics.md) -----------
 * The drivers of `drivers:` marked `free: true` move as the loads make them
 * move: mech_simulate integrates the equations of motion in those free
 * coordinates with SUNDIALS CVODE and writes one row per output time: the
 * columns of mech_solve with forces (t, the outputs, reactions, driver
 * loads, power residual), then energy.kinetic, energy.gravity,
 * energy.springs, work.loads, work.drivers, work.dampers and
 * energy.balance (J). */
enum { MECH_SIM_BDF = 0, MECH_SIM_ADAMS = 1 };

typedef struct mech_simulate_options {
    size_t size;       /* sizeof the struct, set by mech_simulate_options_default (the
                          library refuses another size, as for mech_solve_options) */
    double to;         /* last time, s (NAN: the sweep's last) */
    double step;       /* output spacing, s (0: the sweep's) */
    double rtol, atol; /* CVODE's tolerances (default 1e-8, 1e-10) */
    int method;        /* MECH_SIM_BDF (default) or MECH_SIM_ADAMS */
    long max_steps;    /* integration steps between two output times (default 1e6) */
    int stop_at_rest;  /* 1: end the run where a free coordinate's rate crosses zero
                          (CVODE's root finding; the last row is at that time) */
    const char *stop_when; /* NULL, or "NAME.MEMBER=VALUE": end the run where a point's x
                          or y, a link's angle or a slider's s crosses VALUE (bare numbers
                          mm or deg, or with a unit: "x_C.s=150 mm", "crank.angle=2 rad") */
} mech_simulate_options;

typedef struct mech_simulate_stats {
    long steps, rhs_evals, jac_evals; /* CVODE's */
    long evaluations;      /* states evaluated (positions, rates, mass matrix) */
    long force_solves;
    int rows;              /* output rows written */
    double worst_residual; /* largest Newton residual of the loops, m */
    double worst_free_load;/* largest |load| a free driver still needed at an output row
                              (0 in exact arithmetic: the equations of motion's residual) */
    double stop_time;      /* where the run ended, s */
    int stopped_at_rest;   /* the free driver (index in drivers) whose rate crossed zero
                              there (stop_at_rest), else -1 */
    double seconds;        /* wall time */
} mech_simulate_stats;

/* The defaults in *o (and o->size): call it before setting any field. */
void mech_simulate_options_default(mech_simulate_options *o);
/* Simulate a checked model with free drivers. MECH_OK; MECH_ESOLVE when the
 * run stopped early (a limit position, a dead point, an integrator failure:
 * d says where and why; out holds the rows so far); MECH_EINPUT when the
 * model has no free driver or has what the simulation does not model
 * (Coulomb friction, loads of accelerations). stats may be NULL. */
int mech_simulate(const mech_model *m, const mech_simulate_options *o, mech_table *out,
                  mech_simulate_stats *stats, mech_diag *d);

/* ---- Synthesis (src/output/fit_setup.c, src/study/fit*.c, docs/synthesis.md)
 * mech_fit fits the file's free parameters so that solved outputs meet
 * targets read from a CSV, as `mech fit FILE` does (least squares, MINPACK
 * lmder, exact Jacobian, bounds, constraints, several starts): the options
 * are those of the command; what they leave NULL or 0 comes from the file's
 * `fit:` section. libmech.so links MINPACK (libcminpack); a static link
 * that calls mech_fit adds -lcminpack. */
typedef struct mech_fit_options {
    const char *free;              /* "r=15mm:25mm,l,b" as --free; NULL: the fit: section's */
    const char *target;            /* the targets' CSV; NULL: the fit: section's (relative
                                      to the file's folder) */
    const char *const *columns;    /* [ncolumns] target columns; 0: the section's, or every
                                      column after the first */
    int ncolumns;
    const char *const *weights;    /* [nweights] "COLUMN=W" */
    int nweights;
    int starts;                    /* 0: the section's, else 16 with bounds on every free
                                      parameter, else 1 */
    int jobs;                      /* worker threads; 0: the default */
    int whole_range, free_timing;  /* 1: on (as the flags; the section may turn them on) */
    const char *transmission;      /* "A,B,MIN" as --transmission; NULL: the section's */
    unsigned long seed;            /* as --seed: 0 the Halton starts, else shifted at random */
} mech_fit_options;

typedef struct mech_fit_result {
    int nfree;
    char **names;           /* [nfree] the free parameters, owned */
    double *values;         /* [nfree] the best solution, SI */
    double objective;       /* its sum of squared weighted residuals (SI) */
    int ncolumns;
    char **columns;         /* [ncolumns] the target columns, owned */
    double *worst_error;    /* [ncolumns] the largest |solved - target|, SI */
    int nconstraints;
    char **constraints;     /* [nconstraints] the fit: section's constraints as written,
                               then "transmission A/B" */
    double *margins;        /* [nconstraints] -g, SI (>= 0: met; a transmission's least
                               angle minus its min, rad) */
    int info;               /* lmder's info for the best (1..4 converged, 5 the limit) */
    int starts, accepted;   /* local fits run; those accepted */
    int violated;           /* rejected for a violated constraint */
    long solves;            /* evaluations (the file loaded and the targets solved) */
    double seconds;         /* wall time */
} mech_fit_result;

void mech_fit_options_default(mech_fit_options *o);
/* The fit of the file at path. MECH_OK with the best solution in *r (free
 * with mech_fit_result_free); MECH_ESOLVE when no start gives a solution
 * that assembles at every target within the constraints (*r's counts say
 * how many ran); MECH_EINPUT (the file, the targets, the options), MECH_EIO,
 * MECH_ENOMEM, with the errors in d. */
int mech_fit(const char *path, const mech_fit_options *o, mech_fit_result *r, mech_diag *d);
void mech_fit_result_free(mech_fit_result *r);

/* Sensitivities (src/study/sensitivity.c, docs/sensitivity.md): to `table`, the
 * result of mech_solve(m, o, ...), add for each parameter names[k] and each
 * kinematic column COL (points' x, y, vx, vy, ax, ay; links' angle, omega,
 * alpha; sliders' s, v, a) a column "d(COL)/d(NAME)" in COL's unit over
 * NAME's SI unit (per 1 of a bare number), from the implicit-function
 * theorem: J dx/dp = -df/dp at each row, and the derivatives of the
 * velocity and acceleration equations for the rates; exact to rounding.
 * The derivatives of the points by the parameters come from the model's
 * parameter expressions (a model from a file or from memory alike; ov and
 * nov, the replacements it was loaded with, are no longer needed: the model
 * holds them); force columns get none. MECH_OK, or an error in d (an unknown
 * parameter, a parameter that sets a slider's angle or a gear pair's
 * numbers, redundant constraints, a singular row). */
int mech_sensitivity(const mech_model *m, const mech_override *ov, int nov,
                     const mech_solve_options *o, const char *const *names, int nnames,
                     mech_table *table, mech_diag *d);

/* Tolerance stack-up (docs/sensitivity.md): to `table`, the result of
 * mech_solve(m, o, ...), add for every kinematic column COL the columns
 * "worst(COL)" = sum over the parameters p with a tolerance of
 * |d(COL)/dp| tol_p, and "rss(COL)" = sqrt(sum (d(COL)/dp tol_p)^2), in
 * COL's unit (first order: from mech_sensitivity's derivatives). An error
 * when no parameter has a tolerance. */
int mech_tolerances(const mech_model *m, const mech_override *ov, int nov,
                    const mech_solve_options *o, mech_table *table, mech_diag *d);

/* ---- The analysed system ----------------------------------------------
 * mech_solve is three steps that callers may also take themselves:
 *
 *   mech_analysis_new    everything fixed for a model and options: the loop
 *                        equations and derivatives, the unknowns the outputs
 *                        need, the compiled tape, the linear solvers' pattern
 *                        analysis, the force system's pattern, the columns;
 *   mech_analysis_solve  a sweep: it allocates its own numeric state
 *                        (unknowns, rates, tape registers, factors), solves
 *                        the rows and frees the state;
 *   mech_analysis_free.
 *
 * Thread safety: an analysis is read only after mech_analysis_new, so any
 * number of threads may call mech_analysis_solve on the same analysis at
 * once, each with its own table, stats and diag. The model must outlive
 * the analysis and must not change meanwhile; options.log (if set) is
 * written only by mech_analysis_new. */
typedef struct mech_analysis mech_analysis;

/* Analyse a checked model for the options (the driver positions are the
 * file's, or the options' range). MECH_OK, or an error in d. */
int mech_analysis_new(const mech_model *m, const mech_solve_options *o, mech_analysis **out,
                      mech_diag *d);
void mech_analysis_free(mech_analysis **a);
/* Columns of the tables the analysis produces; mech_analysis_header gives
 * their names and units in a table with no rows (free it with
 * mech_table_free). MECH_OK, MECH_ENOMEM, or MECH_EINPUT for a NULL a or out. */
int mech_analysis_columns(const mech_analysis *a);
int mech_analysis_header(const mech_analysis *a, mech_table *out);
/* Solve the driver positions q[0..nq-1] (in order: each row continues from
 * the one before), or the analysis's own when q is NULL. Results, failures
 * and stats as mech_solve. */
int mech_analysis_solve(const mech_analysis *a, const double *q, int nq, mech_table *out,
                        mech_solve_stats *stats, mech_diag *d);

/* Parse a driver position from the command line: bare numbers are degrees
 * (is_angle) or millimetres, or give a unit ("2.0864 rad", "0.15 m");
 * is_angle == 2: a time (drivers as laws of t), bare numbers in seconds. */
int mech_parse_value(const char *text, int is_angle, double *si, char *err, size_t errsize);

/* Parse a comma-separated list of point, moving-link and slider names into
 * *out (the model's `forces` choice is kept); the caller frees it with
 * mech_outputs_free and passes it as mech_solve_options.outputs: the model
 * itself never changes after load. On an unknown, repeated or empty name
 * returns MECH_EINPUT with a message in err (*out untouched); an
 * empty item ("B,,C", "B,") or a name given twice is an error too. */
int mech_outputs_parse(const mech_model *m, const char *list, mech_outputs *out, char *err,
                       size_t errsize);
void mech_outputs_free(mech_outputs *o);

/* Write a table as CSV (header "name [unit]"), to a temporary file in the
 * same directory renamed over `path` when complete; "-" writes to stdout.
 * Returns MECH_OK or MECH_EIO (with a message in d). */
int mech_table_write_csv(const mech_table *t, const char *path, mech_diag *d);
/* Read a table that mech_table_write_csv, `mech solve` or `mech simulate`
 * wrote: a CSV, or HDF5 (`-o OUT.h5`, docs/cli.md), told apart by the
 * file's content. *out is overwritten (free it with mech_table_free).
 * Returns MECH_OK, MECH_EINPUT (a malformed file, FILE:LINE:COLUMN in d),
 * MECH_EIO or MECH_ENOMEM; then *out is empty. */
int mech_table_read(const char *path, mech_table *out, mech_diag *d);

/* ---- Sweeps: many variants of one mechanism file ----------------------
 * `mech sweep` as a call (src/study/sweep_run.c, docs/batch.md, docs/api.md):
 *
 *   mech_sweep_new       an empty sweep;
 *   mech_sweep_vary, mech_sweep_list, mech_sweep_metric
 *                        the grid's parameters and the summaries of each
 *                        variant's table, in the command line's words
 *                        ("l=130mm:150mm:5", "r=30mm,40mm", "range:x_B.s");
 *   mech_sweep_prepare   the file, the options (random samples instead of
 *                        a grid, forces, the shard, threads), checked once:
 *                        the first variant loads, each metric names columns
 *                        its table has;
 *   mech_sweep_run       every variant of the shard on worker threads, each
 *                        reduced to one row handed to the caller, nothing
 *                        of it kept afterwards (constant memory per variant);
 *   mech_sweep_free.
 *
 * Messages about the sweep's own arguments (not its file) have the file
 * MECH_SWEEP_ARGUMENTS; a variant that cannot be solved is a row with its
 * status, not an error. */
#define MECH_SWEEP_ARGUMENTS "mech sweep"

typedef struct mech_sweep mech_sweep;

typedef struct mech_sweep_options {
    size_t size;               /* sizeof the struct the caller was compiled with, set by
                                  mech_sweep_options_init (as mech_solve_options) */
    int forces;                /* 1: the force analysis in every variant (driver.torque) */
    long nrandom;              /* > 0: N variants with every parameter that has a
                                  tolerance uniform within it (Monte Carlo), no grid */
    unsigned long long seed;   /* of the samples (default 1): a variant's sample depends
                                  on the seed and its index only */
    long index_offset;         /* variant i of the grid is numbered index_offset + i */
    int shard_k, shard_m;      /* only the variants i % shard_m == shard_k (default 0, 1) */
    int nthreads;              /* worker threads; 0 (default): the CPUs this process
                                  may run on (its affinity mask) */
} mech_sweep_options;

/* The defaults in *o, a struct of `size` bytes, as mech_solve_options_init:
 * MECH_OK, or MECH_EINPUT when the library does not know that size (then
 * o->size is 0 and mech_sweep_prepare refuses it). */
int mech_sweep_options_init(mech_sweep_options *o, size_t size);
/* mech_sweep_options_init(o, sizeof *o), the size the caller's. */
static inline void mech_sweep_options_default(mech_sweep_options *o)
{
    (void)mech_sweep_options_init(o, sizeof *o);
}

/* What became of a variant (its table's rows are reduced to the metrics). */
typedef enum {
    MECH_VARIANT_OK,           /* "ok": every driver position solved */
    MECH_VARIANT_NO_ASSEMBLY,  /* "no-assembly": some position not reached */
    MECH_VARIANT_SINGULAR,     /* "singular": a singular position on the way */
    MECH_VARIANT_SELF_LOCKING, /* "self-locking": joint friction locks it */
    MECH_VARIANT_INVALID,      /* "invalid": the variant's model does not load or check */
    MECH_VARIANT_ERROR,        /* "error": its file could not be read */
    MECH_VARIANT_NON_FINITE    /* "non-finite": a column overflowed double precision */
} mech_variant_status;

/* "ok", "no-assembly", ... (the status column of mech sweep's CSV). */
const char *mech_variant_status_name(mech_variant_status s);

/* One variant, as mech_sweep_run hands it over (valid during the call). */
typedef struct mech_variant {
    long index;                 /* its number (index_offset included) */
    long row;                   /* this shard's row, 0 .. mech_sweep_count - 1 */
    mech_variant_status status;
    int rows;                   /* driver positions solved */
    const double *params;       /* [mech_sweep_nparams] its parameters, SI */
    const double *metrics;      /* [mech_sweep_nmetrics]; NaN when not solved */
    const char *messages;       /* "variant I: r=45 mm\n" and what its load and
                                   solve said, one line each */
    mech_fail_kind suspect;     /* solved, but its assembly is suspect: the first such
                                   warning's kind (docs/solver.md section 9), else
                                   MECH_FAIL_NONE (last: the fields before keep
                                   their places) */
} mech_variant;

/* Where the rows go. row is called once per variant, one call at a time
 * (under the sweep's lock), in the order the workers finish; done, when
 * not NULL, is asked first from any worker: 1 leaves row `row` out (it is
 * there already: mech sweep --resume). */
typedef struct mech_sweep_sink {
    void (*row)(void *ctx, const mech_variant *v);
    int (*done)(void *ctx, long row);
    void *ctx;
} mech_sweep_sink;

typedef struct mech_sweep_stats {
    long solved;       /* variants with status ok */
    long shared;       /* variants solved through the sweep's one analysis ... */
    long alone;        /* ... and those analysed on their own (docs/batch.md) */
} mech_sweep_stats;

/* An empty sweep into *out: MECH_OK or MECH_ENOMEM. */
int mech_sweep_new(mech_sweep **out);
/* A parameter of the grid: "NAME=FROM:TO:COUNT" (COUNT values from FROM to
 * TO, a unit after the numbers, the same on both: "l=130mm:150mm:5") or,
 * for mech_sweep_list, "NAME=A,B,..." (each value a quantity: "r=30mm,
 * 45 mm"). Every value of one parameter has the same dimension; at most 8
 * parameters, a grid of at most 10^7 variants. MECH_OK or MECH_EINPUT. */
int mech_sweep_vary(mech_sweep *s, const char *spec, mech_diag *d);
int mech_sweep_list(mech_sweep *s, const char *spec, mech_diag *d);
/* A summary of each variant's table (at most 32): "range:COL" (max - min),
 * "max:COL", "min:COL", "maxabs:COL", "transmission:LINK1,LINK2" (the
 * smallest angle between the links, 0..pi/2 rad), "flywheel:CS" (the
 * flywheel inertia for the coefficient of speed fluctuation CS; forces).
 * MECH_OK or MECH_EINPUT. */
int mech_sweep_metric(mech_sweep *s, const char *spec, mech_diag *d);
/* The file and options, checked: a grid or random samples (not both),
 * the file loads with the first variant's parameters, the metrics' columns
 * exist (a note when forces are asked of a file with no mass and no load).
 * o may be NULL (the defaults). MECH_OK, or the first problem's status. */
int mech_sweep_prepare(mech_sweep *s, const char *path, const mech_sweep_options *o,
                       mech_diag *d);

/* A prepared sweep's shape: its variants in all and in this shard; its
 * parameters (the grid's, or those with a tolerance) and metrics, with
 * their SI units ("m", "-" for a bare number). */
long mech_sweep_total(const mech_sweep *s);
long mech_sweep_count(const mech_sweep *s);
int mech_sweep_nparams(const mech_sweep *s);
const char *mech_sweep_param(const mech_sweep *s, int k, const char **unit);
int mech_sweep_nmetrics(const mech_sweep *s);
const char *mech_sweep_metric_label(const mech_sweep *s, int k, const char **unit);

/* Solve every variant of the shard on worker threads, each row to sink.
 * MECH_OK (whatever became of the variants: see their status), or
 * MECH_EINPUT when not prepared. stats may be NULL. */
int mech_sweep_run(mech_sweep *s, const mech_sweep_sink *sink, mech_sweep_stats *stats,
                   mech_diag *d);
void mech_sweep_free(mech_sweep **s);

/* Exit codes of the `mech` program. */
enum {
    MECH_EXIT_OK = 0,
    MECH_EXIT_SOLVE = 1,  /* input fine, but the mechanism could not be solved */
    MECH_EXIT_INPUT = 2,  /* bad usage or bad input */
    MECH_EXIT_IO = 3      /* cannot read or write a file */
};

/* ------------------------------------------------------------------ */
/* NULL arguments. Outputs a caller may not want, and inputs that have   */
/* a default, may be NULL (in brackets: what NULL means); every other    */
/* pointer is required: NULL there is MECH_EINPUT with "FUNCTION: error: */
/* ARG is NULL ..." in d (a function returning an index gives -1, a      */
/* count 0; a void one does nothing).                                     */
/*                                                                        */
/*   mech_diag_init(d), mech_diag_free(d)     d                           */
/*   mech_diag_print(d, out)                  d (nothing), out (stderr)   */
/*   mech_load_file(path, out, d)             out (the file is checked,   */
/*   mech_load_file_with(path, ov, nov,           the model freed), d;    */
/*                       out, d)                  ov when nov is 0        */
/*   mech_load_string(text, len, name,        name ("<string>"), out, d   */
/*                    out, d)                                             */
/*   mech_model_free(m)                       m, *m                       */
/*   mech_find_link, _joint, _point(m, name)  m, name (-1)                */
/*   mech_check(m, s, d)                      s, d                        */
/*   mech_system_new(m, out, d), _named       d                           */
/*   mech_system_free(s)                      s, *s                       */
/*   mech_system_size(s)                      s (0)                       */
/*   mech_system_print(s, fmt, out)           s (nothing), out (stdout)   */
/*   mech_solve_options_init(o, size)         none                        */
/*   mech_solve(m, o, out, stats, d)          o (the defaults), out (the  */
/*                                            rows are not kept), stats, d */
/*   mech_pose_guess(m, q, out, d)            d                           */
/*   mech_pose_point(m, p, link, k, xy)       m, p, xy (nothing); NaN for */
/*                                            a link or point not in m    */
/*   mech_pose_free(p)                        p                           */
/*   mech_sensitivity(m, ov, nov, o, names,   ov when nov is 0, o, names  */
/*                    nnames, table, d)       when nnames is 0, d         */
/*   mech_tolerances(m, ov, nov, o, table, d) ov when nov is 0, o, d      */
/*   mech_analysis_new(m, o, out, d)          o, d                        */
/*   mech_analysis_free(a)                    a, *a                       */
/*   mech_analysis_columns(a)                 a (0)                       */
/*   mech_analysis_header(a, out)             none                        */
/*   mech_analysis_solve(a, q, nq, out,       q (the analysis's own       */
/*                       stats, d)            positions), out, stats, d   */
/*   mech_table_free(t)                       t                           */
/*   mech_table_column(t, name)               t, name (-1)                */
/*   mech_table_get(t, row, col)              none (inline, unchecked)    */
/*   mech_table_write_csv(t, path, d)         d                           */
/*   mech_table_read(path, out, d)            d                           */
/*   mech_parse_value(text, is_angle, si,     si (the text is checked),   */
/*                    err, errsize)           err (no message)            */
/*   mech_outputs_parse(m, list, out, err,    out (the list is checked),  */
/*                      errsize)              err                         */
/*   mech_outputs_free(o)                     o                           */
/*   mech_version()                           -                           */

/* ------------------------------------------------------------------ */
/* Versions (docs/api.md, "Versions and the ABI").                      */

/* The library's version, its MECH_VERSION as built: a program may compare
 * it with the MECH_VERSION of the header it was compiled with. */
const char *mech_version(void);

/* The ABI. libmech.so's symbols carry the version node MECH_<major>.<minor>
 * of the release that brought them (MECH_0.2: libmech.map); the soname is
 * libmech.so.0.<minor> before 1.0 (each 0.x may change the ABI) and
 * libmech.so.<major> from 1.0. Within one soname:
 *   - functions are only added (in a new node), never changed or removed;
 *   - mech_solve_options grows at its end only: the library reads the
 *     caller's o->size bytes and takes the defaults for the rest;
 *   - mech_model is the library's: fields are only appended to it (read
 *     through a pointer, an older program sees the part it knows); the
 *     structs of its arrays (mech_link, mech_point, ...) and the caller's
 *     structs the library writes (mech_diag, mech_summary, mech_table,
 *     mech_column, mech_gap, mech_solve_stats, mech_outputs) do not change:
 *     changing one of them takes a new soname. */

#endif /* MECH_H */
