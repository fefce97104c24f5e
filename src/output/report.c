/* src/output/report.c: the HTML report page (mech report, docs/report.md): the SVG
 * documents of the figures and the animation captured from src/plot*.c
 * through a private temporary directory, then the page itself: one
 * self-contained file (inline CSS, SVG, JSON and script; a Content-Security-
 * Policy that forbids every load from elsewhere), written whole. The
 * sections' HTML is src/output/report_parts.c. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base.h"
#include "output.h"

void report_free_strings(char **s, int n)
{
    if (!s)
        return;
    for (int i = 0; i < n; i++)
        free(s[i]);
    free(s);
}

/* ------------------------------------------------------------------ */
/* Capturing the SVGs: plot_figure_write and plot_animation_write write */
/* files; they are drawn into a mkdtemp directory and read back.        */

typedef struct scratch {
    char dir[4096];   /* the temporary directory */
    char path[4200];  /* dir/image.svg */
} scratch;

static int scratch_open(scratch *s, mech_diag *d)
{
    const char *tmp = getenv("TMPDIR");
    snprintf(s->dir, sizeof s->dir, "%s/mech-report-XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(s->dir)) {
        char eb[128];
        return diag_fail(d, MECH_FAIL_IO, s->dir, (mech_mark){0, 0}, "cannot create a temporary "
                         "directory for the figures: %s", diag_strerror(errno, eb, sizeof eb));
    }
    snprintf(s->path, sizeof s->path, "%s/image.svg", s->dir);
    return MECH_OK;
}

static void scratch_close(scratch *s)
{
    unlink(s->path);
    rmdir(s->dir);
}

/* The whole file s->path into *text (malloc'ed), then the file removed. */
static int scratch_take(scratch *s, char **text, mech_diag *d)
{
    char eb[128];
    FILE *f = fopen(s->path, "rb");
    if (!f)
        return diag_fail(d, MECH_FAIL_IO, s->path, (mech_mark){0, 0}, "cannot read the figure "
                         "back: %s", diag_strerror(errno, eb, sizeof eb));
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    while (buf) {
        len += fread(buf + len, 1, cap - len - 1, f);
        if (len < cap - 1)
            break;
        char *more = xrealloc_array(buf, cap, 2);
        if (!more)
            free(buf);
        buf = more;
        cap *= 2;
    }
    int bad = !buf || ferror(f);
    fclose(f);
    unlink(s->path);
    if (bad) {
        free(buf);
        return diag_fail(d, MECH_FAIL_IO, s->path, (mech_mark){0, 0},
                         "cannot read the figure back");
    }
    buf[len] = '\0';
    *text = buf;
    return MECH_OK;
}

/* One cam figure drawn into the scratch file and taken as out[*k]. */
typedef struct report_cams {
    const mech_model *m;
    scratch *s;
    char **out;
    int *k, max;
    mech_diag *d;
} report_cams;

static int report_cam_figure(void *vctx, const mech_table *t, const plot_figure *f)
{
    report_cams *c = vctx;
    if (*c->k >= c->max)
        return MECH_OK;
    int rc = plot_figure_write(c->m, t, f, c->m->name, c->s->path, c->d);
    if (rc == MECH_OK && (rc = scratch_take(c->s, &c->out[*c->k], c->d)) == MECH_OK)
        (*c->k)++;
    return rc;
}

