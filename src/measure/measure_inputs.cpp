// Reading and checking the inputs of image::measure (measure_inputs.hpp).
#include "measure_inputs.hpp"

#include <cctype>
#include <cmath>
#include <utility>

#include "roughscope/core/response.hpp"

namespace roughscope::image::detail {

namespace {

std::string where(const MeasureRequest& request) {
    return request.source.empty() ? std::string("measure") : request.source;
}

std::string shot_key(const std::string& bracket_key, std::size_t j) {
    return concat(bracket_key, "[", std::to_string(j), "].image");
}

// The images of a bracket on the code scale, and their exposure times; every image must have the
// first one's size and channels (one scene from one camera position).
std::pair<std::vector<LinearImage>, std::vector<double>> read_bracket(
    const MeasureRequest& request, const std::vector<BracketShot>& shots,
    const std::string& bracket_key) {
    std::vector<LinearImage> images;
    std::vector<double> times;
    for (std::size_t j = 0; j < shots.size(); ++j) {
        images.push_back(keyed(request, shot_key(bracket_key, j),
                               [&] { return read_image(shots[j].image, code_scale()); }));
        if (j > 0)
            check_same_size(images.back(), images.front(), where(request), shot_key(bracket_key, j),
                            shot_key(bracket_key, 0));
        times.push_back(shots[j].exposure_s);
    }
    return {std::move(images), std::move(times)};
}

std::string response_text(const ImageInfo& info) {
    if (info.response == Response::Gamma) return concat("gamma ", check::format_number(info.gamma));
    return std::string(to_string(info.response));
}

// "an 8-bit srgb PNG file", "a 14-bit linear camera RAW file", "a 32-bit float linear TIFF file".
std::string recording(const ImageInfo& info) {
    const std::string depth = info.is_float ? std::string("32-bit float")
                                            : concat(std::to_string(info.bits_per_sample), "-bit");
    const std::string kind = info.format == "raw" ? std::string("camera RAW") : [&] {
        std::string upper = info.format;
        for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        return upper;
    }();
    const char* article = depth.rfind("8-", 0) == 0 || depth.rfind("11-", 0) == 0 ? "an" : "a";
    return concat(article, " ", depth, " ", response_text(info), " ", kind, " file");
}

}  // namespace

ReadOptions code_scale() {
    ReadOptions options;
    options.response = Response::Linear;
    options.black_level_dn = std::vector<double>{0.0};
    return options;
}

Loader::Loader(const MeasureRequest& request) : request_(request) {
    if (!request.response_bracket.empty()) {
        // (Not a structured binding: clang before 16 cannot capture one in a lambda.)
        const auto bracket = read_bracket(request, request.response_bracket, "response.bracket");
        curve_ = keyed(request, "response.bracket",
                       [&] { return recover_response_debevec(bracket.first, bracket.second); });
    }
}

LinearImage Loader::image(const std::string& path, const std::string& key) const {
    // The read options come from the capture file: a level they set that the file cannot take
    // (a black level at or above its white level, one per plane of another number of planes) is
    // that key's error.
    const std::string blame =
        request_.read.black_level_dn ? concat("black_level_dn (", key, ")") : key;
    if (!curve_) return keyed(request_, blame, [&] { return read_image(path, request_.read); });
    LinearImage image = keyed(request_, key, [&] { return read_image(path, code_scale()); });
    keyed(request_, key, [&] { apply_response_curve(image, *curve_); });
    return image;
}

LinearImage Loader::capture(const CaptureSpec& spec, std::size_t k) const {
    const std::string key = concat("captures[", std::to_string(k), "]");
    if (spec.bracket.empty()) return image(spec.image, concat(key, ".image"));
    const std::string bracket_key = concat(key, ".bracket");
    const auto bracket = read_bracket(request_, spec.bracket, bracket_key);
    const ResponseCurve curve = curve_ ? *curve_ : keyed(request_, "response", [&] {
        return response_curve_of(request_.read.response.value_or(Response::Srgb),
                                 request_.read.gamma, bracket.first.front().channels);
    });
    return keyed(request_, bracket_key,
                 [&] { return merge_hdr(bracket.first, bracket.second, curve); });
}

void check_same_size_pixels(const LinearImage& image, const LinearImage& first,
                            const std::string& src, const std::string& key) {
    if (image.width != first.width || image.height != first.height)
        throw DataError(concat(src, ": ", key, ": ", image.info.source, " is ",
                               std::to_string(image.width), " x ", std::to_string(image.height),
                               " but ", first.info.source, " is ", std::to_string(first.width),
                               " x ", std::to_string(first.height),
                               ": the normal map must have the captures' size"));
}

void check_same_size(const LinearImage& image, const LinearImage& first, const std::string& src,
                     const std::string& key, const std::string& first_key) {
    if (image.width != first.width || image.height != first.height ||
        image.channels != first.channels)
        throw DataError(concat(src, ": ", key, ": ", image.info.source, " is ",
                               std::to_string(image.width), " x ", std::to_string(image.height),
                               " x ", std::to_string(image.channels), " but ", first_key, " ",
                               first.info.source, " is ", std::to_string(first.width), " x ",
                               std::to_string(first.height), " x ", std::to_string(first.channels),
                               ": every capture, bracket photograph, dark frame and flat field "
                               "must have the same size and channels"));
}

void check_same_recording(const LinearImage& frame, const LinearImage& capture,
                          const std::string& src, const std::string& key) {
    const ImageInfo& f = frame.info;
    const ImageInfo& c = capture.info;
    const bool same_gamma =
        f.response != Response::Gamma || std::abs(f.gamma - c.gamma) <= 1e-9 * c.gamma;
    if ((f.format == "raw") == (c.format == "raw") && f.bits_per_sample == c.bits_per_sample &&
        f.is_float == c.is_float && f.response == c.response && same_gamma)
        return;
    throw DataError(concat(
        src, ": ", key, ": ", f.source, " is ", recording(f), " but ", c.source, " is ",
        recording(c),
        ": a dark frame or flat field must be recorded as the captures are (same camera, file "
        "kind, bit depth and response); each file's values are on the scale of its own full "
        "range and response, so this one would correct by the wrong amount. Record it again "
        "with the captures' settings, or convert it to their bit depth and response"));
}

void assumption_warnings(const MeasureRequest& request, const CaptureSpec& spec,
                         const ImageInfo& info, std::vector<std::string>& warnings) {
    // Files read through a recovered curve or merged from a bracket have no declared response.
    if (!request.response_bracket.empty() || !spec.bracket.empty()) return;
    const bool integer_file = info.format != "raw" && !info.is_float;
    if (integer_file && info.bits_per_sample == 8 && request.read.response == Response::Linear &&
        !info.file_response)
        warnings.push_back(concat(
            spec.image,
            ": 8-bit file read as linear because the capture file says \"response\": \"linear\" "
            "(the file itself says nothing of its response); 8-bit camera files are almost "
            "always tone-mapped (sRGB or a gamma), and a tone-mapped pair read as linear gives a "
            "biased E1/E2 and σ/T: unless the camera wrote linear 8-bit values, declare \"srgb\" "
            "or {\"gamma\": γ}, or recover the response from an exposure bracket"));
    if (integer_file && info.response == Response::Linear && !request.read.black_level_dn &&
        !request.dark_frame)
        warnings.push_back(concat(
            spec.image, ": black level 0 assumed for this ", std::to_string(info.bits_per_sample),
            "-bit linear file (the capture file gives no black_level_dn and no dark_frame): a "
            "camera offset left in the values biases E1/E2 and σ/T; give black_level_dn (the "
            "camera's black level in DN) or a dark frame"));
}

}  // namespace roughscope::image::detail
