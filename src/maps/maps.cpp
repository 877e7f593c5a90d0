// Roughness maps: two photographs → σ/T per pixel or tile (maps/maps.hpp, docs/maps.md): the
// input checks, the bands of rows on worker threads beside the registration, and the summaries
// (classes, regions). The table of the inverse is ratio_table.cpp, the cells map_evaluator.cpp,
// the passes over the rows map_passes.cpp and their loops row_kernels.cpp.
#include "roughscope/maps/maps.hpp"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <exception>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "maps/map_evaluator.hpp"
#include "maps/map_internal.hpp"
#include "roughscope/core/errors.hpp"
#include "roughscope/core/memory.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {

using detail::Accumulator;
using detail::ClassSums;
using detail::clear_rows;
using detail::Counts;
using detail::Evaluator;
using detail::kSumRestartRows;
using detail::lean_pixel_map;
using detail::pixel_map;
using detail::tile_map;

namespace {

constexpr std::size_t kMaxWindowPx = 4096;

struct RegionAccumulator {
    Accumulator gaussian, exponential, T;
    Accumulator log_ratio;  // ln(E1/E2) of the region's tiles/pixels
    std::size_t missing = 0;
    std::array<std::size_t, 3> classes{};
};

}  // namespace

// ---------------------------------------------------------------------------------------------
// Classes

RoughnessClass roughness_class_of_sigma_over_T(double sigma_over_T, double slightly_rough_max,
                                               double very_rough_min) {
    if (sigma_over_T < slightly_rough_max) return RoughnessClass::SlightlyRough;
    if (sigma_over_T > very_rough_min) return RoughnessClass::VeryRough;
    return RoughnessClass::ModeratelyRough;
}

// ---------------------------------------------------------------------------------------------
// roughness_map

