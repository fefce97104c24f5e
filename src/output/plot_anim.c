/* src/output/plot_anim.c: the animated SVG of the mechanism (mech animate): the
 * solved positions read from the table, the scale and the frames chosen,
 * link outlines (convex hulls), then the drawing: traced paths, slider
 * guides, ground pivots, links, slider blocks and points, each moving by
 * SMIL <animate>/<animateTransform> (no script), or a still of one row.
 * docs/plots.md, "mech animate". Shared SVG pieces: src/output/plot_svg.c.
 *
 * The file is written whole (write_file_whole, src/output/output.c). Coordinates
 * are rounded to 0.1 px (4 significant digits of a drawing about 800 px
 * wide). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "load.h"
#include "output.h"

void plot_anim_options_default(plot_anim_options *o)
{
    memset(o, 0, sizeof *o);
    o->duration = 4.0;
    o->frame = -1;
    o->max_frames = 1000;
    o->pause_at = -1;
}

enum { ANIM_DRAW = 760, ANIM_PAD = 40, ANIM_TOP = 56, ANIM_DEC = 1 };
enum { ANIM_SCALE_BAR = 18 };  /* px below the bottom pad: the scale bar's strip */
enum { ANIM_LEGEND = 36 };     /* px under the caption for the legend of a ghost */

/* The animation: the table's positions on screen, the frames, the outlines. */
enum { CAM_SEGMENTS = 180 };  /* points of a cam's drawn profile */

typedef struct anim_ctx {
    const mech_model *m;
    const mech_table *t;
    const plot_anim_options *o;
    int np;            /* point names */
    int nrows;
    size_t cells;      /* nrows * max(np, 1): entries of X and Y */
    double *X, *Y;     /* [nrows * np] screen position of each point name per row */
    double *ang;       /* [nrows * nlinks] link angle, rad (ground 0) */
    int *rows;         /* [nframes] table rows shown */
    int nframes;
    double s, ox, oy;  /* screen = (ox + s x, oy - s y) */
    int width, height;
    double (*guide)[2];/* [njoints] guide segment: s from, s to (world, m) */
    int **hull;        /* [nlinks] point indices of the drawn outline, or NULL */
    int *nhull;        /* [nlinks] */
    unsigned char *on_ground, *pinned; /* [np] point on the ground; on 2+ links or sliding */
    double *GX, *GY;   /* [points of all links] the ghost pose's points, world m then
                          screen px (o->ghost), else NULL */
    int *gbase;        /* [nlinks] index in GX, GY of each link's first point */
    double *cam;       /* [ncams * 2 CAM_SEGMENTS] each cam's profile from its pivot, in its
                          frame, m (computed once: the same at every frame) */
} anim_ctx;

static double cross3(const mech_point *o, const mech_point *a, const mech_point *b)
{
    return (a->x - o->x) * (b->y - o->y) - (a->y - o->y) * (b->x - o->x);
}

static const mech_point *cmp_pts; /* qsort context (single-threaded) */
static int cmp_xy(const void *a, const void *b)
{
    const mech_point *p = &cmp_pts[*(const int *)a], *q = &cmp_pts[*(const int *)b];
    return p->x < q->x ? -1 : p->x > q->x ? 1 : p->y < q->y ? -1 : p->y > q->y ? 1 : 0;
}

/* Convex hull of a link's points in its own frame (Andrew's monotone chain);
 * out[] gets point indices counter-clockwise; returns their count (2 for a
 * bar: collinear points give the two extreme ones). */
static int link_hull(const mech_link *l, int *out)
{
    int n = l->npoints;
    int *idx = xcalloc((size_t)n, sizeof *idx);
    if (!idx)
        return 0;
    for (int i = 0; i < n; i++)
        idx[i] = i;
    cmp_pts = l->points;
    qsort(idx, (size_t)n, sizeof *idx, cmp_xy);
    int k = 0;
    for (int i = 0; i < n; i++) {
        while (k >= 2 && cross3(&l->points[out[k - 2]], &l->points[out[k - 1]],
                                &l->points[idx[i]]) <= 0)
            k--;
        out[k++] = idx[i];
    }
    for (int i = n - 2, lo = k + 1; i >= 0; i--) {
        while (k >= lo && cross3(&l->points[out[k - 2]], &l->points[out[k - 1]],
                                 &l->points[idx[i]]) <= 0)
            k--;
        out[k++] = idx[i];
    }
    free(idx);
    return k > 1 ? k - 1 : k;
}

static void anim_free(anim_ctx *c)
{
    free(c->X);
    free(c->Y);
    free(c->ang);
    free(c->rows);
    free(c->guide);
    if (c->hull)
        for (int i = 0; i < c->m->nlinks; i++)
            free(c->hull[i]);
    free(c->hull);
    free(c->nhull);
    free(c->on_ground);
    free(c->pinned);
    free(c->GX);
    free(c->GY);
    free(c->gbase);
    free(c->cam);
}

/* Sliding point (name id), through point (name id) and guide link of joint j. */
static void slider_points(const mech_model *m, int j, int *slide, int *through, int *guide)
{
    const mech_joint *jt = &m->joints[j];
    *slide = m->links[jt->link[0]].points[jt->point[0]].id;
    *through = m->links[jt->link[1]].points[jt->point[1]].id;
    *guide = jt->link[1];
}

/* ------------------------------------------------------------------ */
/* Reading the table: positions, scale, frames, outlines.              */

/* The sizes and the arrays of c (freed by anim_free). */
static int anim_alloc(anim_ctx *c, mech_diag *d)
{
    const mech_model *m = c->m;
    c->np = m->npoint_names;
    c->nrows = c->t->nrows;
    if (c->nrows < 1)
        return diag_error(d, m->file, (mech_mark){0, 0}, "nothing to draw: no solved position");
    c->cells = (size_t)c->nrows * (size_t)(c->np > 0 ? c->np : 1);
    c->X = xcalloc(c->cells, sizeof *c->X);
    c->Y = xcalloc(c->cells, sizeof *c->Y);
    c->ang = xcalloc((size_t)c->nrows * (size_t)m->nlinks, sizeof *c->ang);
    c->guide = xcalloc((size_t)m->njoints + 1, sizeof *c->guide);
    c->hull = xcalloc((size_t)m->nlinks, sizeof *c->hull);
    c->nhull = xcalloc((size_t)m->nlinks, sizeof *c->nhull);
    c->on_ground = xcalloc((size_t)c->np + 1, 1);
    c->pinned = xcalloc((size_t)c->np + 1, 1);
    c->rows = xcalloc((size_t)c->nrows, sizeof *c->rows);
    c->cam = xcalloc(2 * CAM_SEGMENTS * (size_t)model_ncams(m) + 1, sizeof *c->cam);
    if (!c->X || !c->Y || !c->ang || !c->guide || !c->hull || !c->nhull || !c->on_ground ||
        !c->pinned || !c->rows || !c->cam)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    return MECH_OK;
}

