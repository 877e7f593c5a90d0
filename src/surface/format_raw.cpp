// Placeholder: implemented by the surface-formats work (see formats.hpp).
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"

namespace roughscope::surface::formats {
HeightMap decode_raw(std::string_view, const std::string& name, const HeightReadOptions&) {
    throw DataError(name + ": the raw reader is not available yet");
}
std::string encode_raw(const HeightMap&, const HeightWriteOptions&) {
    throw InvalidArgument("the raw writer is not available yet");
}
}  // namespace roughscope::surface::formats
