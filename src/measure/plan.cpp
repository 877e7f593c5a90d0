// Planning a capture (plan.hpp, docs/uncertainty.md "Planning a capture"): every pair of light
// zeniths of a grid, its predicted E1/E2 at the expected σ/T and the first-order u(σ/T) of the
// measurement budget's model; the smallest one recommended, the paper's 30°/45° beside it.
#include "roughscope/measure/plan.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/parallel.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/estimation/estimation.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image {
namespace {

constexpr std::array<NameEntry<PlanExposure>, 2> kExposureNames{{
    {"per_capture", PlanExposure::PerCapture},
    {"common", PlanExposure::Common},
}};

constexpr double kPaperTheta1Deg = 30.0;
constexpr double kPaperTheta2Deg = 45.0;
constexpr std::size_t kMaxPairs = 200'000;
constexpr std::size_t kMaxRangePoints = 50;
constexpr std::size_t kMaxTop = 1000;

// The inputs of the model, in x (the budget's names, so that the lines read alike).
constexpr std::size_t kTheta1 = 0, kTheta2 = 1, kTilt = 2, kExposure1 = 3, kExposure2 = 4,
                      kBlack = 5, kNoise1 = 6, kNoise2 = 7;

// The tolerances in force, after the defaults.
struct Tolerances {
    double angle_rad = 0.0;
    double exposure_rel = 0.0;
    double black_level_rel = 0.0;
};

// The model of one pair at one true σ/T: x → σ/T as measured.
class PairModel {
  public:
    PairModel(const PlanRequest& request, const Tolerances& tol, double theta1_rad,
              double theta2_rad, double sigma_over_T)
        : request_(request) {
        options_.factor = request.factor;
        ratio_ = model_ratio_very_rough(normal_view_geometry(theta1_rad),
                                        normal_view_geometry(theta2_rad), sigma_over_T,
                                        request.correlation, options_);
        if (!(ratio_ > 1e-12 && ratio_ < 1e12))
            throw NoSolution(concat("E1/E2 = ", check::format_number(ratio_),
                                    " is beyond what a camera resolves (1e-12 to 1e12)"));
        // Fractions of full scale reached by each capture, and their relative noise.
        m1_ = m2_ = request.fill;
        double noise1 = request.noise_rel, noise2 = request.noise_rel;
        if (request.exposure == PlanExposure::Common) {
            if (ratio_ >= 1.0)
                m2_ = request.fill / ratio_;
            else
                m1_ = request.fill * ratio_;
            noise1 *= std::sqrt(request.fill / m1_);
            noise2 *= std::sqrt(request.fill / m2_);
        }
        closed_ = !(tol.angle_rad > 0.0);
        inputs_ = {
            {"theta_i of capture 1", theta1_rad, tol.angle_rad},
            {"theta_i of capture 2", theta2_rad, tol.angle_rad},
            {"theta_s of the camera (captures 1 and 2)", 0.0, tol.angle_rad},
            {"exposure of capture 1", 0.0, tol.exposure_rel},
            {"exposure of capture 2", 0.0, tol.exposure_rel},
            {"black level (every photograph)", 0.0, tol.black_level_rel},
            {"pixel noise of capture 1", 0.0, noise1},
            {"pixel noise of capture 2", 0.0, noise2},
        };
    }

    double ratio() const { return ratio_; }
    const std::vector<UncertainInput>& inputs() const { return inputs_; }

    void operator()(std::span<const double> x, std::span<std::optional<double>> y) const {
        y[0] = std::nullopt;
        // m' = (m − δ)/(1 − δ): the region mean re-read with the black level off by δ (W − b).
        const double d = x[kBlack];
        const double m1 = (m1_ - d) / (1.0 - d), m2 = (m2_ - d) / (1.0 - d);
        const double s1 = 1.0 + x[kExposure1], s2 = 1.0 + x[kExposure2];
        if (!(m1 > 0.0) || !(m2 > 0.0) || !(s1 > 0.0) || !(s2 > 0.0)) return;
        const double ratio =
            ratio_ * (m1 / m1_) * (1.0 + x[kNoise1]) / s1 / ((m2 / m2_) * (1.0 + x[kNoise2]) / s2);
        const auto g1 = signed_geometry(x[kTheta1], x[kTilt], 0.0);
        const auto g2 = signed_geometry(x[kTheta2], x[kTilt], 0.0);
        if (!g1 || !g2 || !(ratio > 0.0)) return;
        try {
            y[0] =
                closed_ && g1->phi_s_rad == 0.0 && g2->phi_s_rad == 0.0
                    ? sigma_over_T_from_ratio(request_.correlation, ratio, g1->theta_i_rad,
                                              g2->theta_i_rad, request_.factor)
                    : sigma_over_T_two_geometries(ratio, *g1, *g2, request_.correlation, options_);
        } catch (const Error&) {
        }
    }

