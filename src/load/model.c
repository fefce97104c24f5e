/* src/load/model.c: the loaded model: lookups, release, and the outputs chosen
 * on the command line (the structural check is check.c's). */
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "base.h"
#include "load.h"

int model_point_in_link(const mech_link *l, int name_id)
{
    for (int i = 0; i < l->npoints; i++)
        if (l->points[i].id == name_id)
            return i;
    return -1;
}

int mech_find_link(const mech_model *m, const char *name)
{
    if (!m || !name)
        return -1;
    for (int i = 0; i < m->nlinks; i++)
        if (m->links[i].name && strcmp(m->links[i].name, name) == 0)
            return i;
    return -1;
}

int mech_find_joint(const mech_model *m, const char *name)
{
    if (!m || !name)
        return -1;
    for (int i = 0; i < m->njoints; i++)
        if (m->joints[i].name && strcmp(m->joints[i].name, name) == 0)
            return i;
    return -1;
}

int mech_find_point(const mech_model *m, const char *name)
{
    if (!m || !name)
        return -1;
    for (int i = 0; i < m->npoint_names; i++)
        if (strcmp(m->point_names[i], name) == 0)
            return i;
    return -1;
}

void mech_model_free(mech_model **pm)
{
    mech_model *m = pm ? *pm : NULL;
    if (!m)
        return;
    for (int i = 0; i < m->nparams; i++)
        free(m->params[i].name);
    free(m->params);
    for (int i = 0; i < m->nlinks; i++) {
        mech_link *l = &m->links[i];
        for (int p = 0; p < l->npoints; p++)
            free(l->points[p].name);
        free(l->points);
        free(l->name);
        free(l->symbol);
    }
    free(m->links);
    for (int i = 0; i < m->njoints; i++) {
        free(m->joints[i].name);
        free(m->joints[i].symbol);
    }
    free(m->joints);
    for (int i = 0; i < m->npoint_names; i++)
        free(m->point_names[i]);
    free(m->point_names);
    free(m->driver.values);
    drivers_free(m);
    free(m->guesses);
    free(m->branches);
    for (int i = 0; i < m->nloops; i++) {
        free(m->loops[i].points);
        free(m->loops[i].marks);
    }
    free(m->loops);
    free(m->loads);
    for (int i = 0; i < m->nsprings; i++)
        free(m->springs[i].name);
    free(m->springs);
    state_loads_free(m->state_loads);
    pexpr_free(m->pexpr);
    free(m->units);
    model_fit_free_all(m->fit);
    for (int i = 0; i < m->ngears; i++)
        free(m->gears[i].name);
    free(m->gears);
    model_cams_free(m->cams);
    free(m->outputs.points);
    free(m->outputs.links);
    free(m->outputs.sliders);
    free(m->outputs.cams);
    free(m->file);
    free(m->name);
    free(m->description);
    free(m);
    *pm = NULL;
}

/* ---- outputs chosen on the command line -------------------------------- */

/* Every point, link and slider name, for "did you mean". */
static const char **all_names(const mech_model *m, int *count)
{
    const char **v = xcalloc((size_t)(m->npoint_names + m->nlinks + m->njoints) + 1, sizeof *v);
    int n = 0;
    for (int i = 0; v && i < m->npoint_names; i++)
        v[n++] = m->point_names[i];
    for (int i = 1; v && i < m->nlinks; i++)
        v[n++] = m->links[i].name;
    for (int i = 0; v && i < m->njoints; i++)
        if (m->joints[i].kind == MECH_JOINT_SLIDER)
            v[n++] = m->joints[i].name;
    *count = n;
    return v;
}

/* The output name that `w` likely meant: the same letters in other case
 * ("b" for "B", one only), the name of a column ("B.x" for "B"), or a
 * near one by edit distance; NULL when none. */
static const char *output_near(const char *w, const char **names, int n)
{
    const char *same = NULL;
    int nsame = 0;
    for (int i = 0; i < n; i++)
        if (names[i] && strcasecmp(w, names[i]) == 0)
            same = names[i], nsame++;
    if (nsame == 1)
        return same;
    const char *dot = strchr(w, '.');
    for (int i = 0; dot && i < n; i++)
        if (names[i] && strlen(names[i]) == (size_t)(dot - w) &&
            strncmp(w, names[i], (size_t)(dot - w)) == 0)
            return names[i];
    return nearest_name(w, names, (size_t)n);
}

static int cam_by_name(const mech_model *m, const char *w)
{
    for (int i = 0; i < model_ncams(m); i++)
        if (m->cams->cam[i].name && strcmp(m->cams->cam[i].name, w) == 0)
            return i;
    return -1;
}

