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

// The names of the correlation descriptor (correlation.hpp), in the table scheme of names.hpp.
constexpr std::array<NameEntry<Correlation>, kCorrelationCount> correlation_names() {
    std::array<NameEntry<Correlation>, kCorrelationCount> names{};
    for (std::size_t k = 0; k < kCorrelationCount; ++k)
        names[k] = {kCorrelationInfo[k].name, kCorrelationInfo[k].correlation};
    return names;
}
constexpr std::array<NameEntry<Correlation>, kCorrelationCount> kCorrelationNames =
    correlation_names();

constexpr std::array<NameEntry<Regime>, 5> kRegimeNames{{
    {"auto", Regime::Auto},
    {"series", Regime::Series},
    {"slightly_rough", Regime::SlightlyRough},
    {"very_rough", Regime::VeryRough},
    {"very_rough_series_limit", Regime::VeryRoughSeriesLimit},
}};

}  // namespace

std::string_view to_string(Correlation c) { return name_of(kCorrelationNames, c); }
std::string_view to_string(DiffuseMethod m) {
    switch (m) {
        case DiffuseMethod::ClosedForm:
            return "closed_form";
        case DiffuseMethod::Summation:
            return "summation";
        case DiffuseMethod::LargeGExpansion:
            return "large_g_expansion";
    }
    return "unknown";
}

void check_length_um(std::string_view name, double value_um) {
    if (!(value_um >= kMinLengthUm && value_um <= kMaxLengthUm)) {
        std::string message(name);
        message.append(" = ")
            .append(check::format_number(value_um))
            .append(" um is outside the valid range [")
            .append(check::format_number(kMinLengthUm))
            .append(", ")
            .append(check::format_number(kMaxLengthUm))
            .append("] um");
        throw InvalidArgument(message);
    }
}
std::string_view to_string(Regime r) { return name_of(kRegimeNames, r); }
Correlation parse_correlation(std::string_view name) {
    return parse_name(kCorrelationNames, "correlation", name);
}
Regime parse_regime(std::string_view name) { return parse_name(kRegimeNames, "regime", name); }

ScatteredPower mean_scattered_power(const Geometry& geom, const Surface& surface,
                                    const ModelOptions& options) {
    check::geometry(geom);
    check_length_um("sigma", surface.sigma_um);
    check_length_um("T", surface.T_um);
    check_length_um("wavelength", options.wavelength_um);
    check_length_um("patch_x (half-width X)", options.patch_x_um);
    check_length_um("patch_y (half-width Y)", options.patch_y_um);
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

    ScatteredPower out;
    out.method = DiffuseMethod::ClosedForm;
    Regime regime = options.regime;
    if (regime == Regime::Auto) {
        const double ratio = second_term_ratio(surface.correlation, g, T * T * vxy2);
        regime = ratio < options.auto_tolerance ? Regime::SlightlyRough : Regime::Series;
        // The omitted terms relative to the first (the term ratios decrease, Eq. 2).
        if (regime == Regime::SlightlyRough) out.relative_error_bound = ratio / (1.0 - ratio);
    }

    double D = 0.0;
    const Correlation c = surface.correlation;
    switch (regime) {
        case Regime::Series: {
            const SeriesResult sum = diffuse_series(c, g, T * T * vxy2);
            D = info(c).diffuse_prefactor * T * T / area * F2 * sum.value;
            out.method = sum.method;
            out.relative_error_bound = sum.relative_error_bound;
            break;
        }
        case Regime::SlightlyRough:
            D = diffuse_power_slightly_rough(c, F2, T, area, g, vxy2);
            break;
        case Regime::VeryRough:
            D = diffuse_power_very_rough(c, F2, sigma, T, area, vz2, vxy2);
            break;
        case Regime::VeryRoughSeriesLimit:
            D = diffuse_power_very_rough_series_limit(c, F2, sigma, T, area, g, vz2, vxy2);
            break;
        case Regime::Auto:
            break;  // resolved above
    }

    out.coherent = coherent_power(rho0, g);
    out.diffuse = D;
    out.total = out.coherent + D;
    out.brightness = out.total * radiometric_factor(options.radiometry, geom);
    out.g = g;
    out.regime = regime;
    out.roughness_class = roughness_class(g);
    if (!std::isfinite(out.brightness) || !std::isfinite(out.total)) {
        std::string message = "the scattered power exceeds the double range (D = ";
        message.append(check::format_number(D))
            .append(") at theta_i = ")
            .append(check::format_number(rad_to_deg(geom.theta_i_rad)))
            .append(" deg, theta_s = ")
            .append(check::format_number(rad_to_deg(geom.theta_s_rad)))
            .append(" deg with sigma = ")
            .append(check::format_number(sigma))
            .append(" um, T = ")
            .append(check::format_number(T))
            .append(" um, wavelength = ")
            .append(check::format_number(options.wavelength_um))
            .append(" um, patch_x = ")
            .append(check::format_number(options.patch_x_um))
            .append(" um, patch_y = ")
            .append(check::format_number(options.patch_y_um))
            .append(" um: enlarge the patch or move away from grazing angles");
        throw InvalidArgument(message);
    }
    return out;
}