/* World positions of every point name (X, Y hold metres until the scale is
 * known) and the angle of every moving link, per row. */
static int read_rows(anim_ctx *c, mech_diag *d)
{
    const mech_model *m = c->m;
    const mech_table *t = c->t;
    char name[160];
    for (int p = 0; p < c->np; p++) {
        snprintf(name, sizeof name, "%s.x", m->point_names[p]);
        int cx = mech_table_column(t, name);
        snprintf(name, sizeof name, "%s.y", m->point_names[p]);
        int cy = mech_table_column(t, name);
        if (cx < 0 || cy < 0)
            return diag_error(d, m->file, (mech_mark){0, 0},
                              "internal: no position column for point '%s'", m->point_names[p]);
        for (int r = 0; r < c->nrows; r++) {
            c->X[(size_t)r * c->np + p] = mech_table_get(t, r, cx);
            c->Y[(size_t)r * c->np + p] = mech_table_get(t, r, cy);
        }
    }
    for (int i = 1; i < m->nlinks; i++) {
        snprintf(name, sizeof name, "%s.angle", m->links[i].name);
        int ca = mech_table_column(t, name);
        if (ca < 0)
            return diag_error(d, m->file, (mech_mark){0, 0},
                              "internal: no angle column for link '%s'", m->links[i].name);
        for (int r = 0; r < c->nrows; r++)
            c->ang[(size_t)r * m->nlinks + i] = mech_table_get(t, r, ca);
    }
    return MECH_OK;
}

/* The ghost pose's points, link by link (world m until the scale is known):
 * a point on two links has two places when the pose does not close a loop. */
static int read_ghost(anim_ctx *c, mech_diag *d)
{
    const mech_model *m = c->m;
    if (!c->o->ghost)
        return MECH_OK;
    size_t total = 0;
    c->gbase = xcalloc((size_t)m->nlinks, sizeof *c->gbase);
    for (int l = 0; c->gbase && l < m->nlinks; l++) {
        c->gbase[l] = (int)total;
        total += (size_t)m->links[l].npoints;
    }
    c->GX = xcalloc(total + 1, sizeof *c->GX);
    c->GY = xcalloc(total + 1, sizeof *c->GY);
    if (!c->gbase || !c->GX || !c->GY)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    for (int l = 0; l < m->nlinks; l++)
        for (int k = 0; k < m->links[l].npoints; k++) {
            double xy[2];
            mech_pose_point(m, c->o->ghost, l, k, xy);
            c->GX[c->gbase[l] + k] = xy[0];
            c->GY[c->gbase[l] + k] = xy[1];
        }
    return MECH_OK;
}

/* The number of the ghost's points (0 without a ghost). */
static size_t ghost_points(const anim_ctx *c)
{
    int l = c->m->nlinks - 1;
    return c->GX ? (size_t)c->gbase[l] + (size_t)c->m->links[l].npoints : 0;
}

/* Which points are pins (on two links or more), which are on the ground. */
static int mark_points(anim_ctx *c, mech_diag *d)
{
    const mech_model *m = c->m;
    int *count = xcalloc((size_t)c->np + 1, sizeof *count);
    if (!count)
        return diag_nomem(d, m->file, (mech_mark){0, 0});
    for (int i = 0; i < m->nlinks; i++)
        for (int k = 0; k < m->links[i].npoints; k++) {
            count[m->links[i].points[k].id]++;
            if (i == 0)
                c->on_ground[m->links[i].points[k].id] = 1;
        }
    for (int p = 0; p < c->np; p++)
        c->pinned[p] = count[p] >= 2;
    free(count);
    return MECH_OK;
}

/* A bounding box, world metres. */
typedef struct box {
    double xmin, xmax, ymin, ymax;
} box;

/* The box b grown to hold the finite points (x[k], y[k]), k < n. */
static void grow_box(box *b, const double *x, const double *y, size_t n)
{
    for (size_t k = 0; k < n; k++) {
        if (!isfinite(x[k]) || !isfinite(y[k]))
            continue;
        b->xmin = fmin(b->xmin, x[k]);
        b->xmax = fmax(b->xmax, x[k]);
        b->ymin = fmin(b->ymin, y[k]);
        b->ymax = fmax(b->ymax, y[k]);
    }
}

/* The bounding box of every point over every row, and of the ghost's (0..1
 * when there is none). */
static void bounds(const anim_ctx *c, box *b)
{
    box g = {INFINITY, -INFINITY, INFINITY, -INFINITY};
    if (c->np > 0)
        grow_box(&g, c->X, c->Y, c->cells);
    grow_box(&g, c->GX, c->GY, ghost_points(c));
    double xmin = g.xmin, xmax = g.xmax, ymin = g.ymin, ymax = g.ymax;
    if (!(xmax >= xmin) || !(ymax >= ymin))
        xmin = ymin = 0, xmax = ymax = 1;
    *b = (box){xmin, xmax, ymin, ymax};
}

/* Guides: the line through `through` covering every position of the slider
 * plus `margin` (m) at both ends; the sliding points become pins; the box
 * grows to hold the guides. */
