// Pieces of the pybind11 module roughscope._core; module.cpp calls every bind_* function.
#pragma once

#include <pybind11/pybind11.h>

#include "roughscope/serialize/json.hpp"

namespace roughscope::python {

void bind_core(pybind11::module_& m);        // python/bind_core.cpp: models, geometry (§2–3)
void bind_estimation(pybind11::module_& m);  // python/bind_estimation.cpp: §4 estimators, fits
void bind_curet(pybind11::module_& m);       // python/bind_curet.cpp: CUReT / BRDF tables

// Results cross into Python as real objects, built from the library's serializer
// (roughscope/serialize): objects → dict (key order kept), arrays → list, numbers → int/float,
// null → None. Defined in module.cpp.
pybind11::object to_python(const serialize::Json& value);

// Named options from Python (a dict or keyword arguments, values None/bool/int/float/str or
// sequences of them) → JSON for the library's *_options_from functions. numpy scalars and
// arrays are accepted (via float()/tolist()). InvalidArgument for anything else.
serialize::Json from_python(pybind11::handle value, const std::string& where = "option");

}  // namespace roughscope::python
