/* src/output/plot_svg.c: the SVG pieces the figures (plot.c, plot_path.c) and the
 * animation (plot_anim.c) share: numbers without noise (plot_fmt), 1-2-5
 * tick steps, text escaping, axes (range, ticks, labels, titles), series
 * styles, and the path data of a curve: whole, thinned to within a
 * tolerance in page px (plot_thin_draw, the sleeve), or to four vertices
 * per pixel column.
 * Declarations: src/output/output.h (private), src/output/output.h (plot_fmt,
 * plot_nice_step). docs/plots.md, "Axes, units, styles". */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "output.h"

/* ------------------------------------------------------------------ */
/* Numbers and text.                                                   */

char *plot_fmt(char *buf, double v, int decimals)
{
    if (!isfinite(v)) {
        snprintf(buf, 32, "0");
        return buf;
    }
    snprintf(buf, 32, "%.*f", decimals, v);
    if (strchr(buf, '.')) {
        char *e = buf + strlen(buf) - 1;
        while (*e == '0')
            *e-- = '\0';
        if (*e == '.')
            *e = '\0';
    }
    if (strcmp(buf, "-0") == 0)
        snprintf(buf, 32, "0");
    return buf;
}

double plot_nice_step(double span, int target)
{
    static const double mult[] = {1.0, 2.0, 5.0, 10.0};
    if (!(span > 0) || !isfinite(span) || target < 1)
        return 1.0;
    double raw = span / target;
    double mag = pow(10.0, floor(log10(raw)));
    for (size_t i = 0; i < sizeof mult / sizeof mult[0]; i++)
        if (mult[i] * mag >= raw * (1 - 1e-9))
            return mult[i] * mag;
    return 10.0 * mag;
}

/* Write text with &, <, >, " escaped. */
void plot_put_text(FILE *f, const char *s)
{
    for (; *s; s++) {
        switch (*s) {
        case '&': fputs("&amp;", f); break;
        case '<': fputs("&lt;", f); break;
        case '>': fputs("&gt;", f); break;
        case '"': fputs("&quot;", f); break;
        default: fputc(*s, f);
        }
    }
}

/* " x,y" with `dec` decimals (the separator first). */
void plot_put_xy(FILE *f, const char *sep, double x, double y, int dec)
{
    char a[32], b[32];
    fprintf(f, "%s%s,%s", sep, plot_fmt(a, x, dec), plot_fmt(b, y, dec));
}

/* ------------------------------------------------------------------ */
/* Axes.                                                               */

/* Ticks for [lo, hi]; round_out widens the range to whole steps. */
void plot_axis_make(plot_axis *a, double lo, double hi, int target, int round_out)
{
    if (!isfinite(lo) || !isfinite(hi)) {
        lo = 0;
        hi = 1;
    }
    double mag = fmax(fabs(lo), fabs(hi));
    if (hi - lo <= 1e-9 * mag || hi <= lo) { /* constant: a band around it */
        double w = mag > 0 ? 0.1 * mag : 1.0;
        lo -= w;
        hi += w;
    }
    if (round_out) { /* keep the curves off the frame */
        double pad = 0.02 * (hi - lo);
        lo -= pad;
        hi += pad;
    }
    a->step = plot_nice_step(hi - lo, target);
    if (round_out) {
        lo = floor(lo / a->step + 1e-9) * a->step;
        hi = ceil(hi / a->step - 1e-9) * a->step;
    }
    plot_axis_fixed(a, lo, hi, a->step);
}

void plot_axis_fixed(plot_axis *a, double lo, double hi, double step)
{
    a->step = step;
    a->lo = lo;
    a->hi = hi;
    double mag = fmax(fabs(lo), fabs(hi));
    a->exp10 = 0;
    if (mag >= 1e5 || a->step < 1e-3)
        a->exp10 = 3 * (int)floor(log10(mag) / 3.0);
    double s = a->step / pow(10.0, a->exp10);
    a->dec = s >= 1 ? 0 : (int)ceil(-log10(s) - 1e-9);
}

/* Axis title with its unit, and "x10^k" when the labels are scaled. */
void plot_put_axis_title(FILE *f, const char *what, const char *unit, int exp10)
{
    plot_put_text(f, what);
    fputs(" [", f);
    if (exp10 != 0)
        fprintf(f, "\xc3\x97" "10<tspan dy=\"-6\" font-size=\"10\">%d</tspan>"
                   "<tspan dy=\"6\"> </tspan>", exp10);
    plot_put_text(f, unit);
    fputs("]", f);
}

void plot_put_ticks(FILE *f, const plot_axis *a, int vertical, double p0, double p1)
{
    plot_area area = {vertical ? AX_L : p0, vertical ? AX_R : p1, vertical ? p1 : AX_T,
                      vertical ? p0 : AX_B};
    plot_put_ticks_in(f, a, vertical, &area);
}

