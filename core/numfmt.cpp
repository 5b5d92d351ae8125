// numfmt.cpp - the shortest round-trip decimal of a double: Dragonbox (Debian's
// libdragonbox-dev, header-only) finds the shortest digits that read back to the same
// double, and this file lays them out as ECMAScript's Number::toString does, behind a C
// API. Dragonbox rather than double-conversion: about 150 instructions a double against
// 1250 (callgrind, 4 million doubles of a packing), the writers' hot path.
#include <dragonbox/dragonbox.h>

#include <cmath>
#include <cstdint>
#include <cstring>

#include "grainpack/out.h"

namespace {

// ECMAScript's choice between the two notations: plain decimals while the decimal
// exponent n (the value is 0.d1d2... x 10^n) lies in (-6, 21], exponential outside. Every
// JSON, CSV and XML reader parses both.
constexpr int PLAIN_MIN_EXCLUSIVE = -6;
constexpr int PLAIN_MAX = 21;

// "00" to "99": digits are written two at a time.
constexpr char PAIRS[] = "00010203040506070809101112131415161718192021222324252627282930313233343536373839"
                         "40414243444546474849505152535455565758596061626364656667686970717273747576777879"
                         "8081828384858687888990919293949596979899";

constexpr std::uint64_t POW10[20] = {1ull, 10ull, 100ull, 1000ull, 10000ull, 100000ull, 1000000ull,
                                     10000000ull, 100000000ull, 1000000000ull, 10000000000ull,
                                     100000000000ull, 1000000000000ull, 10000000000000ull,
                                     100000000000000ull, 1000000000000000ull, 10000000000000000ull,
                                     100000000000000000ull, 1000000000000000000ull,
                                     10000000000000000000ull};

// The number of decimal digits of v > 0: log10(2) ~ 1233 / 4096 gives it from the bit
// length, off by one at most.
int count_digits(std::uint64_t v)
{
    int bits = 64 - __builtin_clzll(v);
    int k = (bits * 1233) >> 12;
    return k + (v >= POW10[k]);
}

void write_pair(char *p, std::uint32_t pair)
{
    std::memcpy(p, PAIRS + 2 * pair, 2);
}

// Writes exactly 8 digits of v < 10^8 at p[0..7], with 32-bit arithmetic.
void write8(char *p, std::uint32_t v)
{
    std::uint32_t hi = v / 10000, lo = v % 10000;
    write_pair(p, hi / 100);
    write_pair(p + 2, hi % 100);
    write_pair(p + 4, lo / 100);
    write_pair(p + 6, lo % 100);
}

// Writes the k digits of v at out[0..k-1], from the last: eight at a time while more
// than eight remain, then two at a time.
void write_digits(char *out, std::uint64_t v, int k)
{
    char *p = out + k;
    while (k > 8) {
        p -= 8;
        write8(p, static_cast<std::uint32_t>(v % 100000000));
        v /= 100000000;
        k -= 8;
    }
    std::uint32_t w = static_cast<std::uint32_t>(v);
    for (; k >= 2; k -= 2) {
        p -= 2;
        write_pair(p, w % 100);
        w /= 100;
    }
    if (k)
        *--p = static_cast<char>('0' + w);
}

} // namespace

extern "C" size_t gp_fmt_double(char *buf, double x)
{
    char *p = buf;
    if (std::isnan(x)) {
        std::memcpy(buf, "NaN", 4);
        return 3;
    }
    if (std::signbit(x) && x == x) {
        if (x == 0.0) { // ECMAScript writes -0 as 0; we keep the sign so the bits read back
            std::memcpy(buf, "-0", 3);
            return 2;
        }
        *p++ = '-';
        x = -x;
    }
    if (std::isinf(x)) {
        std::memcpy(p, "Infinity", 9);
        return static_cast<size_t>(p - buf) + 8;
    }
    if (x == 0.0) {
        std::memcpy(p, "0", 2);
        return static_cast<size_t>(p - buf) + 1;
    }
    auto dec = jkj::dragonbox::to_decimal(x, jkj::dragonbox::policy::sign::ignore,
                                          jkj::dragonbox::policy::trailing_zero::remove);
    int k = count_digits(dec.significand);
    int n = k + dec.exponent; // x = 0.d1d2...dk x 10^n
    if (k <= n && n <= PLAIN_MAX) { // an integer: the digits, then zeros
        write_digits(p, dec.significand, k);
        std::memset(p + k, '0', static_cast<size_t>(n - k));
        p += n;
    } else if (0 < n && n <= PLAIN_MAX) { // the point inside the digits: d.ddd, dd.ddd...
        write_digits(p + 1, dec.significand, k);
        // shift the integer part left by one; spelled out for the everyday 1 to 3 digits,
        // which a loop (made a memmove call by the compiler) would cost twice as much
        p[0] = p[1];
        if (n > 1) {
            p[1] = p[2];
            if (n > 2) {
                p[2] = p[3];
                for (int i = 3; i < n; i++)
                    p[i] = p[i + 1];
            }
        }
        p[n] = '.';
        p += k + 1;
    } else if (PLAIN_MIN_EXCLUSIVE < n && n <= 0) { // 0.000ddd
        *p++ = '0';
        *p++ = '.';
        for (int i = 0; i < -n; i++)
            *p++ = '0';
        write_digits(p, dec.significand, k);
        p += k;
    } else { // d.ddde+N
        write_digits(p + 1, dec.significand, k);
        p[0] = p[1];
        if (k > 1) {
            p[1] = '.';
            p += k + 1;
        } else {
            p += 1;
        }
        int e = n - 1;
        *p++ = 'e';
        *p++ = e < 0 ? '-' : '+';
        unsigned ae = static_cast<unsigned>(e < 0 ? -e : e);
        int ke = ae >= 100 ? 3 : ae >= 10 ? 2 : 1;
        write_digits(p, ae, ke);
        p += ke;
    }
    *p = '\0';
    return static_cast<size_t>(p - buf);
}
