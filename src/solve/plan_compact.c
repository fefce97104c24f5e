/* src/solve/plan_compact.c: give back what only the set-up of a solver plan
 * needed, once the plan is complete (docs/performance.md, "Target 2").
 *
 * solver_plan_init builds the symbolic system (expression DAG, residual,
 * Jacobian and rate expressions, the system's own tape and registers)
 * and compiles from it the solver's tape; from then on the sweep reads
 * only the solver's tape (by the registers in preg/vreg/areg/xreg), the
 * pattern, the spanning tree and a few tables of the system (unknown kinds,
 * the names of the unknowns and the driver, link_var, joint_var, loops). On a chain of N four-bars the
 * parts freed here are about 4 KiB per loop of the 7.7 KiB resident.
 *
 * Only the sweep's analysis (mech_analysis_new) calls this: codegen walks
 * the plan's roots in the DAG, `mech equations` and the sensitivities build
 * their own systems. */
#include <stdlib.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "solve.h"

/* Set-up memory freed above which the allocator is asked to give the free
 * pages back to the system (glibc keeps freed small blocks in its heap; a
 * chain of 10^4 loops: 2 KiB per loop resident for nothing). Below it the
 * trim's walk over the heap is not worth its time. */
enum { TRIM_BYTES = 8 << 20 };

void solver_plan_compact(solver_plan *sp)
{
    mech_system *s = sp->sys;
    if (!s)
        return;
    size_t freed = s->ex.cap * sizeof(expr_node) + s->ex.tcap * sizeof(int) +
                   (size_t)s->tp.nins * sizeof(tape_ins) +
                   (size_t)s->tp.nreg * sizeof(double);
    expr_free(&s->ex);  /* every ex below indexes it: all go */
    void *sym[] = {s->f, s->Jx, s->fq, s->vel, s->acc, s->link_angle, s->slide, s->reg};
    for (size_t k = 0; k < sizeof sym / sizeof sym[0]; k++)
        free(sym[k]);
    s->f = s->Jx = s->fq = s->vel = s->acc = s->link_angle = s->slide = NULL;
    s->reg = NULL;
    tape_free(&s->tp);  /* the system's tape, if a sys_eval_* compiled it */
    free(s->Jp);        /* the whole Jacobian's pattern: the plan has its solved part */
    free(s->Ji);
    s->Jp = s->Ji = NULL;
    /* LaTeX names are for `mech equations` (its own system); the messages
       name unknowns (and the driver), never the rates */
    for (int v = 0; v < s->nnames; v++) {
        if (s->latex) {
            free(s->latex[v]);
            s->latex[v] = NULL;
        }
        if (s->names && v > s->n) {
            free(s->names[v]);
            s->names[v] = NULL;
        }
    }
    /* the solver's tape: DAG node -> register was for set-up (the roots'
       registers are in preg, vreg, areg) */
    free(sp->tp.node_reg);
    sp->tp.node_reg = NULL;
    if (!sp->aug) {  /* square: the values' image is all zeros */
        free(sp->Ax0);
        sp->Ax0 = NULL;
    }
    free(sp->proot);
    free(sp->vroot);
    free(sp->aroot);
    sp->proot = sp->vroot = sp->aroot = NULL;
#ifdef __GLIBC__
    if (freed >= TRIM_BYTES)
        malloc_trim(0);
#else
    (void)freed;
#endif
}
