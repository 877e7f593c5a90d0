// Placeholder: implemented by the surface-formats work (see formats.hpp).
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"

namespace roughscope::surface::formats {
HeightMap decode_x3p(std::string_view, const std::string& name, const HeightReadOptions&) {
    throw DataError(name + ": the x3p reader is not available yet");
}
std::string encode_x3p(const HeightMap&, const HeightWriteOptions&) {
    throw InvalidArgument("the x3p writer is not available yet");
}
}  // namespace roughscope::surface::formats
