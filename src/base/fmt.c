/* src/base/fmt.c: a double as the shortest decimal that reads back as the
 * same double (strtod), the nearest such when several are as short, laid
 * out as printf's %.17g lays out a number (positional from 1e-4 to below
 * 1e17, else d.ddde+XX): the numbers of the result tables (output.c), of
 * mech sweep's rows and of mech compare's messages (docs/cli.md).
 *
 * Debian ships no C library for this (Ryu and Dragonbox are C++ or not
 * packaged), so it is done here, exactly, with integers. A double v = m
 * 2^e (m < 2^53) has the neighbours' midpoints (4m -+ 2) 2^(e-2) (4m - 1
 * below a power of two); every decimal strictly between them (or on them,
 * m even: strtod rounds a tie to the even m) reads back as v. Scaled by
 * 10^p so that v 10^p has 17 or 18 digits, these three are
 * (4m -+ 2) 5^p / 2^s with s = 2 - e - p, exact in 192 bits while 0 <= p
 * <= 55 and s >= 0 (about 1e-39 <= |v| < 1e16): the integers A <= B that
 * bound the decimals c 10^t in the interval come from shifts, and the
 * largest t for which some c is in [A / 10^t, B / 10^t] gives the fewest
 * digits; of those c, the nearest to v (a tie: the even one). Outside that
 * range (very small or large magnitudes, subnormals) the digits come from
 * printf's correctly rounded %.*e at 1, 2, ... 17 digits, the first that
 * reads back: slower, the same result (the first precision that reads back
 * ends in a digit other than 0). tests/unit/test_fmt.c holds the two
 * against each other and strtod on 300 000 values. */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"

__extension__ typedef unsigned __int128 u128;

static const uint64_t POW10[20] = {
    1ull, 10ull, 100ull, 1000ull, 10000ull, 100000ull, 1000000ull, 10000000ull,
    100000000ull, 1000000000ull, 10000000000ull, 100000000000ull, 1000000000000ull,
    10000000000000ull, 100000000000000ull, 1000000000000000ull, 10000000000000000ull,
    100000000000000000ull, 1000000000000000000ull, 10000000000000000000ull};

enum { MAX_P = 55 };  /* 5^55 < 2^128 */

/* 5^p, 0 <= p <= MAX_P, as {high, low} 64 bits */
static const uint64_t POW5[MAX_P + 1][2] = {
    {0x0000000000000000ull, 0x0000000000000001ull}, {0x0000000000000000ull, 0x0000000000000005ull},
    {0x0000000000000000ull, 0x0000000000000019ull}, {0x0000000000000000ull, 0x000000000000007dull},
    {0x0000000000000000ull, 0x0000000000000271ull}, {0x0000000000000000ull, 0x0000000000000c35ull},
    {0x0000000000000000ull, 0x0000000000003d09ull}, {0x0000000000000000ull, 0x000000000001312dull},
    {0x0000000000000000ull, 0x000000000005f5e1ull}, {0x0000000000000000ull, 0x00000000001dcd65ull},
    {0x0000000000000000ull, 0x00000000009502f9ull}, {0x0000000000000000ull, 0x0000000002e90eddull},
    {0x0000000000000000ull, 0x000000000e8d4a51ull}, {0x0000000000000000ull, 0x0000000048c27395ull},
    {0x0000000000000000ull, 0x000000016bcc41e9ull}, {0x0000000000000000ull, 0x000000071afd498dull},
    {0x0000000000000000ull, 0x0000002386f26fc1ull}, {0x0000000000000000ull, 0x000000b1a2bc2ec5ull},
    {0x0000000000000000ull, 0x000003782dace9d9ull}, {0x0000000000000000ull, 0x00001158e460913dull},
    {0x0000000000000000ull, 0x000056bc75e2d631ull}, {0x0000000000000000ull, 0x0001b1ae4d6e2ef5ull},
    {0x0000000000000000ull, 0x000878678326eac9ull}, {0x0000000000000000ull, 0x002a5a058fc295edull},
    {0x0000000000000000ull, 0x00d3c21bcecceda1ull}, {0x0000000000000000ull, 0x0422ca8b0a00a425ull},
    {0x0000000000000000ull, 0x14adf4b7320334b9ull}, {0x0000000000000000ull, 0x6765c793fa10079dull},
    {0x0000000000000002ull, 0x04fce5e3e2502611ull}, {0x000000000000000aull, 0x18f07d736b90be55ull},
    {0x0000000000000032ull, 0x7cb2734119d3b7a9ull}, {0x00000000000000fcull, 0x6f7c40458122964dull},
    {0x00000000000004eeull, 0x2d6d415b85acef81ull}, {0x00000000000018a6ull, 0xe32246c99c60ad85ull},
    {0x0000000000007b42ull, 0x6fab61f00de36399ull}, {0x000000000002684cull, 0x2e58e9b04570f1fdull},
    {0x00000000000c097cull, 0xe7bc90715b34b9f1ull}, {0x00000000003c2f70ull, 0x86aed236c807a1b5ull},
    {0x00000000012ced32ull, 0xa16a1b11e8262889ull}, {0x0000000005e0a1fdull, 0x2712875988becaadull},
    {0x000000001d6329f1ull, 0xc35ca4bfabb9f561ull}, {0x0000000092efd1b8ull, 0xd0cf37be5aa1cae5ull},
    {0x00000002deaf189cull, 0x140c16b7c528f679ull}, {0x0000000e596b7b0cull, 0x643c7196d9ccd05dull},
    {0x00000047bf19673dull, 0xf52e37f2410011d1ull}, {0x00000166bb7f0435ull, 0xc9e717bb45005915ull},
    {0x00000701a97b150cull, 0xf18376a85901bd69ull}, {0x000023084f676940ull, 0xb7915149bd08b30dull},
    {0x0000af298d050e43ull, 0x95d69670b12b7f41ull}, {0x00036bcfc1194751ull, 0xed30f03375d97c45ull},
    {0x00111b0ec57e6499ull, 0xa1f4b1014d3f6d59ull}, {0x00558749db77f700ull, 0x29c77506823d22bdull},
    {0x01aba4714957d300ull, 0xd0e549208b31adb1ull}, {0x085a36366eb71f04ull, 0x147a6da2b7f86475ull},
    {0x29c30f1029939b14ull, 0x6664242d97d9f649ull}, {0xd0cf4b50cfe20765ull, 0xfff4b4e3f741cf6dull}};

