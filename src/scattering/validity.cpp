#include "roughscope/scattering/validity.hpp"

namespace roughscope {

std::string_view to_string(RoughnessClass c) {
    switch (c) {
        case RoughnessClass::SlightlyRough:
            return "slightly_rough";
        case RoughnessClass::ModeratelyRough:
            return "moderately_rough";
        case RoughnessClass::VeryRough:
            return "very_rough";
    }
    return "unknown";
}

}  // namespace roughscope
