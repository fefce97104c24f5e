/* tests/unit/test_fmt.c: fmt_double (src/base/fmt.c), the numbers of the
 * result tables, against independent truths: strtod reads every text back
 * as the same double (bit for bit), and the text equals the one built from
 * glibc's correctly rounded %.*e at the fewest digits that read back (the
 * shortest, the nearest of the shortest) on 300 000 values: random bit
 * patterns (every exponent, subnormals), random magnitudes from 1e-48 to
 * 1e22, short decimals, and neighbours of round numbers; and known texts. */
#include <criterion/criterion.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base.h"

static uint64_t state = 88172645463325252ull;

static uint64_t next(void)
{
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
}

static double value(long i)
{
    uint64_t r = next();
    double v, w;
    switch (i % 4) {
    case 0: memcpy(&v, &r, sizeof v); break;  /* any bits: NaNs, infinities, subnormals */
    case 1: v = (double)(r >> 11) * 0x1p-53 * pow(10, (int)(next() % 70) - 48); break;
    case 2: v = (double)(long)(r % 100000) / pow(10, (int)(next() % 9)); break;
    default:  /* a neighbour (-2 .. +2 ulp) of a short decimal */
        v = (double)(long)(r % 1000) / 8.0 * pow(10, (int)(next() % 9) - 4);
        memcpy(&r, &v, sizeof r);
        r += next() % 5 - 2;
        memcpy(&w, &r, sizeof w);
        v = w;
        break;
    }
    return next() & 1 ? -v : v;
}

Test(fmt, reads_back_and_equals_the_shortest_of_printf)
{
    char a[FMT_DOUBLE_MAX], b[FMT_DOUBLE_MAX];
    long bad = 0, fast = 0;
    for (long i = 0; i < 300000; i++) {
        double v = value(i), back;
        int n = fmt_double(v, a);
        fmt_double_printf(v, b);
        back = strtod(a, NULL);
        int same = isnan(v) ? isnan(back) && signbit(back) == signbit(v)
                            : memcmp(&back, &v, sizeof v) == 0;
        if (!same || strcmp(a, b) != 0 || n != (int)strlen(a)) {
            if (bad++ < 5)
                cr_log_error("%.17g: '%s', printf's shortest '%s', reads back as %.17g", v, a, b,
                             back);
        }
        fast += fabs(v) >= 1e-30 && fabs(v) < 1e15;
    }
    cr_assert_eq(bad, 0, "%ld values differ", bad);
    cr_assert_gt(fast, 100000, "the integer path was exercised %ld times", fast);
}

Test(fmt, known_texts)
{
    static const struct {
        double v;
        const char *text;
    } known[] = {
        {0.2, "0.2"}, {0.1 + 0.2, "0.30000000000000004"}, {2.0 / 3.0, "0.6666666666666666"},
        {300, "300"}, {-1.5, "-1.5"}, {1e16, "10000000000000000"}, {1e17, "1e+17"},
        {1e23, "1e+23"}, {5e-5, "5e-05"}, {1e-4, "0.0001"}, {5e-324, "5e-324"},
        {1.7976931348623157e308, "1.7976931348623157e+308"}, {0.0, "0"}, {-0.0, "-0"},
        {9007199254740993.0, "9007199254740992"}, {123456789.125, "123456789.125"},
        {1e-20, "1e-20"}, {4.35e-18, "4.35e-18"}, {INFINITY, "inf"}, {-INFINITY, "-inf"}};
    char out[FMT_DOUBLE_MAX];
    for (size_t i = 0; i < sizeof known / sizeof known[0]; i++) {
        fmt_double(known[i].v, out);
        cr_expect_str_eq(out, known[i].text, "%.17g", known[i].v);
    }
}
