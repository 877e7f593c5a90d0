// write_significant (roughscope/core/numbers.hpp) against the C library's "%.*g": the same bytes
// for every number class and every precision 1..17 (the CLI prints 10 digits, messages 6, the
// JSON degrees search 1..17).
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"

using namespace roughscope;

namespace {

std::string via_snprintf(double value, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    return buf;
}

std::string via_write(double value, int digits) {
    char buf[kSignificantBufferSize];
    return std::string(buf, write_significant(buf, value, digits));
}

double from_bits(std::uint64_t bits) {
    double v = 0.0;
    std::memcpy(&v, &bits, sizeof v);
    return v;
}

// Values where "%g" switches style, rounds across a power of ten or sits on a decimal tie.
std::vector<double> edge_values() {
    std::vector<double> out = {0.0,
                               -0.0,
                               1.0,
                               -1.0,
                               0.5,
                               0.125,
                               2.5,
                               0.15,
                               0.25,
                               1.5e-5,
                               9.9999999999e-5,
                               1e-4,
                               1e-5,
                               1e-7,
                               0.1,
                               0.555,
                               1e21,
                               1e22,
                               1e23,
                               9.999999999e9,
                               9.9999999995e9,
                               99999.5,
                               999999.5,
                               123456789012345678.0,
                               4503599627370496.5,
                               9007199254740993.0,
                               DBL_MAX,
                               -DBL_MAX,
                               DBL_MIN,
                               std::nextafter(DBL_MIN, 1.0),
                               std::nextafter(DBL_MIN, 0.0),
                               std::numeric_limits<double>::denorm_min(),
                               1.0 / 3.0,
                               2.0 / 3.0,
                               3.141592653589793,
                               2.45598509e-08,
                               2.000005127e-13};
    for (int e = -320; e <= 308; ++e) {
        const double p = std::pow(10.0, e);
        out.push_back(p);
        out.push_back(std::nextafter(p, 0.0));
        out.push_back(std::nextafter(p, DBL_MAX));
        out.push_back(-p);
        out.push_back(5.0 * p);
        out.push_back(9.5 * p);
        out.push_back(1.25 * p);
    }
    for (long long n = -1000; n <= 1000; ++n) out.push_back(static_cast<double>(n));
    for (int b = 0; b < 63; ++b) out.push_back(std::ldexp(1.0, b));
    return out;
}

void expect_same(double v, int digits) {
    ASSERT_EQ(via_write(v, digits), via_snprintf(v, digits)) << "value bits " << std::hex << [&] {
        std::uint64_t bits = 0;
        std::memcpy(&bits, &v, sizeof bits);
        return bits;
    }() << std::dec << ", digits " << digits;
}

}  // namespace

TEST(WriteSignificant, MatchesPrintfOnEdgeValuesAtEveryPrecision) {
    for (const double v : edge_values())
        for (int digits = 1; digits <= 17; ++digits) expect_same(v, digits);
}

TEST(WriteSignificant, MatchesPrintfOnRandomBitPatterns) {
    std::mt19937_64 rng(20260101);
    for (int i = 0; i < 200000; ++i) {
        const double v = from_bits(rng());
        if (!std::isfinite(v)) continue;
        for (const int digits : {1, 3, 6, 10, 15, 16, 17}) expect_same(v, digits);
    }
}

TEST(WriteSignificant, MatchesPrintfOnRandomDecimalsAndSubnormals) {
    // Short decimals (ties after rounding are common among them), subnormals (whose shortest
    // digits are not the rounded ones) and any mantissa between 2^-75 and 2^75.
    std::mt19937_64 rng(7);
    std::uniform_int_distribution<int> mantissa(0, 99999999), exponent(-30, 30);
    std::uniform_int_distribution<std::uint64_t> subnormal(1, (std::uint64_t{1} << 52) - 1);
    for (int i = 0; i < 100000; ++i) {
        const double d = mantissa(rng) * std::pow(10.0, exponent(rng));
        const double s = from_bits(subnormal(rng));
        // Any bits in the range where one exact power of ten scales to the digits (10^±22).
        const double r = std::ldexp(from_bits(0x3ff0000000000000 | (rng() >> 12)),
                                    static_cast<int>(rng() % 150) - 75);
        for (int digits = 1; digits <= 17; ++digits) {
            expect_same(d, digits);
            expect_same(-s, digits);
            expect_same(r, digits);
        }
    }
}

