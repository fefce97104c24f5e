/* src/symbolic/tape.c: compile the DAG to a register program, and run it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"
#include "symbolic.h"

void tape_free(tape *t)
{
    free(t->reg0);
    free(t->const_reg);
    free(t->const_val);
    free(t->ins);
    free(t->var_reg);
    free(t->node_reg);
    free(t->fns);
    memset(t, 0, sizeof *t);
}

static int op_of(expr_op op)
{
    switch (op) {
    case EX_ADD: return TOP_ADD;
    case EX_MUL: return TOP_MUL;
    case EX_NEG: return TOP_NEG;
    case EX_SIN: return TOP_SIN;
    case EX_COS: return TOP_COS;
    case EX_CALL: return TOP_CALL;
    default: abort(); /* constants and variables are not instructions */
    }
}

/* Post-order over the DAG from e (iterative: sums of long loops are deep). */
typedef struct work_stack {
    int *v;
    size_t n, cap;
} work_stack;

static int push(work_stack *s, int e)
{
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 256;
        int *v = xrealloc_array(s->v, cap, sizeof *v);
        if (!v)
            return -1;
        s->v = v;
        s->cap = cap;
    }
    s->v[s->n++] = e;
    return 0;
}

static int emit(tape *t, const expr_ctx *c, ex root, work_stack *st, size_t *cap_ins)
{
    st->n = 0;
    if (push(st, root) < 0)
        return -1;
    while (st->n > 0) {
        ex e = st->v[st->n - 1];
        if (t->node_reg[e] >= 0) {
            st->n--;
            continue;
        }
        const expr_node *n = &c->nodes[e];
        if (n->op == EX_CONST || n->op == EX_VAR) {
            t->node_reg[e] = t->nreg++;
            if (n->op == EX_CONST)
                t->reg0[t->node_reg[e]] = n->value;
            else
                t->var_reg[n->var] = t->node_reg[e];
            st->n--;
            continue;
        }
        int pending = 0;
        if (n->b >= 0 && t->node_reg[n->b] < 0) {
            if (push(st, n->b) < 0)
                return -1;
            pending = 1;
        }
        if (t->node_reg[n->a] < 0) {
            if (push(st, n->a) < 0)
                return -1;
            pending = 1;
        }
        if (pending)
            continue;
        if ((size_t)t->nins == *cap_ins) {
            size_t cap = *cap_ins ? 2 * *cap_ins : 256;
            tape_ins *ni = xrealloc_array(t->ins, cap, sizeof *ni);
            if (!ni)
                return -1;
            t->ins = ni;
            *cap_ins = cap;
        }
        t->node_reg[e] = t->nreg++;
        t->ins[t->nins++] = n->op == EX_CALL
                                ? (tape_ins){TOP_CALL, t->node_reg[e], t->node_reg[n->a], n->var,
                                             (int)n->value}
                                : (tape_ins){op_of(n->op), t->node_reg[e], t->node_reg[n->a],
                                             n->b >= 0 ? t->node_reg[n->b] : 0, 0};
        st->n--;
    }
    return 0;
}

/* sin(x) and cos(x) of the same register in one phase become one SINCOS
 * at the first of the two (a loop equation's Jacobian has both of every
 * angle): glibc's sincos costs little more than one of them. The later
 * instruction is removed; registers are single-assignment, so computing
 * its value earlier is harmless. */
static int fuse_sincos(tape *t)
{
    int *first = xcalloc((size_t)t->nreg + 1, sizeof *first);  /* 1 + where, by argument */
    if (!first)
        return -1;
    int out = 0;
    for (int k = 0; k < t->nphases; k++) {
        int start = t->phase_start[k], end = t->phase_start[k + 1];
        t->phase_start[k] = out;
        for (int i = start; i < end; i++) {
            tape_ins in = t->ins[i];
            if (in.op == TOP_SIN || in.op == TOP_COS) {
                int f = first[in.a] - 1;
                if (f >= t->phase_start[k] && t->ins[f].op != in.op &&
                    t->ins[f].op != TOP_SINCOS) {
                    int sin_d = in.op == TOP_SIN ? in.d : t->ins[f].d;
                    int cos_d = in.op == TOP_COS ? in.d : t->ins[f].d;
                    t->ins[f] = (tape_ins){TOP_SINCOS, sin_d, in.a, cos_d, 0};
                    continue;  /* dropped */
                }
                if (f < t->phase_start[k])
                    first[in.a] = out + 1;
            }
            t->ins[out++] = in;
        }
        t->phase_split[k] = t->phase_start[k];
    }
    t->phase_start[t->nphases] = t->nins = out;
    free(first);
    return 0;
}

