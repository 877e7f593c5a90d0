// The strict number parser and the formatter family (roughscope/core/numbers.hpp).
#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"

using namespace roughscope;

namespace {

std::string reason_for(std::string_view text) {
    std::string reason;
    EXPECT_FALSE(try_parse_number(text, reason).has_value()) << text;
    return reason;
}

std::string message_of(auto&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    ADD_FAILURE() << "no exception";
    return {};
}

}  // namespace

TEST(Numbers, ParsesWholeTextWithSurroundingSpaces) {
    std::string reason;
    EXPECT_EQ(try_parse_number("1.5", reason), 1.5);
    EXPECT_EQ(try_parse_number("  -2e-3\t", reason), -2e-3);
    EXPECT_EQ(try_parse_number("+7", reason), 7.0);
    EXPECT_EQ(try_parse_number("0.1\r\n", reason), 0.1);
    EXPECT_EQ(try_parse_number("1e308", reason), 1e308);
    EXPECT_EQ(parse_number(" 42 ", "x"), 42.0);
}

TEST(Numbers, TrimSpace) {
    EXPECT_EQ(trim_space(" \t 1.5 \r\n"), "1.5");
    EXPECT_EQ(trim_space("   "), "");
    EXPECT_EQ(trim_space("a b"), "a b");
}

TEST(Numbers, RejectsAnythingButOneFiniteNumber) {
    EXPECT_EQ(reason_for(""), "empty (a number is required)");
    EXPECT_EQ(reason_for("   "), "empty (a number is required)");
    EXPECT_EQ(reason_for("1.5x"), "not a number");
    EXPECT_EQ(reason_for("1 2"), "not a number");
    EXPECT_EQ(reason_for("+"), "not a number");
    EXPECT_EQ(reason_for("++1"), "not a number");
    EXPECT_EQ(reason_for("0x10"), "not a number");
    EXPECT_EQ(reason_for("1,5"), "not a number");
    EXPECT_EQ(reason_for("nan"), "not a finite number (NaN is not accepted)");
    EXPECT_EQ(reason_for("-inf"), "not a finite number (infinity is not accepted)");
    EXPECT_EQ(reason_for("1e999"), "out of the range of double-precision numbers");
}

TEST(Numbers, ParseNumberThrowsNamingTheInput) {
    const std::string m = message_of([] { parse_number(" 1.5x ", "--sigma"); });
    EXPECT_EQ(m, "--sigma: '1.5x' is not a number");
    EXPECT_THROW(parse_number("inf", "x"), InvalidArgument);
}

TEST(Numbers, ParseNumberList) {
    EXPECT_EQ(parse_number_list("1, 2,3", 3, "--n"), (std::vector<double>{1, 2, 3}));
    EXPECT_EQ(message_of([] { parse_number_list("1,2", 3, "--n"); }),
              "--n: expected 3 comma-separated numbers, got '1,2'");
    EXPECT_EQ(message_of([] { parse_number_list("1,x,3", 3, "--n"); }),
              "--n (item 2): 'x' is not a number");
}

TEST(Numbers, RoundTripIsShortestAndExact) {
    for (double v : {0.1, 1.0 / 3.0, 1e-300, -2.5e17, 123456.789, 0.0}) {
        const std::string s = format_roundtrip(v);
        std::string reason;
        EXPECT_EQ(try_parse_number(s, reason), v) << s;
    }
    EXPECT_EQ(format_roundtrip(0.1), "0.1");
    EXPECT_EQ(format_roundtrip(90.0), "90");
}

TEST(Numbers, RoundTripAndSignificantRefuseNonFinite) {
    EXPECT_THROW(format_roundtrip(std::nan("")), Error);
    EXPECT_THROW(format_significant(std::numeric_limits<double>::infinity(), 6), Error);
    EXPECT_NE(message_of([] { format_significant(std::nan(""), 6, "sigma"); }).find("sigma"),
              std::string::npos);
    EXPECT_THROW(format_significant(1.0, 0), InvalidArgument);
}

