// Dark frame, flat field and scale (image/radiometry.hpp).
#include "roughscope/photo/radiometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {

namespace {

std::string source_of(const LinearImage& image) {
    return image.info.source.empty() ? std::string("(unnamed image)") : image.info.source;
}

std::string shape_of(const LinearImage& image) {
    return concat(std::to_string(image.width), " x ", std::to_string(image.height), " x ",
                  std::to_string(image.channels));
}

void check_same_shape(const LinearImage& image, const LinearImage& other, std::string_view role) {
    check_linear_image(image);
    check_linear_image(other);
    if (image.width != other.width || image.height != other.height ||
        image.channels != other.channels)
        throw InvalidArgument(concat(role, " ", source_of(other), " is ", shape_of(other),
                                     " (width x height x channels) but the image ",
                                     source_of(image), " is ", shape_of(image),
                                     "; they must match"));
}

}  // namespace

void subtract_dark_frame(LinearImage& image, const LinearImage& dark) {
    check_same_shape(image, dark, "dark frame");
    const std::size_t pixels = image.pixel_count();
    for (std::size_t i = 0; i < image.values.size(); ++i) {
        const double difference =
            static_cast<double>(image.values[i]) - static_cast<double>(dark.values[i]);
        if (!(std::abs(difference) <= std::numeric_limits<float>::max()))
            throw InvalidArgument(concat("dark frame ", source_of(dark), ": sample ",
                                         std::to_string(i), " of the image ", source_of(image),
                                         " minus the dark frame is beyond the float range"));
    }
    for (std::size_t i = 0; i < image.values.size(); ++i) image.values[i] -= dark.values[i];
    for (std::size_t i = 0; i < pixels; ++i) {
        std::uint8_t f = image.flags[i] | dark.flags[i];
        for (std::size_t c = 0; c < image.channels; ++c)
            if (image.values[c * pixels + i] <= 0.0F) f |= kPixelClippedLow;
        image.flags[i] = f;
    }
}

void subtract_offset(LinearImage& image, const std::vector<double>& offset) {
    check_linear_image(image);
    if (offset.size() != image.channels)
        throw InvalidArgument(concat("black offset: ", std::to_string(offset.size()),
                                     " values for an image of ", std::to_string(image.channels),
                                     " channel(s)"));
    for (const double o : offset) check::finite("black offset", o);
    const std::size_t pixels = image.pixel_count();
    for (std::size_t c = 0; c < image.channels; ++c) {
        float* v = image.values.data() + c * pixels;
        const auto o = static_cast<float>(offset[c]);
        for (std::size_t i = 0; i < pixels; ++i) {
            v[i] -= o;
            if (v[i] <= 0.0F) image.flags[i] |= kPixelClippedLow;
        }
    }
}

void divide_flat_field(LinearImage& image, const LinearImage& flat) {
    check_same_shape(image, flat, "flat field");
    const std::size_t pixels = image.pixel_count();
    for (std::size_t c = 0; c < image.channels; ++c) {
        const float* f = flat.plane(c);
        double sum = 0.0;
        std::size_t usable = 0;
        for (std::size_t i = 0; i < pixels; ++i) {
            if (flat.flags[i] != 0 || !(f[i] > 0.0F)) continue;
            sum += f[i];
            ++usable;
        }
        if (usable == 0)
            throw InvalidArgument(concat("flat field ", source_of(flat),
                                         " has no usable pixel "
                                         "(unflagged and > 0) in channel ",
                                         std::to_string(c)));
        const double mean = sum / static_cast<double>(usable);
        float* v = image.values.data() + c * pixels;
        for (std::size_t i = 0; i < pixels; ++i) {
            if (flat.flags[i] != 0 || !(f[i] > 0.0F)) {
                image.flags[i] |= kPixelNoFlatField;
                continue;
            }
            const auto corrected = static_cast<float>(v[i] * (mean / f[i]));
            if (std::isfinite(corrected))
                v[i] = corrected;
            else
                image.flags[i] |= kPixelNoFlatField;  // a flat value so small the result overflows
        }
    }
}

void scale(LinearImage& image, double factor) {
    if (!(std::isfinite(factor) && factor > 0.0))
        throw InvalidArgument(concat("scale factor ", check::format_number(factor), " for ",
                                     source_of(image), "; valid: a finite value > 0"));
    float largest = 0.0F;
    for (const float v : image.values) largest = std::max(largest, std::abs(v));
    if (static_cast<double>(largest) * factor > std::numeric_limits<float>::max())
        throw InvalidArgument(concat("scale factor ", check::format_number(factor), " for ",
                                     source_of(image), " takes the value ",
                                     check::format_number(largest), " beyond the largest float"));
    for (float& v : image.values) v = static_cast<float>(v * factor);
}

}  // namespace roughscope::image
