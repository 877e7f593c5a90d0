// roughscope._core: text for people from the library's one formatter — format_uncertain,
// "value ± error" (core/uncertainty.hpp), the same text as the CLI's reports.
#include <optional>
#include <string>

#include <pybind11/pybind11.h>

#include "bindings.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/uncertainty.hpp"

namespace py = pybind11;

namespace roughscope::python {

void bind_documents(py::module_& m) {
    m.def(
        "format_uncertain",
        [](py::handle value, py::handle std_error, py::handle digits) {
            const double v = real_scalar("value", value);
            check::finite("value", v);
            const std::optional<double> e = optional_real("std_error", std_error);
            const long long d = integer_scalar("digits", digits);
            if (d < 1 || d > 17)
                throw InvalidArgument("digits = " + std::to_string(d) +
                                      " is outside the valid range [1, 17]");
            return format_uncertain(v, e, static_cast<int>(d), "value");
        },
        py::arg("value"), py::arg("std_error") = py::none(), py::arg("digits") = 4,
        "'value ± error' as people read it: the error with 2 significant digits, the value to "
        "the same decimal place (0.29991 ± 0.00025); without a usable error (None, 0, "
        "negative, NaN) the value alone with `digits` significant digits. InvalidArgument for a "
        "NaN or infinite value.");
}

}  // namespace roughscope::python
