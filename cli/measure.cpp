// `roughscope measure CAPTURE.json`: roughness from photographs (image/measure.hpp). The capture
// file names the images, their light and view directions and exposures, and the region; the
// result is σ (specular capture, Eq. 13), σ/T (Eq. 17/19 or the two-geometry solver), T given σ
// (Eq. 15), with standard errors. The JSON document is serialize/measure.hpp's (the same as the
// Python module's dict); --report DIR writes the HTML report through the Python package
// (roughscope.report_measure). Keys and the capture file: docs/measure.md.
#include "roughscope/measure/measure.hpp"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "commands.hpp"
#include "common.hpp"
#include "python_runner.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/maps/map_files.hpp"
#include "roughscope/serialize/json.hpp"
#include "roughscope/serialize/measure.hpp"

namespace roughscope::cli {
namespace {

namespace fs = std::filesystem;

struct MeasureCommand {
    std::string capture_file;
    bool json_output = false;
    std::string output_path;
    std::string report_dir;
    std::string maps_dir;
    CLI::Option *o_output{}, *o_report{}, *o_maps{};
};

// The map's layers as files (docs/measure.md "Map files"): <layer>.tiff (float32) and <layer>.npy
// for every float layer, <layer>.png (false colour with a colour bar) for σ/T and T, <class
// layer>.png and .npy (codes as float, NaN for none). Encoded in memory: {file name, bytes}.
std::vector<std::pair<std::string, std::string>> encode_map_files(const image::RoughnessMap& map) {
    std::vector<std::pair<std::string, std::string>> files;
    for (const auto& layer : serialize::map_float_layers(map)) {
        files.emplace_back(layer.name + ".tiff",
                           image::encode_map_tiff_float(*layer.values, map.width, map.height));
        files.emplace_back(layer.name + ".npy",
                           image::encode_npy(*layer.values, map.width, map.height));
        if (layer.name.find("stderr") == std::string::npos && layer.name != "E1_over_E2")
            files.emplace_back(
                layer.name + ".png",
                image::encode_map_png(*layer.values, map.width, map.height,
                                      image::finite_range(*layer.values), layer.name));
    }
    for (const auto& layer : serialize::map_class_layers(map)) {
        files.emplace_back(layer.name + ".png",
                           image::encode_class_png(*layer.values, map.width, map.height));
        std::vector<float> codes(layer.values->size());
        for (std::size_t k = 0; k < codes.size(); ++k)
            codes[k] = (*layer.values)[k] == image::kClassNone
                           ? std::numeric_limits<float>::quiet_NaN()
                           : static_cast<float>((*layer.values)[k]);
        files.emplace_back(layer.name + ".npy", image::encode_npy(codes, map.width, map.height));
    }
    return files;
}

// Photometric stereo's per-pixel results as files (docs/photometric-stereo.md "Files"):
// normals.npy (height × width × 3, NaN off the object), normals.png (v = (n + 1)/2), albedo.npy,
// residual.npy (the quality map), and for a rough model sigma_over_T_<correlation>.npy,
// sigma_over_T_stderr_<correlation>.npy, delta_aic.npy, sigma_over_T_<correlation>.png and the
// class of each pixel's σ/T, roughness_class.png and .npy (codes as float, NaN for none).
std::vector<std::pair<std::string, std::string>> encode_photometric_files(
    const image::PhotometricStereoResult& r, const image::MeasureRequest& request) {
    std::vector<std::pair<std::string, std::string>> files;
    files.emplace_back("normals.npy", image::encode_npy(r.normals, r.width, r.height, 3));
    files.emplace_back("normals.png", image::encode_normals_png(r.normals, r.width, r.height));
    files.emplace_back("albedo.npy", image::encode_npy(r.albedo, r.width, r.height));
    files.emplace_back("residual.npy", image::encode_npy(r.residual, r.width, r.height));
    if (r.model != image::PhotometricModel::Lambert) {
        const std::string c =
            r.model == image::PhotometricModel::VeryRoughGaussian ? "gaussian" : "exponential";
        files.emplace_back(concat("sigma_over_T_", c, ".npy"),
                           image::encode_npy(r.sigma_over_T, r.width, r.height));
        files.emplace_back(concat("sigma_over_T_stderr_", c, ".npy"),
                           image::encode_npy(r.sigma_over_T_stderr, r.width, r.height));
        files.emplace_back("delta_aic.npy", image::encode_npy(r.delta_aic, r.width, r.height));
        files.emplace_back(
            concat("sigma_over_T_", c, ".png"),
            image::encode_map_png(r.sigma_over_T, r.width, r.height,
                                  image::finite_range(r.sigma_over_T), concat("sigma_over_T_", c)));
        // The class of each pixel's σ/T (the maps' thresholds, the capture file's "maps").
        const image::MapOptions thresholds =
            request.maps ? request.maps->options : image::MapOptions{};
        std::vector<std::uint8_t> classes(r.sigma_over_T.size(), image::kClassNone);
        std::vector<float> codes(r.sigma_over_T.size(), std::numeric_limits<float>::quiet_NaN());
        for (std::size_t k = 0; k < classes.size(); ++k)
            if (std::isfinite(r.sigma_over_T[k])) {
                classes[k] = static_cast<std::uint8_t>(image::roughness_class_of_sigma_over_T(
                    r.sigma_over_T[k], thresholds.slightly_rough_max_sigma_over_T,
                    thresholds.very_rough_min_sigma_over_T));
                codes[k] = static_cast<float>(classes[k]);
            }
        files.emplace_back("roughness_class.png",
                           image::encode_class_png(classes, r.width, r.height));
        files.emplace_back("roughness_class.npy", image::encode_npy(codes, r.width, r.height));
    }
    return files;
}

// Every file the run reads: the capture file, the photographs (and bracket shots), the response
// bracket, the dark frame, the flat field and the normal map.
std::vector<fs::path> input_files(const image::MeasureRequest& r, const std::string& capture_file) {
    std::vector<fs::path> files{capture_file};
    for (const auto& c : r.captures) {
        files.emplace_back(c.image);
        for (const auto& shot : c.bracket) files.emplace_back(shot.image);
    }
    for (const auto& shot : r.response_bracket) files.emplace_back(shot.image);
    if (r.dark_frame) files.emplace_back(*r.dark_frame);
    if (r.flat_field) files.emplace_back(*r.flat_field);
    if (!r.object.normal_map.empty()) files.emplace_back(r.object.normal_map);
    return files;
}

// InvalidArgument when `output` (written for `flag`) is one of the run's inputs: a run never
// overwrites what it reads.
void refuse_output_onto_input(const fs::path& output, const std::string& flag,
                              const std::vector<fs::path>& inputs) {
    for (const auto& input : inputs) {
        std::error_code ec;
        if (fs::equivalent(output, input, ec))
            throw InvalidArgument(concat(flag, " ", output.string(), ": is an input of this run (",
                                         input.string(), "); write the result to another file"));
    }
}

// One command, one commit: every output of the run (--maps files, --report's index.html,
// --output) is prepared in memory and opened as a temporary file first; only when all of them
// are written are they renamed into place, one after the other. A failure before that leaves
// nothing new behind (the folders created for them are removed again), as does a signal
// (io::install_output_cleanup_handlers).
struct PendingOutputs {
    std::vector<io::OutputDirectory> folders;
    std::vector<io::OutputFile> files;

