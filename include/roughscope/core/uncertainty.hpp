// A value with its standard error as people read it: "0.29991 ± 0.00025". The one formatter of
// "value ± error" for every text output of the library and its front ends (the CLI's reports,
// the Python module's HTML).
//
// The error is shown with kErrorDigits (2) significant digits, and the value to the same decimal
// place (the digits beyond are noise): 0.2999123 ± 0.000251 → "0.29991 ± 0.00025",
// 1234.5678 ± 12.3 → "1235 ± 12", 0.3 ± 0.00025 → "0.30000 ± 0.00025" (trailing zeros kept: they
// are digits the error says are known). Both use fixed notation while the error is within
// [1e-5, 1e15) and the value below 1e15; otherwise scientific, "1.500e-07 ± 2.3e-09". Without a
// usable error (absent, zero, negative, NaN or infinite) the value alone with `digits`
// significant digits ("%.*g", as format_significant).
#pragma once

#include <optional>
#include <string>
#include <string_view>

namespace roughscope {

// Significant digits of a standard error in text.
inline constexpr int kErrorDigits = 2;

// "value ± error" (see above). `digits` (1..17, else InvalidArgument) applies when there is no
// usable error. Throws roughscope::Error naming `name` when the value is NaN or infinite (results
// are never printed as NaN).
std::string format_uncertain(double value, std::optional<double> std_error, int digits = 10,
                             std::string_view name = "value");

}  // namespace roughscope
