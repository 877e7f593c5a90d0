// The roughness map's cells into its layers (map_evaluator.hpp, docs/maps.md): the σ/T tables
// of a flat sample or the two-geometry solver per cell of a normal map, the standard errors, the
// classes and T given σ.
#include "maps/map_evaluator.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope::image::detail {

Evaluator::Evaluator(const std::vector<MapCapture>& captures, const MapOptions& o,
                     RoughnessMap& map)
    : c1_(captures[0]), c2_(captures[1]), o_(o), map_(map) {
    model_.factor = o.factor;
    model_.radiometry = o.radiometry;
    model_.wavelength_um = o.wavelength_um;
    flat_ = o.normal_map.empty();
    if (flat_) {
        // The tables are shared by the threads' copies (read only). A lean per-pixel map
        // needs only the primary correlation's, unless both layers or regions are asked for
        // (the regions' pooled σ/T give both).
        const bool both = !lean_pixel_map(o) || o.both_correlations || !o.region_labels.empty();
        const auto build = [&](Correlation c) {
            return std::make_shared<const RatioInverseTable>(
                RatioInverseTable::sigma_over_T(c1_.geometry, c2_.geometry, c, model_, o.table));
        };
        if (both || o.correlation == Correlation::Gaussian) table_g_ = build(Correlation::Gaussian);
        if (both || o.correlation == Correlation::Exponential)
            table_e_ = build(Correlation::Exponential);
        map_.method = normal_view(c1_.geometry) && normal_view(c2_.geometry)
                          ? "table (Eq. 17/19)"
                          : "table (two-geometry model)";
        if (o.sigma_um) {
            const double g = std::max(roughness_g(c1_.geometry, *o.sigma_um, o.wavelength_um),
                                      roughness_g(c2_.geometry, *o.sigma_um, o.wavelength_um));
            flat_g_class_ = roughness_class(g);
            // T from the diffuse term valid at the sample's g: Eq. 3 (Eq. 15) for a
            // slightly rough sample, the exact series at any other g (Eq. 4/5 leave it:
            // at g = 18 Eq. 4 gives T 4 % high, Eq. 5 80 % low).
            TwoGeometryOptions m = model_;
            m.regime = *flat_g_class_ == RoughnessClass::SlightlyRough ? Regime::SlightlyRough
                                                                       : Regime::Series;
            try {
                table_t_ =
                    std::make_shared<const RatioInverseTable>(RatioInverseTable::correlation_length(
                        c1_.geometry, c2_.geometry, *o.sigma_um, o.correlation, m, o.table));
                if (o.sigma_um_stderr > 0.0) {
                    sigma_step_ = *o.sigma_um * 1e-4;
                    table_t2_ = std::make_shared<const RatioInverseTable>(
                        RatioInverseTable::correlation_length(c1_.geometry, c2_.geometry,
                                                              *o.sigma_um + sigma_step_,
                                                              o.correlation, m, o.table));
                }
            } catch (const NoSolution& e) {
                map_.warnings.push_back(concat("T given σ: ", e.what()));
            }
        }
    } else {
        map_.method = "solver per tile (two-geometry model)";
    }
}

// A flat sample's pixel (the layers' cells already NaN / no class): the two tables at the
// ratio E1/E2, the error through their slopes.
void Evaluator::evaluate_flat(std::size_t index, double ratio, double sd_lr) {
    map_.E1_over_E2[index] = static_cast<float>(ratio);
    RatioInverseTable::Value vg, ve;
    const bool g = table_g_->find_ratio(ratio, vg, hint_g_);
    const bool e = table_e_->find_ratio(ratio, ve, hint_e_);
    if (g) {
        map_.sigma_over_T_gaussian[index] = static_cast<float>(vg.x);
        map_.sigma_over_T_gaussian_stderr[index] =
            static_cast<float>(std::abs(vg.dx_dlog_ratio) * sd_lr);
    }
    if (e) {
        map_.sigma_over_T_exponential[index] = static_cast<float>(ve.x);
        map_.sigma_over_T_exponential_stderr[index] =
            static_cast<float>(std::abs(ve.dx_dlog_ratio) * sd_lr);
    }
    const bool gaussian = o_.correlation == Correlation::Gaussian;
    const bool has_primary = gaussian ? g : e;
    if (!(gaussian ? e : g)) ++counts_.no_solution_other;
    if (o_.sigma_um) estimate_T(index, std::log(ratio), sd_lr, std::nullopt, std::nullopt);
    if (!has_primary) {
        ++counts_.no_solution;
        return;
    }
    ++counts_.valid;
    const double x = gaussian ? vg.x : ve.x;
    map_.roughness_class[index] = class_code(roughness_class_of_sigma_over_T(
        x, o_.slightly_rough_max_sigma_over_T, o_.very_rough_min_sigma_over_T));
}