static void place_guides(anim_ctx *c, box *b, double margin)
{
    const mech_model *m = c->m;
    for (int j = 0; j < m->njoints; j++) {
        if (m->joints[j].kind != MECH_JOINT_SLIDER)
            continue;
        c->pinned[m->links[m->joints[j].link[0]].points[m->joints[j].point[0]].id] = 1;
        int sp, tp, g;
        slider_points(m, j, &sp, &tp, &g);
        double smin = 0, smax = 0;
        for (int r = 0; r < c->nrows; r++) {
            double a = c->ang[(size_t)r * m->nlinks + g] + m->joints[j].angle;
            double dx = c->X[(size_t)r * c->np + sp] - c->X[(size_t)r * c->np + tp];
            double dy = c->Y[(size_t)r * c->np + sp] - c->Y[(size_t)r * c->np + tp];
            double sv = dx * cos(a) + dy * sin(a);
            if (isfinite(sv)) {
                smin = fmin(smin, sv);
                smax = fmax(smax, sv);
            }
        }
        c->guide[j][0] = smin - margin;
        c->guide[j][1] = smax + margin;
        for (int r = 0; r < c->nrows; r++) {
            double a = c->ang[(size_t)r * m->nlinks + g] + m->joints[j].angle;
            for (int e = 0; e < 2; e++) {
                double x = c->X[(size_t)r * c->np + tp] + c->guide[j][e] * cos(a);
                double y = c->Y[(size_t)r * c->np + tp] + c->guide[j][e] * sin(a);
                if (isfinite(x) && isfinite(y)) {
                    b->xmin = fmin(b->xmin, x);
                    b->xmax = fmax(b->xmax, x);
                    b->ymin = fmin(b->ymin, y);
                    b->ymax = fmax(b->ymax, y);
                }
            }
        }
    }
}

/* A gear's pitch circle (docs/format.md 6.4): drawn about its pivot; the box
 * grows to hold it. Gear k of pair i is `which` = 2 i + k. */
enum { GEAR_SEGMENTS = 72 };

static void gear_of(const anim_ctx *c, int which, int *link, int *p, double *radius)
{
    const mech_gear *g = &c->m->gears[which / 2];
    int k = which % 2;
    *link = g->link[k];
    *p = c->m->links[g->link[k]].points[g->pivot[k]].id;
    *radius = g->radius[k];
}

/* The box grows to hold a circle of radius rad about point p in every row. */
static void hold_circle(const anim_ctx *c, int p, double rad, box *b)
{
    for (int r = 0; r < c->nrows; r++) {
        double x = c->X[(size_t)r * c->np + p], y = c->Y[(size_t)r * c->np + p];
        if (isfinite(x) && isfinite(y)) {
            b->xmin = fmin(b->xmin, x - rad);
            b->xmax = fmax(b->xmax, x + rad);
            b->ymin = fmin(b->ymin, y - rad);
            b->ymax = fmax(b->ymax, y + rad);
        }
    }
}

static void place_gears(const anim_ctx *c, box *b)
{
    for (int w = 0; w < 2 * c->m->ngears; w++) {
        if (c->m->gears[w / 2].kind == MECH_GEAR_RACK && w % 2)
            continue;
        int l, p;
        double rad;
        gear_of(c, w, &l, &p, &rad);
        hold_circle(c, p, rad, b);
    }
}

/* A cam's profile (docs/cams.md 5): drawn about its pivot in the cam's
 * frame, CAM_SEGMENTS points of cam_geometry over a turn (kept in c->cam);
 * the box holds its farthest. */

static void place_cams(anim_ctx *c, box *b)
{
    for (int w = 0; w < model_ncams(c->m); w++) {
        const mech_cam *cm = &c->m->cams->cam[w];
        const mech_point *oc = &c->m->links[cm->cam].points[cm->cam_pivot[0]];
        int p = oc->id;
        double rad = 0.0, *xy = c->cam + 2 * CAM_SEGMENTS * (size_t)w;
        for (int k = 0; k < CAM_SEGMENTS; k++) {  /* a whole turn */
            cam_point g;
            cam_geometry(c->m, cm, 2.0 * 3.14159265358979323846 * k / CAM_SEGMENTS, &g);
            xy[2 * k] = g.profile[0] - oc->x;
            xy[2 * k + 1] = g.profile[1] - oc->y;
            rad = fmax(rad, hypot(xy[2 * k], xy[2 * k + 1]));
        }
        hold_circle(c, p, rad, b);
    }
}

/* The scale (the larger side of box b is ANIM_DRAW px; pads leave room for
 * symbols), the page size, and X, Y from metres to screen px. */
static void set_scale(anim_ctx *c, const box *b)
{
    double xmin = b->xmin, xmax = b->xmax, ymin = b->ymin, ymax = b->ymax;
    double size = fmax(fmax(xmax - xmin, ymax - ymin), 1e-9);
    c->s = ANIM_DRAW / size;
    c->width = (int)ceil((xmax - xmin) * c->s) + 2 * ANIM_PAD;
    int top = ANIM_TOP + (c->GX ? ANIM_LEGEND : 0);
    c->height = (int)ceil((ymax - ymin) * c->s) + ANIM_PAD + top + ANIM_SCALE_BAR;
    if (c->width < 320)
        c->width = 320;
    c->ox = (c->width - (xmax - xmin) * c->s) / 2 - xmin * c->s;
    c->oy = top + ymax * c->s;
    for (size_t k = 0; k < c->cells && c->np > 0; k++) {
        c->X[k] = c->ox + c->s * c->X[k];
        c->Y[k] = c->oy - c->s * c->Y[k];
    }
    for (size_t k = 0; k < ghost_points(c); k++) {
        c->GX[k] = c->ox + c->s * c->GX[k];
        c->GY[k] = c->oy - c->s * c->GY[k];
    }
}

/* The rows shown: row `frame` alone, or at most max_frames evenly spread. */
static int choose_frames(anim_ctx *c, mech_diag *d)
{
    if (c->o->frame >= 0) {
        if (c->o->frame >= c->nrows)
            return diag_error(d, c->m->file, (mech_mark){0, 0},
                              "--frame %d: the sweep has %d positions (frames 0 to %d)",
                              c->o->frame, c->nrows, c->nrows - 1);
        c->rows[0] = c->o->frame;
        c->nframes = 1;
    } else {
        c->nframes = plot_anim_frame_rows(c->nrows, c->o->max_frames, c->rows);
    }
    return MECH_OK;
}

int plot_anim_frame_rows(int nrows, int max_frames, int *rows)
{
    int nf = nrows;
    if (max_frames > 1 && nf > max_frames)
        nf = max_frames;
    for (int k = 0; k < nf; k++)
        rows[k] = nf > 1 ? (int)((long long)k * (nrows - 1) / (nf - 1)) : 0;
    return nf;
}

