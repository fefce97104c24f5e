/* tests/unit/test_latex_symbols.c: a link's or a slider's `symbol:` in
 * `mech equations --format latex` (src/equations/system.c latex_symbol; issue 32
 * point 10). A symbol that is inert LaTeX math (letters, digits, primes,
 * Greek letters, one subscript and one superscript) is printed as written;
 * any other text as upright text with LaTeX's special characters escaped,
 * so that no symbol breaks the document or runs a command. Each case
 * checks the exact text of the unknown's line, and that the whole document
 * keeps its braces balanced and no unescaped command of the symbol. */
#include <criterion/criterion.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "helpers.h"

/* The four-bar with the rocker's symbol `sym` (a YAML double-quoted string:
 * backslashes doubled by the caller), printed in LaTeX. */
static char *latex_with_symbol(const char *sym)
{
    char yaml[2048];
    snprintf(yaml, sizeof yaml,
             "name: symbols\n"
             "units: {length: mm, angle: deg}\n"
             "ground: {O: [0, 0], C: [70, 0]}\n"
             "links:\n"
             "  crank: {points: {O: [0, 0], A: [20, 0]}}\n"
             "  coupler: {points: {A: [0, 0], B: [60, 0]}}\n"
             "  rocker: {symbol: \"%s\", points: {C: [0, 0], B: [50, 0]}}\n"
             "driver: {link: crank, angle: {from: 0, to: 360, steps: 4}}\n"
             "initial: {coupler: 40, rocker: 100}\n",
             sym);
    mech_model *m = load_text(yaml);
    char *buf = system_text(m, MECH_FORMAT_LATEX, 0);
    mech_model_free(&m);
    return buf;
}

/* Braces balanced outside escapes (\{ \}), every $ closed. */
static void check_balanced(const char *t, const char *sym)
{
    int brace = 0, dollars = 0;
    for (const char *p = t; *p; p++) {
        if (*p == '\\' && p[1]) {
            p++;  /* an escaped character, or a command's first letter */
            continue;
        }
        brace += *p == '{' ? 1 : *p == '}' ? -1 : 0;
        dollars += *p == '$';
        cr_assert_geq(brace, 0, "symbol \"%s\": '}' without '{' at offset %td", sym, p - t);
    }
    cr_expect_eq(brace, 0, "symbol \"%s\": %d braces open", sym, brace);
    cr_expect_eq(dollars % 2, 0, "symbol \"%s\": a $ not closed", sym);
}

/* yaml: the symbol as written in the file's double quotes; want: the
 * unknown's LaTeX. */
static void expect_symbol(const char *yaml, const char *want)
{
    char *t = latex_with_symbol(yaml);
    char line[512];
    snprintf(line, sizeof line, "\\item $x_{2} = %s$: angle of link 'rocker'\n", want);
    cr_expect(strstr(t, line) != NULL, "symbol \"%s\": no line\n%s in\n%.600s", yaml, line, t);
    /* the velocity's name decorates it */
    snprintf(line, sizeof line, "\\dot{%s}", want);
    cr_expect(strstr(t, line) != NULL, "symbol \"%s\": no %s", yaml, line);
    check_balanced(t, yaml);
    free(t);
}

Test(latex_symbols, inert_math_is_printed_as_written)
{
    expect_symbol("phi2", "phi2");
    expect_symbol("Theta4", "Theta4");
    expect_symbol("\\\\theta_2", "\\theta_2");
    expect_symbol("x_{B1}", "x_{B1}");
    expect_symbol("\\\\varphi'_{2,a}^\\\\ast", "\\mathrm{\\backslash{}varphi'\\_\\{2,a\\}"
                  "\\text{\\textasciicircum}\\backslash{}ast}");  /* \ast: not a letter */
    expect_symbol("\\\\alpha^2", "\\alpha^2");
}

Test(latex_symbols, other_text_is_escaped)
{
    /* a command that would read a file */
    expect_symbol("\\\\input{/etc/passwd}", "\\mathrm{\\backslash{}input\\{/etc/passwd\\}}");
    char *t = latex_with_symbol("\\\\input{/etc/passwd}");
    cr_expect(strstr(t, "\\input") == NULL, "an unescaped \\input in the document");
    free(t);
    /* every special character */
    expect_symbol("50%_a^b~c d$&#", "\\mathrm{50\\%\\_a\\text{\\textasciicircum}b"
                  "\\text{\\textasciitilde}c\\ d\\$\\&\\#}");
    /* two subscripts, an empty one, unbalanced braces, a Greek-like word */
    expect_symbol("a_b_c", "\\mathrm{a\\_b\\_c}");
    expect_symbol("x_", "\\mathrm{x\\_}");
    expect_symbol("x_{1", "\\mathrm{x\\_\\{1}");
    expect_symbol("}{", "\\mathrm{\\}\\{}");
    expect_symbol("\\\\thetax", "\\mathrm{\\backslash{}thetax}");
    /* UTF-8: one '?' per character */
    expect_symbol("\xcf\x86" "1", "\\mathrm{?1}");
}
