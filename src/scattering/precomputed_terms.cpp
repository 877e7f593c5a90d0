// Geometry-only terms of the very-rough and Oren–Nayar models (precomputed_terms.hpp).
#include "roughscope/scattering/precomputed_terms.hpp"

#include <cassert>
#include <cmath>
#include <string>

#include "roughscope/core/errors.hpp"

namespace roughscope {

namespace {
void check_geometries(std::span<const Geometry> geoms) {
    for (std::size_t k = 0; k < geoms.size(); ++k)
        check::geometry(geoms[k], "geometry " + std::to_string(k));
}
}  // namespace

VeryRoughTerms::VeryRoughTerms(std::span<const Geometry> geoms, GeometricFactor factor,
                               Radiometry radiometry) {
    check_geometries(geoms);
    a_.resize(geoms.size());
    b_.resize(geoms.size());
    for (std::size_t k = 0; k < geoms.size(); ++k) {
        const Geometry& g = geoms[k];
        const ScatteringDirection q = scattering_direction(g);  // §3.1
        const double F2 = geometric_factor_squared(factor, g);  // §3.2
        a_[k] = F2 / q.qz2() * radiometric_factor(radiometry, g);
        b_[k] = q.qxy2() / q.qz2();
    }
}

void VeryRoughTerms::brightness(double sigma_over_T, Correlation correlation,
                                std::span<double> out) const {
    check::positive("sigma_over_T", sigma_over_T);
    assert(out.size() == size());
    const double m2 = sigma_over_T * sigma_over_T;
    for (std::size_t k = 0; k < size(); ++k)
        out[k] = a_[k] * very_rough_profile(correlation, b_[k] / m2);  // Eq. 4 / Eq. 5
}

void VeryRoughTerms::brightness_and_log_derivative(
    double sigma_over_T, Correlation correlation, std::span<double> out,
    std::span<double> d_out_d_ln_sigma_over_T) const {
    brightness(sigma_over_T, correlation, out);
    assert(d_out_d_ln_sigma_over_T.size() == size());
    const double m2 = sigma_over_T * sigma_over_T;
    for (std::size_t k = 0; k < size(); ++k) {
        d_out_d_ln_sigma_over_T[k] =
            out[k] * d_log_very_rough_profile_d_log_slope(correlation, b_[k] / m2);
    }
}

OrenNayarTerms::OrenNayarTerms(std::span<const Geometry> geoms) {
    check_geometries(geoms);
    const std::size_t n = geoms.size();
    p0_.resize(n);
    g2_.resize(n);
    g3_.resize(n);
    g4_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        const double ti = geoms[k].theta_i_rad, ts = geoms[k].theta_s_rad;
        const double alpha = std::max(ti, ts), beta = std::min(ti, ts);
        const double cos_dphi = -std::cos(geoms[k].phi_s_rad);  // cos(φr − φi) with φi = π
        const double two_beta_pi = 2.0 * beta / kPi;
        const double ab = 4.0 * alpha * beta / (kPi * kPi);
        p0_[k] = std::cos(ti) / kPi;
        g2_[k] = cos_dphi * std::tan(beta) *
                 (cos_dphi >= 0.0 ? std::sin(alpha)
                                  : std::sin(alpha) - two_beta_pi * two_beta_pi * two_beta_pi);
        g3_[k] = (1.0 - std::abs(cos_dphi)) * ab * ab * std::tan(0.5 * (alpha + beta));
        g4_[k] = 0.17 * p0_[k] * (1.0 - cos_dphi * two_beta_pi * two_beta_pi);
    }
}

OrenNayarTerms::Coefficients OrenNayarTerms::coefficients(double sigma_rad) {
    check::non_negative("oren_nayar sigma", sigma_rad, "rad");
    const double s2 = sigma_rad * sigma_rad;
    Coefficients c;
    c.C1 = 1.0 - 0.5 * oren_nayar_saturation(s2, 0.33);
    c.c2 = 0.45 * oren_nayar_saturation(s2, 0.09);
    c.c3 = 0.125 * oren_nayar_saturation(s2, 0.09);
    c.c4 = oren_nayar_saturation(s2, 0.13);
    return c;
}

void OrenNayarTerms::components(double sigma_rad, std::span<double> A, std::span<double> B) const {
    const Coefficients c = coefficients(sigma_rad);
    assert(A.size() == size() && B.size() == size());
    for (std::size_t k = 0; k < size(); ++k) {
        A[k] = term_a(k, c);
        B[k] = term_b(k, c);
    }
}

void OrenNayarTerms::radiance(const OrenNayarParams& params, std::span<double> out) const {
    check::non_negative("oren_nayar sigma", params.sigma_rad, "rad");
    if (!(std::isfinite(params.albedo) && params.albedo >= 0.0 && params.albedo <= 1.0))
        throw InvalidArgument("albedo = " + check::format_number(params.albedo) +
                              " is outside the valid range [0, 1]");
    assert(out.size() == size());
    std::vector<double> B(size());
    components(params.sigma_rad, out, B);
    const double rho = params.albedo;
    for (std::size_t k = 0; k < size(); ++k) out[k] = rho * out[k] + rho * rho * B[k];
}

}  // namespace roughscope
