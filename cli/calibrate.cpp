// `roughscope calibrate light IMAGE --sphere CX,CY,R`: the light's direction from a photograph of
// a mirror sphere (objects/mirror_sphere.hpp; docs/calibration.md). The JSON document is
// serialize/calibration.hpp's (the same as roughscope.calibrate_light's dict).
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "roughscope/core/response.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/objects/mirror_sphere.hpp"
#include "roughscope/photo/read.hpp"
#include "roughscope/serialize/calibration.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::cli {
namespace {

struct LightCommand {
    std::string image_path;
    std::string sphere;     // "CX,CY,R"
    std::string mask_path;  // an image, nonzero = the sphere
    std::string view = "0,0,1";
    std::optional<Response> response;
    double gamma = 2.2;
    double circle_uncertainty_px = 0.5;
    bool json_output = false;
    CLI::Option *o_sphere{}, *o_mask{}, *o_gamma{};
};

// The mask file's pixels: nonzero (any channel) = on the sphere. It must be as large as the image.
std::vector<std::uint8_t> read_mask(const std::string& path, const image::LinearImage& photo) {
    image::ReadOptions linear;
    linear.response = Response::Linear;
    const image::LinearImage m = image::read_image(path, linear);
    if (m.width != photo.width || m.height != photo.height)
        throw InvalidArgument(concat("--mask ", path, ": ", std::to_string(m.width), " x ",
                                     std::to_string(m.height), " pixels; the image is ",
                                     std::to_string(photo.width), " x ",
                                     std::to_string(photo.height)));
    std::vector<std::uint8_t> mask(m.pixel_count(), 0);
    for (std::size_t c = 0; c < m.channels; ++c)
        for (std::size_t k = 0; k < mask.size(); ++k)
            if (m.plane(c)[k] > 0.0f) mask[k] = 1;
    return mask;
}

void run_light(const LightCommand& c) {
    if (!given(c.o_sphere) && !given(c.o_mask))
        throw UsageError(
            "calibrate light: give the sphere's circle (--sphere CX,CY,R) or its "
            "pixels (--mask FILE)");
    if (given(c.o_gamma) && c.response != Response::Gamma)
        throw UsageError("--gamma applies only with --response gamma");
    image::ReadOptions read;
    read.response = c.response;
    if (c.response == Response::Gamma) read.gamma = c.gamma;
    const image::LinearImage photo = image::read_image(c.image_path, read);
    std::optional<std::vector<std::uint8_t>> mask;
    if (given(c.o_mask)) mask = read_mask(c.mask_path, photo);
    image::CircleFit circle;
    if (given(c.o_sphere)) {
        const std::vector<double> v = parse_number_list(c.sphere, 3, "--sphere CX,CY,R");
        circle.centre_x_px = v[0];
        circle.centre_y_px = v[1];
        circle.radius_px = v[2];
    } else {
        circle = image::circle_from_mask(*mask, photo.width, photo.height);
    }
    image::MirrorSphereOptions options;
    const std::vector<double> view = parse_number_list(c.view, 3, "--view X,Y,Z");
    options.view = Eigen::Vector3d(view[0], view[1], view[2]);
    options.circle_uncertainty_px = c.circle_uncertainty_px;
    const image::MirrorSphereLight light =
        image::mirror_sphere_light(photo, circle, mask ? &*mask : nullptr, options);
    write_output(std::nullopt, c.json_output
                                   ? serialize::dump(serialize::versioned(
                                         serialize::to_json(light, options.circle_uncertainty_px)))
                                   : serialize::light_calibration_text(light));
}

}  // namespace

void register_calibrate(CLI::App& app) {
    CLI::App* cmd = app.add_subcommand(
        "calibrate", "Calibration of a capture: the light's direction (docs/calibration.md)");
    cmd->require_subcommand(1);
    auto args = std::make_shared<LightCommand>();
    LightCommand& c = *args;
    CLI::App* light = cmd->add_subcommand(
        "light",
        "The light's direction from a photograph of a mirror sphere (a ball bearing): the "
        "highlight, where the sphere's normal bisects the view and the light");
    light->add_option("image", c.image_path, "The photograph (PNG, TIFF, JPEG, camera RAW)")
        ->required();
    c.o_sphere = light->add_option("--sphere", c.sphere,
                                   "The sphere's circle in the image: centre x, centre y, radius "
                                   "(px; x right, y down, pixel centres at +0.5)");
    c.o_mask = light->add_option("--mask", c.mask_path,
                                 "An image as large as the photograph, nonzero on the sphere: "
                                 "the highlight is searched there (and the circle taken from it "
                                 "without --sphere)");
    light
        ->add_option("--view", c.view,
                     "The view direction V (camera frame, unit, towards the camera)")
        ->default_str("0,0,1");
    add_non_negative_option(*light, "--circle-uncertainty", c.circle_uncertainty_px,
                            "Standard uncertainty of the circle's centre and radius (px; "
                            "default 0.5)",
                            "px");
    add_enum_option(*light, "--response", c.response, parse_response,
                    "The photograph's response to invert: linear, srgb or gamma (default: what "
                    "the file says, docs/image.md)");
    c.o_gamma =
        add_positive_option(*light, "--gamma", c.gamma, "gamma of --response gamma (default 2.2)");
    light->add_flag("--json", c.json_output, "Print JSON (keys in docs/calibration.md)");
    light->callback([args]() { run_light(*args); });
}

}  // namespace roughscope::cli
