// Reading the CUReT BRDF database (paper §5.3). See curet.hpp for the file formats.
#include "roughscope/brdf/curet.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <set>
#include <string>
#include <system_error>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/io/data_locator.hpp"

namespace roughscope {
namespace {

namespace fs = std::filesystem;

const char* const kNeededFiles =
    "table.txt (205 lines: measurement theta_v phi_v theta_i phi_i, radians) and abrdf.dat "
    "(one line per sample: sample number then 205 BRDF values in 1/sr)";
const char* const kWhereFrom =
    "the CUReT database (Dana, van Ginneken, Nayar, Koenderink, 'Reflectance and texture of "
    "real-world surfaces', ACM TOG 18(1), 1999), published by Columbia University's CAVE lab "
    "(www.cs.columbia.edu/CAVE/software/curet)";

// One non-blank line of whitespace-separated fields (views into the reader's buffer).
struct Line {
    std::size_t number = 0;
    std::vector<std::string_view> fields;
};

// Opens `path` for line-by-line reading (io/csv.hpp: UTF-8 BOM and CRLF accepted, NUL bytes
// refused). Throws DataError "<path>: does not exist" or "<path>: is a directory, not a file".
io::LineReader open_lines(const fs::path& path) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw DataError(path.string() + ": does not exist");
    return io::LineReader(path);
}

// The next non-blank line of `reader`; false at the end of the file.
bool next_line(io::LineReader& reader, Line& line) {
    std::string_view text;
    while (reader.next(text)) {
        line.fields = io::split_whitespace(text);
        line.number = reader.line_number();
        if (!line.fields.empty()) return true;
    }
    return false;
}

[[noreturn]] void fail(const fs::path& file, std::size_t line, const std::string& what) {
    throw DataError(file.string() + ":" + std::to_string(line) + ": " + what);
}

double field_number(const fs::path& file, const Line& line, std::size_t k, const char* what) {
    std::string reason;
    const auto v = try_parse_number(line.fields[k], reason);
    if (!v)
        fail(file, line.number,
             std::string("field ") + std::to_string(k + 1) + " (" + what +
                 "): " + quote_input(line.fields[k]) + " is " + reason);
    return *v;
}

// Measurement and sample numbers: decimal digits only (core/numbers.hpp), 1..1e6.
int field_integer(const fs::path& file, const Line& line, std::size_t k, const char* what) {
    std::string reason;
    const auto v = try_parse_integer(line.fields[k], 1, 1000000, reason);
    if (!v)
        fail(file, line.number,
             std::string("field ") + std::to_string(k + 1) + " (" + what +
                 "): " + quote_input(line.fields[k]) + " is " + reason);
    return static_cast<int>(*v);
}

std::vector<CuretAngles> read_angle_table(const fs::path& file) {
    io::LineReader reader = open_lines(file);
    std::vector<CuretAngles> angles;
    Line line;
    while (next_line(reader, line)) {
        if (line.fields.size() != 5)
            fail(file, line.number,
                 "expected 5 fields (measurement theta_v phi_v theta_i phi_i), found " +
                     std::to_string(line.fields.size()));
        CuretAngles a;
        a.measurement = field_integer(file, line, 0, "measurement");
        if (a.measurement != static_cast<int>(angles.size()) + 1)
            fail(file, line.number,
                 "measurement " + std::to_string(a.measurement) + " where " +
                     std::to_string(angles.size() + 1) +
                     " was expected (rows must be measurements 1..205 in order)");
        a.theta_v_rad = field_number(file, line, 1, "theta_v");
        a.phi_v_rad = field_number(file, line, 2, "phi_v");
        a.theta_i_rad = field_number(file, line, 3, "theta_i");
        a.phi_i_rad = field_number(file, line, 4, "phi_i");
        for (auto [name, value] :
             {std::pair{"theta_v", a.theta_v_rad}, std::pair{"theta_i", a.theta_i_rad}})
            if (!(value >= 0.0 && value < kPi / 2))
                fail(file, line.number,
                     std::string(name) + " = " + check::format_number(value) +
                         " rad is outside the valid range [0, pi/2)");
        angles.push_back(a);
    }
    if (angles.size() != static_cast<std::size_t>(kCuretMeasurementCount))
        throw DataError(file.string() + ": " + std::to_string(angles.size()) +
                        " measurement rows, expected " + std::to_string(kCuretMeasurementCount));
    return angles;
}

// Reads a per-sample file (BRDF or overflow): sample number + 205 values per line.
void read_sample_file(const fs::path& file, bool fractions, std::vector<int>& samples,
                      std::vector<std::vector<double>>& values) {
    io::LineReader reader = open_lines(file);
    std::set<int> seen;
    Line line;
    while (next_line(reader, line)) {
        const std::size_t expected = kCuretMeasurementCount + 1;
        if (line.fields.size() != expected)
            fail(file, line.number,
                 "expected " + std::to_string(expected) +
                     " fields (sample number then 205 values), found " +
                     std::to_string(line.fields.size()));
        const int sample = field_integer(file, line, 0, "sample number");
        if (!seen.insert(sample).second)
            fail(file, line.number, "sample " + std::to_string(sample) + " appears twice");
        std::vector<double> row(kCuretMeasurementCount);
        for (int j = 0; j < kCuretMeasurementCount; ++j) {
            row[j] = field_number(file, line, static_cast<std::size_t>(j) + 1,
                                  fractions ? "overflow fraction" : "BRDF value");
            if (fractions && !(row[j] >= 0.0 && row[j] <= 1.0))
                fail(file, line.number,
                     "measurement " + std::to_string(j + 1) + ": overflow fraction " +
                         check::format_number(row[j]) + " is outside [0, 1]");
        }
        samples.push_back(sample);
        values.push_back(std::move(row));
    }
    if (samples.empty()) throw DataError(file.string() + ": no sample rows");
}

char channel_letter(CuretChannel c) {
    switch (c) {
        case CuretChannel::Mean:
            return 'a';
        case CuretChannel::Red:
            return 'r';
        case CuretChannel::Green:
            return 'g';
        case CuretChannel::Blue:
            return 'b';
    }
    return 'a';
}

bool has_curet_files(const fs::path& dir) {
    std::error_code ec;
    return fs::is_regular_file(dir / "table.txt", ec) && fs::is_regular_file(dir / "abrdf.dat", ec);
}

}  // namespace

