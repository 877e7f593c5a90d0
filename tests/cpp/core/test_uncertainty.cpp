// "value ± error" (roughscope/core/uncertainty.hpp): the error's two significant digits decide
// the value's last digit; without a usable error the value alone.
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/uncertainty.hpp"

using namespace roughscope;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(FormatUncertain, TheErrorsTwoDigitsDecideTheValuesDigits) {
    EXPECT_EQ(format_uncertain(0.29991, 0.00025), "0.29991 ± 0.00025");
    EXPECT_EQ(format_uncertain(0.2999123456, 0.000251), "0.29991 ± 0.00025");
    EXPECT_EQ(format_uncertain(0.123456, 0.0095), "0.1235 ± 0.0095");
    EXPECT_EQ(format_uncertain(1234.5678, 12.3), "1235 ± 12");
    EXPECT_EQ(format_uncertain(-3.14159, 0.5), "-3.14 ± 0.50");
    // Trailing zeros are digits the error says are known.
    EXPECT_EQ(format_uncertain(0.3, 0.00025), "0.30000 ± 0.00025");
    // The error rounds up to the next power of ten: the value follows its new place.
    EXPECT_EQ(format_uncertain(0.5, 0.000996), "0.5000 ± 0.0010");
    // The error's digits left of the decimal point: both rounded to that place.
    EXPECT_EQ(format_uncertain(12346.0, 123.0), "12350 ± 120");
    EXPECT_EQ(format_uncertain(96.0, 120.0), "100 ± 120");
    EXPECT_EQ(format_uncertain(1e-20, 3e10), "0 ± 30000000000");
    // A small negative value rounded to zero has no sign.
    EXPECT_EQ(format_uncertain(-0.000001, 0.00025), "0.00000 ± 0.00025");
}

TEST(FormatUncertain, ScientificOutsideTheFixedRange) {
    EXPECT_EQ(format_uncertain(1.5e-7, 2.3e-9), "1.500e-07 ± 2.3e-09");
    // Rounding carries into the next power of ten: still to the error's place.
    EXPECT_EQ(format_uncertain(9.99996e-7, 2.3e-10), "1.00000e-06 ± 2.3e-10");
    EXPECT_EQ(format_uncertain(2.5e16, 3e14), "2.500e+16 ± 3.0e+14");
    EXPECT_EQ(format_uncertain(1e-30, 1e-9), "0 ± 1.0e-09");
}

TEST(FormatUncertain, WithoutAUsableErrorTheValueAlone) {
    EXPECT_EQ(format_uncertain(0.2999123456789, std::nullopt), "0.2999123457");
    EXPECT_EQ(format_uncertain(0.2999123456789, 0.0), "0.2999123457");
    EXPECT_EQ(format_uncertain(0.2999123456789, -1.0), "0.2999123457");
    EXPECT_EQ(format_uncertain(0.2999123456789, kNaN), "0.2999123457");
    EXPECT_EQ(format_uncertain(0.2999123456789, kInf), "0.2999123457");
    EXPECT_EQ(format_uncertain(0.2999123456789, std::nullopt, 4), "0.2999");
    EXPECT_THROW((void)format_uncertain(0.3, 0.1, 0), InvalidArgument);
    EXPECT_THROW((void)format_uncertain(0.3, std::nullopt, 18), InvalidArgument);
}

TEST(FormatUncertain, ANonFiniteValueIsNeverPrinted) {
    for (const double bad : {kNaN, kInf, -kInf}) {
        try {
            (void)format_uncertain(bad, 0.1, 10, "sigma_um");
            FAIL() << "no error for " << bad;
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("sigma_um"), std::string::npos) << e.what();
        }
    }
}

}  // namespace
