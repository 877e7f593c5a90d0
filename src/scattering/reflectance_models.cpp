#include "roughscope/scattering/reflectance_models.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "roughscope/core/errors.hpp"

namespace roughscope {
namespace {

void check_oren_nayar(const OrenNayarParams& p) {
    check::non_negative("oren_nayar sigma", p.sigma_rad, "rad");
    if (!(std::isfinite(p.albedo) && p.albedo >= 0.0 && p.albedo <= 1.0))
        throw InvalidArgument("albedo = " + check::format_number(p.albedo) +
                              " is outside the valid range [0, 1]");
}

}  // namespace

double lambert_brightness(double theta_i_rad) {
    check::polar_angle("theta_i", theta_i_rad);
    return std::cos(theta_i_rad);
}

double oren_nayar_radiance(const Geometry& geom, const OrenNayarParams& p) {
    check::geometry(geom);
    check_oren_nayar(p);
    const double s2 = p.sigma_rad * p.sigma_rad;
    const double ti = geom.theta_i_rad, ts = geom.theta_s_rad;
    const double alpha = std::max(ti, ts), beta = std::min(ti, ts);
    const double cos_dphi = -std::cos(geom.phi_s_rad);  // cos(φr − φi) with φi = π
    const double C1 = 1.0 - 0.5 * oren_nayar_saturation(s2, 0.33);
    const double two_beta_pi = 2.0 * beta / kPi;
    const double C2 = cos_dphi >= 0.0
                          ? 0.45 * oren_nayar_saturation(s2, 0.09) * std::sin(alpha)
                          : 0.45 * oren_nayar_saturation(s2, 0.09) *
                                (std::sin(alpha) - two_beta_pi * two_beta_pi * two_beta_pi);
    const double ab = 4.0 * alpha * beta / (kPi * kPi);
    const double C3 = 0.125 * oren_nayar_saturation(s2, 0.09) * ab * ab;
    const double E0cos = std::cos(ti);  // irradiance for unit E0 along L
    const double L1 = p.albedo / kPi * E0cos *
                      (C1 + cos_dphi * C2 * std::tan(beta) +
                       (1.0 - std::abs(cos_dphi)) * C3 * std::tan(0.5 * (alpha + beta)));
    const double L2 = 0.17 * p.albedo * p.albedo / kPi * E0cos * oren_nayar_saturation(s2, 0.13) *
                      (1.0 - cos_dphi * two_beta_pi * two_beta_pi);
    return L1 + L2;
}

double oren_nayar_qualitative_radiance(const Geometry& geom, const OrenNayarParams& p) {
    check::geometry(geom);
    check_oren_nayar(p);
    const double s2 = p.sigma_rad * p.sigma_rad;
    const double alpha = std::max(geom.theta_i_rad, geom.theta_s_rad);
    const double beta = std::min(geom.theta_i_rad, geom.theta_s_rad);
    const double cos_dphi = -std::cos(geom.phi_s_rad);
    const double A = 1.0 - 0.5 * oren_nayar_saturation(s2, 0.33);
    const double B = 0.45 * oren_nayar_saturation(s2, 0.09);
    return p.albedo / kPi * std::cos(geom.theta_i_rad) *
           (A + B * std::max(0.0, cos_dphi) * std::sin(alpha) * std::tan(beta));
}

double lafortune_brdf(const Geometry& geom, const std::vector<LafortuneLobe>& lobes, double rho_d) {
    check::geometry(geom);
    check::non_negative("rho_d", rho_d);
    const Eigen::Vector3d L = light_direction(geom), V = view_direction(geom);
    double f = rho_d / kPi;
    for (std::size_t k = 0; k < lobes.size(); ++k) {
        const LafortuneLobe& lobe = lobes[k];
        const std::string name = "lobe " + std::to_string(k);
        check::finite(name + " Cx", lobe.Cx);
        check::finite(name + " Cy", lobe.Cy);
        check::finite(name + " Cz", lobe.Cz);
        check::positive(name + " n", lobe.n);
        check::non_negative(name + " albedo", lobe.albedo);
        const double dot =
            lobe.Cx * L.x() * V.x() + lobe.Cy * L.y() * V.y() + lobe.Cz * L.z() * V.z();
        if (dot > 0.0) f += lobe.albedo * std::pow(dot, lobe.n);  // else: a physical zero
        if (!std::isfinite(f))
            throw InvalidArgument(name + ": albedo (Cx Lx Vx + Cy Ly Vy + Cz Lz Vz)^n = " +
                                  check::format_number(lobe.albedo) + " * " +
                                  check::format_number(dot) + "^" + check::format_number(lobe.n) +
                                  " exceeds the double range; use coefficients with a bracket "
                                  "<= 1 (a physical lobe) or a smaller n");
    }
    return f;
}

double lafortune_diffuse_brightness(const Geometry& geom, double n) {
    check::geometry(geom);
    check::positive("n", n);
    const double ci = std::cos(geom.theta_i_rad), cs = std::cos(geom.theta_s_rad);
    return std::pow(ci * cs, n) * ci;
}

}  // namespace roughscope
