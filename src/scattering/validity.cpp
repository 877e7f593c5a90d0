#include "roughscope/scattering/validity.hpp"

#include <array>

#include "roughscope/core/names.hpp"

namespace roughscope {

namespace {
constexpr std::array<NameEntry<RoughnessClass>, 3> kRoughnessClassNames{{
    {"slightly_rough", RoughnessClass::SlightlyRough},
    {"moderately_rough", RoughnessClass::ModeratelyRough},
    {"very_rough", RoughnessClass::VeryRough},
}};
}  // namespace

std::string_view to_string(RoughnessClass c) { return name_of(kRoughnessClassNames, c); }
RoughnessClass parse_roughness_class(std::string_view name) {
    return parse_name(kRoughnessClassNames, "roughness class", name);
}

}  // namespace roughscope