// The file letters a, r, g, b are accepted as aliases.
constexpr std::array<NameEntry<CuretChannel>, 8> kChannelNames{{
    {"mean", CuretChannel::Mean},
    {"red", CuretChannel::Red},
    {"green", CuretChannel::Green},
    {"blue", CuretChannel::Blue},
    {"a", CuretChannel::Mean},
    {"r", CuretChannel::Red},
    {"g", CuretChannel::Green},
    {"b", CuretChannel::Blue},
}};

std::string_view to_string(CuretChannel channel) { return name_of(kChannelNames, channel); }

CuretChannel parse_curet_channel(std::string_view name) {
    return parse_name(kChannelNames, "channel", name);
}

std::string curet_brdf_file_name(CuretChannel channel) {
    return std::string(1, channel_letter(channel)) + "brdf.dat";
}

std::size_t CuretDatabase::row(int sample) const {
    for (std::size_t k = 0; k < samples.size(); ++k)
        if (samples[k] == sample) return k;
    const auto [lo, hi] = std::minmax_element(samples.begin(), samples.end());
    throw InvalidArgument(
        "sample = " + std::to_string(sample) + " is not in the database (valid samples: " +
        (samples.empty() ? std::string("none") : std::to_string(*lo) + ".." + std::to_string(*hi)) +
        ")");
}

BrdfTable CuretDatabase::sample_table(int sample) const {
    const std::size_t r = row(sample);
    BrdfTable table;
    table.name = "CUReT sample " + std::to_string(sample);
    table.channel = std::string(to_string(channel));
    table.measurements.reserve(angles.size());
    for (std::size_t j = 0; j < angles.size(); ++j) {
        const CuretAngles& a = angles[j];
        std::optional<double> over;
        if (!overflow.empty()) over = overflow[r][j];
        table.measurements.push_back(make_brdf_measurement(a.measurement, a.theta_i_rad,
                                                           a.phi_i_rad, a.theta_v_rad, a.phi_v_rad,
                                                           brdf[r][j], 1.0, over));
    }
    return table;
}

