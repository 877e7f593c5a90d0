// Example 1 — the forward model (paper §2–3): how bright is a rough surface?
//
//   1. the imaging geometry (θi, θs, φs) from a surface normal N, a light direction L and a
//      viewing direction V (§2, the paper's frame: φs = 0 is the specular half-plane);
//   2. Eq. 1 for a surface of known σ and T: coherent + diffuse power, with the regime chosen
//      from g = σ²v_z² (`auto`);
//   3. the very-rough shape (Eq. 4) as the viewer moves in the plane of incidence, and the
//      retro-scattering closed form Eq. 9, which must equal the general form at θi = θs, φs = π.
// Exits non-zero if a check fails, so the test suite runs it.
#include <cmath>
#include <cstdio>
#include <numbers>

#include "roughscope/roughscope.hpp"

namespace rs = roughscope;

int main() {
    // 1. Light 45° from the normal on one side, camera 30° on the other side, in one plane.
    const Eigen::Vector3d N(0, 0, 1);
    const Eigen::Vector3d L(-std::sin(rs::deg_to_rad(45)), 0, std::cos(rs::deg_to_rad(45)));
    const Eigen::Vector3d V(std::sin(rs::deg_to_rad(30)), 0, std::cos(rs::deg_to_rad(30)));
    const auto geom = rs::geometry_from_vectors(N, L, V);
    if (!geom) return std::puts("light or viewer below the horizon"), 1;
    std::printf("theta_i = %.1f deg, theta_s = %.1f deg, phi_s = %.1f deg\n",
                rs::rad_to_deg(geom->theta_i_rad), rs::rad_to_deg(geom->theta_s_rad),
                rs::rad_to_deg(geom->phi_s_rad));

    // 2. A slightly rough surface: σ = 0.01 µm, T = 1 µm, seen in green light (λ = 0.555 µm).
    const rs::Surface surface{.sigma_um = 0.01, .T_um = 1.0};
    const rs::ScatteredPower p = rs::mean_scattered_power(*geom, surface);
    std::printf("g = %.4f (%s): coherent %.4g, diffuse %.4g, brightness %.4g\n", p.g,
                std::string(rs::to_string(p.roughness_class)).c_str(), p.coherent, p.diffuse,
                p.brightness);

    // 3. A very rough surface (σ/T = 0.5) lit from 45°: brightness across the viewing angle.
    std::puts("theta_s  very-rough brightness (Eq. 4, V-H factor)");
    for (double theta_s_deg = 0; theta_s_deg < 90; theta_s_deg += 15) {
        const auto g = rs::make_geometry(rs::deg_to_rad(45), rs::deg_to_rad(theta_s_deg), 0.0);
        std::printf("%5.0f    %.6g\n", theta_s_deg,
                    rs::very_rough_brightness(g, 0.5, rs::Correlation::Gaussian));
    }
    // Eq. 9 is the general form at the retro-reflection geometry, up to its constant 4.
    for (double theta_deg : {10.0, 40.0, 70.0}) {
        const double theta = rs::deg_to_rad(theta_deg);
        const double closed = rs::retro_vh_gaussian_very_rough(theta, 0.5);
        const double general = 4 * rs::very_rough_brightness(rs::retro_geometry(theta), 0.5,
                                                             rs::Correlation::Gaussian);
        if (std::abs(closed / general - 1) > 1e-12) {
            std::printf("Eq. 9 disagrees with Eq. 4 at %g deg: %.17g vs %.17g\n", theta_deg, closed,
                        general);
            return 1;
        }
    }
    std::puts("Eq. 9 = Eq. 4 at the retro geometry: ok");
    return 0;
}
