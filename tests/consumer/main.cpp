// Downstream consumer of an installed roughscope (see CMakeLists.txt here).
#include <cmath>
#include <cstdio>

#include <roughscope/scattering/geometry.hpp>
#include <roughscope/scattering/reflectance_models.hpp>
#include <roughscope/version.hpp>

int main() {
    const double theta = 0.5;  // radians
    const double brightness = roughscope::lambert_brightness(theta);
    // Lambert's law: brightness = cos(theta).
    if (!(std::abs(brightness - std::cos(theta)) <= 1e-12)) {
        std::fprintf(stderr, "lambert_brightness(%g) = %.17g, expected cos(%g) = %.17g\n", theta,
                     brightness, theta, std::cos(theta));
        return 1;
    }
    std::printf("roughscope %s: lambert_brightness(%g) = %.6f\n", ROUGHSCOPE_VERSION_STRING, theta,
                brightness);
    return 0;
}
