/* src/load.h: private to the loader (load.c, load_tree.c, load_links.c,
 * load_joints.c, load_motion.c, load_outputs.c): the loader's state and the
 * stages and helpers they share. Not for the other modules. */
#ifndef MECH_LOAD_H
#define MECH_LOAD_H

#include "internal.h"

enum {
    MAX_NAME = 64,            /* bytes in a name */
    MAX_LINKS = 1000000,      /* links with the ground: 999 999 moving */
    MAX_POINTS_PER_LINK = 10000,
    MAX_GROUND_POINTS = 1000000, /* the ground holds every fixed pivot: a chain of
                                    100 000 four-bars has 100 001 */
    MAX_STEPS = 1000000,      /* driver intervals in one sweep (docs/limits.md) */
    MAX_PARAMS = 100000,
    MAX_LOADS = 1000000,
    MAX_LOOPS = 1000,         /* listed loops: for the papers' mechanisms; larger ones */
    MAX_LOOP_POINTS = 1000,   /* leave 'loops' out (found automatically, linear time) */
    MAX_LIST = 4000000,       /* items in any other list */
    MAX_SUGGEST = 1000        /* names searched for a "did you mean" */
};

enum { LINK_FAILED = 1, LINK_UNPLACED = 2 };  /* bits of loader.link_failed */

typedef struct loader {
    const char *file;
    mech_diag *d;
    mech_model *m;
    unit_defaults units;
    expr_param *params;   /* [m->nparams] dimensions of the parameters */
    expr_env env;
    name_map point_map;   /* point name -> id */
    name_map link_map;    /* link name -> index */
    name_map joint_map;   /* joint name -> index */
    /* Follow-on errors are not reported: one mistake, one message. */
    unsigned char *link_failed; /* [links allocated] LINK_FAILED: errors were reported about
                                   the link's points or joints: skip checks that would only
                                   echo them; LINK_UNPLACED: some point's coordinates could
                                   not be read (an error elsewhere) and are taken as 0, 0 */
    int links_bad;        /* 'links' missing or unreadable: names of links are not known */
    int points_bad;       /* some link's points unreadable: names of points are not known */
    name_map bad_params;  /* parameters whose definition failed (keys borrowed from the tree) */
    name_map param_map;   /* parameter name -> index into params (keys borrowed) */
    int *carrier_start;   /* [npoint_names + 1] after the links: the links carrying point id */
    int *carrier_link;    /* are carrier_link[carrier_start[id] .. carrier_start[id + 1] - 1], */
    int *carrier_point;   /* ascending, with the point's index in each (carrier_point) */
    int carrier_ids;      /* point ids indexed (0: no index, search the links) */
    name_map next_suffix; /* default joint name -> next suffix to try (keys: joint names) */
    const mech_override *ov; /* [nov] parameter definitions replaced (mech sweep) */
    int nov;
    unsigned char *ov_used;  /* [nov] the file defines it */
    int angle_unit_given; /* 'units:' names the angle unit: bare driver angles are meant */
    const char *seed;     /* the parameter p whose derivatives d/dp are carried (sensitivities:
                             mech_point.dxy), or NULL */
    double dlast;         /* d/dp of the last quantity evaluated (env.dvalue points here) */
} loader;

/* Index of a point, link or joint name, or -1. */
static inline int find_point(const loader *ld, const char *name)
{
    return name_map_get(&ld->point_map, name);
}
static inline int find_link(const loader *ld, const char *name)
{
    return name_map_get(&ld->link_map, name);
}
static inline int find_joint(const loader *ld, const char *name)
{
    return name_map_get(&ld->joint_map, name);
}

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))

/* ---- load_tree.c: walking the YAML tree. Every reader reports its own
 *      error (file:line:col of the node) and returns 0, -1 or NULL. */
int load_err(loader *ld, const ynode *n, const char *fmt, ...) MECH_PRINTF(3, 4);
int load_want_kind(loader *ld, const ynode *n, ynode_kind kind, const char *what);
/* A mapping's keys: scalars, no duplicates, all in `allowed`, or (allowed
 * NULL) names of `noun`s. 1 when the mapping can be read. */
int load_check_map(loader *ld, const ynode *map, const char *const *allowed, size_t nallowed,
                   const char *where, const char *noun);