int report_figures(const mech_model *m, const mech_table *t, char ***svgs, int *n, mech_diag *d)
{
    enum { MAXFIG = 4096 };
    *svgs = NULL;
    *n = 0;
    plot_figure *figs = xcalloc(MAXFIG, sizeof *figs);
    char **out = xcalloc(MAXFIG, sizeof *out);
    scratch s;
    int rc = !figs || !out ? MECH_ENOMEM : scratch_open(&s, d);
    if (rc == MECH_ENOMEM)
        diag_nomem(d, m->file, (mech_mark){0, 0});
    if (rc != MECH_OK) {
        free(figs);
        free(out);
        return rc;
    }
    int nf = plot_plan_all(m, t, figs, MAXFIG), k = 0;
    for (; k < nf && rc == MECH_OK; k++) {
        rc = plot_figure_write(m, t, &figs[k], m->name, s.path, d);
        if (rc == MECH_OK)
            rc = scratch_take(&s, &out[k], d);
    }
    if (rc == MECH_OK && m->cams) {  /* each cam's figures, as mech plot writes them */
        report_cams rcx = {m, &s, out, &k, MAXFIG, d};
        rc = cam_figures_each(m, report_cam_figure, &rcx, d);
        nf = k;
    }
    if (rc == MECH_OK && m->fit && nf < MAXFIG) {
        /* the fit: section's figure last, as mech plot writes it; left
           out (the reasons as warnings in d) when it cannot be drawn */
        rc = fit_figure_of_model(m, s.path, d);
        if (rc == MECH_OK && (rc = scratch_take(&s, &out[k], d)) == MECH_OK)
            nf = ++k;
        else if (rc == MECH_EINPUT)
            rc = MECH_OK;
    }
    scratch_close(&s);
    free(figs);
    if (rc != MECH_OK) {
        report_free_strings(out, k);
        return rc;
    }
    *svgs = out;
    *n = nf;
    return MECH_OK;
}

int report_animation(const mech_model *m, const mech_table *t, const plot_anim_options *o,
                     char **svg, mech_diag *d)
{
    size_t len = 0;
    *svg = NULL;
    FILE *f = open_memstream(svg, &len);
    if (!f)
        return diag_error(d, m->file, (mech_mark){0, 0}, "out of memory"), MECH_ENOMEM;
    int rc = plot_animation_fprint(m, t, o, f, d);
    if (fclose(f) != 0 && rc == MECH_OK) {
        diag_error(d, m->file, (mech_mark){0, 0}, "out of memory");
        rc = MECH_ENOMEM;
    }
    if (rc != MECH_OK) {
        free(*svg);
        *svg = NULL;
    }
    return rc;
}

/* ------------------------------------------------------------------ */
/* The page.                                                           */

/* No network: the policy forbids loading anything that is not in the
   page (the page has no reference to load anyway; this makes sure). */
static const char page_head[] =
    "<!DOCTYPE html>\n"
    "<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\">\n<head>\n"
    "<meta charset=\"utf-8\"/>\n"
    "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; "
    "style-src 'unsafe-inline'; script-src 'unsafe-inline'; img-src data:\"/>\n"
    "<meta name=\"viewport\" content=\"width=device-width\"/>\n";

const char report_page_style[] =
    "<style>\n"
    "body{font-family:'DejaVu Sans',Arial,Helvetica,sans-serif;margin:0;color:#222;"
    "background:#f4f5f7;font-size:14px}\n"
    "header{background:#2c3e50;color:#fff;padding:14px 24px}\n"
    "header h1{margin:0;font-size:22px}header p{margin:4px 0 0;color:#d5dde6}\n"
    "nav a{color:#fff;margin-right:16px}\n"
    "main{padding:8px 24px 40px}\n"
    "section{background:#fff;border:1px solid #d8dce2;border-radius:6px;margin:16px 0;"
    "padding:8px 16px 16px}\n"
    "h2{font-size:18px;margin:8px 0 12px}h3{font-size:15px;margin:16px 0 6px}\n"
    "table{border-collapse:collapse;margin:4px 0}\n"
    "td,th{border:1px solid #d8dce2;padding:3px 8px;text-align:left;vertical-align:top}\n"
    "th{background:#eef1f5}td.num{text-align:right;font-family:'DejaVu Sans Mono',monospace}\n"
    ".row{display:flex;flex-wrap:wrap;gap:16px;align-items:flex-start}\n"
    ".anim{display:inline-block;border:1px solid #d8dce2;line-height:0}\n"
    ".anim svg{max-width:100%;height:auto;display:block}\n"
    ".controls{margin:8px 0;display:flex;align-items:center;gap:12px}\n"
    "#slider{width:480px}\n"
    ".figs{display:flex;flex-wrap:wrap;gap:12px}\n"
    "figure{margin:0;border:1px solid #d8dce2;line-height:0;box-sizing:border-box;"
    "width:calc(50% - 12px);min-width:360px}\n"
    "figure svg{width:100%;height:auto;display:block}\n"
    "pre{background:#f7f7f9;border:1px solid #d8dce2;padding:8px;overflow:auto;"
    "font-size:12px;max-height:600px}\n"
    ".warning{color:#9a5b00}.error{color:#b00020}.note{color:#2c5d8f}\n"
    "</style>\n";