  private:
    const PlanRequest& request_;
    TwoGeometryOptions options_;
    double ratio_ = 1.0;
    double m1_ = 1.0, m2_ = 1.0;
    bool closed_ = false;
    std::vector<UncertainInput> inputs_;
};

// The pair's u(σ/T) at every point, the worst kept; has_value false if one has none.
PlannedPair evaluate_pair(const PlanRequest& request, const Tolerances& tol,
                          const std::vector<double>& points, double theta1_deg, double theta2_deg,
                          const PropagationOptions& options) {
    PlannedPair pair;
    pair.theta1_deg = theta1_deg;
    pair.theta2_deg = theta2_deg;
    pair.method = options.method;
    const std::vector<std::string> names{correlation_key("sigma_over_T", request.correlation)};
    bool first = true;
    for (const double s : points) {
        std::optional<PairModel> model;
        try {
            model.emplace(request, tol, deg_to_rad(theta1_deg), deg_to_rad(theta2_deg), s);
        } catch (const Error& e) {
            pair.has_value = false;
            pair.reason = concat("σ/T ", format_significant(s, 3), ": ", e.what());
            return pair;
        }
        const PairModel& m = *model;
        const Propagation p = propagate_uncertainty(
            m.inputs(), names,
            [&m](std::span<const double> x, std::span<std::optional<double>> y) { m(x, y); },
            options);
        const auto& out = p.outputs[0];
        if (!out || !std::isfinite(out->uncertainty)) {
            pair.has_value = false;
            pair.reason = concat(
                "σ/T ", format_significant(s, 3), ": E1/E2 = ", format_significant(m.ratio(), 4),
                p.warnings.empty() ? std::string(": no value") : concat(": ", p.warnings.back()));
            return pair;
        }
        const double rel = out->uncertainty / s;
        if (first || rel > pair.relative_uncertainty) {
            pair.sigma_over_T = s;
            pair.E1_over_E2 = m.ratio();
            pair.relative_uncertainty = rel;
            pair.result = *out;
            pair.method = p.method;
        }
        first = false;
    }
    pair.has_value = true;
    return pair;
}

void check_request(const PlanRequest& r) {
    check::positive("plan: sigma_over_T", r.sigma_over_T);
    if (r.sigma_over_T_max) {
        check::finite("plan: sigma_over_T_max", *r.sigma_over_T_max);
        if (*r.sigma_over_T_max < r.sigma_over_T)
            throw InvalidArgument(
                concat("plan: sigma_over_T_max = ", check::format_number(*r.sigma_over_T_max),
                       " must be ≥ sigma_over_T = ", check::format_number(r.sigma_over_T)));
        if (r.range_points < 2 || r.range_points > kMaxRangePoints)
            throw InvalidArgument(concat("plan: range_points = ", std::to_string(r.range_points),
                                         " must be 2 to ", std::to_string(kMaxRangePoints)));
    }
    if (!is_valid(r.correlation))
        throw InvalidArgument("plan: correlation must be gaussian or exponential");
    const SetupTolerances& t = r.tolerances;
    for (const auto& [key, v] :
         {std::pair{"angle_deg", t.angle_deg}, std::pair{"exposure_rel", t.exposure_rel},
          std::pair{"black_level_dn", t.black_level_dn},
          std::pair{"black_level_rel", r.black_level_rel}})
        if (v) check::non_negative(concat("plan: uncertainty.", key), *v);
    if (t.angle_deg && *t.angle_deg >= 10.0)
        throw InvalidArgument(concat("plan: uncertainty.angle_deg = ",
                                     check::format_number(*t.angle_deg), " must be below 10°"));
    if (t.exposure_rel && *t.exposure_rel >= 0.5)
        throw InvalidArgument(concat("plan: uncertainty.exposure_rel = ",
                                     check::format_number(*t.exposure_rel), " must be below 0.5"));
    if (t.black_level_dn && !r.full_scale_dn)
        throw InvalidArgument(
            "plan: uncertainty.black_level_dn needs full_scale_dn (W − b, DN) to be read as a "
            "fraction of full scale; or give black_level_rel");
    if (r.full_scale_dn) check::positive("plan: full_scale_dn", *r.full_scale_dn, " DN");
    check::non_negative("plan: noise_rel", r.noise_rel);
    if (r.noise_rel >= 0.5)
        throw InvalidArgument(concat("plan: noise_rel = ", check::format_number(r.noise_rel),
                                     " must be in [0, 0.5)"));
    check::positive("plan: fill", r.fill);
    if (r.fill > 1.0)
        throw InvalidArgument(
            concat("plan: fill = ", check::format_number(r.fill), " must be in (0, 1]"));
    check::finite("plan: theta_min_deg", r.theta_min_deg);
    check::finite("plan: theta_max_deg", r.theta_max_deg);
    check::positive("plan: theta_step_deg", r.theta_step_deg, "°");
    check::non_negative("plan: min_difference_deg", r.min_difference_deg, "°");
    if (r.theta_min_deg < 0.0 || !(r.theta_max_deg < 90.0) || r.theta_min_deg > r.theta_max_deg)
        throw InvalidArgument(concat("plan: the angle grid [theta_min_deg, theta_max_deg] = [",
                                     check::format_number(r.theta_min_deg), ", ",
                                     check::format_number(r.theta_max_deg),
                                     "]° must satisfy 0 ≤ theta_min_deg ≤ theta_max_deg < 90"));
    if (r.top < 1 || r.top > kMaxTop)
        throw InvalidArgument(concat("plan: top = ", std::to_string(r.top), " must be 1 to ",
                                     std::to_string(kMaxTop)));
}

// The grid's zeniths, degrees (min, min + step, ..., ≤ max).
std::vector<double> angle_grid(const PlanRequest& r) {
    const double count = std::floor((r.theta_max_deg - r.theta_min_deg) / r.theta_step_deg + 1e-9);
    if (count * (count + 1.0) / 2.0 > static_cast<double>(kMaxPairs))
        throw InvalidArgument(
            concat("plan: theta_step_deg = ", check::format_number(r.theta_step_deg),
                   "° makes more than ~630 angles (at most 200,000 pairs): a coarser step or a "
                   "narrower grid"));
    std::vector<double> grid;
    for (std::size_t k = 0; k <= static_cast<std::size_t>(count); ++k)
        grid.push_back(r.theta_min_deg + static_cast<double>(k) * r.theta_step_deg);
    return grid;
}

Tolerances tolerances(const PlanRequest& r, std::vector<std::string>& assumed) {
    const SetupTolerances& t = r.tolerances;
    Tolerances tol;
    const auto note = [&assumed](std::string_view key, double value, std::string_view unit) {
        assumed.push_back(concat(key, " = ", format_significant(value, 3), unit));
        return value;
    };
    tol.angle_rad = deg_to_rad(t.angle_deg ? *t.angle_deg
                                           : note("angle_deg", kDefaultAngleUncertaintyDeg, "°"));
    tol.exposure_rel =
        t.exposure_rel ? *t.exposure_rel : note("exposure_rel", kDefaultExposureUncertaintyRel, "");
    tol.black_level_rel = r.black_level_rel ? *r.black_level_rel
                          : t.black_level_dn
                              ? *t.black_level_dn / *r.full_scale_dn
                              : note("black_level_rel", kDefaultBlackLevelFraction, "");
    return tol;
}

bool better(const PlannedPair& a, const PlannedPair& b) {
    if (a.relative_uncertainty != b.relative_uncertainty)
        return a.relative_uncertainty < b.relative_uncertainty;
    return a.theta1_deg != b.theta1_deg ? a.theta1_deg < b.theta1_deg : a.theta2_deg < b.theta2_deg;
}

}  // namespace