/* Outlines of the links in their own frames. */
static int make_outlines(anim_ctx *c, mech_diag *d)
{
    const mech_model *m = c->m;
    for (int i = 1; i < m->nlinks; i++) {
        if (m->links[i].npoints < 2)
            continue;
        c->hull[i] = xcalloc((size_t)m->links[i].npoints + 1, sizeof *c->hull[i]);
        if (!c->hull[i])
            return diag_nomem(d, m->file, (mech_mark){0, 0});
        c->nhull[i] = link_hull(&m->links[i], c->hull[i]);
    }
    return MECH_OK;
}

/* Read the table, choose the frames, the scale and the outlines. */
static int anim_prepare(anim_ctx *c, mech_diag *d)
{
    int rc = anim_alloc(c, d);
    if (rc == MECH_OK)
        rc = read_rows(c, d);
    if (rc == MECH_OK)
        rc = mark_points(c, d);
    if (rc == MECH_OK)
        rc = read_ghost(c, d);
    if (rc != MECH_OK)
        return rc;
    box b;
    bounds(c, &b);
    double size = fmax(fmax(b.xmax - b.xmin, b.ymax - b.ymin), 1e-9);
    place_guides(c, &b, 0.08 * size);
    place_gears(c, &b);
    place_cams(c, &b);
    set_scale(c, &b);
    rc = choose_frames(c, d);
    if (rc == MECH_OK)
        rc = make_outlines(c, d);
    return rc;
}

/* ------------------------------------------------------------------ */
/* Drawing.                                                            */

/* A shape's vertices in row r: fills xs, ys (screen), returns their count. */
typedef int (*shape_fn)(const anim_ctx *c, int which, int r, double *xs, double *ys);

static int link_shape(const anim_ctx *c, int i, int r, double *xs, double *ys)
{
    const mech_link *l = &c->m->links[i];
    for (int k = 0; k < c->nhull[i]; k++) {
        int p = l->points[c->hull[i][k]].id;
        xs[k] = c->X[(size_t)r * c->np + p];
        ys[k] = c->Y[(size_t)r * c->np + p];
    }
    return c->nhull[i];
}

/* The block of slider j: a rectangle along the guide around the sliding point. */
static int block_shape(const anim_ctx *c, int j, int r, double *xs, double *ys)
{
    int sp, tp, g;
    slider_points(c->m, j, &sp, &tp, &g);
    double a = c->ang[(size_t)r * c->m->nlinks + g] + c->m->joints[j].angle;
    double hl = c->m->joints[j].locked ? 17 : 11, hw = c->m->joints[j].locked ? 10 : 6;
    double ux = cos(a), uy = -sin(a); /* screen y points down */
    double vx = -uy, vy = ux;
    double x = c->X[(size_t)r * c->np + sp], y = c->Y[(size_t)r * c->np + sp];
    static const int sx[4] = {-1, 1, 1, -1}, sy[4] = {-1, -1, 1, 1};
    for (int k = 0; k < 4; k++) {
        xs[k] = x + sx[k] * hl * ux + sy[k] * hw * vx;
        ys[k] = y + sx[k] * hl * uy + sy[k] * hw * vy;
    }
    return 4;
}

/* The guide line of slider j. */
static int guide_shape(const anim_ctx *c, int j, int r, double *xs, double *ys)
{
    int sp, tp, g;
    slider_points(c->m, j, &sp, &tp, &g);
    double a = c->ang[(size_t)r * c->m->nlinks + g] + c->m->joints[j].angle;
    for (int e = 0; e < 2; e++) {
        xs[e] = c->X[(size_t)r * c->np + tp] + c->s * c->guide[j][e] * cos(a);
        ys[e] = c->Y[(size_t)r * c->np + tp] - c->s * c->guide[j][e] * sin(a);
    }
    return 2;
}

/* Gear `which`'s pitch circle from a spoke: the pivot, the rim along the
 * gear's x axis, once round (the spoke shows it turn). */
static int gear_shape(const anim_ctx *c, int which, int r, double *xs, double *ys)
{
    int l, p;
    double rad;
    gear_of(c, which, &l, &p, &rad);
    double x = c->X[(size_t)r * c->np + p], y = c->Y[(size_t)r * c->np + p];
    double a = c->ang[(size_t)r * c->m->nlinks + l], pr = c->s * rad;
    xs[0] = x;
    ys[0] = y;
    for (int k = 0; k <= GEAR_SEGMENTS; k++) {
        double t = a + 2.0 * 3.14159265358979323846 * k / GEAR_SEGMENTS;
        xs[k + 1] = x + pr * cos(t);
        ys[k + 1] = y - pr * sin(t);  /* screen y points down */
    }
    return GEAR_SEGMENTS + 2;
}

static int cam_shape(const anim_ctx *c, int which, int r, double *xs, double *ys)
{
    const mech_cam *cm = &c->m->cams->cam[which];
    const mech_point *oc = &c->m->links[cm->cam].points[cm->cam_pivot[0]];
    double x = c->X[(size_t)r * c->np + oc->id], y = c->Y[(size_t)r * c->np + oc->id];
    double a = c->ang[(size_t)r * c->m->nlinks + cm->cam], ca = cos(a), sa = sin(a);
    const double *xy = c->cam + 2 * CAM_SEGMENTS * (size_t)which;
    for (int k = 0; k < CAM_SEGMENTS; k++) {
        double dx = xy[2 * k], dy = xy[2 * k + 1];
        xs[k] = x + c->s * (ca * dx - sa * dy);
        ys[k] = y - c->s * (sa * dx + ca * dy);  /* screen y points down */
    }
    return CAM_SEGMENTS;
}

/* A roller follower's roller: a circle about its centre (the slider's
 * point, or 'at'). */
