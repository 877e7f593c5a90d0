#include "roughscope/scattering/factors.hpp"

#include <array>

#include "roughscope/core/names.hpp"

namespace roughscope {
namespace {

// "vh" is the short name used on the command line; "vernold_harvey" is accepted too.
constexpr std::array<NameEntry<GeometricFactor>, 5> kFactorNames{{
    {"vh", GeometricFactor::VernoldHarvey},
    {"beckmann", GeometricFactor::Beckmann},
    {"ogilvy", GeometricFactor::Ogilvy},
    {"kirchhoff", GeometricFactor::Kirchhoff},
    {"vernold_harvey", GeometricFactor::VernoldHarvey},
}};

constexpr std::array<NameEntry<Radiometry>, 2> kRadiometryNames{{
    {"radiance", Radiometry::Radiance},
    {"intensity", Radiometry::Intensity},
}};

}  // namespace

std::string_view to_string(GeometricFactor factor) { return name_of(kFactorNames, factor); }
std::string_view to_string(Radiometry radiometry) { return name_of(kRadiometryNames, radiometry); }
GeometricFactor parse_geometric_factor(std::string_view name) {
    return parse_name(kFactorNames, "geometric factor", name);
}
Radiometry parse_radiometry(std::string_view name) {
    return parse_name(kRadiometryNames, "radiometry", name);
}

}  // namespace roughscope
