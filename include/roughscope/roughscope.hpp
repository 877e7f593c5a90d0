// Umbrella header: the whole public API of the roughscope library, every public header of every
// topic (docs/architecture.md). Link roughscope::roughscope. The version macros are in the
// generated <roughscope/version.hpp>.
#pragma once

// core: errors and argument checks, the enum-name scheme, number parsing and formatting
#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"

// io: the CSV reader, atomic output files, the reference-data locator
#include "roughscope/io/csv.hpp"
#include "roughscope/io/data_locator.hpp"
#include "roughscope/io/output_file.hpp"

// scattering: geometry, factors, B-K (Eq. 1-5), retro forms, validity, comparison models, batch
// kernel
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/brightness_batch.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/reflectance_models.hpp"
#include "roughscope/scattering/retro.hpp"
#include "roughscope/scattering/validity.hpp"

// estimation: the closed forms of §4, the two-geometry solver, uncertainty
#include "roughscope/estimation/estimation.hpp"

// fit: the least-squares engine and the roughness fits
#include "roughscope/fit/engine.hpp"
#include "roughscope/fit/fit.hpp"

// brdf: BRDF tables, CUReT, the model comparison
#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/curet.hpp"
#include "roughscope/brdf/table.hpp"

// surface: height maps, their files, statistics and generated surfaces
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/generate.hpp"
#include "roughscope/surface/height_map.hpp"
#include "roughscope/surface/spectral.hpp"
#include "roughscope/surface/statistics.hpp"

// simulation: numerical Kirchhoff scattering and synthetic camera captures (ground truth)
#include "roughscope/simulation/capture.hpp"
#include "roughscope/simulation/kirchhoff.hpp"

// image: photographs on a linear scale, regions, the highlight, response curves, measurements
#include "roughscope/image/cylinder.hpp"
#include "roughscope/image/hdr.hpp"
#include "roughscope/image/image.hpp"
#include "roughscope/image/map_files.hpp"
#include "roughscope/image/maps.hpp"
#include "roughscope/image/measure.hpp"
#include "roughscope/image/radiometry.hpp"
#include "roughscope/image/read.hpp"
#include "roughscope/image/region.hpp"
#include "roughscope/image/registration.hpp"
#include "roughscope/image/silhouette.hpp"
#include "roughscope/image/specular.hpp"
#include "roughscope/image/sphere.hpp"
#include "roughscope/image/statistics.hpp"

// serialize: every result type to JSON, CSV and Markdown
#include "roughscope/serialize/comparison.hpp"
#include "roughscope/serialize/estimation.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/measure.hpp"
#include "roughscope/serialize/model.hpp"
#include "roughscope/serialize/paper_tables.hpp"