double very_rough_brightness(const Geometry& geom, double sigma_over_T, Correlation correlation,
                             GeometricFactor factor, Radiometry radiometry) {
    check::geometry(geom);
    check::positive("sigma_over_T", sigma_over_T);
    const ScatteringDirection q = scattering_direction(geom);
    const double F2 = geometric_factor_squared(factor, geom);
    const double shape = very_rough_shape(correlation, F2, q, sigma_over_T);
    return shape * radiometric_factor(radiometry, geom);
}

double diffuse_power_quadrature(Correlation correlation, double F2, double T_um, double area_um2,
                                double g, double vxy2) {
    check::non_negative("F2", F2);
    check::positive("T", T_um, "um");
    check::positive("area", area_um2, "um^2");
    check::non_negative("g", g);
    check::non_negative("vxy2", vxy2, "1/um^2");
    if (!(g <= kQuadratureMaxG))
        throw InvalidArgument("g = " + check::format_number(g) +
                              " is outside the domain of diffuse_power_quadrature: g must be in "
                              "[0, " +
                              check::format_number(kQuadratureMaxG) +
                              "] (use the series, exact for every g)");
    const double w = T_um * std::sqrt(vxy2);  // J0 argument per unit u = τ/T
    if (!(w <= kQuadratureMaxTvxy))
        throw InvalidArgument("T v_xy = " + check::format_number(w) +
                              " is outside the domain of diffuse_power_quadrature: T v_xy must "
                              "be in [0, " +
                              check::format_number(kQuadratureMaxTvxy) + "]");
    const double scale = 2.0 * kPi / area_um2 * F2 * T_um * T_um;  // D = scale ∫ ... du
    if (!std::isfinite(scale))
        throw InvalidArgument("(2 pi/A) F2 T^2 = " + check::format_number(scale) + " (F2 = " +
                              check::format_number(F2) + ", T = " + check::format_number(T_um) +
                              " um, area = " + check::format_number(area_um2) +
                              " um^2) is outside the domain of diffuse_power_quadrature: it "
                              "must be a finite number");
    if (g == 0.0 || scale == 0.0) return 0.0;
    auto C = [correlation](double u) { return acf(correlation, u); };
    // log of the envelope e^{−g}(exp(g C(u)) − 1), without overflow or 0·inf for any g.
    auto log_envelope = [g](double c) {
        const double x = g * c;
        return (x > 30.0 ? x + std::log1p(-std::exp(-x)) : std::log(std::expm1(x))) - g;
    };
    // Integrand in u = τ/T:  e^{−g} (exp(g C(u)) − 1) J0(w u) u.
    auto f = [&](double u) {
        return std::exp(log_envelope(C(u))) * std::cyl_bessel_j(0.0, w * u) * u;
    };
    // Cut where the envelope is below e^{−70} of its value at 0 (doubling, then bisection).
    const double log_env0 = log_envelope(1.0);
    auto negligible = [&](double u) { return log_envelope(C(u)) - log_env0 < -70.0; };
    double u_lo = 0.0, u_max = 1.0;
    while (!negligible(u_max)) {
        u_lo = u_max;
        u_max *= 2.0;
    }
    for (int i = 0; i < 60 && u_max - u_lo > 1e-3 * u_max; ++i) {
        const double mid = 0.5 * (u_lo + u_max);
        (negligible(mid) ? u_max : u_lo) = mid;
    }
    std::vector<double> cuts{0.0};
    // Geometric breakpoints resolve the peak of width ~1/g (exp.) or 1/√g (Gauss.) at u = 0.
    const double width = diffuse_kernel_width_over_T(correlation, g);
    for (double u = width / 8.0; u < u_max; u *= 2.0) cuts.push_back(u);
    // Half-periods of J0 (at most kQuadratureMaxTvxy · u_max / π of them).
    if (w > 0.0)
        for (double u = kPi / w; u < u_max; u += kPi / w) cuts.push_back(u);
    cuts.push_back(u_max);
    std::sort(cuts.begin(), cuts.end());
    double integral = 0.0;
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
        if (cuts[k + 1] <= cuts[k]) continue;
        integral += boost::math::quadrature::gauss_kronrod<double, 61>::integrate(
            f, cuts[k], cuts[k + 1], 0, 1e-13);
    }
    // D ≥ 0; a negative sum is rounding in a far tail of the lobe.
    return std::max(0.0, scale * integral);
}

}  // namespace roughscope