/* The slider: frame k of the animation is SMIL time k / (nf - 1) of its
   duration (the values of every <animate> are evenly spaced); the values
   shown are those of the JSON row of that frame. Play runs the animation
   and moves the slider along (a timer, not requestAnimationFrame: headless
   chromium's virtual time stalls SMIL under a frame loop). The page's
   address may say #row=K (the slider is moved there through its input
   event), #play (Play is clicked) and #test (what the page shows is
   written into <pre id="mech-test"> for tests/browser/report.sh: 100 ms
   later, or 1 s into playing). */
#define SLIDER_SCRIPT \
    "(function () {\n" \
    "'use strict';\n" \
    "var data = JSON.parse(document.getElementById('mech-data').textContent);\n" \
    "var svg = document.querySelector('#anim svg');\n" \
    "var slider = document.getElementById('slider'), where = document.getElementById('where');\n" \
    "var play = document.getElementById('play');\n" \
    "var nf = data.rows.length, dur = data.duration, timer = null;\n" \
    "function fmt(x) { return Number(x.toPrecision(6)).toString(); }\n" \
    "function shown(v, u) {\n" \
    "  if (v === null) return 'n/a';\n" \
    "  if (u === 'm') return fmt(v * 1e3) + ' mm';\n" \
    "  if (u === 'rad') return fmt(v * 180 / Math.PI) + ' deg';\n" \
    "  return fmt(v) + (u === '-' ? '' : ' ' + u);\n" \
    "}\n" \
    "function values(k) {\n" \
    "  var row = data.rows[k];\n" \
    "  for (var c = 0; c < data.columns.length; c++) {\n" \
    "    var v = row[c + 1], u = data.columns[c].unit;\n" \
    "    document.getElementById('v' + c).textContent = v === null ? 'n/a'\n" \
    "      : Object.is(v, -0) ? '-0' : String(v);\n" \
    "    document.getElementById('d' + c).textContent = shown(v, u);\n" \
    "  }\n" \
    "  where.textContent = 'position ' + k + ' of ' + (nf - 1) + ' (row ' + row[0] + '), '\n" \
    "    + data.columns[0].name + ' = ' + shown(row[1], data.columns[0].unit);\n" \
    "}\n" \
    "function time(k) { return nf > 1 ? Math.min(k / (nf - 1), 1 - 1e-9) * dur : 0; }\n" \
    "function show(k) {\n" \
    "  if (svg && svg.pauseAnimations) { svg.pauseAnimations(); svg.setCurrentTime(time(k)); }\n" \
    "  values(k);\n" \
    "}\n" \
    "function stop() {\n" \
    "  if (timer !== null) window.clearInterval(timer);\n" \
    "  timer = null; play.textContent = 'Play';\n" \
    "}\n" \
    "function tick() {  /* while playing, 20 times a second: the slider follows */\n" \
    "  var t = svg.getCurrentTime() % dur, k = Math.round(t / dur * (nf - 1));\n" \
    "  slider.value = k; slider.setAttribute('data-time', t); values(k);\n" \
    "}\n" \
    "slider.addEventListener('input', function () { stop(); show(+slider.value); });\n" \
    "play.addEventListener('click', function () {\n" \
    "  if (timer !== null) { stop(); svg.pauseAnimations(); return; }\n" \
    "  if (nf < 2) return;\n" \
    "  play.textContent = 'Pause';\n" \
    "  svg.setCurrentTime(time(+slider.value)); svg.unpauseAnimations();\n" \
    "  timer = window.setInterval(tick, 50);\n" \
    "});\n" \
    "function box(e) {\n" \
    "  var r = e.getBoundingClientRect();\n" \
    "  return [r.left + window.scrollX, r.top + window.scrollY, r.width, r.height];\n" \
    "}\n" \
    "function report() {\n" \
    "  var out = {slider: +slider.value, row: data.rows[+slider.value][0], values: {},\n" \
    "    points: {}, figures: [], anim: box(svg), where: where.textContent,\n" \
    "    width: svg.width.baseVal.value, transform: svg.getAttribute('data-mech-transform'),\n" \
    "    time: slider.getAttribute('data-time'), duration: dur, frames: nf,\n" \
    "    page: [document.documentElement.scrollWidth, document.documentElement.scrollHeight]};\n" \
    "  for (var c = 0; c < data.columns.length; c++)\n" \
    "    out.values[data.columns[c].name] = document.getElementById('v' + c).textContent;\n" \
    "  var gs = svg.querySelectorAll('g[id^=\"anim-P-\"]');\n" \
    "  for (var i = 0; i < gs.length; i++) {\n" \
    "    var b = box(gs[i].querySelector('circle'));\n" \
    "    out.points[gs[i].id.slice(7)] = [b[0] + b[2] / 2, b[1] + b[3] / 2];\n" \
    "  }\n" \
    "  var fs = document.querySelectorAll('figure svg');\n" \
    "  for (var j = 0; j < fs.length; j++) out.figures.push(box(fs[j]));\n" \
    "  document.getElementById('mech-test').textContent = JSON.stringify(out);\n" \
    "}\n" \
    "function start() {  /* once loaded: the address's hooks */\n" \
    "  var h = window.location.hash, m = /row=([0-9]+)/.exec(h);\n" \
    "  if (m) { slider.value = m[1]; slider.dispatchEvent(new Event('input')); }\n" \
    "  else show(+slider.value);\n" \
    "  if (/play/.test(h)) play.click();\n" \
    "  if (/test/.test(h))  /* after the drawing has followed */\n" \
    "    window.setTimeout(report, /play/.test(h) ? 1000 : 100);\n" \
    "}\n" \
    "show(+slider.value);\n" \
    "window.addEventListener('load', start);\n" \
    "})();\n"