static int roller_shape(const anim_ctx *c, int which, int r, double *xs, double *ys)
{
    const mech_cam *cm = &c->m->cams->cam[which];
    const mech_joint *jt = cm->slider >= 0 ? &c->m->joints[cm->slider] : NULL;
    const mech_link *fl = &c->m->links[cm->follower];
    int p = (jt ? fl->points[jt->point[0]] : fl->points[cm->at]).id;
    double x = c->X[(size_t)r * c->np + p], y = c->Y[(size_t)r * c->np + p], pr = c->s * cm->roller;
    for (int k = 0; k < GEAR_SEGMENTS; k++) {
        double t = 2.0 * 3.14159265358979323846 * k / GEAR_SEGMENTS;
        xs[k] = x + pr * cos(t);
        ys[k] = y - pr * sin(t);
    }
    return GEAR_SEGMENTS;
}

static void put_vertices(FILE *f, const double *xs, const double *ys, int n)
{
    for (int k = 0; k < n; k++)
        plot_put_xy(f, k ? " " : "", xs[k], ys[k], ANIM_DEC);
}

/* A <polygon> or <polyline> (tag) whose "points" follow shape(which);
 * `attrs` are its other attributes; `moving` 0 for a static shape. */
static void put_shape(FILE *f, const anim_ctx *c, const char *tag, const char *attrs,
                      shape_fn shape, int which, int moving, double *xs, double *ys)
{
    int n = shape(c, which, c->rows[0], xs, ys);
    if (n < 2)
        return;
    fprintf(f, "<%s %s points=\"", tag, attrs);
    put_vertices(f, xs, ys, n);
    if (!moving || c->nframes < 2) {
        fputs("\"/>\n", f);
        return;
    }
    char b[32];
    fprintf(f, "\"><animate attributeName=\"points\" dur=\"%ss\" repeatCount=\"indefinite\" "
               "values=\"", plot_fmt(b, c->o->duration, 3));
    for (int k = 0; k < c->nframes; k++) {
        if (k)
            fputc(';', f);
        shape(c, which, c->rows[k], xs, ys);
        put_vertices(f, xs, ys, n);
    }
    fprintf(f, "\"/></%s>\n", tag);
}

static const char *const link_fill[6] = {"#9ec5e8", "#f2b8a0", "#b5dcae", "#d3bde6", "#f1d79a",
                                         "#a8dcd9"};
static const char *const link_stroke[6] = {"#2c5d8f", "#a5462a", "#3c7a34", "#6a4391", "#9a7415",
                                           "#2a7d78"};

/* Ground pivot symbol at (x, y): a triangle, its base and hatching. */
static void put_pivot(FILE *f, double x, double y, int test)
{
    char a[32], b[32];
    fprintf(f, "<g transform=\"translate(%s,%s)\" stroke=\"%s\" stroke-width=\"1.3\">"
               "<path d=\"M0,0L-9,15H9z\" fill=\"%s\"/><path d=\"M-15,15H15\"/>"
               "<path d=\"M-13,21l5-6M-7,21l5-6M-1,21l5-6M5,21l5-6M11,21l4-4.8\"/></g>\n",
            plot_fmt(a, x, ANIM_DEC), plot_fmt(b, y, ANIM_DEC), test ? "#555" : "#333",
            test ? "#ccc" : "#e8e8e8");
}

/* Hatching beside a ground guide from (x0,y0) to (x1,y1): short strokes every 10 px. */
static void put_guide_hatch(FILE *f, double x0, double y0, double x1, double y1, int test)
{
    double len = hypot(x1 - x0, y1 - y0);
    if (!(len > 0))
        return;
    double ux = (x1 - x0) / len, uy = (y1 - y0) / len, nx = uy, ny = -ux; /* one side */
    char a[32], b[32], e[32], g[32];
    fprintf(f, "<path stroke=\"%s\" stroke-width=\"1\" d=\"", test ? "#777" : "#666");
    for (double s = 4; s < len - 4; s += 10) {
        double x = x0 + s * ux + 13 * nx, y = y0 + s * uy + 13 * ny;
        fprintf(f, "M%s,%sl%s,%s", plot_fmt(a, x, ANIM_DEC), plot_fmt(b, y, ANIM_DEC),
                plot_fmt(e, 6 * ux - 6 * nx, ANIM_DEC), plot_fmt(g, 6 * uy - 6 * ny, ANIM_DEC));
    }
    fputs("\"/>\n", f);
}

/* Unique test colour of point name p: red 255, green and blue from p, never grey. */
static void test_colour(int p, char *buf, size_t n)
{
    unsigned g = (unsigned)(p * 37 + 11) % 251u, b = (unsigned)(p * 101 + 3) % 241u;
    snprintf(buf, n, "#ff%02x%02x", g, b);
}

/* The document's start: root element with the mapping from metres, title,
 * background, and the caption (the name; the driver range, or the driver
 * position of a still). dur: the duration as printed. */
static void put_caption(FILE *f, const anim_ctx *c, const char *dur)
{
    const mech_model *m = c->m;
    char b1[32], b2[32];
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%d\" height=\"%d\" "
               "viewBox=\"0 0 %d %d\" font-family=\"DejaVu Sans,Arial,Helvetica,sans-serif\" "
               "font-size=\"12\" data-mech-transform=\"%.9g %.9g %.9g\">\n",
            c->width, c->height, c->width, c->height, c->s, c->ox, c->oy);
    fputs("<!-- screen x = ox + s*x, y = oy - s*y (x, y in metres); "
          "data-mech-transform holds s ox oy -->\n<title>", f);
    plot_put_text(f, m->name ? m->name : m->file);
    fputs("</title>\n", f);
    fprintf(f, "<rect width=\"%d\" height=\"%d\" fill=\"#fff\"/>\n", c->width, c->height);
    /* caption */
    fputs("<text x=\"12\" y=\"22\" font-size=\"15\" font-weight=\"bold\" fill=\"#222\">", f);
    plot_put_text(f, m->name ? m->name : m->file);
    fputs("</text>\n<text x=\"12\" y=\"40\" fill=\"#555\">", f);
    if (c->o->caption) {
        plot_put_text(f, c->o->caption);
        fputs("</text>\n", f);
        return;
    }
    int slider_drv = m->has_driver && m->driver.kind == MECH_DRIVE_SLIDER;
    int time_drv = m->has_driver && m->driver.kind == MECH_DRIVE_TIME;  /* laws of t */
    double qk = time_drv ? 1.0 : slider_drv ? 1e3 : RAD2DEG;
    const char *qu = time_drv ? "s" : slider_drv ? "mm" : "deg";
    if (c->nframes == 1)
        fprintf(f, "driver %s = %s %s (position %d of %d)",
                time_drv ? "time" : slider_drv ? "displacement" : "angle",
                plot_fmt(b1, mech_table_get(c->t, c->rows[0], 0) * qk, 3), qu, c->rows[0],
                c->nrows);
    else
        fprintf(f, "driver from %s to %s %s, %d frames in %s s",
                plot_fmt(b1, mech_table_get(c->t, 0, 0) * qk, 3),
                plot_fmt(b2, mech_table_get(c->t, c->nrows - 1, 0) * qk, 3), qu, c->nframes, dur);
    fputs("</text>\n", f);
}

