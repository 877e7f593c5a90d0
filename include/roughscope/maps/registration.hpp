// Misregistration of two photographs of one scene (docs/maps.md "Registration").
//
// A roughness map divides two photographs pixel by pixel (or tile by tile), so a camera that moved
// between them mixes the brightness of different surface points: at a region border the ratio is
// then meaningless. estimate_misregistration measures the translation of b relative to a by
// phase correlation (as cv::phaseCorrelate, with its Hanning window, on the average of the
// channels; the transforms are FFTW's real-to-complex ones): the peak of the inverse Fourier
// transform of the normalised cross-power spectrum, located by its 5 × 5 weighted centroid; that
// centroid is pulled toward whole pixels (by up to ~0.3 px), so the peak is then located on the
// surface upsampled around it by the matrix-product DFT of Guizar-Sicairos, Thurman & Fienup
// (2008): ±0.6 px in steps of 0.1 px, then to a fraction of a step by the parabola through the
// best point and its neighbours. The images' means are removed before the window is applied.
// Images larger than RegistrationOptions::max_side_px on a side are correlated on their central
// crop of at most max_side_px × max_side_px pixels at full resolution (sub-pixel accuracy kept,
// cost bounded).
//
// Whether the peak means anything: the peak-to-sidelobe ratio PSR = (peak − mean)/sd of the
// correlation surface outside the peak's 11 × 11 neighbourhood. Images that share no structure (a
// uniform surface seen through independent noise) give the largest of N nearly Gaussian values,
// PSR ≈ √(2 ln N) ≈ 4–5 for N = 10³–10⁶ pixels; a real common structure gives tens to hundreds.
// A shift measured with a low PSR is not evidence of a movement (roughness_map only warns then).
#pragma once

#include <cstddef>

#include "roughscope/photo/image.hpp"

namespace roughscope::image {

struct RegistrationOptions {
    // Larger images are correlated on their central crop of this side (pixels, ≥ 16).
    std::size_t max_side_px = 512;
};

struct Registration {
    double shift_x_px = 0.0;    // b(x, y) ≈ a(x − shift_x, y − shift_y): + = b moved right
    double shift_y_px = 0.0;    // + = b moved down (rows)
    double magnitude_px = 0.0;  // √(shift_x² + shift_y²)
    double response = 0.0;      // the correlation peak's height (cv::phaseCorrelate), [0, 1]
    double peak_to_sidelobe = 0.0;  // PSR, see above
    std::size_t crop_width_px = 0;  // the region correlated (the whole image or its centre)
    std::size_t crop_height_px = 0;
};

// Throws InvalidArgument when an image is inconsistent (check_linear_image_layout, and a
// non-finite value in the correlated crop: the only values read), the two differ in
// width, height or channels, either side is below 16 pixels, or max_side_px < 16.
Registration estimate_misregistration(const LinearImage& a, const LinearImage& b,
                                      const RegistrationOptions& options = {});

}  // namespace roughscope::image
