// An unknown camera response recovered from an exposure bracket, and high-dynamic-range merging
// (Debevec & Malik, "Recovering high dynamic range radiance maps from photographs", SIGGRAPH
// 1997; the response by OpenCV's photo module, CalibrateDebevec). For 8-bit photographs whose
// response is neither sRGB nor a known gamma.
//
// Input: a bracket of 8-bit photographs of one still scene (camera and light fixed) with known
// exposure times, read on the *code* scale: read_image with Response::Linear and black level 0,
// so that a value v is the stored code z = v · 255 (image/read.hpp). Model: z = f(E · t); the
// recovered curve gives, per channel and code, the light X(z) = f⁻¹(z) ∝ E · t, up to one scale
// per channel that the method cannot fix. Ratios of brightness — all that σ/T needs — do not
// depend on that scale when every capture goes through the same curve.
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "roughscope/photo/image.hpp"

namespace roughscope::image {

struct ResponseCurve {
    // light[c][z]: X(z) of channel c, normalised so that X(255) = 1 (code 255 is full scale).
    std::vector<std::array<double, 256>> light;
};

struct DebevecOptions {
    int samples = 70;          // pixels sampled on a regular grid (OpenCV's default, > 0)
    double smoothness = 10.0;  // λ of the smoothness term on g'' (> 0)
};

// Throws InvalidArgument naming the input unless: ≥ 2 images of equal size and channels, 8 bits
// per sample read on the code scale (linear response, black level 0), one exposure time > 0 per
// image, the exposures not all equal.
ResponseCurve recover_response_debevec(const std::vector<LinearImage>& bracket,
                                       const std::vector<double>& exposure_s,
                                       const DebevecOptions& options = {});

// The curve of a known response for 8-bit codes: X(z) = z/255 (linear), srgb_decode(z/255)
// (sRGB) or (z/255)^γ (gamma, γ > 0): for merging a bracket of a camera whose response is known.
ResponseCurve response_curve_of(Response response, double gamma, std::size_t channels);

// Replaces every value (a code on the code scale, as above) by X(code) of its channel: the image
// is then on a linear scale with full scale 1. Flags are kept. InvalidArgument as above, or when
// the curve has fewer channels than the image.
void apply_response_curve(LinearImage& image, const ResponseCurve& curve);

// The bracket merged into one image of relative radiance E (per second of exposure): the
// weighted mean over the exposures of X(z)/t with Debevec's hat weight w(z) = min(z, 255 − z)
// on the well-exposed codes 16..239 (zero outside: clipped codes and those next to clipping,
// where the recovered curve is least certain, never enter). A pixel with no well-exposed code in
// any exposure is flagged (kPixelSaturated when bright, kPixelClippedLow when dark), value 0.
// info is the first image's, with info.exposure_s = 1 (the values are per second).
LinearImage merge_hdr(const std::vector<LinearImage>& bracket,
                      const std::vector<double>& exposure_s, const ResponseCurve& curve);

}  // namespace roughscope::image
