// Roughness estimation from brightness measurements (paper §4): estimates with first-order
// uncertainty and the derived quantities of §3.5 (RMS slope, Caron's θK and ξK, g, class).
#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "estimation_detail.hpp"
#include "roughscope/estimation/estimation.hpp"

namespace roughscope {
using namespace estimation_detail;
// ---------------------------------------------------------------------------------------------
// Derived quantities and roughness class

namespace {

std::string class_text(RoughnessClass c) { return std::string(to_string(c)); }

constexpr std::size_t kListedMeasurements = 4;

// "measurement 2 (...)" or "measurements 1 (...), 3 (...), ... (7 of 205)".
std::string list_measurements(const std::vector<std::string>& items, std::size_t count,
                              std::size_t total) {
    std::string s = count == 1 ? "measurement " : "measurements ";
    for (std::size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + items[i];
    if (count > items.size()) s += ", ...";
    if (count > 1) s += " (" + std::to_string(count) + " of " + std::to_string(total) + ")";
    return s;
}

bool is_normal_view(const Geometry& g) { return g.theta_s_rad == 0.0; }

void check_noise(const BrightnessNoise& n) {
    check::non_negative("relative noise of E1", n.relative_E1);
    check::non_negative("relative noise of E2", n.relative_E2);
}

double log_ratio_variance(const BrightnessNoise& n) {
    return n.relative_E1 * n.relative_E1 + n.relative_E2 * n.relative_E2;
}

}  // namespace

// §3.5: m = σ√2/T, θK = π/2 − atan(m), ξK = 1 − exp(−T²/4σ²), with first-order errors.
void fill_derived_quantities(RoughnessEstimate& est, const std::vector<Geometry>& geometries) {
    if (!est.sigma_over_T) return;
    const double s = est.sigma_over_T->value, sd = est.sigma_over_T->std_error;
    est.rms_slope = Estimate{rms_slope(s), std::sqrt(2.0) * sd};
    est.theta_K_rad = Estimate{caron_theta_K_rad(s), std::sqrt(2.0) / (1.0 + 2.0 * s * s) * sd};
    est.xi_K = Estimate{caron_xi_K(s), std::exp(-1.0 / (4.0 * s * s)) / (2.0 * s * s * s) * sd};
    if (!info(est.correlation).caron_formulas) {
        // θK is Caron's angle for a Gaussian correlation: the validity warning uses it only then.
        est.warnings.push_back(
            "theta_K, xi_K and the RMS slope are Caron's formulas for a Gaussian correlation "
            "function; for this " +
            std::string(info(est.correlation).name) +
            "-correlation estimate they are indicative only");
        return;
    }
    const double theta_K = est.theta_K_rad->value;
    std::vector<std::string> items;
    std::size_t count = 0;
    for (std::size_t i = 0; i < geometries.size(); ++i) {
        const Geometry& g = geometries[i];
        const double angle = std::max(g.theta_i_rad, g.theta_s_rad);
        if (angle > theta_K) {
            ++count;
            if (items.size() < kListedMeasurements)
                items.push_back(std::to_string(i + 1) + " (" +
                                (g.theta_i_rad >= g.theta_s_rad ? "theta_i" : "theta_s") + " = " +
                                deg(angle) + ")");
        }
    }
    if (count > 0)
        est.warnings.push_back(
            list_measurements(items, count, geometries.size()) +
            (count == 1 ? " exceeds" : " exceed") +
            " Caron's angle of RMS slope theta_K = " + deg(theta_K) +
            ": the model is not valid there (paper 5.2: shadowing and multiple scattering)");
}

void fill_roughness_class(RoughnessEstimate& est, const std::vector<Geometry>& geometries,
                          double sigma_um, double wavelength_um,
                          std::optional<RoughnessClass> assumed) {
    est.g.clear();
    double g_max = 0.0;
    std::vector<std::string> items;
    std::size_t count = 0;
    for (std::size_t i = 0; i < geometries.size(); ++i) {
        const double g = roughness_g(geometries[i], sigma_um, wavelength_um);
        est.g.push_back(g);
        g_max = std::max(g_max, g);
        const RoughnessClass c = roughness_class(g);
        if (assumed && c != *assumed) {
            ++count;
            if (items.size() < kListedMeasurements)
                items.push_back(std::to_string(i + 1) + " (g = " + format_message(g, 4) + ", " +
                                class_text(c) + ")");
        }
    }
    if (count > 0) {
        const std::string form =
            *assumed == RoughnessClass::SlightlyRough
                ? "the slightly-rough form (Eq. 3) assumes g < " + fmt(kSlightlyRoughMaxG)
            : *assumed == RoughnessClass::VeryRough
                ? "the very-rough forms (Eq. 4, 5) assume g > " + fmt(kVeryRoughMinG)
                : "the estimator assumes a moderately rough surface";
        est.warnings.push_back(list_measurements(items, count, geometries.size()) + ": " + form +
                               "; the estimate is approximate");
    }
    est.roughness_class = roughness_class(g_max);
    est.roughness_class_assumed = false;
}

// ---------------------------------------------------------------------------------------------
// Estimates with uncertainty

// Eq. 12–13 with first-order propagation of the brightness noise.
RoughnessEstimate estimate_sigma_specular(const SpecularInput& in) {
    check::non_negative("relative noise of E_tot", in.relative_noise_tot);
    check::non_negative("relative noise of E_dif", in.relative_noise_dif);
    double R = in.R_spec;
    if (in.E_tot || in.E_dif) {
        if (!(in.E_tot && in.E_dif))
            throw InvalidArgument(
                "E_tot and E_dif must be given together (R_spec = 1 - E_dif/E_tot)");
        R = specular_reflectance_from_brightness(*in.E_tot, *in.E_dif);
        check::positive("R0", in.R0);
        if (!(R < in.R0))  // name the inputs, not only the derived R_spec
            throw InvalidArgument(
                "R_spec = 1 - E_dif/E_tot = " + check::format_number(R) + " (E_tot = " +
                check::format_number(*in.E_tot) + ", E_dif = " + check::format_number(*in.E_dif) +
                ") is invalid: it must be below R0 = " + check::format_number(in.R0) +
                " (Eq. 13 needs 0 < R_spec < R0; E_dif/E_tot must exceed " +
                check::format_number(1.0 - in.R0) + ")");
    }
    const double sigma = sigma_from_specular(R, in.theta_rad, in.wavelength_um, in.R0);
    const double sd_R = (1.0 - R) * std::sqrt(in.relative_noise_tot * in.relative_noise_tot +
                                              in.relative_noise_dif * in.relative_noise_dif);
    const double dsdR = d_sigma_d_specular_reflectance(R, in.theta_rad, in.wavelength_um, in.R0);
    RoughnessEstimate est;
    const double sd_sigma = sd_R == 0.0 ? 0.0 : std::abs(dsdR) * sd_R;
    est.sigma_um = Estimate{sigma, sd_sigma};
    if (!std::isfinite(sd_sigma))
        est.warnings.push_back(
            "the standard error of sigma is unavailable: at R_spec = " + check::format_number(R) +
            " dsigma/dR_spec times the noise exceeds the double range (R_spec is too close to 0 "
            "for the noise to bound sigma)");
    // Eq. 12 (the coherent term) holds in every regime: no class is assumed.
    const Geometry geom = specular_geometry(in.theta_rad);
    fill_roughness_class(est, {geom}, sigma, in.wavelength_um, std::nullopt);
    return est;
}

// Eq. 14–15 (or the general solver) with first-order propagation.
RoughnessEstimate estimate_correlation_length(const CorrelationLengthInput& in) {
    check_noise(in.noise);
    check::non_negative("standard error of sigma", in.sigma_um_std_error, "um");
    const TwoGeometryOptions& o = in.options;
    const double var_ln_r = log_ratio_variance(in.noise);
    double T = 0.0, dT_dlnr = 0.0, dT_dsigma = 0.0;
    if (is_normal_view(in.geom1) && is_normal_view(in.geom2) &&
        info(in.correlation).slightly_rough_inverse && o.regime == Regime::SlightlyRough) {
        T = correlation_length_from_ratio(in.E1_over_E2, in.sigma_um, in.geom1.theta_i_rad,
                                          in.geom2.theta_i_rad, o.wavelength_um, o.factor);
        dT_dlnr = d_correlation_length_d_log_ratio(in.E1_over_E2, in.sigma_um, in.geom1.theta_i_rad,
                                                   in.geom2.theta_i_rad, o.wavelength_um, o.factor);
        dT_dsigma = d_correlation_length_d_sigma(in.E1_over_E2, in.sigma_um, in.geom1.theta_i_rad,
                                                 in.geom2.theta_i_rad, o.wavelength_um, o.factor);
    } else {
        T = correlation_length_two_geometries(in.E1_over_E2, in.geom1, in.geom2, in.sigma_um,
                                              in.correlation, o);
        // Implicit function theorem on ln M(σ, T) = ln r.
        auto fT = diffuse_log_ratio_T(in.geom1, in.geom2, in.sigma_um, in.correlation, o);
        const double dlnM_dlnT = d_log_ratio_d_log_x(fT, T);
        auto fs = [&](double sigma) {
            return std::log(diffuse_brightness(in.geom1, sigma, T, in.correlation, o)) -
                   std::log(diffuse_brightness(in.geom2, sigma, T, in.correlation, o));
        };
        const double dlnM_dlns = d_log_ratio_d_log_x(fs, in.sigma_um);
        dT_dlnr = T / dlnM_dlnT;
        dT_dsigma = -(T / in.sigma_um) * dlnM_dlns / dlnM_dlnT;
    }
    const double sd_sigma = in.sigma_um_std_error;
    const double sd_T =
        std::sqrt(dT_dlnr * dT_dlnr * var_ln_r + dT_dsigma * dT_dsigma * sd_sigma * sd_sigma);
    const double s = in.sigma_um / T;
    const double ds_dsigma = 1.0 / T - in.sigma_um / (T * T) * dT_dsigma;
    const double ds_dlnr = -in.sigma_um / (T * T) * dT_dlnr;
    const double sd_s =
        std::sqrt(ds_dsigma * ds_dsigma * sd_sigma * sd_sigma + ds_dlnr * ds_dlnr * var_ln_r);

    RoughnessEstimate est;
    est.correlation = in.correlation;
    est.sigma_um = Estimate{in.sigma_um, sd_sigma};
    est.T_um = Estimate{T, sd_T};
    est.sigma_over_T = Estimate{s, sd_s};
    const std::vector<Geometry> geoms{in.geom1, in.geom2};
    // The one-term forms assume a slightly rough surface; the exact series holds in every
    // regime (Auto picks whichever is accurate), so no class is assumed then.
    fill_roughness_class(est, geoms, in.sigma_um, o.wavelength_um,
                         o.regime == Regime::SlightlyRough
                             ? std::optional<RoughnessClass>(RoughnessClass::SlightlyRough)
                             : std::nullopt);
    fill_derived_quantities(est, geoms);
    return est;
}

// Eq. 16–19 (or the general solver) with first-order propagation.
RoughnessEstimate estimate_slope(const SlopeInput& in) {
    check_noise(in.noise);
    const TwoGeometryOptions& o = in.options;
    double s = 0.0, ds_dlnr = 0.0;
    if (is_normal_view(in.geom1) && is_normal_view(in.geom2)) {
        // θs = 0: the radiometric factor is 1 for both, so Eq. 17/19 apply for any radiometry.
        const double t1 = in.geom1.theta_i_rad, t2 = in.geom2.theta_i_rad;
        s = sigma_over_T_from_ratio(in.correlation, in.E1_over_E2, t1, t2, o.factor);
        ds_dlnr = d_sigma_over_T_d_log_ratio(in.correlation, in.E1_over_E2, t1, t2, o.factor);
    } else {
        s = sigma_over_T_two_geometries(in.E1_over_E2, in.geom1, in.geom2, in.correlation, o);
        auto f = very_rough_log_ratio(in.geom1, in.geom2, in.correlation, o);
        ds_dlnr = s / d_log_ratio_d_log_x(f, s);
    }
    RoughnessEstimate est;
    est.correlation = in.correlation;
    const double sd_s = std::abs(ds_dlnr) * std::sqrt(log_ratio_variance(in.noise));
    est.sigma_over_T = Estimate{s, sd_s};
    const std::vector<Geometry> geoms{in.geom1, in.geom2};
    if (in.sigma_um) {
        check_length_um("sigma", *in.sigma_um);
        check_length_um("wavelength", o.wavelength_um);
        est.sigma_um = Estimate{*in.sigma_um, 0.0};
        est.T_um = Estimate{*in.sigma_um / s, *in.sigma_um / (s * s) * sd_s};
        fill_roughness_class(est, geoms, *in.sigma_um, o.wavelength_um, RoughnessClass::VeryRough);
    } else {
        est.roughness_class = RoughnessClass::VeryRough;
        est.roughness_class_assumed = true;
    }
    fill_derived_quantities(est, geoms);
    return est;
}

}  // namespace roughscope
