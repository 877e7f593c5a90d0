// Pieces of the pybind11 module roughscope._core; module.cpp calls every bind_* function.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "roughscope/photo/image.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/surface/height_map.hpp"

namespace roughscope::python {

// python/bind_core.cpp: named choices, reference data, geometry (§2), v, g and F (§3.1–3.2)
void bind_names_and_shared_data(pybind11::module_& m);
void bind_geometry(pybind11::module_& m);
void bind_scattering_vector(pybind11::module_& m);
// python/bind_power.cpp: the mean scattered power (Eq. 1–5), series sums and diffuse terms
void bind_mean_scattered_power(pybind11::module_& m);
void bind_diffuse_terms(pybind11::module_& m);
// python/bind_models.cpp: retro-scattering forms (Eq. 7–11), validity, comparison models (§5)
void bind_retro_and_validity(pybind11::module_& m);
void bind_reflectance_models(pybind11::module_& m);
// python/bind_estimation.cpp: the paper's tables recomputed, §4 estimators, fits
void bind_paper_tables(pybind11::module_& m);
void bind_closed_form_estimators(pybind11::module_& m);
void bind_two_geometry_solvers(pybind11::module_& m);
void bind_estimates(pybind11::module_& m);
void bind_fits(pybind11::module_& m);
// python/bind_curet.cpp: the CUReT database, BRDF tables and their comparison with the models
void bind_curet_database(pybind11::module_& m);
void bind_brdf_tables(pybind11::module_& m);
// python/bind_surface.cpp: height files; statistics, generation and prediction (§3.1)
void bind_height_files(pybind11::module_& m);
void bind_surface_analysis(pybind11::module_& m);
void bind_simulation(pybind11::module_& m);   // python/bind_simulation.cpp: Kirchhoff Monte Carlo
void bind_capture(pybind11::module_& m);      // python/bind_capture.cpp: synthetic captures
void bind_image(pybind11::module_& m);        // python/bind_image.cpp: photographs to roughness
void bind_calibration(pybind11::module_& m);  // python/bind_calibration.cpp: the light's direction
void bind_plan(pybind11::module_& m);         // python/bind_plan.cpp: the light angles to choose
// python/bind_photometric.cpp: normals and albedo from photographs under several lights
void bind_photometric_stereo(pybind11::module_& m);
void bind_report(pybind11::module_& m);     // python/bind_report.cpp: what the report draws
void bind_documents(pybind11::module_& m);  // python/bind_documents.cpp: text and documents

// Results cross into Python as real objects, built from the library's serializer
// (roughscope/serialize): objects → dict (key order kept), arrays → list, numbers → int/float,
// null → None. Defined in module.cpp.
pybind11::object to_python(const serialize::Json& value);

// ---- Photographs as arguments (python/bind_calibration.cpp) --------------------------------
// An image on a linear scale from an array — (height, width), or (channels, height, width), or
// with `channels_last` (height, width, channels) — and its flags ((height, width) uint8, or None).
image::LinearImage image_from_array(pybind11::handle values, pybind11::handle flags,
                                    bool channels_last);
// A path (str or os.PathLike: read with `read`), read_image's dict, or an array as above.
image::LinearImage image_argument(pybind11::handle image, const image::ReadOptions& read,
                                  bool channels_last);

// ---- Strict numeric input (docs/python.md, "Types") ---------------------------------------
// A numeric argument accepts a Python int or float, a NumPy integer or floating scalar, an
// ndarray of integer or floating dtype, or a (nested) sequence of such numbers. Anything else —
// bool and NumPy bool, str, bytes, complex (whose imaginary part would be dropped), datetime64,
// timedelta64, object arrays, None where a number is required — raises TypeError naming the
// argument and saying what is accepted. A float64 ndarray passes through without a copy.

// `value` checked: itself (an ndarray of integer or floating dtype, an int, a float) or its NumPy
// array (NumPy scalars, sequences), ready for py::array_t<double>::ensure; TypeError otherwise.
pybind11::object real_array(const char* name, pybind11::handle value);
// `value` as a double: a real number or a 0-d/size-1 real array; TypeError for a non-real type,
// InvalidArgument for an array of another size.
double real_scalar(const char* name, pybind11::handle value);
// None → std::nullopt, else real_scalar.
std::optional<double> optional_real(const char* name, pybind11::handle value);
// A Python or NumPy integer (not bool, not float); TypeError otherwise.
long long integer_scalar(const char* name, pybind11::handle value);
// A Python int for a message: its digits, or its size in bits when it is too long to show (Python
// refuses to convert an int of more than 4300 digits to text).
std::string int_text(pybind11::handle value);
// `path` unchanged, or ValueError "<name>: embedded null byte" as Python's open() raises (the C
// library would read the name only up to the NUL: another file).
std::string path_argument(const char* name, const std::string& path);
// Checks an option value that must be a real number (or, with `pair`, a pair of real numbers) —
// or None when `none_allowed` (None: "not given") — before it becomes JSON: TypeError otherwise.
// Returns the value as float (list of floats).
pybind11::object real_option(const char* name, pybind11::object value, bool pair = false,
                             bool none_allowed = true);
// A HeightMap from a 1-D (profile) or 2-D (ny, nx) real array of heights in µm and the spacings
// dx_um, dy_um (None = dx_um); non-finite heights become missing points (bind_surface.cpp).
surface::HeightMap height_map_from(pybind11::handle heights, pybind11::handle dx,
                                   pybind11::handle dy);

// Geometries from three angle arguments in degrees (each a real number or array; broadcast
// together, then flattened): TypeError for non-real input, InvalidArgument for shapes that do
// not broadcast or an angle out of range (make_geometry). module.cpp.
std::vector<Geometry> broadcast_geometries(pybind11::handle theta_i_deg,
                                           pybind11::handle theta_s_deg,
                                           pybind11::handle phi_s_deg);

// Throws MemoryError (checked before allocating) when `elements` float64 values, `arrays` times,
// exceed what this machine can hold; `what` describes the shape.
void check_allocation(double elements, int arrays, const std::string& what);

// Named options from Python (a dict or keyword arguments, values None/bool/int/float/str or
// sequences of them) → JSON for the library's *_options_from functions. numpy scalars and
// arrays are accepted (via tolist()). TypeError for anything else (complex, bytes, objects).
serialize::Json from_python(pybind11::handle value, const std::string& where = "option");

}  // namespace roughscope::python
