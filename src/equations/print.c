/* src/equations/print.c: `mech equations`: the derived equations, printed so a person
 * can hold them next to a paper (text, or a standalone LaTeX document). */
#include <stdio.h>
#include <string.h>

#include "equations.h"

static void describe_unknown(const mech_system *s, int i, FILE *out)
{
    const mech_model *m = s->model;
    if (s->unk_kind[i] == UNK_ANGLE)
        fprintf(out, "angle of link '%s'", m->links[s->unk_index[i]].name);
    else
    {
        const mech_joint *j = &m->joints[s->unk_index[i]];
        fprintf(out, "displacement of slider '%s' (point '%s' of '%s' along '%s', from '%s')",
                j->name, m->links[j->link[0]].points[j->point[0]].name, m->links[j->link[0]].name,
                m->links[j->link[1]].name, m->links[j->link[1]].points[j->point[1]].name);
    }
}

/* A loop as the walk of its terms: "crank O->A, coupler A->B, +s_B along ground". */
static void print_loop(const mech_system *s, int k, FILE *out)
{
    const mech_model *m = s->model;
    for (int t = s->loops.start[k]; t < s->loops.start[k + 1]; t++) {
        const loop_term *lt = &s->loops.terms[t];
        if (t > s->loops.start[k])
            fputs(", ", out);
        if (lt->kind == TERM_BODY) {
            const mech_link *l = &m->links[lt->link];
            fprintf(out, "%s %s->%s", l->name, l->points[lt->p0].name, l->points[lt->p1].name);
        } else {
            const mech_joint *j = &m->joints[lt->joint];
            fprintf(out, "%c%s along %s", lt->sign > 0 ? '+' : '-', j->name, m->links[j->link[1]].name);
        }
    }
}

/* The parameter of named leaf k (SYS_LEAF_NAMED: the parameters come first). */
static const mech_param *leaf_param(const mech_system *s, int k)
{
    return &s->model->params[s->coef[k].param];
}

/* SYS_LEAF_NAMED: the parameters and named lengths and angles the equations use. */
static void print_coefficients(const mech_system *s, FILE *out)
{
    int first = SYS_NVARS(s->n), ncoef = s->nvars - first;
    if (ncoef <= 0)
        return;
    fprintf(out, "parameters (SI units) and the lengths and angles named after them:\n");
    for (int k = 0; k < ncoef; k++) {
        const mech_param *p = s->coef_desc[k] ? NULL : leaf_param(s, k);
        if (!p)
            fprintf(out, "  %s\n", s->coef_desc[k]);
        else
            fprintf(out, "  %s = %.10g%s%s\n", s->names[first + k], p->value,
                    p->unit[0] ? " " : "", p->unit);
    }
    fputc('\n', out);
}

/* What row r is: "    [loop 1, x]", "    [gear pair 'g']", "    [driver 'crank']". */
static void row_tag(const mech_system *s, int r, FILE *out)
{
    const row_desc *rd = &s->rows[r];
    char owner[160];
    if (rd->kind == ROW_LOOP_X || rd->kind == ROW_LOOP_Y)
        fprintf(out, "    [loop %d, %c]\n", rd->owner + 1, rd->kind == ROW_LOOP_Y ? 'y' : 'x');
    else
        fprintf(out, "    [%s]\n", rows_constraint(s->model, rd->kind, rd->owner, owner,
                                                  sizeof owner));
}

static expr_names names_of(const mech_system *s)
{
    return (expr_names){(const char *const *)s->names, (const char *const *)s->latex};
}

