// Placeholder: implemented by the surface-formats work (see formats.hpp).
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"

namespace roughscope::surface::formats {
HeightMap decode_png(std::string_view, const std::string& name, const HeightReadOptions&) {
    throw DataError(name + ": the png reader is not available yet");
}
std::string encode_png(const HeightMap&, const HeightWriteOptions&) {
    throw InvalidArgument("the png writer is not available yet");
}
HeightMap decode_tiff(std::string_view, const std::string& name, const HeightReadOptions&) {
    throw DataError(name + ": the tiff reader is not available yet");
}
std::string encode_tiff(const HeightMap&, const HeightWriteOptions&) {
    throw InvalidArgument("the tiff writer is not available yet");
}
}  // namespace roughscope::surface::formats
