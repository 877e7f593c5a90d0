// JSON schema of the model outputs (serialize/model.hpp).
#include "roughscope/serialize/model.hpp"

#include <string>

#include "roughscope/scattering/validity.hpp"

namespace roughscope::serialize {

Json to_json(const ScatteredPower& p) {
    return {{"brightness", number(p.brightness)},
            {"coherent", number(p.coherent)},
            {"diffuse", number(p.diffuse)},
            {"total", number(p.total)},
            {"g", number(p.g)},
            {"regime", std::string(to_string(p.regime))},
            {"roughness_class", std::string(to_string(p.roughness_class))},
            {"method", std::string(to_string(p.method))},
            {"relative_error_bound", number(p.relative_error_bound)}};
}

}  // namespace roughscope::serialize
