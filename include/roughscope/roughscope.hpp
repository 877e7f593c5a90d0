// Umbrella header: the whole public API of the roughscope library, every public header of every
// topic (docs/architecture.md; tests/python/test_architecture.py checks that none is missing).
// Link roughscope::roughscope. The version macros are in the generated <roughscope/version.hpp>.
#pragma once

// core: errors and argument checks, the enum-name scheme, numbers, memory limit, parallel loops,
// response curves
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/parallel.hpp"
#include "roughscope/core/response.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/core/uncertainty.hpp"

// io: the CSV reader, input-file checks, atomic output files, the reference-data locator
#include "roughscope/io/csv.hpp"
#include "roughscope/io/data_locator.hpp"
#include "roughscope/io/input_file.hpp"
#include "roughscope/io/output_file.hpp"

// scattering: geometry, factors, B-K (Eq. 1-5), retro forms, validity, comparison models, batch
// kernel
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/brightness_batch.hpp"
#include "roughscope/scattering/correlation.hpp"
#include "roughscope/scattering/factors.hpp"
#include "roughscope/scattering/geometry.hpp"
#include "roughscope/scattering/precomputed_terms.hpp"
#include "roughscope/scattering/reflectance_models.hpp"
#include "roughscope/scattering/retro.hpp"
#include "roughscope/scattering/validity.hpp"

// estimation: the closed forms of §4, the two-geometry solver, uncertainty
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/estimation/propagation.hpp"

// fit: the least-squares engine and the roughness fits
#include "roughscope/fit/engine.hpp"
#include "roughscope/fit/fit.hpp"

// brdf: BRDF tables, CUReT, the model comparison
#include "roughscope/brdf/comparison.hpp"
#include "roughscope/brdf/curet.hpp"
#include "roughscope/brdf/table.hpp"

// surface: height maps, their files, statistics, generated surfaces, predictions
#include "roughscope/surface/formats.hpp"
#include "roughscope/surface/generate.hpp"
#include "roughscope/surface/height_map.hpp"
#include "roughscope/surface/predict.hpp"
#include "roughscope/surface/spectral.hpp"
#include "roughscope/surface/statistics.hpp"

// simulation: numerical Kirchhoff scattering and synthetic camera captures (ground truth)
#include "roughscope/simulation/capture.hpp"
#include "roughscope/simulation/kirchhoff.hpp"

// photo: photographs on a linear scale (decoders, metadata, radiometry, HDR)
#include "roughscope/photo/hdr.hpp"
#include "roughscope/photo/image.hpp"
#include "roughscope/photo/radiometry.hpp"
#include "roughscope/photo/read.hpp"

// region: regions of a photograph, their statistics, the highlight
#include "roughscope/region/region.hpp"
#include "roughscope/region/specular.hpp"
#include "roughscope/region/statistics.hpp"

// maps: registration, per-pixel and per-tile roughness maps, map files
#include "roughscope/maps/map_files.hpp"
#include "roughscope/maps/maps.hpp"
#include "roughscope/maps/registration.hpp"

// objects: curved objects of known shape (silhouette, cylinder, sphere), the mirror sphere's light
#include "roughscope/objects/cylinder.hpp"
#include "roughscope/objects/mirror_sphere.hpp"
#include "roughscope/objects/photometric_stereo.hpp"
#include "roughscope/objects/silhouette.hpp"
#include "roughscope/objects/sphere.hpp"

// measure: the capture file and the measurement
#include "roughscope/measure/budget.hpp"
#include "roughscope/measure/exact_series.hpp"
#include "roughscope/measure/finite_distance.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/measure/photometric_regions.hpp"
#include "roughscope/measure/plan.hpp"

// serialize: every result type to JSON, CSV, Markdown and text
#include "roughscope/serialize/calibration.hpp"
#include "roughscope/serialize/capture.hpp"
#include "roughscope/serialize/comparison.hpp"
#include "roughscope/serialize/estimation.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/measure.hpp"
#include "roughscope/serialize/model.hpp"
#include "roughscope/serialize/paper_tables.hpp"
#include "roughscope/serialize/photometric_stereo.hpp"
#include "roughscope/serialize/plan.hpp"
#include "roughscope/serialize/simulation.hpp"
#include "roughscope/serialize/surface.hpp"
#include "roughscope/serialize/text.hpp"
