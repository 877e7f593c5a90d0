// The inputs of image::measure (image/measure.hpp): the captures, the dark frame and the flat
// field read the way the capture file says, and the checks that they belong together — one size,
// one way of recording (bit depth, response) — with warnings that say what was assumed where the
// file could not tell (docs/measure.md "The capture file"). A failure caused by a value of the
// capture file names the file and its key.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/measure/measure.hpp"
#include "roughscope/photo/hdr.hpp"

namespace roughscope::image::detail {

// Runs `f`. An InvalidArgument it throws is caused by the capture file's value of `key`: with a
// capture file (request.source not empty) it becomes a DataError "<file>: <key>: <reason>" (a data
// error, exit 4 in the CLI, as every other bad value of the file); without one (a request built
// in code) it is thrown as it is. A DataError (a file named by the key that is missing or
// unreadable) gets the same "<file>: <key>: " in front, unless it already names the file.
template <class F>
decltype(auto) keyed(const MeasureRequest& request, const std::string& key, F&& f) {
    try {
        return f();
    } catch (const InvalidArgument& e) {
        if (request.source.empty()) throw;
        throw DataError(concat(request.source, ": ", key, ": ", e.what()));
    } catch (const DataError& e) {
        const std::string_view what = e.what();
        if (request.source.empty() || what.substr(0, request.source.size()) == request.source)
            throw;
        throw DataError(concat(request.source, ": ", key, ": ", what));
    }
}

// 8-bit files on the code scale (value · 255 = the stored code), for response curves and normal
// maps.
ReadOptions code_scale();

// How the files become linear: the declared response (read_image with the request's options), or
// a curve recovered from the request's exposure bracket (response.bracket).
class Loader {
  public:
    explicit Loader(const MeasureRequest& request);
    // The file at `path`, the capture file's `key` (for messages).
    LinearImage image(const std::string& path, const std::string& key) const;
    // Capture k: its file, or its bracket merged into one image per second of exposure.
    LinearImage capture(const CaptureSpec& spec, std::size_t k) const;

  private:
    const MeasureRequest& request_;
    std::optional<ResponseCurve> curve_;
};

// DataError "<src>: <key>: ..." unless `image` has the width, height (and, for the second form,
// the channels) of `first`, the capture file's `first_key`.
void check_same_size_pixels(const LinearImage& image, const LinearImage& first,
                            const std::string& src, const std::string& key);
void check_same_size(const LinearImage& image, const LinearImage& first, const std::string& src,
                     const std::string& key, const std::string& first_key);

// A dark frame or flat field must be recorded as the capture it corrects: the same kind of file
// (camera RAW or not), bit depth, integer or float samples and response. Each file's values are
// on the scale of its own full range and response (image/read.hpp), so a 16-bit dark frame of
// 8-bit captures (or a linear one of sRGB captures) would subtract a different quantity than the
// captures' offset. DataError "<src>: <key>: ..." naming both files and how each was recorded.
// Captures merged from a bracket (values per second of exposure) are not compared.
void check_same_recording(const LinearImage& frame, const LinearImage& capture,
                          const std::string& src, const std::string& key);

// Warnings on what was assumed in reading capture `spec` (its ImageInfo `info`), appended to
// `warnings`: an 8-bit file taken as linear because the capture file says so while its own
// metadata is silent (8-bit camera files are almost always tone-mapped), and a linear non-RAW
// file read with black level 0 because neither black_level_dn nor a dark frame was given.
void assumption_warnings(const MeasureRequest& request, const CaptureSpec& spec,
                         const ImageInfo& info, std::vector<std::string>& warnings);

// Throws InvalidArgument naming the key unless every declared standard uncertainty of the setup
// and of the captures (budget.hpp) is finite and ≥ 0 (budget.cpp).
void check_tolerances(const MeasureRequest& request);

}  // namespace roughscope::image::detail
