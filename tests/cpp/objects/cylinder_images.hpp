// Synthetic images of a cylinder for the tests of its profile's steps (objects/cylinder_steps.hpp):
// the brightness of each pixel a known function of its signed distance d from the axis.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "roughscope/objects/silhouette.hpp"
#include "roughscope/photo/image.hpp"

namespace roughscope::testing {

// A grey width × height image whose pixel centre (c + ½, r + ½) has the value law(d), d =
// axis.across_distance_px (silhouette.hpp), plus Gaussian noise of standard deviation `noise`
// (fixed seed); every `flag_every`-th pixel (0: none) flagged saturated.
template <class Law>
image::LinearImage cylinder_law_image(std::size_t width, std::size_t height,
                                      const image::CylinderAxis& axis, Law law, double noise = 0.0,
                                      std::size_t flag_every = 0) {
    image::LinearImage img;
    img.width = width;
    img.height = height;
    img.channels = 1;
    img.values.assign(width * height, 0.0F);
    img.flags.assign(width * height, 0);
    std::mt19937_64 rng(12345);
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (std::size_t r = 0; r < height; ++r)
        for (std::size_t c = 0; c < width; ++c) {
            const double d =
                axis.across_distance_px(static_cast<double>(c) + 0.5, static_cast<double>(r) + 0.5);
            const std::size_t i = r * width + c;
            img.values[i] = static_cast<float>(law(d) + (noise > 0 ? noise * gauss(rng) : 0.0));
            if (flag_every > 0 && (r * 31 + c * 17) % flag_every == 0)
                img.flags[i] = image::kPixelSaturated;
        }
    return img;
}

// A Lambert cylinder lit from the camera: cos α = √(1 − (d/R)²) on the object, scaled by `peak`,
// over a background of `background`.
inline auto lambert_law(double radius_px, double peak, double background) {
    return [=](double d) {
        const double s = d / radius_px;
        return background + (s * s < 1.0 ? peak * std::sqrt(1.0 - s * s) : 0.0);
    };
}

}  // namespace roughscope::testing
