// Placeholder: implemented by the surface-spectral work (see spectral.hpp).
#include "roughscope/surface/spectral.hpp"

namespace roughscope::surface {
Acf2d acf_2d(const HeightMap&, AcfEstimator) { return {}; }
Curve radial_acf(const Acf2d&) { return {}; }
TextureParameters texture_parameters(const Acf2d&, double) { return {}; }
Curve psd_x(const HeightMap&) { return {}; }
Curve psd_radial(const HeightMap&) { return {}; }
}  // namespace roughscope::surface