// Returns the row's class sums.
ClassSums Evaluator::evaluate_flat_row(std::size_t begin, std::size_t count, const double* ratio,
                                       const double* var_log_ratio, const double* state) {
    const bool gaussian = o_.correlation == Correlation::Gaussian;
    const Correlation c = o_.correlation, oc = other_correlation(c);
    const bool other = !map_.sigma_over_T(oc).empty();
    for (auto* v : {&xp_, &sp_, &xo_, &so_, &klass_}) v->resize(count);
    const RatioInverseTable& tp = gaussian ? *table_g_ : *table_e_;
    const RatioInverseTable* to = gaussian ? table_e_.get() : table_g_.get();
    const bool pending_p = tp.find_ratio_bins(count, ratio, xp_.data(), sp_.data());
    const bool pending_o = other && to->find_ratio_bins(count, ratio, xo_.data(), so_.data());
    // The ratios outside the bins (few, or none): find at ln ratio (NaN stays where the
    // table has no solution).
    const auto rest = [&](const RatioInverseTable& table, std::vector<double>& x,
                          std::vector<double>& slope, std::size_t& hint) {
        for (std::size_t i = 0; i < count; ++i) {
            if (state[i] != 0.0 || !std::isnan(x[i])) continue;
            RatioInverseTable::Value v;
            if (!table.find(std::log(ratio[i]), v, hint)) continue;
            x[i] = v.x;
            slope[i] = v.dx_dlog_ratio;
        }
    };
    if (pending_p) rest(tp, xp_, sp_, gaussian ? hint_g_ : hint_e_);
    if (pending_o) rest(*to, xo_, so_, gaussian ? hint_e_ : hint_g_);
    MapLayerValues& lp = map_.sigma_over_T(c);
    MapLayerValues& lpse = map_.sigma_over_T_stderr(c);
    MapLayerValues& lo = map_.sigma_over_T(oc);
    MapLayerValues& lose = map_.sigma_over_T_stderr(oc);
    const FlatRowIn in{ratio,
                       var_log_ratio,
                       state,
                       xp_.data(),
                       sp_.data(),
                       xo_.data(),
                       so_.data(),
                       o_.slightly_rough_max_sigma_over_T,
                       o_.very_rough_min_sigma_over_T};
    const FlatRowOut out{map_.E1_over_E2.empty() ? nullptr : map_.E1_over_E2.data() + begin,
                         lp.data() + begin,
                         lpse.data() + begin,
                         other ? lo.data() + begin : nullptr,
                         other ? lose.data() + begin : nullptr,
                         klass_.data(),
                         map_.roughness_class.data() + begin};
    const RowCounts row = write_flat_row(count, in, out);
    counts_.valid += row.valid;
    counts_.missing += row.missing;
    counts_.no_solution += row.no_solution;
    counts_.no_solution_other += row.no_solution_other;
    return row.classes;
}

void Evaluator::evaluate(std::size_t index, const Cell& cell) {
    const double lr = cell.log_ratio;
    map_.E1_over_E2[index] = static_cast<float>(cell.ratio);
    const double sd_lr = std::sqrt(cell.var_log_ratio);
    std::optional<Estimate> g, e;
    std::optional<Geometry> geom1, geom2;
    if (flat_) {
        if (auto v = table_g_->lookup(lr, hint_g_))
            g = Estimate{v->x, std::abs(v->dx_dlog_ratio) * sd_lr};
        if (auto v = table_e_->lookup(lr, hint_e_))
            e = Estimate{v->x, std::abs(v->dx_dlog_ratio) * sd_lr};
    } else {
        const double nn = cell.normal.norm();
        if (nn > 0.0) {
            const Eigen::Vector3d n = cell.normal / nn;
            geom1 = geometry_from_vectors(n, *c1_.light, *c1_.view);
            geom2 = geometry_from_vectors(n, *c2_.light, *c2_.view);
        }
        if (!geom1 || !geom2) {
            ++counts_.missing;
            map_.roughness_class[index] = kClassNone;
            if (!map_.roughness_class_g.empty()) map_.roughness_class_g[index] = kClassNone;
            return;
        }
        g = solve(lr, sd_lr, *geom1, *geom2, Correlation::Gaussian);
        e = solve(lr, sd_lr, *geom1, *geom2, Correlation::Exponential);
    }
    if (g) {
        map_.sigma_over_T_gaussian[index] = static_cast<float>(g->value);
        map_.sigma_over_T_gaussian_stderr[index] = static_cast<float>(g->std_error);
    }
    if (e) {
        map_.sigma_over_T_exponential[index] = static_cast<float>(e->value);
        map_.sigma_over_T_exponential_stderr[index] = static_cast<float>(e->std_error);
    }
    const std::optional<Estimate>& primary = o_.correlation == Correlation::Gaussian ? g : e;
    const std::optional<Estimate>& other = o_.correlation == Correlation::Gaussian ? e : g;
    if (!other) ++counts_.no_solution_other;
    if (o_.sigma_um) estimate_T(index, lr, sd_lr, geom1, geom2);
    if (!primary) {
        ++counts_.no_solution;
        map_.roughness_class[index] = kClassNone;
        return;
    }
    ++counts_.valid;
    map_.roughness_class[index] = class_code(roughness_class_of_sigma_over_T(
        primary->value, o_.slightly_rough_max_sigma_over_T, o_.very_rough_min_sigma_over_T));
}