fs::path find_curet_directory(const std::optional<fs::path>& explicit_dir) {
    if (explicit_dir) {
        std::error_code ec;
        if (!fs::is_directory(*explicit_dir, ec))
            throw DataError(
                "CUReT directory " + explicit_dir->string() +
                (fs::exists(*explicit_dir, ec) ? " is not a directory" : " does not exist") +
                "; it must be a directory holding " + kNeededFiles + ", from " + kWhereFrom);
        for (const char* name : {"table.txt", "abrdf.dat"}) {
            const fs::path file = *explicit_dir / name;
            if (!fs::exists(file, ec))
                throw DataError("CUReT directory " + explicit_dir->string() + " lacks " + name +
                                "; it must hold " + kNeededFiles + ", from " + kWhereFrom);
            if (!fs::is_regular_file(file, ec))
                throw DataError(file.string() + ": " +
                                (fs::is_directory(file, ec) ? "is a directory, not a file"
                                                            : "is not a regular file") +
                                "; the CUReT directory must hold " + kNeededFiles);
        }
        return *explicit_dir;
    }
    // The reference-data locator (io/data_locator.hpp): $ROUGHSCOPE_SHARED_DIR/data/curet, else
    // ../shared/data/curet from the current directory upward.
    if (auto located = io::curet_data_dir()) return *located;
    if (const char* env = std::getenv("ROUGHSCOPE_CURET"); env && *env) {
        fs::path dir(env);
        if (!has_curet_files(dir))
            throw DataError("ROUGHSCOPE_CURET = " + dir.string() + " does not hold " +
                            kNeededFiles + "; get them from " + kWhereFrom);
        return dir;
    }
    throw DataError("CUReT data not found: looked in " +
                    io::shared_search_description(io::kCuretRelative) +
                    " and $ROUGHSCOPE_CURET (unset); give --data DIR or set ROUGHSCOPE_CURET to "
                    "a directory holding " +
                    kNeededFiles + ", from " + kWhereFrom);
}

CuretDatabase load_curet(const fs::path& dir, CuretChannel channel) {
    CuretDatabase db;
    db.directory = dir;
    db.channel = channel;
    db.angles = read_angle_table(dir / "table.txt");
    read_sample_file(dir / curet_brdf_file_name(channel), false, db.samples, db.brdf);

    // Overflow (saturation) fractions, when published beside the BRDF file.
    std::vector<std::string> candidates;
    std::error_code ec;
    const std::string own = std::string(1, channel_letter(channel)) + "over.dat";
    if (fs::is_regular_file(dir / own, ec)) {
        candidates.push_back(own);
    } else if (channel == CuretChannel::Mean) {
        for (const char* f : {"rover.dat", "gover.dat", "bover.dat"})
            if (fs::is_regular_file(dir / f, ec)) candidates.push_back(f);
    }
    for (const std::string& name : candidates) {
        std::vector<int> samples;
        std::vector<std::vector<double>> values;
        read_sample_file(dir / name, true, samples, values);
        if (db.overflow.empty())
            db.overflow.assign(db.samples.size(), std::vector<double>(kCuretMeasurementCount, 0.0));
        for (std::size_t r = 0; r < db.samples.size(); ++r) {
            const auto it = std::find(samples.begin(), samples.end(), db.samples[r]);
            if (it == samples.end())
                throw DataError((dir / name).string() + ": sample " +
                                std::to_string(db.samples[r]) + " of " +
                                curet_brdf_file_name(channel) + " is missing");
            const std::vector<double>& v = values[static_cast<std::size_t>(it - samples.begin())];
            for (int j = 0; j < kCuretMeasurementCount; ++j)
                db.overflow[r][j] = std::max(db.overflow[r][j], v[j]);
        }
        db.overflow_files.push_back(name);
    }
    return db;
}

std::string_view curet_sample_name(int sample) {
    switch (sample) {
        case 25:
            return "Quarry tile";
        case 34:
            return "Slate b";
        case 41:
            return "Brick b";
        default:
            return "";
    }
}

std::optional<OrenNayarParams> paper_oren_nayar_params(int sample) {
    // Table 3 of the paper (σ_ON in rad, ρ_ON), as tabulated in the CUReT database.
    switch (sample) {
        case 25:
            return OrenNayarParams{0.3606, 0.1060};
        case 34:
            return OrenNayarParams{0.3096, 0.0685};
        case 41:
            return OrenNayarParams{0.2760, 0.0577};
        default:
            return std::nullopt;
    }
}

}  // namespace roughscope