static void print_text(const mech_system *s, FILE *out)
{
    const mech_model *m = s->model;
    expr_names nm = names_of(s);
    int n = s->n;
    fprintf(out, "# %s (%s)\n\n", m->name ? m->name : "mechanism", m->file);
    fprintf(out, "unknowns x (%d):\n", n);
    for (int i = 0; i < n; i++) {
        fprintf(out, "  x%-3d %-14s ", i + 1, s->names[i]);
        describe_unknown(s, i, out);
        fputc('\n', out);
    }
    fprintf(out, "input q: %s = %s, with rates %s and %s\n\n", s->names[n],
            m->driver.kind == MECH_DRIVE_TIME ? "time, the drivers' laws' variable"
            : m->driver.kind == MECH_DRIVE_ANGLE ? "driver link angle" : "driver slider displacement",
            s->names[SYS_VAR_QDOT(n)], s->names[SYS_VAR_QDDOT(n)]);
    print_coefficients(s, out);
    fprintf(out, "loops (%d, %s):\n", s->loops.nloops,
            s->loops.from_file ? "as listed in the file" : "found automatically");
    for (int k = 0; k < s->loops.nloops; k++) {
        fprintf(out, "  L%d: ", k + 1);
        print_loop(s, k, out);
        fputc('\n', out);
    }
    fprintf(out, "\nposition equations f(x, q) = 0:\n");
    for (int r = 0; r < s->m; r++) {
        fprintf(out, "  f%d = ", r + 1);
        expr_print(&s->ex, s->f[r], &nm, 0, out);
        row_tag(s, r, out);
    }
    fprintf(out, "\njacobian df/dx (%d nonzeros):\n", s->nnz);
    for (int j = 0; j < n; j++)
        for (int k = s->Jp[j]; k < s->Jp[j + 1]; k++) {
            fprintf(out, "  df%d/d%s = ", s->Ji[k] + 1, s->names[j]);
            expr_print(&s->ex, s->Jx[k], &nm, 0, out);
            fputc('\n', out);
        }
    fprintf(out, "\nvelocity: J x' = b\n");
    for (int r = 0; r < s->m; r++) {
        fprintf(out, "  b%d = ", r + 1);
        expr_print(&s->ex, s->vel[r], &nm, 0, out);
        fputc('\n', out);
    }
    fprintf(out, "\nacceleration: J x'' = c\n");
    for (int r = 0; r < s->m; r++) {
        fprintf(out, "  c%d = ", r + 1);
        expr_print(&s->ex, s->acc[r], &nm, 0, out);
        fputc('\n', out);
    }
}

/* Text with LaTeX's special characters escaped. */
static void latex_text(const char *t, FILE *out)
{
    for (; *t; t++) {
        if (strchr("#$%&_{}", *t))
            fputc('\\', out);
        if (*t == '\\' || *t == '^' || *t == '~')
            fputs(*t == '\\' ? "\\textbackslash{}" : *t == '^' ? "\\^{}" : "\\~{}", out);
        else
            fputc(*t, out);
    }
}

/* A loop's walk in LaTeX text: "->" as an arrow, the rest escaped. */
static void latex_loop_text(const char *t, FILE *out)
{
    char piece[2] = {0, 0};
    for (; *t; t++) {
        if (t[0] == '-' && t[1] == '>') {
            fputs("$\\to$", out);
            t++;
            continue;
        }
        piece[0] = *t;
        latex_text(piece, out);
    }
}

static void latex_rows(const mech_system *s, const char *lhs, const ex *rows, const char *rhs,
                       FILE *out)
{
    expr_names nm = names_of(s);
    fputs("\\begin{align*}\n", out);
    for (int r = 0; r < s->m; r++) {
        fprintf(out, "%s_{%d} &= ", lhs, r + 1);
        expr_print(&s->ex, rows[r], &nm, 1, out);
        fprintf(out, "%s%s\n", rhs, r + 1 < s->m ? " \\\\" : "");
    }
    fputs("\\end{align*}\n", out);
}

static void latex_coefficients(const mech_system *s, FILE *out)
{
    int first = SYS_NVARS(s->n), ncoef = s->nvars - first;
    if (ncoef <= 0)
        return;
    fputs("\\subsection*{Parameters (SI units)}\n\\begin{itemize}\n", out);
    for (int k = 0; k < ncoef; k++) {
        if (!s->coef_desc[k]) {
            fprintf(out, "\\item $%s = %.10g$ ", s->latex[first + k], leaf_param(s, k)->value);
            latex_text(leaf_param(s, k)->unit, out);  /* kg/m^3: ^ escaped */
            fputc('\n', out);
            continue;
        }
        fprintf(out, "\\item $%s$", s->latex[first + k]);
        const char *colon = strstr(s->coef_desc[k], ": ");
        fputs(": ", out);
        latex_text(colon ? colon + 2 : s->coef_desc[k], out);
        fputc('\n', out);
    }
    fputs("\\end{itemize}\n", out);
}

