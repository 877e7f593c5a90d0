// Placeholder: implemented by the surface-formats work (see formats.hpp).
#include "roughscope/core/errors.hpp"
#include "roughscope/surface/formats.hpp"

namespace roughscope::surface::formats {
HeightMap decode_csv_matrix(std::string_view, const std::string& name, const HeightReadOptions&) {
    throw DataError(name + ": the csv_matrix reader is not available yet");
}
std::string encode_csv_matrix(const HeightMap&, const HeightWriteOptions&) {
    throw InvalidArgument("the csv_matrix writer is not available yet");
}
HeightMap decode_xyz(std::string_view, const std::string& name, const HeightReadOptions&) {
    throw DataError(name + ": the xyz reader is not available yet");
}
std::string encode_xyz(const HeightMap&, const HeightWriteOptions&) {
    throw InvalidArgument("the xyz writer is not available yet");
}
}  // namespace roughscope::surface::formats