/* Give back what compiling over-allocated: the instruction array grew by
 * doubling (the image sized for every node of the DAG is already freed:
 * constant_list). A failed shrink keeps the larger block. */
static void trim(tape *t)
{
    if (t->nins > 0) {
        tape_ins *ins = xrealloc_array(t->ins, (size_t)t->nins, sizeof *ins);
        if (ins)
            t->ins = ins;
    }
}

/* Registers an instruction reads: a; then b; then c. */
static int operands(int op)
{
    switch (op) {
    case TOP_ADD: case TOP_MUL: return 2;
    case TOP_MULADD: case TOP_MULMUL: case TOP_ADDADD: return 3;
    default: return 1;  /* NEG, SIN, COS; SINCOS writes b */
    }
}

/* How many instructions (of any phase) read each register; a root, which
 * the caller reads, counts as a use that can never be fused away. */
static int *count_uses(const tape *t, const ex *const *roots, const int *nroots)
{
    int *uses = xcalloc((size_t)t->nreg + 1, sizeof *uses);
    if (!uses)
        return NULL;
    for (int i = 0; i < t->nins; i++) {
        const tape_ins *in = &t->ins[i];
        int k = operands(in->op);
        uses[in->a]++;
        if (k >= 2)
            uses[in->b]++;
        if (k == 3)
            uses[in->c]++;
    }
    for (int k = 0; k < t->nphases; k++)
        for (int i = 0; i < nroots[k]; i++)
            uses[t->node_reg[roots[k][i]]] += 2;
    return uses;
}

/* The superinstruction of consumer `use` (ADD or MUL) reading the result of
 * `def` (ADD or MUL), or -1 when there is none. */
static int fused_op(int use, int def)
{
    if (use == TOP_ADD && def == TOP_MUL)
        return TOP_MULADD;
    if (use == TOP_MUL && def == TOP_MUL)
        return TOP_MULMUL;
    if (use == TOP_ADD && def == TOP_ADD)
        return TOP_ADDADD;
    return -1;
}

/* Fuse the instructions of [from, to) into ins[out..]; returns the new out. */
static int fuse_range(tape *t, const int *uses, const int *def, int from, int to, int out)
{
    for (int i = from; i < to; i++) {
        tape_ins *in = &t->ins[i];
        for (int side = 0; side < 2 && (in->op == TOP_ADD || in->op == TOP_MUL); side++) {
            int r = side ? in->b : in->a, p = def[r] - 1;
            if (p < from || uses[r] != 1)
                continue;
            int op = fused_op(in->op, t->ins[p].op);
            if (op < 0)
                continue;
            *in = (tape_ins){op, in->d, t->ins[p].a, t->ins[p].b, side ? in->a : in->b};
            t->ins[p].op = TOP_DROPPED;
        }
    }
    for (int i = from; i < to; i++)
        if (t->ins[i].op != TOP_DROPPED)
            t->ins[out++] = t->ins[i];
    return out;
}

/* Number the registers still in use 0, 1, ... in their order: the fused
 * instructions' results leave holes (a chain of four-bars: 34 registers per
 * loop, 26 in use: bench-scale), and every register file is nreg long. */