static const char page_script[] = "<script>//<![CDATA[\n" SLIDER_SCRIPT "//]]></script>\n";
const char report_slider_script[] = SLIDER_SCRIPT;

static void put_header(FILE *f, const report_input *in)
{
    const mech_model *m = in->m;
    const char *name = m->name ? m->name : m->file;
    fputs(page_head, f);
    fputs("<title>", f);
    plot_put_text(f, name);
    fputs(" - mech report</title>\n", f);
    fputs(report_page_style, f);
    fputs("</head>\n<body>\n<header>\n<h1>", f);
    plot_put_text(f, name);
    fputs("</h1>\n<p>", f);
    plot_put_text(f, m->file);
    if (m->description) {
        fputs(": ", f);
        plot_put_text(f, m->description);
    }
    fprintf(f, " (mech %s)</p>\n<nav><a href=\"#animation\">Animation</a>"
               "<a href=\"#structure\">Structure</a><a href=\"#diagnostics\">Diagnostics</a>"
               "<a href=\"#figures\">Figures (%d)</a><a href=\"#equations\">Equations</a>"
               "</nav>\n</header>\n<main>\n", MECH_VERSION, in->nfigures);
}

void report_put_animation(FILE *f, const report_input *in)
{
    const mech_table *t = in->t;
    fputs("<section id=\"animation\">\n<h2>Animation</h2>\n<div class=\"row\">\n"
          "<div>\n<div class=\"anim\" id=\"anim\">\n", f);
    report_put_svg(f, in->animation, "anim-");
    fprintf(f, "</div>\n<div class=\"controls\"><button id=\"play\" type=\"button\">Play"
               "</button><input type=\"range\" id=\"slider\" min=\"0\" max=\"%d\" step=\"1\" "
               "value=\"0\" aria-label=\"driver position\"/></div>\n"
               "<p id=\"where\">position 0 of %d</p>\n</div>\n",
            in->nframes - 1, in->nframes - 1);
    fputs("<table id=\"values\"><thead><tr><th>column</th><th>value (SI, as the CSV)</th>"
          "<th>unit</th><th>shown as</th></tr></thead>\n<tbody>\n", f);
    for (int c = 0; c < t->ncolumns; c++) {
        fputs("<tr><td>", f);
        plot_put_text(f, t->columns[c].name);
        double v = in->nframes > 0 ? mech_table_get(t, in->frame_rows[0], c) : NAN;
        char num[FMT_DOUBLE_MAX];
        if (isfinite(v) && fmt_double(v, num) > 0)
            fprintf(f, "</td><td class=\"num\" id=\"v%d\">%s</td><td>", c, num);
        else
            fprintf(f, "</td><td class=\"num\" id=\"v%d\">n/a</td><td>", c);
        plot_put_text(f, t->columns[c].unit);
        fprintf(f, "</td><td class=\"num\" id=\"d%d\"></td></tr>\n", c);
    }
    fputs("</tbody></table>\n</div>\n</section>\n", f);
}

