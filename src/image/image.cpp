#include "roughscope/image/image.hpp"

#include <algorithm>
#include <cmath>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"

namespace roughscope::image {

void check_linear_image(const LinearImage& image) {
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
    const auto bad = std::find_if(image.values.begin(), image.values.end(),
                                  [](float v) { return !std::isfinite(v); });
    if (bad != image.values.end())
        throw InvalidArgument(concat(name, ": value ", check::format_number(*bad), " at sample ",
                                     std::to_string(bad - image.values.begin()), " is not finite"));
}

std::size_t count_flagged(const LinearImage& image, std::uint8_t mask) {
    return static_cast<std::size_t>(
        std::count_if(image.flags.begin(), image.flags.end(),
                      [mask](std::uint8_t f) { return (f & mask) != 0; }));
}

}  // namespace roughscope::image