/* Point p of the animation, row r, in page px (plot_vertex_fn). */
typedef struct trace_ref {
    const anim_ctx *c;
    int p;
} trace_ref;

static int trace_vertex(const void *v, int r, double *px, double *py)
{
    const trace_ref *k = v;
    *px = k->c->X[(size_t)r * k->c->np + k->p];
    *py = k->c->Y[(size_t)r * k->c->np + k->p];
    return isfinite(*px) && isfinite(*py);
}

/* Traced paths of the chosen points (not of ground points), through every
 * solved row, not only the frames: whole up to THIN_FROM rows, else thinned
 * to within PLOT_THIN_TOL px (docs/plots.md, "Long sweeps"). */
static void put_traces(FILE *f, const anim_ctx *c)
{
    int test = c->o->test_colours;
    for (int k = 0; k < c->o->ntrace; k++) {
        int p = c->o->trace[k];
        if (p < 0 || p >= c->np || c->on_ground[p])
            continue;
        fprintf(f, "<path fill=\"none\" stroke=\"%s\" stroke-width=\"1.2\" "
                   "stroke-dasharray=\"4,2\" data-trace=\"%s\" d=\"", test ? "#bbb" : "#e07b39",
                c->m->point_names[p]);
        trace_ref ref = {c, p};
        plot_pen pen = {f, 0, ANIM_DEC, 0};
        if (c->nrows <= THIN_FROM)
            plot_draw_all(&pen, trace_vertex, &ref, c->nrows);
        else
            plot_thin_draw(&pen, plot_thin_tolerance(trace_vertex, &ref, c->nrows, 2 * THIN_FROM),
                           trace_vertex, &ref, c->nrows);
        fputs("\"/>\n", f);
    }
}

/* The scale bar, bottom left: 1, 2 or 5 x 10^k mm, 60 to 150 px long, with
 * end ticks and its length written beside it; data-mech-scale-bar holds its
 * length in metres and its left end, right end and y on the page. */
static void put_scale_bar(FILE *f, const anim_ctx *c)
{
    double mm = plot_nice_step(60.0 * 1e3 / c->s, 1);  /* the bar in mm */
    double len = mm * 1e-3 * c->s, x0 = 12, y = c->height - 14;
    char b1[32], b2[32], b3[32];
    const char *colour = c->o->test_colours ? "#00a0ff" : "#222";
    fprintf(f, "<g id=\"scale-bar\" data-mech-scale-bar=\"%.9g %s %s %s\" fill=\"%s\" "
               "shape-rendering=\"crispEdges\">", mm * 1e-3, plot_fmt(b1, x0, 2),
            plot_fmt(b2, x0 + len, 2), plot_fmt(b3, y, 2), colour);
    fprintf(f, "<rect x=\"%s\" y=\"%s\" width=\"%s\" height=\"3\"/>", b1,
            plot_fmt(b3, y - 1.5, 2), plot_fmt(b2, len, 2));
    fprintf(f, "<rect x=\"%s\" y=\"%s\" width=\"1.5\" height=\"9\"/>", b1,
            plot_fmt(b3, y - 4.5, 2));
    fprintf(f, "<rect x=\"%s\" y=\"%s\" width=\"1.5\" height=\"9\"/>",
            plot_fmt(b2, x0 + len - 1.5, 2), b3);
    fprintf(f, "<text x=\"%s\" y=\"%s\" font-size=\"11\" fill=\"#222\" "
               "shape-rendering=\"auto\">%s mm</text></g>\n", plot_fmt(b1, x0 + len + 6, 2),
            plot_fmt(b2, y + 4, 2), plot_fmt(b3, mm, 6));
}

/* Slider guides, hatched when on the ground; ground pivots under the
 * ground points that are pins. xs, ys: workspace of 2 or more vertices. */
static void put_guides_and_pivots(FILE *f, const anim_ctx *c, double *xs, double *ys)
{
    const mech_model *m = c->m;
    int test = c->o->test_colours;
    for (int j = 0; j < m->njoints; j++) {
        if (m->joints[j].kind != MECH_JOINT_SLIDER)
            continue;
        int g = m->joints[j].link[1];
        put_shape(f, c, "polyline", test ? "stroke=\"#888\" stroke-width=\"2\" fill=\"none\""
                                         : "stroke=\"#555\" stroke-width=\"2\" fill=\"none\"",
                  guide_shape, j, g != 0, xs, ys);
        if (g == 0) {
            guide_shape(c, j, c->rows[0], xs, ys);
            put_guide_hatch(f, xs[0], ys[0], xs[1], ys[1], test);
        }
    }
    for (int k = 0; k < m->links[0].npoints; k++) {
        int p = m->links[0].points[k].id;
        if (c->pinned[p])
            put_pivot(f, c->X[p], c->Y[p], test);
    }
}

/* Links: plates (3+ points not on a line) and bars; then the slider blocks.
 * xs, ys: workspace of as many vertices as the largest outline (4 or more). */
