// Profile-likelihood intervals of the exact-series joint fit (exact_series_profile.hpp).
#include "exact_series_profile.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <utility>

#include "roughscope/core/errors.hpp"

namespace roughscope::image::detail {
namespace {

constexpr double kSpan = 100.0;  // the profiles search σ0/kSpan … σ0·kSpan (and T)
constexpr double kChi2Quantile95 = 3.841458820694124;  // χ²(1) 95 % quantile
constexpr double kInf = std::numeric_limits<double>::infinity();

double chi2_at(const std::vector<Measurement>& data, const FitOptions& options, double sigma_um,
               double T_um) {
    std::vector<double> b(data.size());
    double wb = 0.0, wbb = 0.0;
    try {
        for (std::size_t i = 0; i < data.size(); ++i) {
            b[i] = fit_model_brightness(data[i].geometry, {sigma_um, T_um}, options) /
                   data[i].brightness;
            wb += data[i].weight * b[i];
            wbb += data[i].weight * b[i] * b[i];
        }
    } catch (const Error&) {
        return kInf;  // outside the model's domain
    }
    if (!(wbb > 0.0) || !std::isfinite(wbb)) return kInf;
    const double K = wb / wbb;
    double chi2 = 0.0;
    for (std::size_t i = 0; i < data.size(); ++i)
        chi2 += data[i].weight * std::pow(K * b[i] - 1.0, 2);
    return chi2;
}

// Points of each profile and of the scan of the free parameter; golden-section steps after it.
constexpr int kProfilePoints = 81;
constexpr int kFreeScan = 25;
constexpr int kRatioScan = 61;
constexpr int kBisections = 8;  // of an interval's end between two profile points
constexpr int kGoldenSteps = 24;

// min over b in [lo, hi] of f(b), and the b where it is: a scan, then golden sections.
std::pair<double, double> minimise_1d(const std::function<double(double)>& f, double lo, double hi,
                                      int scan = kFreeScan) {
    double best = kInf, at = lo;
    const double step = (hi - lo) / (scan - 1);
    for (int k = 0; k < scan; ++k) {
        const double b = lo + step * k;
        const double v = f(b);
        if (v < best) {
            best = v;
            at = b;
        }
    }
    double a = std::max(lo, at - step), c = std::min(hi, at + step);
    const double r = 0.5 * (std::sqrt(5.0) - 1.0);
    double x1 = c - r * (c - a), x2 = a + r * (c - a);
    double f1 = f(x1), f2 = f(x2);
    for (int k = 0; k < kGoldenSteps; ++k) {
        if (f1 < f2) {
            c = x2;
            x2 = x1;
            f2 = f1;
            x1 = c - r * (c - a);
            f1 = f(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + r * (c - a);
            f2 = f(x2);
        }
    }
    for (const auto& [v, b] : {std::pair{f1, x1}, std::pair{f2, x2}})
        if (v < best) {
            best = v;
            at = b;
        }
    return {best, at};
}

// A profile: for a on a grid over [lo, hi] (logs), χ²_p(a) = min over the free parameter.
struct Profile {
    double lo = 0.0, hi = 0.0;
    std::vector<double> chi2, free_at;
    double a(int k) const { return lo + (hi - lo) * k / (kProfilePoints - 1); }
    double step() const { return (hi - lo) / (kProfilePoints - 1); }
};

Profile profile(double lo, double hi, const std::function<std::pair<double, double>(double)>& m) {
    Profile p{lo, hi, {}, {}};
    for (int k = 0; k < kProfilePoints; ++k) {
        const auto [v, b] = m(p.a(k));
        p.chi2.push_back(v);
        p.free_at.push_back(b);
    }
    return p;
}

using ProfileFunction = std::function<std::pair<double, double>(double)>;

// The interval {a : χ²_p(a) ≤ limit}: its ends where χ²_p crosses the limit, found by bisection
// of the profile itself between the grid points either side (χ²_p can rise steeply there); open
// where it reaches an end of the grid. nullopt when no point is inside.
std::optional<ProfileInterval> interval_of(const Profile& p, const ProfileFunction& m,
                                           double limit) {
    int k0 = -1, k1 = -1;
    for (int k = 0; k < kProfilePoints; ++k)
        if (p.chi2[static_cast<std::size_t>(k)] <= limit) {
            if (k0 < 0) k0 = k;
            k1 = k;
        }
    if (k0 < 0) return std::nullopt;
    const auto crossing = [&](double in, double out) {
        for (int b = 0; b < kBisections; ++b) {
            const double mid = 0.5 * (in + out);
            (m(mid).first <= limit ? in : out) = mid;
        }
        return 0.5 * (in + out);
    };
    const double lo = k0 == 0 ? p.lo : crossing(p.a(k0), p.a(k0 - 1));
    const double hi = k1 == kProfilePoints - 1 ? p.hi : crossing(p.a(k1), p.a(k1 + 1));
    return ProfileInterval{std::exp(lo), std::exp(hi), k0 == 0, k1 == kProfilePoints - 1};
}

}  // namespace

ProfileIntervals profile_intervals(const std::vector<Measurement>& data, const FitOptions& options,
                                   double sigma0_um, double T0_um) {
    ProfileIntervals out;
    if (!(sigma0_um > 0.0 && T0_um > 0.0) || data.size() < 3) return out;
    const double s_lo = std::log(std::max(sigma0_um / kSpan, options.sigma_min_um));
    const double s_hi = std::log(std::min(sigma0_um * kSpan, options.sigma_max_um));
    const double t_lo = std::log(std::max(T0_um / kSpan, options.T_min_um));
    const double t_hi = std::log(std::min(T0_um * kSpan, options.T_max_um));
    if (!(s_lo < s_hi && t_lo < t_hi)) return out;
    const auto chi2 = [&](double ls, double lt) {
        return chi2_at(data, options, std::exp(ls), std::exp(lt));
    };
    const ProfileFunction ms = [&](double ls) {
        return minimise_1d([&](double lt) { return chi2(ls, lt); }, t_lo, t_hi);
    };
    const ProfileFunction mt = [&](double lt) {
        return minimise_1d([&](double ls) { return chi2(ls, lt); }, s_lo, s_hi);
    };
    const Profile ps = profile(s_lo, s_hi, ms);
    const Profile pt = profile(t_lo, t_hi, mt);
    // σ/T = q: for each ln q the free ln T, with ln σ = ln q + ln T inside σ's range.
    const double q0 = std::log(sigma0_um / T0_um);
    const double q_lo = std::max(q0 - std::log(kSpan), s_lo - t_hi);
    const double q_hi = std::min(q0 + std::log(kSpan), s_hi - t_lo);
    const ProfileFunction mq = [&](double lq) {
        const double lo = std::max(t_lo, s_lo - lq), hi = std::min(t_hi, s_hi - lq);
        if (!(lo < hi)) return std::pair{kInf, lo};
        // Along a fixed σ/T, χ² changes fast with the scale (g ∝ σ²): a finer scan.
        return minimise_1d([&](double lt) { return chi2(lq + lt, lt); }, lo, hi, kRatioScan);
    };
    const Profile pq = profile(q_lo, q_hi, mq);
    double chi2_min = chi2(std::log(sigma0_um), std::log(T0_um));
    out.best_sigma_um = sigma0_um;
    out.best_T_um = T0_um;
    for (int k = 0; k < kProfilePoints; ++k)
        if (ps.chi2[static_cast<std::size_t>(k)] < chi2_min) {
            chi2_min = ps.chi2[static_cast<std::size_t>(k)];
            out.best_sigma_um = std::exp(ps.a(k));
            out.best_T_um = std::exp(ps.free_at[static_cast<std::size_t>(k)]);
        }
    for (const Profile* p : {&pt, &pq})
        chi2_min = std::min(chi2_min, *std::min_element(p->chi2.begin(), p->chi2.end()));
    if (!std::isfinite(chi2_min)) return out;
    const int dof = static_cast<int>(data.size()) - 3;
    const double threshold = kChi2Quantile95 * (dof > 0 ? std::max(1.0, chi2_min / dof) : 1.0);
    const auto s = interval_of(ps, ms, chi2_min + threshold);
    const auto t = interval_of(pt, mt, chi2_min + threshold);
    const auto q = interval_of(pq, mq, chi2_min + threshold);
    if (!s || !t || !q) return out;
    out.sigma_um = *s;
    out.T_um = *t;
    out.sigma_over_T = *q;
    out.chi2_min = chi2_min;
    out.threshold = threshold;
    out.ok = true;
    return out;
}

}  // namespace roughscope::image::detail