namespace {

std::string capture_name(const MapCapture& c, std::size_t k) {
    if (!c.name.empty()) return c.name;
    if (c.image != nullptr && !c.image->info.source.empty()) return c.image->info.source;
    return concat("captures[", std::to_string(k), "]");
}

void check_map_input(const std::vector<MapCapture>& captures, const MapOptions& o) {
    if (captures.size() < 2)
        throw InvalidArgument(concat("roughness map: ", std::to_string(captures.size()),
                                     " capture(s) given; a map needs at least 2 (two light "
                                     "directions)"));
    for (std::size_t k = 0; k < captures.size(); ++k) {
        const MapCapture& c = captures[k];
        const std::string name = concat("roughness map: captures[", std::to_string(k), "]");
        if (c.image == nullptr) throw InvalidArgument(concat(name, ": no image"));
        // The values are checked where they are read (load_row): one pass over the images less.
        check_linear_image_layout(*c.image);
        check::positive(concat(name, ": exposure_scale"), c.exposure_scale);
        const LinearImage& first = *captures[0].image;
        if (c.image->width != first.width || c.image->height != first.height)
            throw InvalidArgument(concat(
                "roughness map: ", capture_name(c, k), " is ", std::to_string(c.image->width),
                " x ", std::to_string(c.image->height), " but ", capture_name(captures[0], 0),
                " is ", std::to_string(first.width), " x ", std::to_string(first.height),
                ": every capture must have the same size"));
        if (o.normal_map.empty()) {
            check::geometry(c.geometry, name);
        } else {
            if (!c.light || !c.view)
                throw InvalidArgument(concat(name,
                                             ": a normal map needs the light and view "
                                             "directions of every capture"));
            for (const auto* v : {&*c.light, &*c.view})
                if (!v->allFinite() || std::abs(v->norm() - 1.0) > 1e-6)
                    throw InvalidArgument(
                        concat(name, ": light and view must be finite unit vectors"));
        }
    }
    if (o.window_px < 1 || o.window_px > kMaxWindowPx)
        throw InvalidArgument(concat("roughness map: window_px = ", std::to_string(o.window_px),
                                     " must be in [1, ", std::to_string(kMaxWindowPx), "]"));
    if (!(o.min_used_fraction > 0.0 && o.min_used_fraction <= 1.0))
        throw InvalidArgument(
            concat("roughness map: min_used_fraction = ", check::format_number(o.min_used_fraction),
                   " must be in (0, 1]"));
    check::positive("roughness map: wavelength_um", o.wavelength_um, " µm");
    if (o.sigma_um) check::positive("roughness map: sigma_um", *o.sigma_um, " µm");
    check::non_negative("roughness map: sigma_um_stderr", o.sigma_um_stderr, " µm");
    check::non_negative("roughness map: max_shift_px", o.max_shift_px, " px");
    check::non_negative("roughness map: min_peak_to_sidelobe", o.min_peak_to_sidelobe);
    check::positive("roughness map: slightly_rough_max_sigma_over_T",
                    o.slightly_rough_max_sigma_over_T);
    if (!(o.very_rough_min_sigma_over_T >= o.slightly_rough_max_sigma_over_T) ||
        !std::isfinite(o.very_rough_min_sigma_over_T))
        throw InvalidArgument(concat("roughness map: very_rough_min_sigma_over_T = ",
                                     check::format_number(o.very_rough_min_sigma_over_T),
                                     " must be finite and at least slightly_rough_max_sigma_over_T"
                                     " = ",
                                     check::format_number(o.slightly_rough_max_sigma_over_T)));
    const std::size_t pixels = captures[0].image->pixel_count();
    if (!o.normal_map.empty() && o.normal_map.size() != 3 * pixels)
        throw InvalidArgument(concat("roughness map: the normal map has ",
                                     std::to_string(o.normal_map.size()),
                                     " values; it needs 3 per "
                                     "pixel (",
                                     std::to_string(3 * pixels), ")"));
    if (!o.region_labels.empty()) {
        if (o.region_labels.size() != pixels)
            throw InvalidArgument(concat(
                "roughness map: the region labels have ", std::to_string(o.region_labels.size()),
                " values; they need one per pixel (", std::to_string(pixels), ")"));
        const auto n = static_cast<std::int32_t>(o.region_names.size());
        for (std::size_t i = 0; i < pixels; ++i)
            if (o.region_labels[i] < -1 || o.region_labels[i] >= n)
                throw InvalidArgument(concat("roughness map: region label ",
                                             std::to_string(o.region_labels[i]), " at pixel ",
                                             std::to_string(i), " must be −1 (none) or in [0, ",
                                             std::to_string(n), ") (one name per region)"));
    }
}

// σ/T of a region of a flat sample: the inverse at the mean of its cells' ln(E1/E2), with the
// standard error of that mean through the inverse's slope. Averaging the cells' σ/T instead is
// biased where the inverse is curved and the cells are noisy (large σ/T, where E1/E2 hardly
// changes with σ/T).
std::optional<Estimate> pooled_sigma_over_T(const RatioInverseTable& table,
                                            const Accumulator& log_ratio) {
    const auto mean = log_ratio.mean();
    if (!mean) return std::nullopt;
    const auto v = table.lookup(mean->value);
    if (!v) return std::nullopt;
    return Estimate{v->x, std::abs(v->dx_dlog_ratio) * mean->std_error};
}

void summarise(const Evaluator& tables, const MapOptions& o, RoughnessMap& map,
               const std::vector<std::int32_t>& cell_region,
               const std::vector<ClassSums>& row_classes) {
    ClassSums classes;
    for (const ClassSums& row : row_classes)
        for (std::size_t c = 0; c < 3; ++c) {
            classes[c].n += row[c].n;
            classes[c].sum += row[c].sum;
            classes[c].sum2 += row[c].sum2;
        }
    std::vector<RegionAccumulator> regions(o.region_names.size());
    const std::size_t cells = map.width * map.height;
    for (std::size_t i = 0; i < cells && !cell_region.empty(); ++i) {
        const std::uint8_t c = map.roughness_class[i];
        const std::int32_t region = cell_region[i];
        if (region < 0) continue;
        RegionAccumulator& ra = regions[static_cast<std::size_t>(region)];
        if (!map.T_um.empty() && std::isfinite(map.T_um[i])) ra.T.add(map.T_um[i]);
        if (std::isfinite(map.E1_over_E2[i]) && map.E1_over_E2[i] > 0.0f)
            ra.log_ratio.add(std::log(static_cast<double>(map.E1_over_E2[i])));
        if (c == kClassNone) {
            ++ra.missing;
            continue;
        }
        ++ra.classes[c];
        // (A normal map makes both layers; a flat sample pools ln E1/E2 below.)
        if (!map.sigma_over_T_gaussian.empty() && std::isfinite(map.sigma_over_T_gaussian[i]))
            ra.gaussian.add(map.sigma_over_T_gaussian[i]);
        if (!map.sigma_over_T_exponential.empty() && std::isfinite(map.sigma_over_T_exponential[i]))
            ra.exponential.add(map.sigma_over_T_exponential[i]);
    }
    for (std::size_t c = 0; c < 3; ++c) {
        ClassStatistics& s = map.classes[c];
        s.roughness_class = static_cast<RoughnessClass>(c);
        s.count = classes[c].n;
        s.fraction =
            map.valid > 0 ? static_cast<double>(s.count) / static_cast<double>(map.valid) : 0.0;
        s.mean_sigma_over_T = classes[c].mean();
    }
    // A flat sample with regions has both tables (Evaluator).
    const RatioInverseTable* table_g = tables.sigma_over_T_table(Correlation::Gaussian);
    const RatioInverseTable* table_e = tables.sigma_over_T_table(Correlation::Exponential);
    assert(!o.normal_map.empty() || regions.empty() || (table_g && table_e));
    for (std::size_t k = 0; k < regions.size(); ++k) {
        RegionMapStatistics s;
        s.name = o.region_names[k];
        const RegionAccumulator& ra = regions[k];
        s.count = ra.classes[0] + ra.classes[1] + ra.classes[2];
        s.missing = ra.missing;
        // A flat sample: pooled over the region (one geometry); a normal map: the mean of the
        // cells' σ/T (each cell has its own geometry).
        s.mean_sigma_over_T_gaussian =
            table_g ? pooled_sigma_over_T(*table_g, ra.log_ratio) : ra.gaussian.mean();
        s.mean_sigma_over_T_exponential =
            table_e ? pooled_sigma_over_T(*table_e, ra.log_ratio) : ra.exponential.mean();
        s.mean_T_um = ra.T.mean();
        s.class_counts = ra.classes;
        const auto unknown = [](const std::optional<Estimate>& e) {
            return e && std::isnan(e->std_error);
        };
        if (unknown(s.mean_sigma_over_T_gaussian) || unknown(s.mean_sigma_over_T_exponential) ||
            unknown(s.mean_T_um))
            map.warnings.push_back(concat("roughness map: region '", s.name, "' has ",
                                          std::to_string(s.count),
                                          " valid cell(s) without spread between them: the "
                                          "standard error of its mean is unknown (null)"));
        map.regions.push_back(std::move(s));
    }
}

// The registration's verdict (docs/maps.md "Registration"): a shift above max_shift_px is an
// error for a flat sample whose images share structure (unless allowed), else a warning in its
// place among the warnings (at `warning_at`).
void apply_registration(const Registration& reg, const std::vector<MapCapture>& captures,
                        const MapOptions& o, RoughnessMap& map, std::size_t warning_at) {
    map.registration = reg;
    if (reg.magnitude_px > o.max_shift_px) {
        const std::string shift =
            concat(capture_name(captures[1], 1), " is shifted by (",
                   check::format_number(reg.shift_x_px), ", ", check::format_number(reg.shift_y_px),
                   ") px = ", check::format_number(reg.magnitude_px), " px against ",
                   capture_name(captures[0], 0), " (phase correlation, peak-to-sidelobe ",
                   check::format_number(reg.peak_to_sidelobe), "); the threshold max_shift_px is ",
                   check::format_number(o.max_shift_px), " px");
        const auto warn = [&](std::string text) {
            map.warnings.insert(map.warnings.begin() + static_cast<std::ptrdiff_t>(warning_at),
                                std::move(text));
        };
        if (reg.peak_to_sidelobe < o.min_peak_to_sidelobe)
            warn(concat("roughness map: ", shift, ", but the peak-to-sidelobe ratio is below ",
                        check::format_number(o.min_peak_to_sidelobe),
                        ": the images share too little structure to tell"));
        else if (!o.normal_map.empty())
            // A curved object's shading moves with the light, and phase correlation reads
            // that as a shift as confidently as a movement of the camera (docs/maps.md
            // "Registration"): no evidence of a movement, so no refusal.
            warn(concat("roughness map: ", shift,
                        ", but with a normal map the shading moves with the light, which "
                        "phase correlation cannot tell from a movement of the camera: not "
                        "refused; the map assumes the camera did not move"));
        else if (!o.allow_misregistration)
            throw DataError(concat("roughness map: ", shift,
                                   ": register the images (or allow the misregistration)"));
        else
            warn(concat("roughness map: ", shift, " (allowed: ratios near edges are unreliable)"));
    }
}

}  // namespace