static void put_links_and_blocks(FILE *f, const anim_ctx *c, double *xs, double *ys)
{
    const mech_model *m = c->m;
    int test = c->o->test_colours;
    for (int i = 1; i < m->nlinks; i++) {
        char attrs[200];
        int n = c->nhull[i];
        if (n < 2)
            continue;
        const char *fill = test ? "#d6d6d6" : link_fill[i % 6];
        const char *stroke = test ? "#8a8a8a" : link_stroke[i % 6];
        if (n >= 3)
            snprintf(attrs, sizeof attrs, "fill=\"%s\" fill-opacity=\"%s\" stroke=\"%s\" "
                     "stroke-width=\"2.5\" stroke-linejoin=\"round\"", fill, test ? "1" : "0.75",
                     stroke);
        else
            snprintf(attrs, sizeof attrs, "fill=\"none\" stroke=\"%s\" stroke-width=\"8\" "
                     "stroke-linecap=\"round\"", stroke);
        put_shape(f, c, n >= 3 ? "polygon" : "polyline", attrs, link_shape, i, 1, xs, ys);
    }
    for (int j = 0; j < m->njoints; j++)
        if (m->joints[j].kind == MECH_JOINT_SLIDER)
            put_shape(f, c, "polygon",
                      test ? "fill=\"#c4c4c4\" stroke=\"#666\" stroke-width=\"1.5\""
                           : "fill=\"#cfd6de\" stroke=\"#34495e\" stroke-width=\"1.5\" "
                             "stroke-linejoin=\"round\"",
                      block_shape, j, 1, xs, ys);
}

/* Point p: a disc (pins) or a dot, with the name (test mode: a disc of its
 * own colour), moved by an <animateTransform> unless on the ground. */
static void put_point(FILE *f, const anim_ctx *c, int p, const char *dur)
{
    const mech_model *m = c->m;
    char b1[32], b2[32];
    size_t at = (size_t)c->rows[0] * c->np + p;
    fprintf(f, "<g id=\"P-%s\" transform=\"translate(%s,%s)\">", m->point_names[p],
            plot_fmt(b1, c->X[at], ANIM_DEC), plot_fmt(b2, c->Y[at], ANIM_DEC));
    if (c->o->test_colours) {
        char col[16];
        test_colour(p, col, sizeof col);
        fprintf(f, "<circle r=\"5\" fill=\"%s\" data-point=\"%s\"/>", col, m->point_names[p]);
    } else {
        if (c->pinned[p])
            fputs("<circle r=\"4.5\" fill=\"#fff\" stroke=\"#111\" stroke-width=\"1.6\"/>", f);
        else
            fputs("<circle r=\"3\" fill=\"#111\"/>", f);
        fprintf(f, "<text x=\"7\" y=\"-7\" font-size=\"11\" fill=\"#111\">%s</text>",
                m->point_names[p]);
    }
    if (!c->on_ground[p] && c->nframes > 1) {
        fprintf(f, "<animateTransform attributeName=\"transform\" type=\"translate\" "
                   "dur=\"%ss\" repeatCount=\"indefinite\" values=\"", dur);
        for (int k = 0; k < c->nframes; k++) {
            size_t q = (size_t)c->rows[k] * c->np + p;
            fprintf(f, "%s%s %s", k ? ";" : "", plot_fmt(b1, c->X[q], ANIM_DEC),
                    plot_fmt(b2, c->Y[q], ANIM_DEC));
        }
        fputs("\"/>", f);
    }
    fputs("</g>\n", f);
}

/* ------------------------------------------------------------------ */
/* mech draw: the stated pose behind the mechanism, names, the legend. */

#define GHOST_COLOUR "#8c8c8c"

/* Link i of the ghost pose: its outline (the same hull as the link's),
 * dashed, and a ring at each of its points; data-link names it. */
static void put_ghost_link(FILE *f, const anim_ctx *c, int i)
{
    const mech_link *l = &c->m->links[i];
    int n = c->nhull[i], at = c->gbase[i];
    fputs("<g data-link=\"", f);
    plot_put_text(f, l->name);
    fputs("\">", f);
    if (n >= 2) {
        fprintf(f, "<%s fill=\"%s\" fill-opacity=\"0.08\" stroke=\"" GHOST_COLOUR "\" "
                   "stroke-width=\"1.5\" stroke-dasharray=\"6,4\" points=\"",
                n >= 3 ? "polygon" : "polyline", n >= 3 ? GHOST_COLOUR : "none");
        for (int k = 0; k < n; k++)
            plot_put_xy(f, k ? " " : "", c->GX[at + c->hull[i][k]], c->GY[at + c->hull[i][k]],
                        ANIM_DEC);
        fputs("\"/>", f);
    }
    char b1[32], b2[32];
    for (int k = 0; k < l->npoints; k++)
        fprintf(f, "<circle cx=\"%s\" cy=\"%s\" r=\"3\" fill=\"none\" stroke=\"" GHOST_COLOUR
                   "\" data-point=\"%s\"/>", plot_fmt(b1, c->GX[at + k], ANIM_DEC),
                plot_fmt(b2, c->GY[at + k], ANIM_DEC), l->points[k].name);
    fputs("</g>\n", f);
}

/* The ghost pose of every moving link, behind the mechanism. */
static void put_ghost(FILE *f, const anim_ctx *c)
{
    if (!c->GX)
        return;
    fprintf(f, "<g id=\"ghost\" data-mech-pose=\"%s\">\n",
            c->o->ghost->kind == MECH_POSE_DRAWN ? "drawn" : "guessed");
    for (int i = 1; i < c->m->nlinks; i++)
        put_ghost_link(f, c, i);
    fputs("</g>\n", f);
}

/* The legend of a drawing with a ghost, under the caption: the ghost's
 * line and text, then the mechanism's. */
static void put_legend(FILE *f, const anim_ctx *c)
{
    if (!c->GX)
        return;
    fputs("<g id=\"legend\" font-size=\"11\" fill=\"#222\">"
          "<path d=\"M12,56h26\" stroke=\"" GHOST_COLOUR "\" stroke-width=\"1.5\" "
          "stroke-dasharray=\"6,4\"/><text x=\"44\" y=\"60\">", f);
    plot_put_text(f, c->o->ghost_legend ? c->o->ghost_legend : "as stated");
    fputs("</text><path d=\"M12,74h26\" stroke=\"#2c5d8f\" stroke-width=\"4\"/>"
          "<text x=\"44\" y=\"78\">as assembled</text></g>\n", f);
}

/* Names of the links (at the middle of their outlines) and of the joints
 * that are not named after their point (beside the point), in row rows[0]. */
