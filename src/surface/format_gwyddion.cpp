// Placeholder: implemented by the surface-formats work (see formats.hpp).
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"

namespace roughscope::surface::formats {
HeightMap decode_gwy(std::string_view, const std::string& name, const HeightReadOptions&) {
    throw DataError(name + ": the gwy reader is not available yet");
}
HeightMap decode_gsf(std::string_view, const std::string& name, const HeightReadOptions&) {
    throw DataError(name + ": the gsf reader is not available yet");
}
std::string encode_gsf(const HeightMap&, const HeightWriteOptions&) {
    throw InvalidArgument("the gsf writer is not available yet");
}
}  // namespace roughscope::surface::formats