void plot_put_ticks_in(FILE *f, const plot_axis *a, int vertical, const plot_area *ar)
{
    char b1[32], b2[32], b3[32], e0[32], e1[32];
    double p0 = vertical ? ar->b : ar->l, p1 = vertical ? ar->t : ar->r;
    long k0 = (long)ceil(a->lo / a->step - 1e-6), k1 = (long)floor(a->hi / a->step + 1e-6);
    double scale = pow(10.0, -a->exp10);
    for (long k = k0; k <= k1; k++) {
        double v = (double)k * a->step;
        double pos = p0 + (v - a->lo) / (a->hi - a->lo) * (p1 - p0);
        plot_fmt(b3, v * scale, a->dec);
        if (vertical) {
            plot_fmt(e0, ar->l, 2);
            fprintf(f, "<path d=\"M%s,%sH%s\" stroke=\"%s\"/>", e0, plot_fmt(b1, pos, 2),
                    plot_fmt(e1, ar->r, 2), k == 0 ? "#999" : "#e3e3e3");
            fprintf(f, "<path d=\"M%s,%sh-5\" stroke=\"#000\"/>", e0, b1);
            fprintf(f, "<text x=\"%s\" y=\"%s\" text-anchor=\"end\">%s</text>\n",
                    plot_fmt(e1, ar->l - 8, 2), plot_fmt(b2, pos + 4, 2), b3);
        } else {
            plot_fmt(e1, ar->b, 2);
            fprintf(f, "<path d=\"M%s,%sV%s\" stroke=\"#e3e3e3\"/>", plot_fmt(b1, pos, 2),
                    plot_fmt(e0, ar->t, 2), e1);
            fprintf(f, "<path d=\"M%s,%sv5\" stroke=\"#000\"/>", b1, e1);
            fprintf(f, "<text x=\"%s\" y=\"%s\" text-anchor=\"middle\">%s</text>\n", b1,
                    plot_fmt(e0, ar->b + 20, 2), b3);
        }
    }
}

/* ------------------------------------------------------------------ */
/* Series styles.                                                      */

static const char *const series_colour[PLOT_MAX_SERIES] = {
    "#1f4e99", "#c0392b", "#1e7b3c", "#7d3c98", "#b86e00", "#0f7c8c", "#404040", "#a0306a"};
static const char *const series_dash[4] = {"", "7,4", "2,3", "9,3,2,3"};
const char *const plot_marker_path[4] = {
    "M-3.5,0a3.5,3.5 0 1 0 7,0a3.5,3.5 0 1 0-7,0z", "M-3.2-3.2h6.4v6.4h-6.4z",
    "M0-4.3L3.9,2.7H-3.9z", "M0-4.5L4.5,0 0,4.5-4.5,0z"};

void plot_style(int s, const char **colour, const char **dash, int *shape, int *filled)
{
    *colour = series_colour[s % PLOT_MAX_SERIES];
    *dash = series_dash[(s + s / 4) % 4];
    *shape = s % 4;
    *filled = s >= 4;
}

/* ------------------------------------------------------------------ */
/* Path data of a curve, thinned.                                      */

void plot_pen_to(plot_pen *p, double px, double py)
{
    char b1[32], b2[32];
    if (p->f)
        fprintf(p->f, "%s%s,%s", p->state == 0 ? "M" : p->state == 1 ? "L" : " ",
                plot_fmt(b1, px, p->dec), plot_fmt(b2, py, p->dec));
    p->state = p->state == 0 ? 1 : 2;
    p->nvert++;
}

/* The sleeve: from the anchor (the last vertex drawn), the directions a
 * segment may take so that every point passed lies within tol of it: a
 * wedge between the unit vectors (rx, ry) (clockwise bound) and (lx, ly),
 * the intersection of the cones asin(tol / d) around each point at d > tol.
 * Points at most tol from the anchor constrain nothing. A point farther
 * than the candidate end could lie beyond it, so the end must be at least
 * as far as every point passed (dmax). */
typedef struct sleeve {
    plot_pen *pen;
    double tol;
    int open;          /* the piece has its anchor */
    int pending;       /* (ex, ey) received, not drawn */
    double ax, ay;     /* anchor */
    double ex, ey;     /* candidate end: the last point received */
    int wedge;         /* the directions are bounded */
    double rx, ry, lx, ly;
    double dmax;
} sleeve;

static double cross2(double ax, double ay, double bx, double by)
{
    return ax * by - ay * bx;
}

/* May the segment from the anchor end at (x, y), at distance d? */
static int sleeve_admits(const sleeve *s, double x, double y, double d)
{
    if (d < s->dmax)
        return 0;
    if (!s->wedge)
        return 1;
    double vx = x - s->ax, vy = y - s->ay;
    return cross2(s->rx, s->ry, vx, vy) >= 0 && cross2(vx, vy, s->lx, s->ly) >= 0 &&
           vx * (s->rx + s->lx) + vy * (s->ry + s->ly) > 0;
}

