// Placeholder: implemented by the surface-generation work (see generate.hpp).
#include "roughscope/surface/generate.hpp"

#include "roughscope/core/errors.hpp"

namespace roughscope::surface {
HeightMap generate_surface(const GenerationOptions&) {
    throw InvalidArgument("surface generation is not available yet");
}
HeightMap generate_surface_from_psd(const std::function<double(double)>&,
                                    const GenerationOptions&) {
    throw InvalidArgument("surface generation is not available yet");
}
}  // namespace roughscope::surface
