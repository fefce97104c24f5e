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

#endif
