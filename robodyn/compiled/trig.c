/* robodyn.compiled sin and cos: one generic text, the macro RD_TRIG_DEFINE(P, T, U, A),
 * instantiated once per type (codegen.py puts this text and its instantiation for double,
 * the scalar kernels' type, before the kernels; simd.py instantiates it for each SIMD vector
 * of doubles, one state a lane): P the functions' prefix (P##sin, P##cos, P##sincos), T the
 * type, U the unsigned 64-bit integer type of its shape and A the functions' attributes.
 * The per-type helpers P##bits, P##double (bit casts), P##mask (a comparison -> all ones or
 * zero) and P##libm (libm's sin and cos where a mask is set) come before an instantiation.
 *
 * Branch-free arithmetic, the same IEEE operations in the same order on every type (no
 * fused multiply-add: contraction is off), so a lane of a vector rounds as the scalar does:
 * - n = round(x 2/π) by adding and subtracting 1.5·2^52 (the sum's low mantissa bits are n
 *   mod 4, the quadrant);
 * - Cody–Waite: r = x - n π/2 with π/2 = P1 + P2 + P3 + P4 (P1..P3 33 bits, so n·Pk is
 *   exact for |n| < 2^20; x - n·P1 is exact), the rest summed in double-double (TwoSum):
 *   r = hi + lo to ~2^-100 relative however close x is to a multiple of π/2;
 * - fdlibm's kernels (__kernel_sin, __kernel_cos: minimax polynomials on [-π/4, π/4]
 *   taking the tail lo), Horner;
 * - the quadrant picks sin or cos and the sign by bit masks; sin of |x| < 2^-27 is x.
 * Arguments with |x| > RD_TRIG_LIMIT (2^20: |n| stays below 2^20) or not finite go to libm,
 * on every type, so a vector lane stays the scalar's result.
 *
 * The kernels' polynomials and expressions, and the split of π/2, are fdlibm's (FreeBSD
 * k_sin.c, k_cos.c, e_rem_pio2.c), under its notice:
 * Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
 * Developed at SunSoft, a Sun Microsystems, Inc. business.
 * Permission to use, copy, modify, and distribute this software is freely granted,
 * provided that this notice is preserved. */

#define RD_TRIG_LIMIT 1048576.0

#define RD_TRIG_DEFINE(P, T, U, A)                                                                                               \
static inline __attribute__((always_inline)) A void P##sincos_fast(T x, T *s, T *c) {                                            \
    const double shift = 6755399441055744.0; /* 1.5·2^52 */                                                                      \
    const T t = x * 0.63661977236758134308 + shift;                                                                              \
    const U quadrant = P##bits(t);                                                                                               \
    const T n = t - shift;                                                                                                       \
    const T r = x - n * 1.57079632673412561417e+00; /* exact */                                                                  \
    T b = -(n * 6.07710050630396597660e-11);                                                                                     \
    const T h1 = r + b;                                                                                                          \
    T bb = h1 - r;                                                                                                               \
    T lo = (r - (h1 - bb)) + (b - bb);                                                                                           \
    b = -(n * 2.02226624871116645580e-21);                                                                                       \
    const T h2 = h1 + b;                                                                                                         \
    bb = h2 - h1;                                                                                                                \
    lo = lo + ((h1 - (h2 - bb)) + (b - bb));                                                                                     \
    lo = lo - n * 8.47842766036889956997e-32;                                                                                    \
    const T hi = h2 + lo;                                                                                                        \
    lo = lo - (hi - h2);                                                                                                         \
    /* __kernel_sin(hi, lo) */                                                                                                   \
    const T z = hi * hi;                                                                                                         \
    const T v = z * hi;                                                                                                          \
    const T ps = 8.33333333332248946124e-03 +                                                                                    \
                     z * (-1.98412698298579493134e-04 +                                                                          \
                          z * (2.75573137070700676789e-06 +                                                                      \
                               z * (-2.50507602534068634195e-08 + z * 1.58969099521155010221e-10)));                             \
    const T sine = hi - ((z * (0.5 * lo - v * ps) - lo) - v * -1.66666666666666324348e-01);                                      \
    /* __kernel_cos(hi, lo) */                                                                                                   \
    const T w = z * z;                                                                                                           \
    const T pc = z * (4.16666666666666019037e-02 + z * (-1.38888888888741095749e-03 + z * 2.48015872894767294178e-05)) +         \
                     w * w * (-2.75573143513906633035e-07 + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11)); \
    const T hz = 0.5 * z;                                                                                                        \
    const T one = 1.0 - hz;                                                                                                      \
    const T cosine = one + (((1.0 - one) - hz) + (z * pc - hi * lo));                                                            \
    /* quadrant k: sin x = (sin, cos, -sin, -cos)[k], cos x = (cos, -sin, -cos, sin)[k] */                                       \
    const U odd = -(quadrant & 1);                                                                                               \
    const U sb = P##bits(sine), cb = P##bits(cosine);                                                                            \
    const U tiny = P##mask(P##double(P##bits(x) & 0x7fffffffffffffffULL) < 7.450580596923828125e-9);                             \
    const U sin_bits = ((odd & cb) | (~odd & sb)) ^ ((quadrant & 2) << 62);                                                      \
    *s = P##double((tiny & P##bits(x)) | (~tiny & sin_bits));                                                                    \
    *c = P##double(((odd & sb) | (~odd & cb)) ^ (((quadrant + 1) & 2) << 62));                                                   \
}                                                                                                                                \
                                                                                                                                 \
/* sin x and cos x, libm's beyond RD_TRIG_LIMIT (and for NaN and infinities). */                                                 \
static inline __attribute__((always_inline)) A void P##sincos(T x, T *s, T *c) {                                                 \
    P##sincos_fast(x, s, c);                                                                                                     \
    P##libm(x, ~P##mask(P##double(P##bits(x) & 0x7fffffffffffffffULL) <= RD_TRIG_LIMIT), s, c);                                  \
}                                                                                                                                \
                                                                                                                                 \
static inline __attribute__((always_inline)) A T P##sin(T x) {                                                                   \
    T s, c;                                                                                                                      \
    P##sincos(x, &s, &c);                                                                                                        \
    return s;                                                                                                                    \
}                                                                                                                                \
                                                                                                                                 \
static inline __attribute__((always_inline)) A T P##cos(T x) {                                                                   \
    T s, c;                                                                                                                      \
    P##sincos(x, &s, &c);                                                                                                        \
    return c;                                                                                                                    \
}