std::string_view to_string(PlanExposure exposure) { return name_of(kExposureNames, exposure); }

PlanExposure parse_plan_exposure(std::string_view name) {
    return parse_name(kExposureNames, "exposure", name);
}

CapturePlan plan_capture(const PlanRequest& request) {
    check_request(request);
    CapturePlan plan;
    plan.request = request;
    const Tolerances tol = tolerances(request, plan.assumed);
    plan.angle_deg = request.tolerances.angle_deg.value_or(kDefaultAngleUncertaintyDeg);
    plan.exposure_rel = tol.exposure_rel;
    plan.black_level_rel = tol.black_level_rel;
    if (tol.black_level_rel >= request.fill)
        throw InvalidArgument(
            concat("plan: black_level_rel = ", check::format_number(tol.black_level_rel),
                   " must be below fill = ", check::format_number(request.fill)));
    const std::size_t n = request.sigma_over_T_max ? request.range_points : 1;
    for (std::size_t k = 0; k < n; ++k)
        plan.sigma_over_T_points.push_back(
            n == 1
                ? request.sigma_over_T
                : request.sigma_over_T + (*request.sigma_over_T_max - request.sigma_over_T) *
                                             (static_cast<double>(k) / static_cast<double>(n - 1)));
    const std::vector<double> grid = angle_grid(request);
    PropagationOptions search = request.propagation;
    search.method = PropagationMethod::FirstOrder;
    // One band per θ1: its pairs with every θ2 ≥ θ1 + min_difference.
    std::vector<std::vector<PlannedPair>> bands(grid.size());
    run_bands(grid.size(), request.threads, [&](std::size_t i) {
        for (std::size_t j = i + 1; j < grid.size(); ++j)
            if (grid[j] - grid[i] >= request.min_difference_deg - 1e-9)
                bands[i].push_back(evaluate_pair(request, tol, plan.sigma_over_T_points, grid[i],
                                                 grid[j], search));
    });
    std::vector<PlannedPair> ranked;
    for (auto& band : bands)
        for (PlannedPair& p : band) {
            ++plan.pairs;
            if (p.has_value) ranked.push_back(std::move(p));
        }
    if (plan.pairs == 0)
        throw InvalidArgument(concat(
            "plan: the angle grid (theta_min_deg = ", check::format_number(request.theta_min_deg),
            ", theta_max_deg = ", check::format_number(request.theta_max_deg),
            ", theta_step_deg = ", check::format_number(request.theta_step_deg),
            ") has no pair with theta2 − theta1 ≥ min_difference_deg = ",
            check::format_number(request.min_difference_deg), "°"));
    plan.pairs_with_value = ranked.size();
    if (ranked.empty())
        throw NoSolution(concat("plan: no pair of the grid gives σ/T a value at every σ/T in [",
                                format_significant(plan.sigma_over_T_points.front(), 3), ", ",
                                format_significant(plan.sigma_over_T_points.back(), 3),
                                "] (E1/E2 outside the model's range at ± the tolerances)"));
    std::sort(ranked.begin(), ranked.end(), better);
    ranked.resize(std::min(ranked.size(), request.top));
    plan.top = ranked;
    plan.recommended = evaluate_pair(request, tol, plan.sigma_over_T_points, ranked[0].theta1_deg,
                                     ranked[0].theta2_deg, request.propagation);
    plan.reference = evaluate_pair(request, tol, plan.sigma_over_T_points, kPaperTheta1Deg,
                                   kPaperTheta2Deg, request.propagation);
    if (!plan.assumed.empty()) {
        std::string list;
        for (const auto& a : plan.assumed) list += (list.empty() ? "" : ", ") + a;
        plan.warnings.push_back(concat("plan: rests on assumed tolerances (", list,
                                       "): give the setup's (docs/uncertainty.md)"));
    }
    if (plan.reference.has_value && plan.recommended.has_value &&
        plan.reference.relative_uncertainty < plan.recommended.relative_uncertainty)
        plan.warnings.push_back(
            "plan: the paper's 30°/45° (outside the grid or the min_difference_deg constraint) "
            "does better than every pair of the grid");
    if (plan.recommended.method == PropagationMethod::MonteCarlo)
        plan.warnings.push_back(
            "plan: the recommended pair's model is not near-linear at the tolerances: its "
            "uncertainty is Monte Carlo's, the ranking first order's");
    return plan;
}

}  // namespace roughscope::image