static void put_figures(FILE *f, const report_input *in)
{
    fprintf(f, "<section id=\"figures\">\n<h2>Figures (%d)</h2>\n<div class=\"figs\">\n",
            in->nfigures);
    for (int k = 0; k < in->nfigures; k++) {
        char prefix[32];
        snprintf(prefix, sizeof prefix, "fig%d-", k + 1);
        fprintf(f, "<figure id=\"figure-%d\">\n", k + 1);
        report_put_svg(f, in->figures[k], prefix);
        fputs("</figure>\n", f);
    }
    if (in->nfigures == 0)
        fputs("<p>No figures: the file has no outputs.</p>\n", f);
    fputs("</div>\n</section>\n", f);
}

static void put_equations(FILE *f, const report_input *in)
{
    fputs("<section id=\"equations\">\n<h2>Equations</h2>\n"
          "<p>As <code>mech equations</code> prints them: the unknowns, the loops, the "
          "position equations f(x, q) = 0, the nonzeros of the Jacobian df/dx, and the "
          "right-hand sides of the velocity and acceleration equations.</p>\n<pre>", f);
    plot_put_text(f, in->equations ? in->equations : "");
    fputs("</pre>\n</section>\n", f);
}

static int emit_page(FILE *f, const void *ctx)
{
    const report_input *in = ctx;
    put_header(f, in);
    if (in->ngaps > 0)
        fprintf(f, "<p class=\"error\" id=\"partial\"><b>Not every driver position was "
                   "solved:</b> %d of the %d requested (%d gap%s, listed under "
                   "<a href=\"#diagnostics\">Diagnostics</a>). The slider, the values and "
                   "the figures show the positions solved; the curves break at the gaps; the "
                   "animation traces no paths (they would bridge the gaps).</p>\n",
                in->t->nrows, in->t->nrequested, in->ngaps, in->ngaps == 1 ? "" : "s");
    report_put_animation(f, in);
    report_put_structure(f, in);
    report_put_diagnostics(f, in);
    put_figures(f, in);
    put_equations(f, in);
    fputs("<pre id=\"mech-test\" hidden=\"hidden\"></pre>\n</main>\n"
          "<script type=\"application/json\" id=\"mech-data\">", f);
    report_put_json(f, in);
    fputs("</script>\n", f);
    fputs(page_script, f);
    fputs("</body>\n</html>\n", f);
    return ferror(f) ? -1 : 0;
}

int report_write(const report_input *in, const char *path, mech_diag *d)
{
    return write_file_whole(path, emit_page, in, d);
}
