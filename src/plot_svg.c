/* src/plot_svg.c: the SVG pieces the figures (plot.c) and the animation
 * (plot_anim.c) share: numbers without noise (plot_fmt), 1-2-5 tick steps,
 * text escaping, axes (range, ticks, labels, titles) and the path data of a
 * curve, thinned past THIN_FROM rows to four vertices per pixel column.
 * Declarations: src/plot_svg.h (private), src/plot.h (plot_fmt,
 * plot_nice_step). docs/plots.md, "Axes, units, styles". */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "plot_svg.h"

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
    a->lo = lo;
    a->hi = hi;
    mag = fmax(fabs(lo), fabs(hi));
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
    char b1[32], b2[32], b3[32];
    long k0 = (long)ceil(a->lo / a->step - 1e-6), k1 = (long)floor(a->hi / a->step + 1e-6);
    double scale = pow(10.0, -a->exp10);
    for (long k = k0; k <= k1; k++) {
        double v = (double)k * a->step;
        double pos = p0 + (v - a->lo) / (a->hi - a->lo) * (p1 - p0);
        plot_fmt(b3, v * scale, a->dec);
        if (vertical) {
            fprintf(f, "<path d=\"M%d,%sH%d\" stroke=\"%s\"/>", AX_L, plot_fmt(b1, pos, 2), AX_R,
                    k == 0 ? "#999" : "#e3e3e3");
            fprintf(f, "<path d=\"M%d,%sh-5\" stroke=\"#000\"/>", AX_L, b1);
            fprintf(f, "<text x=\"%d\" y=\"%s\" text-anchor=\"end\">%s</text>\n", AX_L - 8,
                    plot_fmt(b2, pos + 4, 2), b3);
        } else {
            fprintf(f, "<path d=\"M%s,%dV%d\" stroke=\"#e3e3e3\"/>", plot_fmt(b1, pos, 2),
                    AX_T, AX_B);
            fprintf(f, "<path d=\"M%s,%dv5\" stroke=\"#000\"/>", b1, AX_B);
            fprintf(f, "<text x=\"%s\" y=\"%d\" text-anchor=\"middle\">%s</text>\n", b1, AX_B + 20,
                    b3);
        }
    }
}

/* ------------------------------------------------------------------ */
/* Path data of a curve, thinned to the pixel columns.                 */

void plot_pen_to(plot_pen *p, double px, double py)
{
    char b1[32], b2[32];
    fprintf(p->f, "%s%s,%s", p->state == 0 ? "M" : p->state == 1 ? "L" : " ",
            plot_fmt(b1, px, 2), plot_fmt(b2, py, 2));
    p->state = p->state == 0 ? 1 : 2;
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
