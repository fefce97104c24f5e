/* bench/bench_util.h: helpers shared by the benchmarks (header-only, every
 * function static): wall clock, medians, and a minimal log-log SVG line
 * plot written with stdio (no plotting package needed). Not a test. */
#ifndef MECH_BENCH_UTIL_H
#define MECH_BENCH_UTIL_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#ifndef M_PI /* not declared under -std=c11 -D_POSIX_C_SOURCE */
#define M_PI 3.14159265358979323846
#endif

static inline double bench_now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* CPU time of this process */
static inline double bench_cpu(void)
{
    struct timespec t;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static inline int bench_cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Sorts v[n] in place; returns the median. */
static inline double bench_median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, bench_cmp);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/* ---- SVG log-log line plots ---------------------------------------------- */

typedef struct svg_series {
    const char *label;
    const double *x, *y;  /* [n]; points with x or y <= 0 or not finite are skipped */
    int n;
    const char *color;    /* "#1f77b4", ... */
    const char *dash;     /* NULL: solid; "6,3": dashed; "2,3": dotted */
} svg_series;

static const char *const SVG_COLORS[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
                                         "#ff7f0e", "#8c564b", "#17becf", "#7f7f7f"};

static inline int svg_ok(double v) { return isfinite(v) && v > 0; }

/* A log-log plot of the series, decades on both axes, legend on the right. */
static inline int svg_loglog(const char *path, const char *title, const char *xlabel,
                      const char *ylabel, const svg_series *s, int ns)
{
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (int k = 0; k < ns; k++)
        for (int i = 0; i < s[k].n; i++)
            if (svg_ok(s[k].x[i]) && svg_ok(s[k].y[i])) {
                xmin = fmin(xmin, s[k].x[i]), xmax = fmax(xmax, s[k].x[i]);
                ymin = fmin(ymin, s[k].y[i]), ymax = fmax(ymax, s[k].y[i]);
            }
    if (!(xmin <= xmax && ymin <= ymax))
        return -1;
    double lx0 = floor(log10(xmin)), lx1 = ceil(log10(xmax));
    double ly0 = floor(log10(ymin)), ly1 = ceil(log10(ymax));
    if (lx1 <= lx0)
        lx1 = lx0 + 1;
    if (ly1 <= ly0)
        ly1 = ly0 + 1;
    FILE *f = fopen(path, "w");
    if (!f)
        return -1;
    const double W = 760, H = 440, L = 80, R = 560, T = 40, B = 380; /* plot box */
#define SVG_X(v) (L + (log10(v) - lx0) / (lx1 - lx0) * (R - L))
#define SVG_Y(v) (B - (log10(v) - ly0) / (ly1 - ly0) * (B - T))
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" "
               "viewBox=\"0 0 %g %g\" font-family=\"sans-serif\" font-size=\"12\">\n",
            W, H, W, H);
    fprintf(f, "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n");
    fprintf(f, "<text x=\"%g\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">%s</text>\n",
            (L + R) / 2, title);
    int xstep = (int)ceil((lx1 - lx0) / 12), ystep = (int)ceil((ly1 - ly0) / 12);
    for (double e = lx0; e <= lx1 + 1e-9; e += xstep) {
        double px = L + (e - lx0) / (lx1 - lx0) * (R - L);
        fprintf(f, "<line x1=\"%.1f\" y1=\"%g\" x2=\"%.1f\" y2=\"%g\" stroke=\"#ddd\"/>\n", px, T,
                px, B);
        fprintf(f, "<text x=\"%.1f\" y=\"%g\" text-anchor=\"middle\">1e%d</text>\n", px, B + 16,
                (int)e);
    }
    for (double e = ly0; e <= ly1 + 1e-9; e += ystep) {
        double py = B - (e - ly0) / (ly1 - ly0) * (B - T);
        fprintf(f, "<line x1=\"%g\" y1=\"%.1f\" x2=\"%g\" y2=\"%.1f\" stroke=\"#ddd\"/>\n", L, py,
                R, py);
        fprintf(f, "<text x=\"%g\" y=\"%.1f\" text-anchor=\"end\">1e%d</text>\n", L - 6, py + 4,
                (int)e);
    }
    fprintf(f, "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" "
               "stroke=\"black\"/>\n", L, T, R - L, B - T);
    fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">%s</text>\n", (L + R) / 2, B + 36,
            xlabel);
    fprintf(f, "<text x=\"18\" y=\"%g\" text-anchor=\"middle\" transform=\"rotate(-90 18 %g)\">"
               "%s</text>\n", (T + B) / 2, (T + B) / 2, ylabel);
    for (int k = 0; k < ns; k++) {
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.8\"%s%s%s points=\"",
                s[k].color, s[k].dash ? " stroke-dasharray=\"" : "", s[k].dash ? s[k].dash : "",
                s[k].dash ? "\"" : "");
        for (int i = 0; i < s[k].n; i++)
            if (svg_ok(s[k].x[i]) && svg_ok(s[k].y[i]))
                fprintf(f, "%.1f,%.1f ", SVG_X(s[k].x[i]), SVG_Y(s[k].y[i]));
        fprintf(f, "\"/>\n");
        for (int i = 0; i < s[k].n; i++)
            if (svg_ok(s[k].x[i]) && svg_ok(s[k].y[i]))
                fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"2.5\" fill=\"%s\"/>\n",
                        SVG_X(s[k].x[i]), SVG_Y(s[k].y[i]), s[k].color);
        double ly = T + 10 + 18 * k;
        fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"%s\" "
                   "stroke-width=\"1.8\"%s%s%s/>\n", R + 14, ly, R + 44, ly, s[k].color,
                s[k].dash ? " stroke-dasharray=\"" : "", s[k].dash ? s[k].dash : "",
                s[k].dash ? "\"" : "");
        fprintf(f, "<text x=\"%g\" y=\"%g\">%s</text>\n", R + 50, ly + 4, s[k].label);
    }
#undef SVG_X
#undef SVG_Y
    fprintf(f, "</svg>\n");
    return fclose(f) == 0 ? 0 : -1;
}

#endif /* MECH_BENCH_UTIL_H */