static void renumber(tape *t, const ex *const *roots, const int *nroots)
{
    int *map = xcalloc((size_t)t->nreg + 1, sizeof *map);  /* 0 unused, else new + 1 */
    if (!map)
        return;  /* the holes stay: still correct */
    for (int i = 0; i < t->nins; i++) {
        const tape_ins *in = &t->ins[i];
        int k = operands(in->op);
        map[in->d] = map[in->a] = 1;
        if (k >= 2 || in->op == TOP_SINCOS)
            map[in->b] = 1;
        if (k == 3)
            map[in->c] = 1;
    }
    for (int v = 0; v < t->nvars; v++)
        if (t->var_reg[v] >= 0)
            map[t->var_reg[v]] = 1;
    for (int k = 0; k < t->nconst; k++)
        map[t->const_reg[k]] = 1;
    for (int k = 0; k < t->nphases; k++)  /* a root may be a constant 0, in no list */
        for (int i = 0; i < nroots[k]; i++)
            map[t->node_reg[roots[k][i]]] = 1;
    int n = 0;
    for (int r = 0; r < t->nreg; r++)
        if (map[r])
            map[r] = ++n;
    for (int i = 0; i < t->nins; i++) {
        tape_ins *in = &t->ins[i];
        int k = operands(in->op);
        in->d = map[in->d] - 1;
        in->a = map[in->a] - 1;
        if (k >= 2 || in->op == TOP_SINCOS)
            in->b = map[in->b] - 1;
        if (k == 3)
            in->c = map[in->c] - 1;
    }
    for (int v = 0; v < t->nvars; v++)
        if (t->var_reg[v] >= 0)
            t->var_reg[v] = map[t->var_reg[v]] - 1;
    for (int k = 0; k < t->nconst; k++)
        t->const_reg[k] = map[t->const_reg[k]] - 1;
    for (size_t e = 0; e < t->nnodes; e++)
        if (t->node_reg[e] >= 0)
            t->node_reg[e] = map[t->node_reg[e]] - 1;
    t->nreg = n;
    free(map);
}

int tape_fuse(tape *t, const ex *const *roots, const int *nroots)
{
    int *uses = count_uses(t, roots, nroots);
    int *def = xcalloc((size_t)t->nreg + 1, sizeof *def);  /* 1 + instruction writing reg */
    if (!uses || !def) {
        free(uses);
        free(def);
        return -1;
    }
    for (int i = 0; i < t->nins; i++)
        def[t->ins[i].d] = i + 1;
    int out = 0;
    for (int k = 0; k < t->nphases; k++) {  /* within each part of each phase */
        int start = t->phase_start[k], split = t->phase_split[k], end = t->phase_start[k + 1];
        t->phase_start[k] = out;
        out = fuse_range(t, uses, def, start, split, out);
        t->phase_split[k] = out;
        out = fuse_range(t, uses, def, split, end, out);
    }
    t->phase_start[t->nphases] = t->nins = out;
    free(uses);
    free(def);
    renumber(t, roots, nroots);
    trim(t);
    return 0;
}

void tape_hoist(tape *t, int phase, const unsigned char *invariant)
{
    unsigned char *variant = xcalloc((size_t)t->nreg + 1, 1);
    tape_ins *moved = xcalloc((size_t)t->nins + 1, sizeof *moved);
    int start = t->phase_start[phase], end = t->phase_start[phase + 1];
    if (!variant || !moved) {  /* no hoisting: still correct, run whole */
        free(variant);
        free(moved);
        return;
    }
    for (int v = 0; v < t->nvars; v++)
        if (t->var_reg[v] >= 0 && !invariant[v])
            variant[t->var_reg[v]] = 1;
    /* registers written by earlier phases count as variant: their inputs
       may change between runs of this phase */
    for (int i = 0; i < start; i++) {
        variant[t->ins[i].d] = 1;
        if (t->ins[i].op == TOP_SINCOS)
            variant[t->ins[i].b] = 1;
    }
    int nfixed = 0, nvar = 0;
    for (int i = start; i < end; i++) {
        tape_ins in = t->ins[i];
        int v = variant[in.a] | (operands(in.op) >= 2 ? variant[in.b] : 0) |
                (operands(in.op) == 3 ? variant[in.c] : 0);
        variant[in.d] = (unsigned char)v;
        if (in.op == TOP_SINCOS)
            variant[in.b] = (unsigned char)v;
        if (v)
            moved[nvar++] = in;
        else
            t->ins[start + nfixed++] = in;  /* stable: order within each part kept */
    }
    if (nvar > 0)  /* t->ins is NULL for an empty tape */
        memcpy(t->ins + start + nfixed, moved, (size_t)nvar * sizeof *moved);
    t->phase_split[phase] = start + nfixed;
    free(variant);
    free(moved);
}

/* The register image as a list of its constants other than +0 (most
 * registers are computed, and the image was copied whole into every
 * register file); +0 is what calloc gives. */
static int kept_const(double v) { return !(v == 0.0 && !signbit(v)); }

