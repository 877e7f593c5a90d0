// One pixel of rough-surface photometric stereo (objects/photometric_stereo.hpp: the very-rough
// model, its fit and the comparison with Lambert's law).
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "roughscope/scattering/correlation.hpp"

namespace roughscope::image::detail {

struct RoughPixelFit {
    bool ok = false;
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    double albedo = 0.0;
    double sigma_over_T = 0.0;
    double sigma_over_T_stderr = 0.0;  // NaN with 4 lights
    double delta_aic = 0.0;            // NaN with 4 lights
    double residual_rel = 0.0;         // RMS residual / (ρ · max_j B_j)
    std::uint32_t set = 0;
    int highlights = 0;
};

struct RoughPixelProblem {
    const std::vector<Eigen::Vector3d>* lights = nullptr;
    const double* value = nullptr;  // I_j / e_j
    std::uint32_t set = 0;          // usable lights (bit j)
    Eigen::Vector3d start_normal = Eigen::Vector3d::UnitZ();
    Correlation correlation = Correlation::Gaussian;
    double highlight_fraction = 0.1;
    double min_sigma_over_T = 0.02;
    double max_sigma_over_T = 20.0;
};

RoughPixelFit fit_rough_pixel(const RoughPixelProblem& problem);

}  // namespace roughscope::image::detail
