// Printable, bounded message text (roughscope/core/text.hpp) and the errors built on it.
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"

using namespace roughscope;
using namespace std::string_literals;

TEST(PrintableText, EscapesControlCharactersAndKeepsUtf8) {
    EXPECT_EQ(printable_text("a\x1b[31mb"), "a\\x1b[31mb");
    EXPECT_EQ(printable_text("x\0y"s), "x\\x00y");
    EXPECT_EQ(printable_text("t\tn\nr\r\x7f"), "t\\tn\\nr\\r\\x7f");
    EXPECT_EQ(printable_text("\xC2\x9B"
                             "2J"),
              "\\u009b2J");  // C1 CSI
    EXPECT_EQ(printable_text("\xFF\xFE"
                             "a\xC3"),
              "\\xff\\xfea\\xc3");                                 // not UTF-8
    EXPECT_EQ(printable_text("\xED\xA0\x80"), "\\xed\\xa0\\x80");  // a surrogate
    EXPECT_EQ(printable_text("5 \xC2\xB5m, \xCE\xB8 = 30\xC2\xB0"),
              "5 \xC2\xB5m, \xCE\xB8 = 30\xC2\xB0");
    EXPECT_EQ(printable_text("C:\\path \\x1b"), "C:\\path \\x1b");  // backslash kept
}

TEST(PrintableText, IsIdempotent) {
    const std::string raw = "head\x1b]0;title\x07\0tail\xFF"s;
    const std::string once = printable_text(raw);
    EXPECT_EQ(printable_text(once), once);
    EXPECT_EQ(once.find('\0'), std::string::npos);
}

TEST(QuoteInput, CutsLongTextAndSaysHowLongItWas) {
    EXPECT_EQ(quote_input("1.5x"), "'1.5x'");
    const std::string big(10'000'000, '7');
    const std::string q = quote_input(big);
    EXPECT_LT(q.size(), 120u);
    EXPECT_EQ(q, "'" + std::string(kQuoteMaxBytes, '7') + "\xE2\x80\xA6' (10000000 bytes in all)");
    // The cut never splits a UTF-8 sequence.
    std::string theta;
    for (int k = 0; k < 100; ++k) theta += "\xCE\xB8";
    const std::string qt = quote_input(theta, 5);
    EXPECT_EQ(qt, "'\xCE\xB8\xCE\xB8\xE2\x80\xA6' (200 bytes in all)");
}

TEST(ErrorMessages, AreNeverCutByNulNorRawNorUnbounded) {
    const DataError nul("f.csv:1: header 'a\0b'"s);
    EXPECT_STREQ(nul.what(), "f.csv:1: header 'a\\x00b'");
    const InvalidArgument ansi("name '\x1b[2J'");
    EXPECT_STREQ(ansi.what(), "name '\\x1b[2J'");
    const Error huge(std::string(10'000'000, 'x'));
    EXPECT_LT(std::string(huge.what()).size(), kMessageMaxBytes + 40);
    EXPECT_NE(std::string(huge.what()).find("(10000000 bytes in all)"), std::string::npos);
}

TEST(ErrorMessages, ParsersQuoteInputsEscapedAndCut) {
    try {
        parse_number("1\x1b[31m", "--sigma");
        FAIL() << "expected InvalidArgument";
    } catch (const InvalidArgument& e) {
        EXPECT_STREQ(e.what(), "--sigma: '1\\x1b[31m' is not a number");
    }
    try {
        parse_number(std::string(1'000'000, '9') + "x", "cell");
        FAIL() << "expected InvalidArgument";
    } catch (const InvalidArgument& e) {
        EXPECT_LT(std::string(e.what()).size(), 150u) << e.what();
        EXPECT_NE(std::string(e.what()).find("(1000001 bytes in all)"), std::string::npos);
    }
}