// σ known: the class by g and T from the diffuse term valid at the cell's g (Eq. 3, i.e.
// Eq. 15, for a slightly rough cell; the exact series otherwise).
void Evaluator::estimate_T(std::size_t index, double lr, double sd_lr,
                           const std::optional<Geometry>& geom1,
                           const std::optional<Geometry>& geom2) {
    const double sigma = *o_.sigma_um;
    RoughnessClass gc = RoughnessClass::VeryRough;
    if (flat_) {
        gc = *flat_g_class_;
    } else {
        gc = roughness_class(std::max(roughness_g(*geom1, sigma, o_.wavelength_um),
                                      roughness_g(*geom2, sigma, o_.wavelength_um)));
    }
    map_.roughness_class_g[index] = class_code(gc);
    std::optional<Estimate> T;
    if (flat_) {
        if (table_t_) {
            if (auto v = table_t_->lookup(lr, hint_t_)) {
                double dT_dsigma = 0.0;
                if (table_t2_) {
                    if (auto v2 = table_t2_->lookup(lr, hint_t2_))
                        dT_dsigma = (v2->x - v->x) / sigma_step_;
                }
                T = Estimate{v->x,
                             std::hypot(v->dx_dlog_ratio * sd_lr, dT_dsigma * o_.sigma_um_stderr)};
            }
        }
    } else {
        TwoGeometryOptions m = model_;
        m.regime = gc == RoughnessClass::SlightlyRough ? Regime::SlightlyRough : Regime::Series;
        try {
            const double t0 = correlation_length_two_geometries(std::exp(lr), *geom1, *geom2, sigma,
                                                                o_.correlation, m);
            const double tp = correlation_length_two_geometries(std::exp(lr + kLogStep), *geom1,
                                                                *geom2, sigma, o_.correlation, m);
            const double ts = correlation_length_two_geometries(
                std::exp(lr), *geom1, *geom2, sigma * (1.0 + 1e-4), o_.correlation, m);
            T = Estimate{t0, std::hypot((tp - t0) / kLogStep * sd_lr,
                                        (ts - t0) / (sigma * 1e-4) * o_.sigma_um_stderr)};
        } catch (const Error&) {
        }
    }
    if (T && std::isfinite(T->value) && std::isfinite(T->std_error)) {
        map_.T_um[index] = static_cast<float>(T->value);
        map_.T_um_stderr[index] = static_cast<float>(T->std_error);
    } else {
        ++counts_.no_solution_T;
    }
}

// The two-geometry solver (normal map), with d(σ/T)/d ln r = σ/T / (d ln M/d ln(σ/T)).
std::optional<Estimate> Evaluator::solve(double lr, double sd_lr, const Geometry& g1,
                                         const Geometry& g2, Correlation c) const {
    try {
        const double s = sigma_over_T_two_geometries(std::exp(lr), g1, g2, c, model_);
        const auto [y, dy] = log_model(
            [&](double x) { return model_ratio_very_rough(g1, g2, x, c, model_); }, std::log(s));
        (void)y;
        const double se = std::abs(s / dy) * sd_lr;
        if (!std::isfinite(s) || !std::isfinite(se)) return std::nullopt;
        return Estimate{s, se};
    } catch (const Error&) {
        return std::nullopt;
    }
}

}  // namespace roughscope::image::detail
