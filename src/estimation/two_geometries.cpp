// Roughness estimation from brightness measurements (paper §4): the general two-geometry
// solver (Eq. 14 and Eq. 16/18 at any two geometries, inverted by bracketed root finding).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <boost/math/tools/minima.hpp>
#include <boost/math/tools/toms748_solve.hpp>

#include "estimation_detail.hpp"
#include "roughscope/estimation/estimation.hpp"

namespace roughscope {
using namespace estimation_detail;
// ---------------------------------------------------------------------------------------------
// General two-geometry solver

namespace {

void check_options(const TwoGeometryOptions& o) {
    check::positive("bracket lower bound", o.lower);
    check::positive("bracket upper bound", o.upper);
    if (!(o.lower < o.upper))
        throw InvalidArgument("bracket lower bound = " + fmt(o.lower) +
                              " must be below the upper bound = " + fmt(o.upper));
    if (!(o.relative_tolerance > 0.0 && o.relative_tolerance < 1.0))
        throw InvalidArgument("relative_tolerance = " + fmt(o.relative_tolerance) +
                              " is outside (0, 1)");
    if (o.max_iterations < 1)
        throw InvalidArgument("max_iterations = " + std::to_string(o.max_iterations) +
                              " must be >= 1");
    if (!(o.min_observable_fraction >= 0.0 && o.min_observable_fraction < 1.0))
        throw InvalidArgument("min_observable_fraction = " + fmt(o.min_observable_fraction) +
                              " is outside [0, 1)");
}

ModelOptions model_options(const TwoGeometryOptions& o) {
    ModelOptions m;
    m.factor = o.factor;
    m.radiometry = o.radiometry;
    m.regime = o.regime;
    m.wavelength_um = o.wavelength_um;
    return m;
}

struct Bracket {
    double lo, hi;      // the unknown x
    double f_lo, f_hi;  // ln M at the ends
};

// Shrinks [lo, hi] (geometrically) until ln M is finite at both ends: the brightness of one
// geometry underflows for extreme values of the unknown (e.g. exp(−T²v_xy²/4)).
template <class F>
Bracket finite_bracket(F&& log_ratio, double lo, double hi) {
    auto shrink = [&](double bad, double good_side, bool from_low) {
        // Move from `bad` toward `good_side` by doubling (in log space) until finite, then
        // refine the boundary by bisection in log space.
        double b = bad, step = 1.0;
        double x = bad, fx = log_ratio(x);
        while (!std::isfinite(fx)) {
            b = x;
            x = from_low ? std::min(x * std::exp(step), good_side)
                         : std::max(x / std::exp(step), good_side);
            step *= 2.0;
            fx = log_ratio(x);
            if (x == good_side) break;
        }
        if (!std::isfinite(fx)) return std::pair{x, fx};
        for (int i = 0; i < 40 && b != x; ++i) {
            const double m = std::sqrt(b * x);
            const double fm = log_ratio(m);
            if (std::isfinite(fm)) {
                x = m;
                fx = fm;
            } else {
                b = m;
            }
            if (std::abs(std::log(x / b)) < 1e-3) break;
        }
        return std::pair{x, fx};
    };
    auto [l, fl] = shrink(lo, hi, true);
    auto [h, fh] = shrink(hi, l, false);
    return {l, h, fl, fh};
}

struct RootResult {
    double x;
    Bracket bracket;
};

// The root of g (in ln x) inside [ya, yb] where g changes sign, by TOMS 748; returns x.
template <class G>
double polish_root(G&& g, double ya, double yb, double fa, double fb, const TwoGeometryOptions& o) {
    if (fa == 0) return std::exp(ya);
    if (fb == 0) return std::exp(yb);
    const double tol = o.relative_tolerance;
    auto stop = [tol](double a, double c) { return std::abs(c - a) <= tol; };
    std::uintmax_t iterations = static_cast<std::uintmax_t>(o.max_iterations);
    const auto [ra, rb] = boost::math::tools::toms748_solve(g, ya, yb, fa, fb, stop, iterations);
    if (iterations >= static_cast<std::uintmax_t>(o.max_iterations) && std::abs(rb - ra) > tol)
        throw NoSolution("the root finder did not converge in " + std::to_string(o.max_iterations) +
                         " iterations");
    return std::exp(0.5 * (ra + rb));
}

template <class F>
RootResult solve_log_ratio(
    F&& log_ratio, double target, const TwoGeometryOptions& o,
    const std::function<std::string(const RatioRange&, const Bracket&)>& no_solution_message) {
    // Bracket the root by expanding geometrically from the middle of [lower, upper] (in log
    // space) until ln M − target changes sign. Where the model is not finite (the brightness of
    // one geometry underflowed), a side's step is halved toward the last finite point instead:
    // the side stops only at its bound or once the edge of the finite range is located to 1e-9
    // in ln x (a root between the last finite point and that edge is not skipped).
    auto g = [&](double y) { return log_ratio(std::exp(y)) - target; };
    const double ylo = std::log(o.lower), yhi = std::log(o.upper);
    const double ymid = 0.5 * (ylo + yhi);
    struct Side {
        double y, f;
        double bound;                 // ln lower or ln upper
        double dir;                   // −1 toward the lower bound, +1 toward the upper
        std::optional<double> y_bad;  // nearest point found non-finite beyond y
        double step = 2.0;
        bool can_grow() const {
            if (dir * (bound - y) <= 0.0) return false;
            return !y_bad || std::abs(*y_bad - y) > 1e-9;
        }
    };
    Side low{ymid, 0.0, ylo, -1.0, {}}, high{ymid, 0.0, yhi, 1.0, {}};
    low.y = std::max(ylo, ymid - 1.0);
    high.y = std::min(yhi, ymid + 1.0);
    low.f = g(low.y);
    high.f = g(high.y);
    // A start that is not finite: it becomes the side's known bad point, and the side restarts
    // from the middle.
    for (Side* side : {&low, &high}) {
        if (!std::isfinite(side->f)) {
            side->y_bad = side->y;
            side->y = ymid;
            side->f = g(ymid);
        }
    }
    auto grow = [&](Side& side) {
        double y = side.y + side.dir * side.step;
        if (side.dir * (y - side.bound) > 0.0) y = side.bound;
        if (side.y_bad && side.dir * (y - *side.y_bad) >= 0.0) y = 0.5 * (side.y + *side.y_bad);
        const double f = g(y);
        if (std::isfinite(f)) {
            side.y = y;
            side.f = f;
            side.step *= 2.0;
        } else {
            side.y_bad = y;
        }
    };
    auto same_sign = [](double u, double v) { return (u > 0) == (v > 0) && u != 0 && v != 0; };
    while (std::isfinite(low.f) && std::isfinite(high.f) && same_sign(low.f, high.f) &&
           (low.can_grow() || high.can_grow())) {
        if (low.can_grow()) grow(low);
        if (high.can_grow()) grow(high);
    }
    double ya = low.y, yb = high.y, fa = low.f, fb = high.f;
    if (!(std::isfinite(fa) && std::isfinite(fb)) || ((fa > 0) == (fb > 0) && fa != 0 && fb != 0)) {
        // No sign change: the ratio is outside what the model produces. Report the range the
        // model spans over the (finite part of the) bracket.
        const Bracket b = finite_bracket(log_ratio, o.lower, o.upper);
        const RatioRange range{std::exp(std::min(b.f_lo, b.f_hi)),
                               std::exp(std::max(b.f_lo, b.f_hi))};
        throw NoSolution(no_solution_message(range, b));
    }
    return {polish_root(g, ya, yb, fa, fb, o), {}};
}

// Every solution of ln M(x) = target in [lower, upper] for a model ratio that need not be
// monotonic in x (the exact series in T: the two geometries' diffuse powers change regime at
// different T). ln M is sampled on a grid of 4 points per decade of x; the edges of the finite
// part are located by bisection; a sign change between neighbours is a root (TOMS 748); an
// interior extremum of the samples is refined (Brent) and, when it crosses the target, gives two
// roots. The range reported for "no solution" is the one M spans over the samples and extrema.
struct ScanResult {
    std::vector<double> roots;  // increasing
    RatioRange range;
    Bracket bracket;  // the finite part of [lower, upper]
};

template <class F>
ScanResult scan_log_ratio(F&& log_ratio, double target, const TwoGeometryOptions& o) {
    auto g = [&](double y) { return log_ratio(std::exp(y)) - target; };
    const double ylo = std::log(o.lower), yhi = std::log(o.upper);
    constexpr double kPointsPerDecade = 4.0;
    const auto n =
        static_cast<std::size_t>(std::ceil((yhi - ylo) / std::log(10.0) * kPointsPerDecade)) + 1;
    std::vector<double> ys, fs;
    ys.reserve(n + 4);
    fs.reserve(n + 4);
    // Bisection toward the edge of the finite part between a finite and a non-finite sample, to
    // 1e-4 in ln x (a root closer than that to where the brightness underflows is not looked for).
    auto edge = [&](double y_good, double y_bad) {
        for (int i = 0; i < 60 && std::abs(y_bad - y_good) > 1e-4; ++i) {
            const double m = 0.5 * (y_good + y_bad);
            if (std::isfinite(g(m)))
                y_good = m;
            else
                y_bad = m;
        }
        return y_good;
    };
    double y_prev = 0.0, f_prev = std::numeric_limits<double>::quiet_NaN();
    for (std::size_t j = 0; j < n; ++j) {
        const double y =
            j + 1 == n ? yhi
                       : ylo + (yhi - ylo) * static_cast<double>(j) / static_cast<double>(n - 1);
        const double f = g(y);
        if (j > 0 && std::isfinite(f) != std::isfinite(f_prev)) {
            const double ye = std::isfinite(f) ? edge(y, y_prev) : edge(y_prev, y);
            if (ye != y && ye != y_prev) {
                ys.push_back(ye);
                fs.push_back(g(ye));
            }
        }
        // Finite samples, and the first non-finite one after finite ones (it marks a gap in
        // the finite part).
        if (std::isfinite(f) || (!ys.empty() && std::isfinite(fs.back()))) {
            ys.push_back(y);
            fs.push_back(f);
        }
        y_prev = y;
        f_prev = f;
    }
    ScanResult out;
    double f_min = std::numeric_limits<double>::infinity(), f_max = -f_min;
    double y_first = yhi, y_last = ylo;
    for (std::size_t j = 0; j < ys.size(); ++j) {
        if (!std::isfinite(fs[j])) continue;
        f_min = std::min(f_min, fs[j]);
        f_max = std::max(f_max, fs[j]);
        y_first = std::min(y_first, ys[j]);
        y_last = std::max(y_last, ys[j]);
    }
    auto add_root = [&](double ya, double yb, double fa, double fb) {
        out.roots.push_back(fa == 0.0 ? std::exp(ya) : polish_root(g, ya, yb, fa, fb, o));
    };
    const int kBits = 24;
    for (std::size_t j = 0; j + 1 < ys.size(); ++j) {
        const double fa = fs[j], fb = fs[j + 1];
        if (!std::isfinite(fa) || !std::isfinite(fb)) continue;
        if (fa == 0.0 || (fa > 0) != (fb > 0)) {
            add_root(ys[j], ys[j + 1], fa, fb);
            continue;
        }
        // An interior extremum of the samples on [y_j − 1, y_j + 1] without a sign change.
        if (j == 0 || !std::isfinite(fs[j - 1])) continue;
        const double fl = fs[j - 1];
        const bool is_min = fa < fl && fa<fb, is_max = fa> fl && fa > fb;
        if (!is_min && !is_max) continue;
        const double sign = is_min ? 1.0 : -1.0;
        const auto [y_ext, f_ext_signed] = boost::math::tools::brent_find_minima(
            [&](double y) {
                const double f = g(y);
                return std::isfinite(f) ? sign * f : std::numeric_limits<double>::infinity();
            },
            ys[j - 1], ys[j + 1], kBits);
        const double f_ext = sign * f_ext_signed;
        f_min = std::min(f_min, f_ext);
        f_max = std::max(f_max, f_ext);
        if (f_ext != 0.0 && (f_ext > 0) != (fa > 0)) {
            // Two roots around the extremum, between the neighbours (a root between y_{j−1} and
            // y_j was taken above only if the samples changed sign there, which they did not).
            if (y_ext > ys[j - 1] && y_ext < ys[j + 1]) {
                add_root(ys[j - 1], y_ext, fl, f_ext);
                add_root(y_ext, ys[j + 1], f_ext, fb);
            }
        }
    }
    std::sort(out.roots.begin(), out.roots.end());
    // Roots closer than the tolerance are one (a root on a sample is found from both sides).
    out.roots.erase(std::unique(out.roots.begin(), out.roots.end(),
                                [&](double a, double b) {
                                    return std::abs(std::log(b / a)) <= 10.0 * o.relative_tolerance;
                                }),
                    out.roots.end());
    if (std::isfinite(f_min))
        out.range = RatioRange{std::exp(f_min + target), std::exp(f_max + target)};
    out.bracket = Bracket{std::exp(y_first), std::exp(y_last), f_min + target, f_max + target};
    return out;
}

}  // namespace

namespace estimation_detail {

double log_very_rough_brightness_shape(const Geometry& geom, double sigma_over_T, Correlation c,
                                       const TwoGeometryOptions& o) {
    const double F2 = geometric_factor_squared(o.factor, geom);
    const ScatteringDirection q = scattering_direction(geom);
    return log_very_rough_shape(c, F2, q, sigma_over_T) +
           std::log(radiometric_factor(o.radiometry, geom));
}

double diffuse_brightness(const Geometry& geom, double sigma_um, double T_um, Correlation c,
                          const TwoGeometryOptions& o) {
    const ScatteredPower p =
        mean_scattered_power(geom, Surface{sigma_um, T_um, c}, model_options(o));
    return p.diffuse * radiometric_factor(o.radiometry, geom);
}

}  // namespace estimation_detail

double model_ratio_very_rough(const Geometry& geom1, const Geometry& geom2, double sigma_over_T,
                              Correlation correlation, const TwoGeometryOptions& options) {
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    check::positive("sigma/T", sigma_over_T);
    return std::exp(log_very_rough_brightness_shape(geom1, sigma_over_T, correlation, options) -
                    log_very_rough_brightness_shape(geom2, sigma_over_T, correlation, options));
}

double model_ratio_diffuse(const Geometry& geom1, const Geometry& geom2, double sigma_um,
                           double T_um, Correlation correlation,
                           const TwoGeometryOptions& options) {
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    return diffuse_brightness(geom1, sigma_um, T_um, correlation, options) /
           diffuse_brightness(geom2, sigma_um, T_um, correlation, options);
}

namespace {

void check_distinct_very_rough(const Geometry& g1, const Geometry& g2) {
    const ScatteringDirection q1 = scattering_direction(g1), q2 = scattering_direction(g2);
    const double a1 = q1.qxy2() / q1.qz2(), a2 = q2.qxy2() / q2.qz2();
    if (std::abs(a1 - a2) <= 1e-12 * std::max({a1, a2, 1e-300}))
        throw InvalidArgument("geom1 " + geometry_text(g1) + " and geom2 " + geometry_text(g2) +
                              " have the same v_xy^2/v_z^2 = " + fmt(a1) +
                              ": their brightness ratio does not depend on sigma/T");
}

void check_distinct_diffuse(const Geometry& g1, const Geometry& g2, double wavelength_um) {
    const double v1 = scattering_vector(g1, wavelength_um).vxy2();
    const double v2 = scattering_vector(g2, wavelength_um).vxy2();
    if (std::abs(v1 - v2) <= 1e-12 * std::max({v1, v2, 1e-300}))
        throw InvalidArgument("geom1 " + geometry_text(g1) + " and geom2 " + geometry_text(g2) +
                              " have the same v_xy^2 = " + fmt(v1) +
                              " um^-2: their brightness ratio does not depend on T");
}

}  // namespace

// Eq. 16/18 generalised to any two geometries, inverted by TOMS 748.
double sigma_over_T_two_geometries(double E1_over_E2, const Geometry& geom1, const Geometry& geom2,
                                   Correlation correlation, const TwoGeometryOptions& options) {
    check_ratio("E1/E2", E1_over_E2);
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    check_options(options);
    check_distinct_very_rough(geom1, geom2);
    auto f = very_rough_log_ratio(geom1, geom2, correlation, options);
    return solve_log_ratio(f, std::log(E1_over_E2), options,
                           [&](const RatioRange& r, const Bracket& b) {
                               return ratio_text(E1_over_E2) + " has no solution for sigma/T (" +
                                      std::string(info(correlation).adjective) + " correlation, " +
                                      std::string(info(correlation).very_rough_equation) + ", " +
                                      factor_name(options.factor) + ") at geom1 " +
                                      geometry_text(geom1) + ", geom2 " + geometry_text(geom2) +
                                      ": for sigma/T in [" + fmt(b.lo) + ", " + fmt(b.hi) +
                                      "] E1/E2 must be " + range_text(r);
                           })
        .x;
}

// Eq. 14 generalised (any geometries, any regime and correlation), inverted by TOMS 748.
double correlation_length_two_geometries(double E1_over_E2, const Geometry& geom1,
                                         const Geometry& geom2, double sigma_um,
                                         Correlation correlation,
                                         const TwoGeometryOptions& options) {
    check_ratio("E1/E2", E1_over_E2);
    check_length_um("sigma", sigma_um);
    check_length_um("wavelength", options.wavelength_um);
    check::geometry(geom1, "geom1");
    check::geometry(geom2, "geom2");
    check_options(options);
    check_distinct_diffuse(geom1, geom2, options.wavelength_um);
    auto f = diffuse_log_ratio_T(geom1, geom2, sigma_um, correlation, options);
    const auto context = [&] {
        return " (" + std::string(to_string(correlation)) + " correlation, " +
               std::string(to_string(options.regime)) + " regime, " + factor_name(options.factor) +
               ", sigma = " + fmt(sigma_um) + " um, lambda = " + fmt(options.wavelength_um) +
               " um) at geom1 " + geometry_text(geom1) + ", geom2 " + geometry_text(geom2);
    };
    const auto no_solution = [&](const RatioRange& r, const Bracket& b) {
        return ratio_text(E1_over_E2) + " has no solution for the correlation length" + context() +
               ": for T in [" + fmt(b.lo) + ", " + fmt(b.hi) + "] um E1/E2 must be " +
               range_text(r);
    };
    // The first term (Eq. 3, or the exponential one) and the very-rough forms give ln M linear
    // in T² (Gaussian) or in ln(1 + T²·const) terms of one sign: monotonic in T. The exact series
    // need not be (the geometries' diffuse powers change regime at different T): every solution
    // is looked for, and more than one is an error that lists them.
    if (options.regime != Regime::Series && options.regime != Regime::Auto)
        return solve_log_ratio(f, std::log(E1_over_E2), options, no_solution).x;
    ScanResult scan = scan_log_ratio(f, std::log(E1_over_E2), options);
    if (scan.roots.empty()) throw NoSolution(no_solution(scan.range, scan.bracket));
    const auto observable = [&](double T_um) {
        for (const Geometry* g : {&geom1, &geom2}) {
            const Geometry specular{g->theta_i_rad, g->theta_i_rad, 0.0};
            const double d = diffuse_brightness(*g, sigma_um, T_um, correlation, options);
            const double peak = diffuse_brightness(specular, sigma_um, T_um, correlation, options);
            if (!(peak > 0.0) || !(d >= options.min_observable_fraction * peak)) return false;
        }
        return true;
    };
    // Several solutions: those where a camera could not see the sample are dropped (kept all
    // when that leaves none).
    if (scan.roots.size() > 1) {
        std::vector<double> kept;
        std::copy_if(scan.roots.begin(), scan.roots.end(), std::back_inserter(kept), observable);
        if (!kept.empty()) scan.roots = std::move(kept);
    }
    if (scan.roots.size() > 1) {
        std::string list;
        for (std::size_t k = 0; k < scan.roots.size(); ++k)
            list += (k == 0                       ? ""
                     : k + 1 == scan.roots.size() ? " and "
                                                  : ", ") +
                    fmt(scan.roots[k]);
        throw NoSolution(ratio_text(E1_over_E2) + " does not determine the correlation length" +
                         context() + ": the model ratio is not monotonic in T there, and T = " +
                         list + " um all give it; narrow the bracket [" + fmt(options.lower) +
                         ", " + fmt(options.upper) + "] um to the solution wanted");
    }
    return scan.roots.front();
}

}  // namespace roughscope