int load_check_keys(loader *ld, const ynode *map, const char *const *allowed, size_t nallowed,
                    const char *where);
int load_misspelt(const ynode *map, const char *key, const char *const *allowed,
                  size_t nallowed);
const ynode *load_key_of(const ynode *map, const char *key);
int load_uses_bad_param(const loader *ld, const char *text);
int load_valid_name(const char *s);
const char *load_get_name(loader *ld, const ynode *n, const char *what); /* borrowed */
/* caller frees; `lines`: line breaks and tabs allowed */
char *load_get_string(loader *ld, const ynode *n, const char *what, size_t max, int lines);
int load_get_quantity(loader *ld, const ynode *n, quantity q, const char *what, double *out);
int load_get_count(loader *ld, const ynode *n, const char *what, long lo, long hi, long *out);
int load_get_bool(loader *ld, const ynode *n, const char *what, int *out);
int load_get_vec2(loader *ld, const ynode *n, quantity q, const char *what, double out[2]);
int load_errors_full(const loader *ld);
void load_err_unknown(loader *ld, const ynode *n, const char *kind, const char *kinds,
                      const char *name, const char *const *cands, size_t ncands);
/* Index of the named link, point or slider joint, or -1 (reported). */
int load_find_link_or_report(loader *ld, const ynode *n, const char *what);
int load_find_point_or_report(loader *ld, const ynode *n, const char *what);
int load_slider_by_name(loader *ld, const ynode *n, const char *what);
void load_carriers_of(const loader *ld, int id, int *first, int *end);
int load_point_in_link(const loader *ld, int li, int id);
/* The links that may carry end k (point id, written pnode) of a two-point
 * element (a spring, a load along a line): links[k] when the file gives
 * `links` (it must carry the point; `what` names it in the message), else
 * every carrier of the point, at most max, into cand. Their count, or -1
 * when reported. */
int load_end_candidates(loader *ld, const ynode *links, int k, int id, const ynode *pnode,
                        const char *what, int *cand, int max);

/* ---- load_links.c: units, parameters, ground, links, their points and mass. */
void load_units(loader *ld, const ynode *map);
void load_parameters(loader *ld, const ynode *map);
void load_ground(loader *ld, const ynode *map);  /* map NULL: no 'ground' key */
void load_links(loader *ld, const ynode *map);

/* ---- load_joints.c: explicit revolutes and sliders, the implicit
 *      revolutes of shared point names, the carriers index. */
void load_index_carriers(loader *ld);
void load_joints(loader *ld, const ynode *seq);
void load_add_implicit_revolutes(loader *ld);
void load_check_link_points(loader *ld);
void load_warn_point_typos(loader *ld);

/* ---- load_motion.c: driver, initial guesses, branch conditions, loops. */
void load_driver(loader *ld, const ynode *map);
/* A driver's (or the sweep's) range: a list or {from, to, steps} of q. */
void load_range(loader *ld, const ynode *n, quantity q, mech_driver *dr);
/* load_drivers.c: 'sweep: {time: RANGE}' and 'drivers: [...]' (laws of time) */
void load_sweep_drivers(loader *ld, const ynode *sweep, const ynode *drivers);
void load_initial(loader *ld, const ynode *map);
void load_branches(loader *ld, const ynode *seq);
void load_loops(loader *ld, const ynode *seq);

/* ---- load_outputs.c: loads and outputs. */
void load_loads(loader *ld, const ynode *seq);
void load_outputs(loader *ld, const ynode *map);
void load_default_outputs(mech_model *m);

/* ---- load_state_loads.c: loads that depend on the motion (docs/format.md 10.2).
 *      wanted: some component of a force [fx, fy] or torque does not read as a
 *      constant quantity; load_state_load compiles them into m->state_loads. */
int load_state_wanted(loader *ld, const ynode *value);
void load_state_load(loader *ld, const ynode *map, const ynode *value, int link, int point);
/* {force: TENSION, between: [P, Q], links: [a, b]}: a force along a line. */
void load_state_line(loader *ld, const ynode *map);

/* ---- load_springs.c: springs and dampers. */
void load_springs(loader *ld, const ynode *seq);

/* ---- load_gears.c: gear pairs and racks. */
void load_gears(loader *ld, const ynode *seq);

#endif
