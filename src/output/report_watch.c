/* src/output/report_watch.c: the live page of `mech watch` (docs/cli.md, "mech
 * watch"), made of mech report's pieces (src/output/report.c, report_parts.c):
 * its style, its animation section with the slider and the values, its
 * diagnostics and the rows' JSON, and its slider's script, run again on
 * every new drawing. The page itself is a shell: its script long-polls
 * /state?since=VERSION and puts the state's HTML in place; a state with an
 * error shows the message (FILE:LINE:COLUMN) above the last good drawing.
 * Like the report, the page loads nothing from elsewhere (its
 * Content-Security-Policy allows its own inline style and script and
 * fetching /state from its own server, nothing else). */
#include <stdio.h>

#include "output.h"

static const char watch_head[] =
    "<!DOCTYPE html>\n"
    "<html xmlns=\"http://www.w3.org/1999/xhtml\" lang=\"en\">\n<head>\n"
    "<meta charset=\"utf-8\"/>\n"
    "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; "
    "style-src 'unsafe-inline'; script-src 'unsafe-inline'; connect-src 'self'; "
    "img-src data:\"/>\n"
    "<meta name=\"viewport\" content=\"width=device-width\"/>\n";

static const char watch_style[] =
    "<style>\n"
    "#problem{border-color:#b00020;background:#fff6f6}\n"
    "#problem pre{color:#b00020;max-height:none;white-space:pre-wrap}\n"
    "#status.error{color:#ffb4b4}\n"
    "</style>\n";

/* The poll loop: each state (JSON: version, good, file, name, time, error,
   html) updates the header and the error box; a new good drawing replaces
   #live and the slider's script runs again on it, the slider kept where it
   was. A failed fetch (the server stopped) is retried every second.
   mechWatchRecord() gives what the page shows (tests/browser/watch.sh). */
static const char watch_script[] =
    "(function () {\n"
    "'use strict';\n"
    "var version = 0, shown = -1, last = null;\n"
    "var live = document.getElementById('live'), problem = document.getElementById('problem');\n"
    "var status = document.getElementById('status');\n"
    "function text(id, t) { document.getElementById(id).textContent = t; }\n"
    "function apply(s) {\n"
    "  text('title', s.name); document.title = s.name + ' - mech watch';\n"
    "  status.textContent = 'watching ' + s.file + ': version ' + s.version + ' at ' + s.time\n"
    "    + (s.error ? ', with an error' : '');\n"
    "  status.className = s.error ? 'error' : '';\n"
    "  problem.hidden = !s.error;\n"
    "  text('error', s.error || '');\n"
    "  text('kept', s.good > 0 ? 'Below: the last good drawing (version ' + s.good + ').'\n"
    "    : 'No version of the file has been solved yet.');\n"
    "  if (s.good !== shown && s.html) {\n"
    "    var old = document.getElementById('slider'), at = old ? +old.value : 0;\n"
    "    live.innerHTML = s.html;\n"
    "    mechSlider();\n"
    "    var slider = document.getElementById('slider');\n"
    "    if (slider && at > 0 && at <= +slider.max) {\n"
    "      slider.value = at; slider.dispatchEvent(new Event('input'));\n"
    "    }\n"
    "    shown = s.good;\n"
    "  }\n"
    "  version = s.version; last = s;\n"
    "}\n"
    "function poll() {\n"
    "  fetch('/state?since=' + version, {cache: 'no-store'})\n"
    "    .then(function (r) { if (!r.ok) throw new Error(r.status); return r.json(); })\n"
    "    .then(function (s) { apply(s); poll(); }, function () {\n"
    "      status.textContent = 'mech watch does not answer (stopped?); trying again';\n"
    "      status.className = 'error';\n"
    "      window.setTimeout(poll, 1000);\n"
    "    });\n"
    "}\n"
    "window.mechWatchRecord = function () {\n"
    "  var svg = document.querySelector('#anim svg'), slider = document.getElementById('slider');\n"
    "  var out = {version: version, good: last ? last.good : -1, shown: shown,\n"
    "    error: problem.hidden ? null : document.getElementById('error').textContent,\n"
    "    transform: svg ? svg.getAttribute('data-mech-transform') : null,\n"
    "    slider: slider ? +slider.value : -1, points: {}, values: {}, colours: {},\n"
    "    anim: null, width: svg ? svg.width.baseVal.value : 0};\n"
    "  if (svg) {\n"
    "    var a = svg.getBoundingClientRect();\n"
    "    out.anim = [a.left + window.scrollX, a.top + window.scrollY, a.width, a.height];\n"
    "  }\n"
    "  var gs = svg ? svg.querySelectorAll('g[id^=\"anim-P-\"]') : [];\n"
    "  for (var i = 0; i < gs.length; i++) {\n"
    "    var c = gs[i].querySelector('circle'), b = c.getBoundingClientRect();\n"
    "    out.colours[gs[i].id.slice(7)] = c.getAttribute('fill');\n"
    "    out.points[gs[i].id.slice(7)] = [b.left + window.scrollX + b.width / 2,\n"
    "      b.top + window.scrollY + b.height / 2];\n"
    "  }\n"
    "  var cells = document.querySelectorAll('#values tbody tr');\n"
    "  for (var k = 0; k < cells.length; k++)\n"
    "    out.values[cells[k].cells[0].textContent] = cells[k].cells[1].textContent;\n"
    "  return JSON.stringify(out);\n"
    "};\n"
    "poll();\n"
    "})();\n";

void report_watch_page(FILE *f, const char *file)
{
    fputs(watch_head, f);
    fputs("<title>", f);
    plot_put_text(f, file);
    fputs(" - mech watch</title>\n", f);
    fputs(report_page_style, f);
    fputs(watch_style, f);
    fputs("</head>\n<body>\n<header>\n<h1 id=\"title\">", f);
    plot_put_text(f, file);
    fputs("</h1>\n<p id=\"status\">watching ", f);
    plot_put_text(f, file);
    fputs(": waiting for the first solve</p>\n</header>\n<main>\n"
          "<section id=\"problem\" hidden=\"hidden\">\n<h2>The file has an error</h2>\n"
          "<pre id=\"error\"></pre>\n<p id=\"kept\"></p>\n</section>\n"
          "<div id=\"live\"></div>\n</main>\n<script>//<![CDATA[\n"
          "function mechSlider() {\n", f);
    fputs(report_slider_script, f);
    fputs("}\n", f);
    fputs(watch_script, f);
    fputs("//]]></script>\n</body>\n</html>\n", f);
}

void report_watch_fragment(FILE *f, const report_input *in)
{
    report_put_animation(f, in);
    report_put_diagnostics(f, in);
    fputs("<script type=\"application/json\" id=\"mech-data\">", f);
    report_put_json(f, in);
    fputs("</script>\n", f);
}