static void put_labels(FILE *f, const anim_ctx *c)
{
    const mech_model *m = c->m;
    int r = c->rows[0];
    char b1[32], b2[32];
    fputs("<g id=\"labels\" font-size=\"11\" font-style=\"italic\" stroke=\"#fff\" "
          "stroke-width=\"3\" paint-order=\"stroke\">\n", f);
    for (int i = 1; i < m->nlinks; i++) {
        double sx = 0, sy = 0;
        int n = c->nhull[i];
        for (int k = 0; k < n; k++) {
            int p = m->links[i].points[c->hull[i][k]].id;
            sx += c->X[(size_t)r * c->np + p];
            sy += c->Y[(size_t)r * c->np + p];
        }
        if (n < 1 || !isfinite(sx) || !isfinite(sy))
            continue;
        fprintf(f, "<text x=\"%s\" y=\"%s\" text-anchor=\"middle\" fill=\"%s\" "
                   "data-link=\"%s\">", plot_fmt(b1, sx / n, ANIM_DEC),
                plot_fmt(b2, sy / n + 14, ANIM_DEC), link_stroke[i % 6], m->links[i].name);
        plot_put_text(f, m->links[i].name);
        fputs("</text>\n", f);
    }
    for (int j = 0; j < m->njoints; j++) {
        const mech_joint *jt = &m->joints[j];
        int p = m->links[jt->link[0]].points[jt->point[0]].id;
        if (jt->kind == MECH_JOINT_REVOLUTE && strcmp(jt->name, m->point_names[p]) == 0)
            continue;  /* the point's own label says it */
        fprintf(f, "<text x=\"%s\" y=\"%s\" fill=\"#555\" data-joint=\"%s\">",
                plot_fmt(b1, c->X[(size_t)r * c->np + p] + 7, ANIM_DEC),
                plot_fmt(b2, c->Y[(size_t)r * c->np + p] + 22, ANIM_DEC), jt->name);
        plot_put_text(f, jt->name);
        fputs("</text>\n", f);
    }
    fputs("</g>\n", f);
}

/* The whole document, from back to front (docs/plots.md). */
static int emit_animation(FILE *f, const void *vctx)
{
    const anim_ctx *c = vctx;
    const mech_model *m = c->m;
    char b3[32];
    int maxv = model_ncams(m) ? CAM_SEGMENTS + 2 : m->ngears ? GEAR_SEGMENTS + 2 : 4;
    for (int i = 0; i < m->nlinks; i++)
        if (c->nhull[i] > maxv)
            maxv = c->nhull[i];
    double *xs = xcalloc((size_t)maxv, sizeof *xs), *ys = xcalloc((size_t)maxv, sizeof *ys);
    if (!xs || !ys) {
        free(xs);
        free(ys);
        return -1;
    }
    const char *dur = plot_fmt(b3, c->o->duration, 3);
    put_caption(f, c, dur);
    put_traces(f, c);
    put_scale_bar(f, c);
    put_ghost(f, c);
    put_guides_and_pivots(f, c, xs, ys);
    put_links_and_blocks(f, c, xs, ys);
    for (int w = 0; w < 2 * m->ngears; w++) {  /* pitch circles over the links */
        if (m->gears[w / 2].kind == MECH_GEAR_RACK && w % 2)
            continue;
        int l = m->gears[w / 2].link[w % 2];
        char attrs[128];
        snprintf(attrs, sizeof attrs, "fill=\"none\" stroke=\"%s\" stroke-width=\"2\" "
                 "stroke-dasharray=\"6 3\"", c->o->test_colours ? "#8a8a8a"
                                                  : l ? link_stroke[l % 6] : "#555");
        put_shape(f, c, "polyline", attrs, gear_shape, w, 1, xs, ys);
    }
    for (int w = 0; w < model_ncams(m); w++) {  /* each cam's profile, turning with it */
        int l = m->cams->cam[w].cam;
        char attrs[128];
        snprintf(attrs, sizeof attrs, "class=\"cam\" fill=\"%s\" fill-opacity=\"0.6\" "
                 "stroke=\"%s\" stroke-width=\"2\"", c->o->test_colours ? "#c8c8c8"
                 : link_fill[l % 6], c->o->test_colours ? "#8a8a8a" : link_stroke[l % 6]);
        put_shape(f, c, "polygon", attrs, cam_shape, w, 1, xs, ys);
        if (m->cams->cam[w].contact == CAM_ROLLER)
            put_shape(f, c, "polygon", "class=\"roller\" fill=\"white\" stroke=\"#444\" "
                      "stroke-width=\"2\"", roller_shape, w, 1, xs, ys);
    }
    for (int p = 0; p < c->np; p++)
        put_point(f, c, p, dur);
    if (c->o->labels && c->nframes == 1)
        put_labels(f, c);
    put_legend(f, c);
    if (c->o->pause_at >= 0 && c->nframes > 1) /* tests: a still of the running animation */
        fprintf(f, "<script>var s = document.documentElement; s.pauseAnimations(); "
                   "s.setCurrentTime(%.9g); window.addEventListener('load', function () "
                   "{ s.pauseAnimations(); s.setCurrentTime(%.9g); });</script>\n",
                c->o->pause_at, c->o->pause_at);
    fputs("</svg>\n", f);
    free(xs);
    free(ys);
    return ferror(f) ? -1 : 0;
}

/* Prepare, then write the document: to `path` whole, or (path NULL) to f. */
static int animation_to(const mech_model *m, const mech_table *t, const plot_anim_options *o,
                        const char *path, FILE *f, mech_diag *d)
{
    anim_ctx c;
    memset(&c, 0, sizeof c);
    c.m = m;
    c.t = t;
    c.o = o;
    int rc = anim_prepare(&c, d);
    if (rc == MECH_OK && path)
        rc = write_file_whole(path, emit_animation, &c, d);
    else if (rc == MECH_OK && emit_animation(f, &c) != 0)
        rc = diag_fail(d, MECH_FAIL_IO, m->file, (mech_mark){0, 0}, "cannot write the animation");
    anim_free(&c);
    return rc;
}

int plot_animation_write(const mech_model *m, const mech_table *t, const plot_anim_options *o,
                         const char *path, mech_diag *d)
{
    return animation_to(m, t, o, path, NULL, d);
}

int plot_animation_fprint(const mech_model *m, const mech_table *t, const plot_anim_options *o,
                          FILE *f, mech_diag *d)
{
    return animation_to(m, t, o, NULL, f, d);
}
