#include "roughscope/scattering/beckmann.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <boost/math/quadrature/gauss_kronrod.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"

namespace roughscope {
namespace {

constexpr std::array<NameEntry<Correlation>, 2> kCorrelationNames{{
    {"gaussian", Correlation::Gaussian},
    {"exponential", Correlation::Exponential},
}};

constexpr std::array<NameEntry<Regime>, 5> kRegimeNames{{
    {"auto", Regime::Auto},
    {"series", Regime::Series},
    {"slightly_rough", Regime::SlightlyRough},
    {"very_rough", Regime::VeryRough},
    {"very_rough_series_limit", Regime::VeryRoughSeriesLimit},
}};

// Relative size of the second series term against the first (bounds all omitted terms).
double second_term_ratio(Correlation c, double g, double T2_vxy2) {
    if (c == Correlation::Gaussian) return g / 4.0 * std::exp(T2_vxy2 / 8.0);  // (g/4) e^{a/2}
    return g * std::pow((1.0 + T2_vxy2) / (4.0 + T2_vxy2), 1.5);
}

}  // namespace

std::string_view to_string(Correlation c) { return name_of(kCorrelationNames, c); }
std::string_view to_string(Regime r) { return name_of(kRegimeNames, r); }
Correlation parse_correlation(std::string_view name) {
    return parse_name(kCorrelationNames, "correlation", name);
}
Regime parse_regime(std::string_view name) { return parse_name(kRegimeNames, "regime", name); }

ScatteredPower mean_scattered_power(const Geometry& geom, const Surface& surface,
                                    const ModelOptions& options) {
    check::geometry(geom);
    check::positive("sigma", surface.sigma_um, "um");
    check::positive("T", surface.T_um, "um");
    check::positive("wavelength", options.wavelength_um, "um");
    check::positive("patch_x (half-width X)", options.patch_x_um, "um");
    check::positive("patch_y (half-width Y)", options.patch_y_um, "um");
    if (!(options.auto_tolerance > 0.0 && options.auto_tolerance < 1.0))
        throw InvalidArgument("auto_tolerance = " + check::format_number(options.auto_tolerance) +
                              " is outside the valid range (0, 1)");

    const ScatteringVector v = scattering_vector(geom, options.wavelength_um);
    const double vxy2 = v.vxy2(), vz2 = v.vz * v.vz;
    const double sigma = surface.sigma_um, T = surface.T_um;
    const double area = 4.0 * options.patch_x_um * options.patch_y_um;  // A = 4XY
    const double g = roughness_g(sigma, v.vz);
    const double F2 = geometric_factor_squared(options.factor, geom);
    const double rho0 = specular_amplitude_rho0(v.vx, v.vy, options.patch_x_um, options.patch_y_um);

    Regime regime = options.regime;
    if (regime == Regime::Auto) {
        regime = second_term_ratio(surface.correlation, g, T * T * vxy2) < options.auto_tolerance
                     ? Regime::SlightlyRough
                     : Regime::Series;
    }

    double D = 0.0;
    const bool gaussian = surface.correlation == Correlation::Gaussian;
    switch (regime) {
        case Regime::Series:
            D = gaussian ? diffuse_power_gaussian_series(F2, T, area, g, vxy2)
                         : diffuse_power_exponential_series(F2, T, area, g, vxy2);
            break;
        case Regime::SlightlyRough:
            D = gaussian ? diffuse_power_slightly_rough_gaussian(F2, T, area, g, vxy2)
                         : diffuse_power_slightly_rough_exponential(F2, T, area, g, vxy2);
            break;
        case Regime::VeryRough:
            D = gaussian ? diffuse_power_very_rough_gaussian(F2, sigma, T, area, vz2, vxy2)
                         : diffuse_power_very_rough_exponential(F2, sigma, T, area, vz2, vxy2);
            break;
        case Regime::VeryRoughSeriesLimit:
            D = gaussian ? diffuse_power_very_rough_gaussian(F2, sigma, T, area, vz2, vxy2)
                         : diffuse_power_very_rough_exponential_series_limit(F2, T, area, g, vxy2);
            break;
        case Regime::Auto:
            break;  // resolved above
    }

    ScatteredPower out;
    out.coherent = coherent_power(rho0, g);
    out.diffuse = D;
    out.total = out.coherent + D;
    out.brightness = out.total * radiometric_factor(options.radiometry, geom);
    out.g = g;
    out.regime = regime;
    out.roughness_class = roughness_class(g);
    return out;
}

double very_rough_brightness(const Geometry& geom, double sigma_over_T, Correlation correlation,
                             GeometricFactor factor, Radiometry radiometry) {
    check::geometry(geom);
    check::positive("sigma_over_T", sigma_over_T);
    const ScatteringDirection q = scattering_direction(geom);
    const double F2 = geometric_factor_squared(factor, geom);
    const double shape = correlation == Correlation::Gaussian
                             ? very_rough_shape_gaussian(F2, q, sigma_over_T)
                             : very_rough_shape_exponential(F2, q, sigma_over_T);
    return shape * radiometric_factor(radiometry, geom);
}

double diffuse_power_quadrature(Correlation correlation, double F2, double T_um, double area_um2,
                                double g, double vxy2) {
    check::non_negative("F2", F2);
    check::positive("T", T_um, "um");
    check::positive("area", area_um2, "um^2");
    check::non_negative("g", g);
    check::non_negative("vxy2", vxy2);
    if (g == 0.0) return 0.0;
    const bool gaussian = correlation == Correlation::Gaussian;
    const double w = T_um * std::sqrt(vxy2);  // J0 argument per unit u = τ/T
    const double eg = std::exp(-g);
    // Integrand in u = τ/T:  e^{−g} (exp(g C(u)) − 1) J0(w u) u.
    auto f = [&](double u) {
        const double C = gaussian ? std::exp(-u * u) : std::exp(-u);
        return eg * std::expm1(g * C) * std::cyl_bessel_j(0.0, w * u) * u;
    };
    // Where the envelope e^{−g}(e^{gC} − 1) ≤ 1e−30 relative to its value at 0 (≈ 1 − e^{−g}).
    const double log_cut = 70.0 + std::log(std::max(g, 1.0));
    const double u_max = gaussian ? std::sqrt(log_cut) : log_cut;
    std::vector<double> cuts{0.0};
    // Geometric breakpoints resolve the peak of width ~1/g (exp.) or 1/√g (Gauss.) at u = 0.
    const double width = gaussian ? 1.0 / std::sqrt(std::max(g, 1.0)) : 1.0 / std::max(g, 1.0);
    for (double u = width / 8.0; u < u_max; u *= 2.0) cuts.push_back(u);
    // Half-periods of J0.
    if (w > 0.0)
        for (double u = kPi / w; u < u_max; u += kPi / w) cuts.push_back(u);
    cuts.push_back(u_max);
    std::sort(cuts.begin(), cuts.end());
    double integral = 0.0;
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
        if (cuts[k + 1] <= cuts[k]) continue;
        integral += boost::math::quadrature::gauss_kronrod<double, 61>::integrate(
            f, cuts[k], cuts[k + 1], 2, 1e-13);
    }
    // D = (2π/A) F² T² ∫ ... du
    return 2.0 * kPi / area_um2 * F2 * T_um * T_um * integral;
}

}  // namespace roughscope
