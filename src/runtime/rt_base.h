/* src/runtime/rt_base.h: what the runtime's files share (src/rt_*.h: the code
 * libmech and the C that `mech codegen` writes have in common, see
 * docs/codegen.md): how they ask the compiler to inline and unroll. The
 * generated source defines RT_KERNEL and RT_UNROLL before the runtime's
 * text, which it carries in this order: rt_base.h, rt_blocklu.h,
 * rt_newton.h, rt_frame.h, (rt_forces.h,) then its own tables and
 * functions, then rt_solver.h. */
#ifndef MECH_RT_BASE_H
#define MECH_RT_BASE_H

/* RT_INLINE: inlined where called, so that sizes that are constants there
 * (the generated code's tables) stay constants (GCC, Clang). */
#if defined(__GNUC__)
#define RT_INLINE static inline __attribute__((always_inline))
#else
#define RT_INLINE static inline
#endif

/* RT_KERNEL: the loops of a general k x k block. libmech calls them out of
 * line (its sizes vary); the generated code defines RT_KERNEL as RT_INLINE,
 * so that the compiler unrolls them for each of its constant block sizes. */
#ifndef RT_KERNEL
#if defined(__GNUC__)
#define RT_KERNEL static __attribute__((noinline, unused))
#else
#define RT_KERNEL static inline
#endif
#endif

/* RT_UNROLL: before a loop whose trip count is a constant where the tables
 * are (the generated code defines it as GCC's unroll pragma; libmech leaves
 * it empty). */
#ifndef RT_UNROLL
#define RT_UNROLL
#endif

/* The numbers of one variant of a sweep, which the solver `mech sweep`
 * compiles for all of its variants reads through its state (s->num, set by
 * P_numbers) where `mech codegen` writes literals (docs/codegen.md, "One
 * solver for a sweep's variants"); the host fills it from the variant's
 * analysis (codegen_numbers_fill). */
struct rt_numbers {
    double lref, ftol;       /* largest length, m; the residual tolerance, m */
    const double *unit;      /* [NX] the unknowns' step units */
    const double *leaf;      /* the leaves' values: the varied lengths and angles */
    const double *attach;    /* [4 NLINKS] the kinematic tree's attachment points */
    const double *points;    /* every link's points (x, y), link after link */
    const double *guess;     /* [NX] the first position's guesses (NaN: none) */
    const void *fcols, *fbody, *fgears, *floads, *fsprings, *ffriction; /* rt_forces.h's */
    const double *fgrav;
};

#endif