static int constant_list(tape *t)
{
    int n = 0;
    for (int r = 0; r < t->nreg; r++)
        n += kept_const(t->reg0[r]);
    t->const_reg = xcalloc((size_t)n + 1, sizeof *t->const_reg);
    t->const_val = xcalloc((size_t)n + 1, sizeof *t->const_val);
    if (!t->const_reg || !t->const_val)
        return -1;
    for (int r = 0; r < t->nreg; r++)
        if (kept_const(t->reg0[r])) {
            t->const_reg[t->nconst] = r;
            t->const_val[t->nconst++] = t->reg0[r];
        }
    free(t->reg0);
    t->reg0 = NULL;
    return 0;
}

int tape_compile(tape *t, expr_ctx *c, int nvars, int nphases, const ex *const *roots,
                 const int *nroots)
{
    memset(t, 0, sizeof *t);
    size_t nodes = c->count, cap_ins = 0;
    t->node_reg = xcalloc(nodes, sizeof *t->node_reg);
    t->nnodes = nodes;
    t->reg0 = xcalloc(nodes, sizeof *t->reg0);      /* at most one register per node */
    t->var_reg = xcalloc((size_t)nvars, sizeof *t->var_reg);
    work_stack stack = {0};
    if (!t->node_reg || !t->reg0 || !t->var_reg || nphases > TAPE_MAX_PHASES)
        goto fail;
    if (c->nfns > 0) {
        if (!(t->fns = xcalloc((size_t)c->nfns, sizeof *t->fns)))
            goto fail;
        memcpy(t->fns, c->fns, (size_t)c->nfns * sizeof *t->fns);
        t->nfns = c->nfns;
    }
    for (size_t i = 0; i < nodes; i++)
        t->node_reg[i] = -1;
    for (int v = 0; v < nvars; v++)
        t->var_reg[v] = -1;
    t->nvars = nvars;
    t->nphases = nphases;
    for (int k = 0; k < nphases; k++) {
        t->phase_start[k] = t->nins;
        for (int i = 0; i < nroots[k]; i++)
            if (emit(t, c, roots[k][i], &stack, &cap_ins) < 0)
                goto fail;
    }
    t->phase_start[nphases] = t->nins;
    for (int k = 0; k < nphases; k++)
        t->phase_split[k] = t->phase_start[k];
    free(stack.v);
    stack.v = NULL;  /* fail: frees it again */
    if (fuse_sincos(t) < 0 || constant_list(t) < 0)
        goto fail;
    trim(t);
    return 0;
fail:
    free(stack.v);
    tape_free(t);
    return -1;
}

static void run_range(const tape *t, double *r, int from, int to)
{
    const tape_ins *ins = t->ins;
    for (int i = from; i < to; i++) {
        const tape_ins *p = &ins[i];
        switch (p->op) {
        case TOP_ADD: r[p->d] = r[p->a] + r[p->b]; break;
        case TOP_MUL: r[p->d] = r[p->a] * r[p->b]; break;
        case TOP_NEG: r[p->d] = -r[p->a]; break;
        case TOP_SIN: r[p->d] = sin(r[p->a]); break;
        case TOP_COS: r[p->d] = cos(r[p->a]); break;
        case TOP_SINCOS: {
            double x = r[p->a];  /* the compiler makes this one sincos call */
            r[p->d] = sin(x);
            r[p->b] = cos(x);
            break;
        }
        case TOP_MULADD: r[p->d] = r[p->a] * r[p->b] + r[p->c]; break;
        case TOP_MULMUL: r[p->d] = r[p->a] * r[p->b] * r[p->c]; break;
        case TOP_ADDADD: r[p->d] = r[p->a] + r[p->b] + r[p->c]; break;
        case TOP_CALL: {
            const expr_fn *f = &t->fns[p->b];
            r[p->d] = f->eval(f->data, p->c, r[p->a]);
            break;
        }
        }
    }
}

void tape_run(const tape *t, double *reg, int phase)
{
    run_range(t, reg, t->phase_start[phase], t->phase_start[phase + 1]);
}

void tape_run_invariant(const tape *t, double *reg, int phase)
{
    run_range(t, reg, t->phase_start[phase], t->phase_split[phase]);
}

void tape_run_variant(const tape *t, double *reg, int phase)
{
    run_range(t, reg, t->phase_split[phase], t->phase_start[phase + 1]);
}

double *tape_registers_new(const tape *t)
{
    double *reg = xcalloc((size_t)t->nreg + 1, sizeof *reg);
    if (reg)
        for (int k = 0; k < t->nconst; k++)
            reg[t->const_reg[k]] = t->const_val[k];
    return reg;
}