/* Add output `w` (a point, moving link, slider or cam name) to `o`; MECH_EINPUT
 * with a message in err when it is none of them. */
static int add_output(const mech_model *m, mech_outputs *o, const char *w, char *err,
                      size_t errsize)
{
    int k;
    if ((k = mech_find_point(m, w)) >= 0)
        o->points[o->npoints++] = k;
    else if ((k = mech_find_link(m, w)) > 0)
        o->links[o->nlinks++] = k;
    else if ((k = mech_find_joint(m, w)) >= 0 && m->joints[k].kind == MECH_JOINT_SLIDER)
        o->sliders[o->nsliders++] = k;
    else if ((k = cam_by_name(m, w)) >= 0)
        o->cams[o->ncams++] = k;
    else {
        int n;
        const char **names = all_names(m, &n);
        const char *near = names ? output_near(w, names, n) : NULL;
        const char *dot = strchr(w, '.');
        int column = near && dot && strlen(near) == (size_t)(dot - w);
        snprintf(err, errsize, "'%s' is not a point, moving link%s of %s%s%s%s%s", w,
                 model_ncams(m) ? ", slider or cam" : " or slider",
                 m->file, near ? " (did you mean '" : "", near ? near : "", near ? "'?)" : "",
                 column ? "; outputs are names, each giving all its columns" : "");
        free(names);
        return MECH_EINPUT;
    }
    return MECH_OK;
}

/* The items of `list` (edited in place: NULs end the words): separated by
 * commas, each one or more words separated by spaces. An empty item (two
 * commas with nothing between, or a comma at either end) and a name given
 * twice are errors. */
static int parse_outputs(const mech_model *m, char *list, mech_outputs *o, char *err,
                         size_t errsize)
{
    name_map seen = {0};  /* words already listed (keys borrowed from list) */
    int rc = MECH_OK, item = 1;
    for (char *s = list; rc == MECH_OK; item++) {
        char *comma = strchr(s, ',');
        if (comma)
            *comma = '\0';
        int words = 0;
        for (char *save = NULL, *w = strtok_r(s, " ", &save); w && rc == MECH_OK;
             w = strtok_r(NULL, " ", &save), words++) {
            if (name_map_get(&seen, w) >= 0)
                snprintf(err, errsize, "'%s' is listed twice", w), rc = MECH_EINPUT;
            else if (name_map_put(&seen, w, 1) < 0)
                snprintf(err, errsize, "out of memory"), rc = MECH_ENOMEM;
            else
                rc = add_output(m, o, w, err, errsize);
        }
        if (rc == MECH_OK && words == 0 && !comma && item == 1)
            snprintf(err, errsize, "the list is empty"), rc = MECH_EINPUT;
        else if (rc == MECH_OK && words == 0)
            snprintf(err, errsize, "item %d of the list is empty (names are separated by one "
                     "comma)", item), rc = MECH_EINPUT;
        if (!comma)
            break;
        s = comma + 1;
    }
    name_map_free(&seen);
    return rc;
}

int mech_outputs_parse(const mech_model *m, const char *list, mech_outputs *out, char *err,
                       size_t errsize)
{
    if (!err)
        errsize = 0;  /* snprintf(NULL, 0, ...) writes nothing */
    if (!m || !list)
        return snprintf(err, errsize, "mech_outputs_parse: %s is NULL", m ? "list" : "m"),
               MECH_EINPUT;
    size_t len = strlen(list);
    char *copy = xstrdup(list);
    mech_outputs o = {0};
    o.points = xcalloc(len + 1, sizeof *o.points);
    o.links = xcalloc(len + 1, sizeof *o.links);
    o.sliders = xcalloc(len + 1, sizeof *o.sliders);
    o.cams = xcalloc(len + 1, sizeof *o.cams);
    o.forces = m->outputs.forces;
    int rc = MECH_OK;
    if (!copy || !o.points || !o.links || !o.sliders || !o.cams) {
        snprintf(err, errsize, "out of memory");
        rc = MECH_ENOMEM;
    }
    if (rc == MECH_OK)
        rc = parse_outputs(m, copy, &o, err, errsize);
    free(copy);
    if (rc != MECH_OK) {
        free(o.points);
        free(o.links);
        free(o.sliders);
        free(o.cams);
        return rc;
    }
    if (out)
        *out = o;
    else
        mech_outputs_free(&o);  /* the list was only checked */
    return MECH_OK;
}

void mech_outputs_free(mech_outputs *o)
{
    if (!o)
        return;
    free(o->points);
    free(o->links);
    free(o->sliders);
    free(o->cams);
    memset(o, 0, sizeof *o);
}
