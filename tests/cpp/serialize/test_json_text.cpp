// The JSON text of serialize::dump and serialize::write_number (roughscope/serialize/json.hpp):
// every double is written with digits that parse back to the same bits, never more digits than
// nlohmann's own formatter (Grisu2) gives and in its layout, and dump() writes nlohmann's
// dump(indent) bytes for every document whose doubles both formatters spell alike.
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "roughscope/serialize/json.hpp"

using namespace roughscope;
using serialize::Json;

namespace {

std::string text_of(double value) {
    char buffer[serialize::kNumberBufferSize];
    return {buffer, serialize::write_number(buffer, value)};
}

// nlohmann's number text, as its dump() writes a double.
std::string nlohmann_text(double value) {
    char buffer[64];
    return {buffer, nlohmann::detail::to_chars(buffer, buffer + sizeof buffer, value)};
}

// The significant digits of a number text (no sign, point, exponent or leading/trailing zeros
// of the layout): "0.00120" and "1.2e-03" both give "12".
std::string significant_digits(std::string_view text) {
    std::string digits;
    for (char c : text) {
        if (c == 'e') break;
        if (c >= '0' && c <= '9') digits += c;
    }
    const auto first = digits.find_first_not_of('0');
    if (first == std::string::npos) return "0";
    digits.erase(0, first);
    while (digits.size() > 1 && digits.back() == '0') digits.pop_back();
    return digits;
}

// Doubles from every corner of the format: special values, subnormals, integers up to 2^53,
// the ends of the decimal layout (1e-5 / 1e-4 and 1e15 / 1e16 and their neighbours), numbers
// with few digits, and random bit patterns.
std::vector<double> test_values() {
    const double min_normal = std::numeric_limits<double>::min();
    const double max = std::numeric_limits<double>::max();
    const double denorm_min = std::numeric_limits<double>::denorm_min();
    std::vector<double> values = {0.0,
                                  1.0,
                                  0.1,
                                  0.5,
                                  1.0 / 3.0,
                                  2.0 / 3.0,
                                  0.30000000000000004,
                                  29.999999999999996,
                                  123456789.123456789,
                                  max,
                                  min_normal,
                                  denorm_min,
                                  2 * denorm_min,
                                  std::nextafter(min_normal, 0.0),
                                  std::nextafter(max, 0.0),
                                  9007199254740992.0,  // 2^53
                                  9007199254740991.0,
                                  4503599627370496.5,
                                  5e-324,
                                  1.7976931348623157e308,
                                  2.2250738585072014e-308,
                                  123456789012345.0,
                                  1234567890123456.0,
                                  999999999999999.9,
                                  0.00009999999999999999};
    for (int e = -8; e <= 18; ++e) {
        const double p = std::pow(10.0, e);
        for (double v : {p, std::nextafter(p, 0.0), std::nextafter(p, 1e300), 1.5 * p, 9.5 * p,
                         1.2345678901234567 * p})
            values.push_back(v);
    }
    for (std::int64_t n = 1; n <= (std::int64_t{1} << 53); n = n * 3 + 1)
        values.push_back(static_cast<double>(n));
    std::mt19937_64 rng(20261204);
    for (int k = 0; k < 200000; ++k) {
        const double v = std::bit_cast<double>(rng());
        if (std::isfinite(v)) values.push_back(v);
    }
    std::uniform_int_distribution<int> digits(1, 17);
    std::uniform_int_distribution<int> exponent(-30, 30);
    for (int k = 0; k < 20000; ++k) {
        // Decimals with few digits (as read from a file), whose shortest text is short.
        const int d = digits(rng);
        const auto mantissa =
            static_cast<double>(rng() % static_cast<std::uint64_t>(std::pow(10.0, d)));
        values.push_back(mantissa * std::pow(10.0, exponent(rng)));
    }
    const std::size_t positive = values.size();
    for (std::size_t k = 0; k < positive; ++k) values.push_back(-values[k]);
    return values;
}

TEST(SerializeJsonText, NumbersParseBackToTheSameBits) {
    for (double v : test_values()) {
        const std::string text = text_of(v);
        ASSERT_LE(text.size(), serialize::kNumberBufferSize);
        char* end = nullptr;
        const double back = std::strtod(text.c_str(), &end);
        ASSERT_EQ(end, text.c_str() + text.size()) << text;
        ASSERT_EQ(std::bit_cast<std::uint64_t>(back), std::bit_cast<std::uint64_t>(v)) << text;
        // A JSON parser reads it too (no "inf", no bare "1.").
        ASSERT_EQ(Json::parse(text).get<double>(), v) << text;
    }
}

TEST(SerializeJsonText, DigitsAreTheShortestOfStdToChars) {
    // The digits and the decimal exponent of std::to_chars's shortest scientific text (the
    // fewest digits that read back, the closest of them when several do), also where a decimal
    // of at most 15 digits is found by the scaling shortcut.
    for (double v : test_values()) {
        if (v == 0.0) continue;
        char scientific[64];
        const char* const end = std::to_chars(scientific, scientific + sizeof scientific, v,
                                              std::chars_format::scientific)
                                    .ptr;
        const std::string reference(scientific, static_cast<std::size_t>(end - scientific));
        const std::string ours = text_of(v);
        ASSERT_EQ(significant_digits(ours), significant_digits(reference))
            << ours << " vs " << reference;
        // Same digits and the same value: the same decimal exponent.
        ASSERT_EQ(std::strtod(ours.c_str(), nullptr), std::strtod(reference.c_str(), nullptr));
    }
}

TEST(SerializeJsonText, NeverMoreDigitsThanNlohmannAndItsLayoutWhenTheDigitsAgree) {
    std::size_t same = 0, shorter = 0;
    for (double v : test_values()) {
        const std::string ours = text_of(v);
        const std::string theirs = nlohmann_text(v);
        const std::string our_digits = significant_digits(ours);
        const std::string their_digits = significant_digits(theirs);
        ASSERT_LE(our_digits.size(), their_digits.size()) << ours << " vs " << theirs;
        if (our_digits == their_digits) {
            ASSERT_EQ(ours, theirs);
            ++same;
        } else {
            ++shorter;
        }
    }
    // Grisu2 is shortest for nearly every double; the test would mean little otherwise.
    EXPECT_GT(same, 100 * shorter);
}

TEST(SerializeJsonText, NumberLayout) {
    // nlohmann's rules: decimal while the point is within 15 digits of the first digit, a zero
    // before the point down to 1e-4, ".0" on integral values, two exponent digits at least.
    EXPECT_EQ(text_of(0.0), "0.0");
    EXPECT_EQ(text_of(-0.0), "-0.0");
    EXPECT_EQ(text_of(1.0), "1.0");
    EXPECT_EQ(text_of(-2.5), "-2.5");
    EXPECT_EQ(text_of(30.0), "30.0");
    EXPECT_EQ(text_of(0.1), "0.1");
    EXPECT_EQ(text_of(1e-4), "0.0001");
    EXPECT_EQ(text_of(1.5e-4), "0.00015");
    EXPECT_EQ(text_of(1e-5), "1e-05");
    EXPECT_EQ(text_of(-1.25e-5), "-1.25e-05");
    EXPECT_EQ(text_of(123456789012345.0), "123456789012345.0");
    EXPECT_EQ(text_of(999999999999999.9), "999999999999999.9");
    EXPECT_EQ(text_of(1e15), "1e+15");
    EXPECT_EQ(text_of(1.5e15), "1.5e+15");
    EXPECT_EQ(text_of(1e100), "1e+100");
    EXPECT_EQ(text_of(9007199254740992.0), "9.007199254740992e+15");
    EXPECT_EQ(text_of(std::numeric_limits<double>::max()), "1.7976931348623157e+308");
    EXPECT_EQ(text_of(std::numeric_limits<double>::denorm_min()), "5e-324");
    EXPECT_EQ(text_of(0.30000000000000004), "0.30000000000000004");
    EXPECT_EQ(text_of(std::numeric_limits<double>::quiet_NaN()), "null");
    EXPECT_EQ(text_of(std::numeric_limits<double>::infinity()), "null");
    EXPECT_EQ(text_of(-std::numeric_limits<double>::infinity()), "null");
}

TEST(SerializeJsonText, ShortestWhereGrisu2IsNot) {
    // Grisu2 does not always find the shortest digits (about one double in a thousand gets a
    // digit too many) nor, among 17-digit texts, always the closest one: find such doubles among
    // random bit patterns and check that our text is the shortest that parses back.
    std::mt19937_64 rng(7);
    int differing = 0, shorter = 0;
    for (int k = 0; k < 2000000 && shorter < 20; ++k) {
        const double v = std::bit_cast<double>(rng() >> 2);  // positive, finite
        const std::string ours = text_of(v);
        const std::string theirs = nlohmann_text(v);
        const std::string digits = significant_digits(ours);
        if (digits == significant_digits(theirs)) continue;
        ++differing;
        ASSERT_EQ(std::strtod(ours.c_str(), nullptr), v) << ours;
        ASSERT_EQ(std::strtod(theirs.c_str(), nullptr), v) << theirs;
        ASSERT_LE(digits.size(), significant_digits(theirs).size()) << ours << " vs " << theirs;
        if (digits.size() == significant_digits(theirs).size()) continue;
        ++shorter;
        // One digit fewer does not round-trip: the closest such text ("%.*e") does not.
        ASSERT_GT(digits.size(), 1u);
        char fewer[64];
        std::snprintf(fewer, sizeof fewer, "%.*e", static_cast<int>(digits.size()) - 2, v);
        EXPECT_NE(std::strtod(fewer, nullptr), v) << fewer << " for " << ours;
    }
    EXPECT_GT(shorter, 0) << "no double where Grisu2 is longer: the check above did not run ("
                          << differing << " differing in the last digit)";
}

// A document of every JSON type, nested, with doubles that both formatters spell alike.
Json nested_document() {
    Json doc = Json::object();
    doc["roughscope_version"] = "0.2.0";
    doc["null"] = nullptr;
    doc["true"] = true;
    doc["false"] = false;
    doc["integer"] = -42;
    doc["unsigned"] = std::uint64_t{18446744073709551615u};
    doc["int64_min"] = std::numeric_limits<std::int64_t>::min();
    doc["doubles"] = Json::array({0.0, -0.0, 1.0, 0.1, 1e-5, 1e15, 123.456, -2.5e-300, 1e300,
                                  0.30000000000000004, 54.735610317245346});
    doc["nan"] = std::numeric_limits<double>::quiet_NaN();
    doc["empty_array"] = Json::array();
    doc["empty_object"] = Json::object();
    doc["nested"] = {{"a", Json::array({Json::array(), Json::object(), Json::array({1, 2})})},
                     {"b", {{"c", {{"d", "deep"}}}}}};
    doc["escapes"] = "quote \" backslash \\ newline \n tab \t control \x01 del \x7f";
    doc["utf8"] = "\xc2\xb5m, \xe2\x80\x93, \xf0\x9f\x98\x80";
    doc["invalid utf8"] = std::string("bad \xff\xfe byte \xc3");
    doc["key \"quoted\"\n"] = 1.5;
    doc["records"] = Json::array();
    for (int k = 0; k < 3; ++k) doc["records"].push_back({{"k", k}, {"x", 0.25 * k}});
    return doc;
}

TEST(SerializeJsonText, DumpIsNlohmannsDumpForDocumentsWithoutDisagreeingDoubles) {
    const Json doc = nested_document();
    for (int indent : {-1, 0, 1, 2, 4}) {
        const std::string expected =
            doc.dump(indent, ' ', false, Json::error_handler_t::replace) + "\n";
        EXPECT_EQ(serialize::dump(doc, indent), expected) << indent;
    }
    // Scalars and empty containers at the top level.
    for (const Json& value : {Json(nullptr), Json(true), Json(7), Json(2.5), Json("s"),
                              Json::array(), Json::object(), Json::array({Json::object()})}) {
        EXPECT_EQ(serialize::dump(value), value.dump(2) + "\n");
        EXPECT_EQ(serialize::dump(value, -1), value.dump() + "\n");
    }
    // Binary values are left to nlohmann, indented to their depth.
    Json with_binary = {{"outer", {{"bytes", Json::binary({1, 2, 3}, 9)}}}};
    EXPECT_EQ(serialize::dump(with_binary), with_binary.dump(2) + "\n");
}

TEST(SerializeJsonText, DumpOfRandomDoublesIsNlohmannsWhereGrisu2IsShortest) {
    std::mt19937_64 rng(99);
    Json doc = Json::object();
    Json& list = doc["values"] = Json::array();
    std::size_t kept = 0;
    while (kept < 5000) {
        const double v = std::bit_cast<double>(rng());
        if (!std::isfinite(v) ||
            significant_digits(text_of(v)) != significant_digits(nlohmann_text(v)))
            continue;
        list.push_back({{"v", v}, {"w", Json::array({v, -v})}});
        ++kept;
    }
    EXPECT_EQ(serialize::dump(doc), doc.dump(2, ' ', false, Json::error_handler_t::replace) + "\n");
    EXPECT_EQ(serialize::dump(doc, -1),
              doc.dump(-1, ' ', false, Json::error_handler_t::replace) + "\n");
}

TEST(SerializeJsonText, DumpWritesEachDoubleAsWriteNumber) {
    const double v = 5e-324;
    std::string expected = "[";
    expected += text_of(v);
    expected += ',';
    expected += text_of(1e21);
    expected += ",-0.0]\n";
    EXPECT_EQ(serialize::dump(Json::array({v, 1e21, -0.0}), -1), expected);
}

}  // namespace