/* A 192-bit product, the limbs low first. */
typedef struct u192 {
    uint64_t w[3];
} u192;

/* a 5^p, a < 2^64 */
static u192 mul_pow5(uint64_t a, int p)
{
    u128 lo = (u128)a * POW5[p][1], hi = (u128)a * POW5[p][0];
    u128 mid = (lo >> 64) + (uint64_t)hi;  /* below 2^65 */
    u192 r = {{(uint64_t)lo, (uint64_t)mid, (uint64_t)(hi >> 64) + (uint64_t)(mid >> 64)}};
    return r;
}

/* floor(x / 2^s), 0 <= s < 192, when it is below 2^64 */
static uint64_t shift_down(const u192 *x, int s)
{
    int k = s / 64, b = s % 64;
    uint64_t lo = x->w[k], hi = k < 2 ? x->w[k + 1] : 0;
    return b ? (lo >> b) | (hi << (64 - b)) : lo;
}

/* x mod 2^s != 0 */
static int low_bits(const u192 *x, int s)
{
    int k = s / 64, b = s % 64;
    for (int i = 0; i < k; i++)
        if (x->w[i])
            return 1;
    return b > 0 && (x->w[k] & ((1ull << b) - 1)) != 0;
}

static int bit_at(const u192 *x, int i) { return (int)((x->w[i / 64] >> (i % 64)) & 1); }

static int ndigits(uint64_t c)
{
    int n = 1;
    while (n < 20 && c >= POW10[n])
        n++;
    return n;
}

/* digits (n of them, no leading zero) times 10^x, x the first digit's
 * exponent, laid out as %.17g does; returns the length */
static int layout(char *out, int neg, const char *digits, int n, int x)
{
    char *o = out;
    if (neg)
        *o++ = '-';
    if (x < -4 || x >= 17) {
        *o++ = digits[0];
        if (n > 1) {
            *o++ = '.';
            memcpy(o, digits + 1, (size_t)n - 1);
            o += n - 1;
        }
        *o++ = 'e';
        *o++ = x < 0 ? '-' : '+';
        int ax = x < 0 ? -x : x;
        if (ax >= 100)
            *o++ = (char)('0' + ax / 100);
        *o++ = (char)('0' + ax / 10 % 10);
        *o++ = (char)('0' + ax % 10);
    } else if (x < 0) {
        *o++ = '0';
        *o++ = '.';
        for (int i = 0; i < -x - 1; i++)
            *o++ = '0';
        memcpy(o, digits, (size_t)n);
        o += n;
    } else {
        int whole = x + 1;
        for (int i = 0; i < whole; i++)
            *o++ = i < n ? digits[i] : '0';
        if (n > whole) {
            *o++ = '.';
            memcpy(o, digits + whole, (size_t)(n - whole));
            o += n - whole;
        }
    }
    *o = '\0';
    return (int)(o - out);
}

/* The shortest digits of v > 0 by printf's %.*e, the first precision that
 * reads back; n digits into digits, *x the exponent. */
