#include "roughscope/photo/image.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <span>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {

namespace {

// The index of the first value that is not finite (exponent bits all ones: ±inf, NaN), or size.
// Blocks of 1024 are tested with a branch-free OR of comparisons on the bit patterns (vectorised; a
// plain find_if with std::isfinite is not), and only a block with a hit is searched element by
// element.
std::size_t first_non_finite(std::span<const float> values) {
    constexpr std::uint32_t kExponent = 0x7f800000U;
    constexpr std::size_t kBlock = 1024;
    const std::size_t n = values.size();
    for (std::size_t start = 0; start < n; start += kBlock) {
        const std::size_t end = std::min(n, start + kBlock);
        std::uint32_t any = 0;
        for (std::size_t i = start; i < end; ++i)
            any |= static_cast<std::uint32_t>(
                (std::bit_cast<std::uint32_t>(values[i]) & kExponent) == kExponent);
        if (any != 0) {
            for (std::size_t i = start; i < end; ++i)
                if (!std::isfinite(values[i])) return i;
        }
    }
    return n;
}

}  // namespace

void check_linear_image(const LinearImage& image) {
    check_linear_image_layout(image);
    const std::size_t bad = first_non_finite(image.values);
    if (bad != image.values.size()) throw_non_finite_value(image, bad);
}

void throw_non_finite_value(const LinearImage& image, std::size_t sample) {
    const std::string name = image.info.source.empty() ? std::string("image") : image.info.source;
    throw InvalidArgument(concat(name, ": value ", check::format_number(image.values[sample]),
                                 " at sample ", std::to_string(sample), " is not finite"));
}

void check_linear_image_layout(const LinearImage& image) {
    const std::string name = image.info.source.empty() ? std::string("image") : image.info.source;
    if (image.width == 0 || image.height == 0)
        throw InvalidArgument(concat(name, ": image size ", std::to_string(image.width), " x ",
                                     std::to_string(image.height), " must be at least 1 x 1"));
    if (image.channels != 1 && image.channels != 3)
        throw InvalidArgument(concat(name, ": ", std::to_string(image.channels),
                                     " channels; valid: 1 (grey) or 3 (R, G, B)"));
    const std::size_t pixels = image.width * image.height;
    if (image.values.size() != image.channels * pixels)
        throw InvalidArgument(concat(name, ": ", std::to_string(image.values.size()),
                                     " values for ", std::to_string(image.channels), " x ",
                                     std::to_string(pixels), " samples"));
    if (image.flags.size() != pixels)
        throw InvalidArgument(concat(name, ": ", std::to_string(image.flags.size()),
                                     " pixel flags for ", std::to_string(pixels), " pixels"));
}

std::size_t count_flagged(const LinearImage& image, std::uint8_t mask) {
    return static_cast<std::size_t>(
        std::count_if(image.flags.begin(), image.flags.end(),
                      [mask](std::uint8_t f) { return (f & mask) != 0; }));
}

}  // namespace roughscope::image