TEST(Numbers, SignificantDigits) {
    EXPECT_EQ(format_significant(1.0 / 3.0, 4), "0.3333");
    EXPECT_EQ(format_significant(123456.0, 3), "1.23e+05");
    EXPECT_EQ(format_significant(-0.0, 10), "0");
    EXPECT_DOUBLE_EQ(round_significant(1.23456789, 3), 1.23);
    EXPECT_TRUE(std::isnan(round_significant(std::nan(""), 3)));
}

TEST(Numbers, MessagesSpellOutNonFinite) {
    EXPECT_EQ(format_message(std::nan("")), "nan");
    EXPECT_EQ(format_message(-std::numeric_limits<double>::infinity()), "-inf");
    EXPECT_EQ(format_message(0.5), "0.5");
    EXPECT_EQ(format_message(1.0 / 3.0, 3), "0.333");
    EXPECT_EQ(check::format_number(0.25), "0.25");  // the message helper of errors.hpp
}

TEST(Numbers, IntegersAreDecimalDigitsOnly) {
    std::string reason;
    EXPECT_EQ(try_parse_integer("25", 1, 61, reason), 25);
    EXPECT_EQ(try_parse_integer(" 25\t", 1, 61, reason), 25);
    EXPECT_EQ(try_parse_integer("+25", 1, 61, reason), 25);
    EXPECT_EQ(try_parse_integer("-3", -5, 5, reason), -3);
}

TEST(Numbers, IntegersRefuseHexFractionsExponentsAndRange) {
    for (const char* text :
         {"0x19", "0X19", "25.0", "2.5e1", "1e3", "", " ", "25x", "+-3", "nan", "inf", "0b11001"}) {
        std::string reason;
        EXPECT_FALSE(try_parse_integer(text, 1, 100, reason).has_value()) << text;
        EXPECT_FALSE(reason.empty()) << text;
    }
    std::string reason;
    EXPECT_FALSE(try_parse_integer("101", 1, 100, reason).has_value());
    EXPECT_EQ(reason, "out of the range [1, 100]");
    EXPECT_FALSE(try_parse_integer("99999999999999999999999", 1, 100, reason).has_value());
    EXPECT_EQ(reason, "out of the range [1, 100]");
    EXPECT_THROW(parse_integer("0x19", 1, 100, "--sample"), InvalidArgument);
    EXPECT_EQ(message_of([] { parse_integer("0x19", 1, 100, "--sample"); }),
              "--sample: '0x19' is not an integer (decimal digits only)");
}

TEST(Numbers, NumbersRefuseDoubleSigns) {
    std::string reason;
    EXPECT_FALSE(try_parse_number("+-3", reason).has_value());
    EXPECT_FALSE(try_parse_number("0x1p3", reason).has_value());
}

TEST(Numbers, MessagesNeverRoundAValueOntoTheLimitItBreaks) {
    // 7 significant digits would print 1.0000001 as "1": "kappa = 1 must exceed 1".
    EXPECT_EQ(format_message(1.00000001, 7), "1.00000001");
    EXPECT_EQ(format_message(0.5, 7), "0.5");
    EXPECT_EQ(format_message(1.0 + 1e-15), "1.000000000000001");
    EXPECT_EQ(format_message(90.0 - 1e-9, 6), "89.999999999");
    EXPECT_EQ(format_message(0.9999999, 6), "0.9999999");
    EXPECT_EQ(format_message(1.0 + 1e-13, 7), "1.0000000000001");
    // Floating-point noise of a unit conversion is not shown: 30 deg through radians.
    EXPECT_EQ(format_message(29.999999999999996, 7), "30");
    EXPECT_EQ(format_message(0.0010000000000000002, 6), "0.001");
    // Rounding to all the digits asked for is kept (it cannot collapse onto a round limit).
    EXPECT_EQ(format_message(1.0250190123, 7), "1.025019");
    EXPECT_EQ(format_message(-2.0 / 3.0, 4), "-0.6667");
    try {
        check::positive("sigma", -5e-324);
        FAIL() << "expected InvalidArgument";
    } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find("-5e-324"), std::string::npos) << e.what();
    }
}