static int digits_by_printf(double v, char digits[20], int *x)
{
    char buf[40];
    for (int prec = 1; prec <= 17; prec++) {
        snprintf(buf, sizeof buf, "%.*e", prec - 1, v);
        if (strtod(buf, NULL) == v || prec == 17)
            break;
    }
    int n = 0;
    const char *p = buf;
    for (; *p && *p != 'e'; p++)
        if (*p >= '0' && *p <= '9')
            digits[n++] = *p;
    *x = *p == 'e' ? atoi(p + 1) : 0;
    return n;
}

/* The same exactly in 128 bits, v = m 2^e > 0 normal; 0 when v is outside
 * the range it covers. */
static int digits_by_integers(uint64_t m, int e, int lower_closer, char digits[20], int *x)
{
    int ebin = e + 52;  /* v in [2^ebin, 2^(ebin + 1)) */
    /* est <= floor(ebin log10 2), so 10^est <= v: 315653 / 2^20 is below
       log10 2, 315654 / 2^20 above (one less at most near an integer: v 10^p
       then has 18 digits, still exact) */
    int est = ebin >= 0 ? (ebin * 315653) >> 20 : -((-ebin * 315654 + (1 << 20) - 1) >> 20);
    int p = 16 - est, s = 2 - e - p;
    if (p < 0 || p > MAX_P || s < 0 || s >= 190)
        return 0;
    u192 vv = mul_pow5(4 * m, p), lo = mul_pow5(4 * m - (lower_closer ? 1 : 2), p),
         hi = mul_pow5(4 * m + 2, p);
    int inclusive = (m & 1) == 0;  /* the midpoints read back as v when m is even */
    uint64_t a = shift_down(&lo, s), b = shift_down(&hi, s);
    if (!inclusive || low_bits(&lo, s))
        a++;  /* the least integer in (or on) the interval */
    if (!inclusive && !low_bits(&hi, s))
        b--;  /* the greatest */
    /* drop digits while a c stays in [a, b] (ceil and floor of the bounds
       over 10^t; constant divisions), and round v 10^p over 10^t: the last
       digit dropped and whether anything below it (or v's fraction) is not 0 */
    uint64_t c = shift_down(&vv, s);
    int t = 0, last = -1, sticky = low_bits(&vv, s);
    while (a / 10 + (a % 10 != 0) <= b / 10) {
        a = a / 10 + (a % 10 != 0), b /= 10;
        sticky |= last > 0;
        last = (int)(c % 10);
        c /= 10;
        t++;
    }
    int up;
    if (last < 0)  /* nothing dropped: v's binary fraction decides */
        up = s > 0 && bit_at(&vv, s - 1) && (low_bits(&vv, s - 1) || (c & 1));
    else
        up = last > 5 || (last == 5 && (sticky || (c & 1)));  /* a tie: to the even c */
    c += (uint64_t)up;
    if (c < a)  /* the nearest outside the interval: its end */
        c = a;
    if (c > b)
        c = b;
    static const char pairs[201] =
        "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
        "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
        "8081828384858687888990919293949596979899";
    int n = ndigits(c), i = n;
    for (; i >= 2; i -= 2, c /= 100)
        memcpy(digits + i - 2, pairs + 2 * (c % 100), 2);
    if (i == 1)
        digits[0] = (char)('0' + c);
    *x = n - 1 + t - p;
    return n;
}

static int word(char *out, const char *w)
{
    size_t n = strlen(w);
    memcpy(out, w, n + 1);
    return (int)n;
}

int fmt_double(double v, char out[FMT_DOUBLE_MAX])
{
    int neg = signbit(v) != 0;
    if (isnan(v))  /* as printf writes them */
        return word(out, neg ? "-nan" : "nan");
    if (isinf(v))
        return word(out, neg ? "-inf" : "inf");
    if (v == 0)
        return word(out, neg ? "-0" : "0");
    double a = fabs(v);
    uint64_t bits;
    memcpy(&bits, &a, sizeof bits);
    int be = (int)(bits >> 52);
    uint64_t frac = bits & ((1ull << 52) - 1);
    char digits[20];
    int x = 0, n = 0;
    if (be > 0)  /* normal */
        n = digits_by_integers(frac | (1ull << 52), be - 1075, frac == 0 && be > 1, digits, &x);
    if (n == 0)
        n = digits_by_printf(a, digits, &x);
    return layout(out, neg, digits, n, x);
}

int fmt_double_printf(double v, char out[FMT_DOUBLE_MAX])
{
    char digits[20];
    int x;
    if (!isfinite(v) || v == 0)
        return fmt_double(v, out);
    int n = digits_by_printf(fabs(v), digits, &x);
    return layout(out, signbit(v) != 0, digits, n, x);
}
