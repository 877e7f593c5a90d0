// Radiometric corrections of linear images (docs/image.md, "Dark frames and flat fields"): the
// dark frame (the signal with no light: offset, dark current, fixed-pattern noise), the flat field
// (the response to uniform light: vignetting, dust, pixel-to-pixel gain) and a plain scale
// (e.g. 1 / exposure time). All work in place on images of the same size and channels.
#pragma once

#include <vector>

#include "roughscope/photo/image.hpp"

namespace roughscope::image {

// image −= dark, sample by sample. Throws InvalidArgument (naming both sources) unless both are
// consistent images (check_linear_image) of the same width, height and channels. The dark frame's
// flags are OR-ed into the image's; values are not clamped (they may go negative), but a pixel
// with any channel ≤ 0 afterwards is flagged kPixelClippedLow.
void subtract_dark_frame(LinearImage& image, const LinearImage& dark);

// image /= flat / mean(flat), per channel: the flat is normalised to its mean over its usable
// pixels (unflagged and > 0 in that channel), so the image keeps its overall scale. Where the flat
// is flagged or ≤ 0 the sample is left as it is and the pixel is flagged kPixelNoFlatField.
// Throws InvalidArgument (naming both sources) for a size or channel mismatch, or when a channel
// of the flat has no usable pixel.
void divide_flat_field(LinearImage& image, const LinearImage& flat);

// image −= offset[c] in channel c (one offset per channel; a black level measured in the scene).
// Like subtract_dark_frame, a pixel with any channel ≤ 0 afterwards is flagged kPixelClippedLow.
// Throws InvalidArgument unless the image is consistent and every offset finite, one per channel.
void subtract_offset(LinearImage& image, const std::vector<double>& offset);

// image *= factor. Throws InvalidArgument unless factor is finite and > 0.
void scale(LinearImage& image, double factor);

}  // namespace roughscope::image
