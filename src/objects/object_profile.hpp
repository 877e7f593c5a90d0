// Internal pieces shared by the curved-object measurements (cylinder.cpp, sphere.cpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <exception>
#include <optional>
#include <string_view>
#include <thread>
#include <vector>

#include <Eigen/Core>

#include "roughscope/core/parallel.hpp"
#include "roughscope/objects/cylinder.hpp"
#include "roughscope/scattering/geometry.hpp"

namespace roughscope::image::detail {

// One row of an object: the columns [begin, end) (begin = end: none). The silhouette's mask is
// filled along rows (find_silhouette), so one run a row is the whole mask.
struct RowRun {
    std::size_t begin = 0, end = 0;
};

// A silhouette (with an empty mask) and its mask as one run per row (height entries).
struct Outline {
    Silhouette silhouette;
    std::vector<RowRun> rows;
};

// find_silhouette without the image-sized mask: the object's rows instead. The values are
// checked as its pass over the image reads them (check_linear_image's InvalidArgument for a
// non-finite one; no separate pass). `threads`: of the passes over the image (0 = all cores; the
// result does not depend on it).
Outline find_outline(const LinearImage& image, const SilhouetteOptions& options,
                     std::size_t threads);

using roughscope::run_bands;
using roughscope::worker_threads;

// InvalidArgument unless v is finite with |‖v‖ − 1| ≤ 1e−6.
void check_unit_direction(std::string_view name, const Eigen::Vector3d& v);

// One point of a bin's pixel distribution: its geometry and the fraction of the bin's pixels.
struct ProfileNode {
    Geometry geometry;
    double weight = 0.0;
    bool lit = false;  // L and V above the horizon of the normal
};

// The node at s = d/R across a cylinder whose in-image across direction is (ux, uy) (image
// coordinates, y down): n = s û + √(1 − s²) ẑ with û = (ux, −uy, 0) in the camera frame.
ProfileNode cylinder_node(double s, double weight, double ux, double uy,
                          const Eigen::Vector3d& light, const Eigen::Vector3d& view);

// Σ_nodes weight · f(geometry) per bin (unlit nodes contribute 0).
template <class F>
std::vector<double> bin_model_averages(const std::vector<std::vector<ProfileNode>>& nodes, F&& f) {
    std::vector<double> out(nodes.size(), 0.0);
    for (std::size_t b = 0; b < nodes.size(); ++b)
        for (const ProfileNode& n : nodes[b])
            if (n.lit) out[b] += n.weight * f(n.geometry);
    return out;
}

// The σ/T fit of ProfileFit (cylinder.hpp).
ProfileFit fit_profile(const std::vector<ProfileBin>& bins,
                       const std::vector<std::vector<ProfileNode>>& nodes, Correlation correlation,
                       GeometricFactor factor, Radiometry radiometry);

// The departure rule of CylinderOptions: the first bin from which `run` consecutive bins (or all
// remaining, when fewer) have |prediction − brightness| > k · standard_error.
std::optional<std::size_t> departure_bin(const std::vector<ProfileBin>& bins,
                                         const std::vector<double>& prediction, double k,
                                         std::size_t run);

}  // namespace roughscope::image::detail
