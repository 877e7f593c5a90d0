// The data side of a BRDF comparison (comparison_data.hpp).
#include "comparison_data.hpp"

#include <algorithm>
#include <limits>
#include <optional>
#include <string>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::detail {

std::vector<bool> select_measurements(const BrdfTable& table, const ComparisonOptions& o,
                                      std::vector<DataIssue>& issues) {
    std::vector<bool> used(table.size(), true);
    for (std::size_t k = 0; k < table.size(); ++k) {
        const BrdfMeasurement& m = table.measurements[k];
        if (m.weight == 0.0) {
            used[k] = false;
            issues.push_back({m.index,
                              m.value,
                              "zero_weight",
                              {"all"},
                              "weight 0: left out of every sum and fit"});
            continue;
        }
        if (o.max_overflow_fraction && m.overflow_fraction &&
            *m.overflow_fraction > *o.max_overflow_fraction) {
            used[k] = false;
            issues.push_back({m.index,
                              m.value,
                              "saturated",
                              {"all"},
                              "overflow fraction " + format_significant(*m.overflow_fraction, 6) +
                                  " > " + format_significant(*o.max_overflow_fraction, 6) +
                                  ": left out of every sum, fit and estimate"});
            continue;
        }
        if (!(m.value > 0.0)) {
            const bool pair = m.index == o.measurement1 || m.index == o.measurement2;
            DataIssue issue{m.index, m.value, "non_positive", {}, ""};
            if (pair) {
                issue.excluded_from = {"two_point_estimate"};
                issue.note =
                    "non-positive BRDF (noise): no ratio E1/E2, so no two-point "
                    "estimate; kept in the error sums and fits";
            } else {
                issue.note =
                    "non-positive BRDF (noise around zero): kept in the error sums "
                    "and fits";
            }
            issues.push_back(issue);
        }
    }
    return used;
}

double copy_used_measurements(const BrdfTable& table, const std::vector<bool>& used,
                              Comparison& c) {
    double dmax = -std::numeric_limits<double>::infinity();
    const auto num_used = static_cast<std::size_t>(std::count(used.begin(), used.end(), true));
    c.measurement.reserve(num_used);
    c.geometry.reserve(num_used);
    c.brightness.reserve(num_used);
    c.weight.reserve(num_used);
    for (std::size_t k = 0; k < table.size(); ++k) {
        if (!used[k]) continue;
        const BrdfMeasurement& m = table.measurements[k];
        c.measurement.push_back(m.index);
        c.geometry.push_back(m.geometry);
        c.brightness.push_back(brightness_from_brdf(m.value, m.theta_i_rad));
        c.weight.push_back(m.weight);
        dmax = std::max(dmax, c.brightness.back());
    }
    return dmax;
}

TwoPointEstimate two_point_estimate(const BrdfTable& table, const std::vector<bool>& used,
                                    const ComparisonOptions& o) {
    TwoPointEstimate t;
    t.measurement1 = o.measurement1;
    t.measurement2 = o.measurement2;
    const std::optional<std::size_t> k1 = table.find(o.measurement1);
    const std::optional<std::size_t> k2 = table.find(o.measurement2);
    if (!k1 || !k2) {
        t.reason = "measurement " + std::to_string(!k1 ? o.measurement1 : o.measurement2) +
                   " is not in the table";
        return t;
    }
    const BrdfMeasurement& m1 = table.measurements[*k1];
    const BrdfMeasurement& m2 = table.measurements[*k2];
    t.theta1_rad = o.theta1_rad.value_or(m1.theta_i_rad);
    t.theta2_rad = o.theta2_rad.value_or(m2.theta_i_rad);
    t.E1 = brightness_from_brdf(m1.value, t.theta1_rad);
    t.E2 = brightness_from_brdf(m2.value, t.theta2_rad);
    for (const BrdfMeasurement* m : {&m1, &m2}) {
        if (!used[m == &m1 ? *k1 : *k2]) {
            t.reason = "measurement " + std::to_string(m->index) +
                       " is excluded (zero weight or saturated)";
            return t;
        }
        if (m->theta_v_rad > o.normal_view_tolerance_rad) {
            t.reason = "measurement " + std::to_string(m->index) +
                       " has theta_v = " + format_significant(rad_to_deg(m->theta_v_rad), 6) +
                       " deg: Eq. 16-19 need the viewer on the normal (theta_v <= " +
                       format_significant(rad_to_deg(o.normal_view_tolerance_rad), 6) + " deg)";
            return t;
        }
    }
    std::string bad;
    for (const BrdfMeasurement* m : {&m1, &m2})
        if (!(m->value > 0.0))
            bad += (bad.empty() ? "" : " and ") + std::string("measurement ") +
                   std::to_string(m->index) + " has f = " + format_significant(m->value, 6) +
                   " <= 0";
    if (!bad.empty()) {
        t.reason = bad +
                   ": the ratio E1/E2 needs two positive brightness values (non-positive "
                   "BRDF values are calibration noise)";
        return t;
    }
    t.available = true;
    t.E1_over_E2 = *t.E1 / *t.E2;
    for (const Correlation c : kCorrelations) {
        try {  // Eq. 17 / Eq. 19
            t.sigma_over_T(c) = sigma_over_T_from_ratio(
                c, *t.E1_over_E2, t.theta1_rad, t.theta2_rad, GeometricFactor::VernoldHarvey);
        } catch (const Error& e) {
            t.correlation_reason(c) = e.what();
        }
    }
    return t;
}

}  // namespace roughscope::detail