RoughnessMap roughness_map(const std::vector<MapCapture>& captures, const MapOptions& o) {
    check_map_input(captures, o);
    RoughnessMap map;
    const LinearImage& a = *captures[0].image;
    const LinearImage& b = *captures[1].image;
    map.window_px = o.window_px;
    map.image_width = a.width;
    map.image_height = a.height;
    map.width = (a.width + o.window_px - 1) / o.window_px;
    map.height = (a.height + o.window_px - 1) / o.window_px;
    if (captures.size() > 2)
        map.warnings.push_back(concat("roughness map: ", std::to_string(captures.size()),
                                      " captures given; the map uses the first two (",
                                      capture_name(captures[0], 0), ", ",
                                      capture_name(captures[1], 1), ") and ignores the others"));
    // The registration check runs beside the map (its own thread): its verdict, an error or a
    // warning in its place among the others, is applied when both are done.
    const bool register_pair = o.check_registration && a.width >= 16 && a.height >= 16;
    std::optional<Registration> registration;
    std::exception_ptr registration_error;
    std::jthread registration_worker;
    if (register_pair)
        registration_worker = std::jthread([&] {
            try {
                registration = estimate_misregistration(a, b, o.registration);
            } catch (...) {
                registration_error = std::current_exception();
            }
        });
    const std::size_t registration_warning_at = map.warnings.size();
    const std::size_t cells = map.width * map.height;
    // The layers without a fill: each band's thread writes every cell of its rows (clear_rows).
    // A flat sample's per-pixel map without σ makes only the layers asked for (and E1/E2 for
    // the regions' pooled σ/T, dropped after); the other maps make all of them and drop those
    // not asked for at the end (tiles are few; cells evaluated one by one write every layer).
    const bool lean = lean_pixel_map(o);
    MapLayerValues& primary = map.sigma_over_T(o.correlation);
    MapLayerValues& primary_stderr = map.sigma_over_T_stderr(o.correlation);
    MapLayerValues& other = map.sigma_over_T(other_correlation(o.correlation));
    MapLayerValues& other_stderr = map.sigma_over_T_stderr(other_correlation(o.correlation));
    resize_large_uninitialised(primary, cells);
    resize_large_uninitialised(primary_stderr, cells);
    if (!lean || o.both_correlations) {
        resize_large_uninitialised(other, cells);
        resize_large_uninitialised(other_stderr, cells);
    }
    if (!lean || o.ratio_layer || !o.region_labels.empty())
        resize_large_uninitialised(map.E1_over_E2, cells);
    resize_large_uninitialised(map.roughness_class, cells);
    if (o.sigma_um) {
        resize_large_uninitialised(map.T_um, cells);
        resize_large_uninitialised(map.T_um_stderr, cells);
        resize_large_uninitialised(map.roughness_class_g, cells);
    }
    std::vector<std::int32_t> cell_region;
    if (!o.region_labels.empty()) cell_region.assign(cells, -1);
    const Evaluator prototype(captures, o, map);
    // Bands of rows (pixel rows, or rows of tiles), one thread each; the result does not depend
    // on the number of threads (each cell is computed from its own pixels).
    const std::size_t rows = map.height;
    std::size_t threads =
        o.threads == 0 ? std::max(1u, std::thread::hardware_concurrency()) : o.threads;
    threads = std::clamp<std::size_t>(threads, 1, std::max<std::size_t>(1, rows / 16));
    if (!o.normal_map.empty() || cells < 65536) threads = std::min<std::size_t>(threads, 1);
    std::vector<Evaluator> evaluators(threads, prototype);
    std::vector<std::exception_ptr> errors(threads);
    std::vector<ClassSums> row_classes(rows);
    // A band's first row (a pixel map's bands start where its column sums restart).
    auto band_start = [&](std::size_t t) {
        const std::size_t r = rows * t / threads;
        return o.window_px == 1 && t < threads ? r / kSumRestartRows * kSumRestartRows : r;
    };
    auto run = [&](std::size_t t) {
        try {
            const std::size_t begin = band_start(t), end = band_start(t + 1);
            if (o.window_px == 1) {
                pixel_map(captures, o, evaluators[t], map, cell_region, row_classes, begin, end);
            } else {
                clear_rows(map, begin, end);
                tile_map(captures, o, evaluators[t], map, cell_region, row_classes, begin, end);
            }
        } catch (...) {
            errors[t] = std::current_exception();
        }
    };
    {
        std::vector<std::jthread> workers;
        for (std::size_t t = 1; t < threads; ++t) workers.emplace_back(run, t);
        run(0);
    }
    if (registration_worker.joinable()) registration_worker.join();
    if (registration_error) std::rethrow_exception(registration_error);
    if (registration) apply_registration(*registration, captures, o, map, registration_warning_at);
    for (const auto& e : errors)
        if (e) std::rethrow_exception(e);
    Counts counts;
    for (auto& ev : evaluators) counts.add(ev.counts());
    map.valid = counts.valid;
    map.missing = counts.missing;
    map.no_solution = counts.no_solution;
    if (o.both_correlations) map.no_solution_other = counts.no_solution_other;
    summarise(prototype, o, map, cell_region, row_classes);
    if (!o.both_correlations) {
        other = MapLayerValues();
        other_stderr = MapLayerValues();
    }
    if (!o.ratio_layer) map.E1_over_E2 = MapLayerValues();
    if (map.no_solution > 0)
        map.warnings.push_back(concat("roughness map: ", std::to_string(map.no_solution), " of ",
                                      std::to_string(cells),
                                      " pixels/tiles have a ratio E1/E2 the model does not produce "
                                      "(no σ/T)"));
    if (o.sigma_um && counts.no_solution_T > 0)
        map.warnings.push_back(concat("roughness map: ", std::to_string(counts.no_solution_T),
                                      " pixels/tiles with σ/T have no T given σ"));
    if (map.valid == 0) map.warnings.push_back("roughness map: no pixel or tile has an estimate");
    return map;
}

}  // namespace roughscope::image