/* Narrow the wedge by the cone of the point (x, y) at distance d > tol. */
static void sleeve_narrow(sleeve *s, double x, double y, double d)
{
    double ux = (x - s->ax) / d, uy = (y - s->ay) / d;
    double sn = s->tol / d, cs = sqrt(1 - sn * sn);  /* half-angle asin(tol/d) */
    double rx = ux * cs + uy * sn, ry = -ux * sn + uy * cs;  /* u rotated by -half */
    double lx = ux * cs - uy * sn, ly = ux * sn + uy * cs;   /* u rotated by +half */
    if (!s->wedge || cross2(s->rx, s->ry, rx, ry) > 0)
        s->rx = rx, s->ry = ry;
    if (!s->wedge || cross2(lx, ly, s->lx, s->ly) > 0)
        s->lx = lx, s->ly = ly;
    s->wedge = 1;
    s->dmax = fmax(s->dmax, d);
}

static void sleeve_anchor(sleeve *s, double x, double y)
{
    s->ax = x;
    s->ay = y;
    s->open = 1;
    s->pending = 0;
    s->wedge = 0;
    s->dmax = 0;
}

static void sleeve_add(sleeve *s, double x, double y)
{
    if (!s->open) {
        plot_pen_to(s->pen, x, y);
        sleeve_anchor(s, x, y);
        return;
    }
    double d = hypot(x - s->ax, y - s->ay);
    if (!sleeve_admits(s, x, y, d)) {  /* the last point received ends the segment */
        plot_pen_to(s->pen, s->ex, s->ey);
        sleeve_anchor(s, s->ex, s->ey);
        d = hypot(x - s->ax, y - s->ay);
    }
    if (d > s->tol)
        sleeve_narrow(s, x, y, d);
    s->ex = x;
    s->ey = y;
    s->pending = 1;
}

/* End of a piece: its last point is drawn. */
static void sleeve_close(sleeve *s)
{
    if (s->open && s->pending)
        plot_pen_to(s->pen, s->ex, s->ey);
    s->open = 0;
    s->pending = 0;
    s->pen->state = 0;
}

long plot_thin_draw(plot_pen *pen, double tol, plot_vertex_fn fn, const void *ctx, int n)
{
    sleeve s = {.pen = pen, .tol = tol};
    long before = pen->nvert;
    for (int i = 0; i < n; i++) {
        double x, y;
        if (fn(ctx, i, &x, &y) && isfinite(x) && isfinite(y))
            sleeve_add(&s, x, y);
        else
            sleeve_close(&s);
    }
    sleeve_close(&s);
    return pen->nvert - before;
}

void plot_draw_all(plot_pen *pen, plot_vertex_fn fn, const void *ctx, int n)
{
    for (int i = 0; i < n; i++) {
        double x, y;
        if (fn(ctx, i, &x, &y) && isfinite(x) && isfinite(y))
            plot_pen_to(pen, x, y);
        else
            pen->state = 0;
    }
}

double plot_thin_tolerance(plot_vertex_fn fn, const void *ctx, int n, long maxv)
{
    double tol = PLOT_THIN_TOL;
    for (int k = 0; k < 40; k++, tol *= 2) {
        plot_pen count = {NULL, 0, 2, 0};
        if (plot_thin_draw(&count, tol, fn, ctx, n) <= maxv)
            break;
    }
    return tol;
}

/* Draw a column's run: its up to 4 points in row order, each once. */
void plot_run_flush(plot_run *c, plot_pen *p)
{
    int done[4] = {0};
    for (int k = 0; k < 4 && c->n > 0; k++) {
        int best = -1;
        for (int i = 0; i < 4; i++)
            if (!done[i] && (best < 0 || c->row[i] < c->row[best]))
                best = i;
        if (best < 0)
            break;
        for (int i = 0; i < 4; i++)  /* the same row twice is drawn once */
            done[i] |= c->row[i] == c->row[best];
        plot_pen_to(p, c->px[best], c->py[best]);
    }
    c->n = 0;
}

void plot_run_add(plot_run *c, plot_pen *p, int row, double px, double py, long col)
{
    if (c->n > 0 && col != c->col)
        plot_run_flush(c, p);
    if (c->n == 0)
        for (int i = 0; i < 4; i++) {
            c->row[i] = row;
            c->px[i] = px;
            c->py[i] = py;
        }
    c->col = col;
    c->n++;
    int slot[2] = {py > c->py[1] ? 1 : -1, py < c->py[2] ? 2 : -1};  /* lo: larger py */
    for (int k = 0; k < 2; k++)
        if (slot[k] >= 0) {
            c->row[slot[k]] = row;
            c->px[slot[k]] = px;
            c->py[slot[k]] = py;
        }
    c->row[3] = row;
    c->px[3] = px;
    c->py[3] = py;
}
