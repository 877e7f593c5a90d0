// Internal pieces shared by the curved-object measurements (silhouette, cylinder, sphere); the
// cylinder profile's steps are in cylinder_steps.hpp.
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

}  // namespace roughscope::image::detail