    void add(const fs::path& path, const std::string& bytes) {
        files.emplace_back(path);
        files.back().write(bytes);
    }
    void commit() {
        for (auto& f : files) f.commit();
        for (auto& d : folders) d.keep();
    }
};

void run_measure(const MeasureCommand& c) {
    const image::MeasureRequest request = image::read_capture_file(c.capture_file);
    const std::vector<fs::path> inputs = input_files(request, c.capture_file);
    if (given(c.o_output)) refuse_output_onto_input(c.output_path, "--output", inputs);
    if (given(c.o_maps) && c.maps_dir.empty())
        throw InvalidArgument("--maps: empty folder name (give the folder for the map's files)");
    if (given(c.o_report) && c.report_dir.empty())
        throw InvalidArgument("--report: empty folder name (give the folder for index.html)");
    const fs::path index = fs::path(c.report_dir) / "index.html";
    if (given(c.o_report)) refuse_output_onto_input(index, "--report", inputs);
    const image::MeasureResult result = image::measure(request);
    serialize::Json doc = serialize::to_json(result, request);

    PendingOutputs pending;
    if (given(c.o_maps)) {
        if (!result.map && !result.photometric_stereo)
            throw InvalidArgument(concat("--maps: ", c.capture_file,
                                         " asks for no map (add \"maps\" to the capture file)"));
        pending.folders.emplace_back(c.maps_dir, "--maps");
        const char* const maps_key = result.map ? "map" : "photometric_stereo";
        doc[maps_key]["directory"] = c.maps_dir;
        std::vector<std::string> names;
        for (auto& [name, bytes] :
             result.map ? encode_map_files(*result.map)
                        : encode_photometric_files(*result.photometric_stereo, request)) {
            refuse_output_onto_input(fs::path(c.maps_dir) / name, "--maps", inputs);
            pending.add(fs::path(c.maps_dir) / name, bytes);
            names.push_back(name);
        }
        doc[maps_key]["files"] = names;
    }
    if (given(c.o_report)) {
        // The report is index.html alone (its figures are embedded): nothing else in the
        // folder is written, replaced or removed. It reads the map files not yet committed
        // from their temporary files ("staged_files").
        pending.folders.emplace_back(c.report_dir, "--report");
        serialize::Json for_report = doc;
        if (given(c.o_maps)) {
            serialize::Json staged = serialize::Json::object();
            for (std::size_t k = 0; k < pending.files.size(); ++k) {
                pending.files[k].flush();
                staged[doc[result.map ? "map" : "photometric_stereo"]["files"][k]
                           .get<std::string>()] = pending.files[k].temporary_path();
            }
            for_report[result.map ? "map" : "photometric_stereo"]["staged_files"] = staged;
        }
        pending.add(index, run_python_module("roughscope.report_measure", {"--out", "-"},
                                             serialize::dump(for_report), "measure --report"));
    }
    const std::string text =
        c.json_output ? serialize::dump(serialize::versioned(doc)) : serialize::measure_text(doc);
    if (given(c.o_output)) pending.add(c.output_path, text);
    pending.commit();
    if (!given(c.o_output)) write_output(std::nullopt, text);
}

}  // namespace

void register_measure(CLI::App& app) {
    auto args = std::make_shared<MeasureCommand>();
    MeasureCommand& c = *args;
    CLI::App* cmd = app.add_subcommand(
        "measure",
        "Roughness from photographs: sigma (specular capture), sigma/T and T from the captures "
        "named in a capture file (docs/measure.md)");
    cmd->add_option("capture_file", c.capture_file, "The capture file (JSON)")->required();
    cmd->add_flag("--json", c.json_output, "Print JSON (keys in docs/measure.md)");
    c.o_output = cmd->add_option("--output", c.output_path, "Write the result to FILE atomically");
    c.o_report = cmd->add_option("--report", c.report_dir,
                                 "Write an HTML report (photographs with the regions, values, "
                                 "checks) to DIR/index.html (nothing else in DIR is touched)");
    c.o_maps = cmd->add_option("--maps", c.maps_dir,
                               "Write the roughness map's layers (float32 TIFF, .npy, false-colour "
                               "PNG, class map) to DIR (the capture file's \"maps\")");
    cmd->callback([args]() { run_measure(*args); });
}

}  // namespace roughscope::cli
