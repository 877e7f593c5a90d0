// Pieces of the pybind11 module roughscope._core; module.cpp calls every bind_* function.
#pragma once

#include <pybind11/pybind11.h>

namespace roughscope::python {

void bind_core(pybind11::module_& m);        // python/bind_core.cpp: models, geometry (§2–3)
void bind_estimation(pybind11::module_& m);  // python/bind_estimation.cpp: §4 estimators, fits
void bind_curet(pybind11::module_& m);       // python/bind_curet.cpp: CUReT / BRDF tables

}  // namespace roughscope::python