static void latex_loops(const mech_system *s, FILE *out)
{
    fprintf(out, "\\subsection*{Loops (%s)}\n",
            s->loops.from_file ? "as listed in the file" : "found automatically");
    if (s->loops.nloops == 0) {  /* a gear train: an empty list is not LaTeX */
        fputs("None: the gear rows alone fix the unknowns.\n", out);
        return;
    }
    fputs("\\begin{enumerate}\n", out);
    for (int k = 0; k < s->loops.nloops; k++) {
        char buf[4096];
        FILE *mem = fmemopen(buf, sizeof buf, "w");
        if (!mem)
            continue;
        print_loop(s, k, mem);
        fclose(mem);
        buf[sizeof buf - 1] = '\0';
        fputs("\\item ", out);
        latex_loop_text(buf, out);
        fputc('\n', out);
    }
    fputs("\\end{enumerate}\n", out);
}

static void print_latex(const mech_system *s, FILE *out)
{
    const mech_model *m = s->model;
    expr_names nm = names_of(s);
    int n = s->n;
    fputs("\\documentclass[10pt]{article}\n\\usepackage[a4paper,landscape,margin=1.5cm]{geometry}\n"
          "\\usepackage{amsmath}\n\\allowdisplaybreaks\n\\begin{document}\n\\section*{",
          out);
    latex_text(m->name ? m->name : "Mechanism", out);
    fputs("}\n\\subsection*{Unknowns}\n\\begin{itemize}\n", out);
    for (int i = 0; i < n; i++) {
        fprintf(out, "\\item $x_{%d} = %s$: ", i + 1, s->latex[i]);
        char buf[512];
        FILE *mem = fmemopen(buf, sizeof buf, "w");
        if (mem) {
            describe_unknown(s, i, mem);
            fclose(mem);
            latex_text(buf, out);
        }
        fputc('\n', out);
    }
    fprintf(out, "\\item input $q = %s$, rates $%s$, $%s$\n\\end{itemize}\n", s->latex[n],
            s->latex[SYS_VAR_QDOT(n)], s->latex[SYS_VAR_QDDOT(n)]);
    latex_coefficients(s, out);
    latex_loops(s, out);
    fputs("\\subsection*{Position equations $f(x, q) = 0$}\n", out);
    latex_rows(s, "f", s->f, " = 0", out);
    fputs("\\subsection*{Jacobian $\\partial f / \\partial x$ (nonzeros)}\n\\begin{align*}\n", out);
    for (int j = 0; j < n; j++)
        for (int k = s->Jp[j]; k < s->Jp[j + 1]; k++) {
            fprintf(out, "\\frac{\\partial f_{%d}}{\\partial %s} &= ", s->Ji[k] + 1, s->latex[j]);
            expr_print(&s->ex, s->Jx[k], &nm, 1, out);
            fputs(j + 1 < n || k + 1 < s->Jp[j + 1] ? " \\\\\n" : "\n", out);
        }
    fputs("\\end{align*}\n\\subsection*{Velocity: $J\\dot{x} = b$}\n", out);
    latex_rows(s, "b", s->vel, "", out);
    fputs("\\subsection*{Acceleration: $J\\ddot{x} = c$}\n", out);
    latex_rows(s, "c", s->acc, "", out);
    fputs("\\end{document}\n", out);
}

void mech_system_print(const mech_system *s, mech_format fmt, FILE *out)
{
    if (!s)
        return;
    if (!out)
        out = stdout;
    if (fmt == MECH_FORMAT_LATEX)
        print_latex(s, out);
    else
        print_text(s, out);
}