TEST(WriteSignificant, OneDecompositionWritesEveryPrecisionAsPrintf) {
    // SignificantDigits finds the shortest digits once and rounds them for each precision (the
    // degrees echo of serialize::degrees tries 1, 2, ... digits): printf's bytes at each.
    std::mt19937_64 rng(31);
    std::vector<double> values = edge_values();
    std::uniform_int_distribution<int> decimals(0, 99999999), places(0, 14);
    for (int i = 0; i < 20000; ++i) {
        const double v = from_bits(rng());
        if (std::isfinite(v)) values.push_back(v);
        // Where the digits come from one exact scaling (to 12 digits): short decimals, whose
        // roundings tie, and any mantissa between 2^-75 and 2^75.
        values.push_back(decimals(rng) / std::pow(10.0, places(rng)));
        values.push_back(std::ldexp(from_bits(0x3ff0000000000000 | (rng() >> 12)),
                                    static_cast<int>(rng() % 150) - 75));
    }
    for (const double v : values) {
        const SignificantDigits sd(v);
        for (int digits = 1; digits <= 17; ++digits) {
            char buf[kSignificantBufferSize];
            const std::string text(buf, sd.write(buf, digits));
            ASSERT_EQ(text, via_snprintf(v, digits)) << v << " digits " << digits;
        }
    }
}

TEST(WriteSignificant, ParseSignificantIsStrtodOfThePrintedText) {
    // parse_significant(v, d) and SignificantDigits::parsed build the double from the rounded
    // digits without the text:
    // the same bits as strtod of printf's "%.*g" at every precision, for short decimals (the
    // degrees that serialize::degrees echoes), values across the whole exponent range and the
    // edge values (ties, powers of ten, subnormals: the text path).
    std::mt19937_64 rng(47);
    std::vector<double> values = edge_values();
    std::uniform_int_distribution<int> decimals(0, 9999999), places(0, 12), exponent(-30, 30);
    std::uniform_real_distribution<double> mantissa(1.0, 10.0);
    for (int i = 0; i < 20000; ++i) {
        values.push_back(decimals(rng) / std::pow(10.0, places(rng)));
        values.push_back(-mantissa(rng) * std::pow(10.0, exponent(rng)));
        const double v = from_bits(rng());
        if (std::isfinite(v)) values.push_back(v);
    }
    for (const double v : values) {
        for (int digits = 1; digits <= 17; ++digits) {
            const double expected = std::strtod(via_snprintf(v, digits).c_str(), nullptr);
            const double got = parse_significant(v, digits);
            ASSERT_EQ(std::memcmp(&got, &expected, sizeof got), 0)
                << v << " digits " << digits << ": " << got << " vs " << expected;
            const double from_digits = SignificantDigits(v).parsed(digits);
            ASSERT_EQ(std::memcmp(&from_digits, &expected, sizeof got), 0)
                << v << " digits " << digits << ": " << from_digits << " vs " << expected;
        }
    }
}

TEST(WriteSignificant, FormatSignificantUsesItAndStillRefusesNonFinite) {
    EXPECT_EQ(format_significant(2.45598509e-08, 10), "2.45598509e-08");
    EXPECT_EQ(format_significant(-0.0, 10), "0");
    EXPECT_EQ(format_significant(9.99999999995e9, 10), "1e+10");
    EXPECT_THROW(format_significant(std::numeric_limits<double>::quiet_NaN(), 10), Error);
    EXPECT_THROW(format_significant(std::numeric_limits<double>::infinity(), 6), Error);
    EXPECT_THROW(format_significant(1.0, 0), InvalidArgument);
}
