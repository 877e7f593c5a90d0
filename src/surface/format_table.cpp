// CSV/ASCII height matrices and XYZ triples (docs/height-files.md, "CSV and XYZ").
//
// Both are text: `#` lines are comments, and a comment of the form `# key = value` (or
// `# key: value`) with a known key is a header line: dx_um, dy_um, x_offset_um, y_offset_um (µm),
// unit (m, mm, um, nm: the unit of the numbers in the file), title; and Gwyddion's "ASCII data
// matrix" export header: `# Channel: <title>`, `# Width: <length> <unit>`, `# Height: <length>
// <unit>`, `# Value units: <unit>`. What the file says wins over HeightReadOptions (the options
// describe files that do not say it). Lines and cells come from io's text reader
// (roughscope/io/csv.hpp), numbers from the library's strict parser (core/numbers.hpp); an empty
// cell or "NaN" is a missing point.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/core/text.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/surface/formats.hpp"
#include "tab_common.hpp"

namespace roughscope::surface::formats {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// An XYZ point may sit this fraction of the grid spacing away from its grid node.
constexpr double kGridTolerance = 0.01;
// An XYZ file may leave at most this share of its grid's nodes without a point (bounds the map a
// few scattered points can ask for).
constexpr std::size_t kMaxGridPerPoint = 16;

struct Header {
    std::optional<double> dx_um, dy_um, x_offset_um, y_offset_um;
    std::optional<tab::LengthUnit> unit;        // unit of the numbers (heights; xyz: x, y, z)
    std::optional<double> width_um, height_um;  // Gwyddion: whole field size
    std::string title;
};

struct Line {
    std::string_view text;
    std::size_t number = 0;  // 1-based
};

std::size_t column_of(std::string_view line, std::string_view part) {
    return static_cast<std::size_t>(part.data() - line.data()) + 1;
}

double header_number(const std::string& name, const Line& line, std::string_view value,
                     std::string_view key) {
    std::string reason;
    if (auto v = try_parse_number(value, reason)) return *v;
    std::string what(key);
    what.append(": ").append(quote_input(trim_space(value))).append(" is ").append(reason);
    throw tab::error_at(name, line.number, column_of(line.text, value), what);
}

double header_positive(const std::string& name, const Line& line, std::string_view value,
                       std::string_view key) {
    const double v = header_number(name, line, value, key);
    if (!(v > 0.0)) {
        std::string what(key);
        what.append(" = ").append(format_message(v)).append(" must be > 0");
        throw tab::error_at(name, line.number, column_of(line.text, value), what);
    }
    return v;
}

tab::LengthUnit header_unit(const std::string& name, const Line& line, std::string_view value,
                            std::string_view key) {
    if (auto unit = tab::parse_length_unit(value)) return *unit;
    std::string what(key);
    what.append(": ").append(quote_input(trim_space(value))).append(" is not one of m, mm, um, nm");
    throw tab::error_at(name, line.number, column_of(line.text, value), what);
}

// "<number> <unit>" (Gwyddion's Width/Height) in µm.
double header_length(const std::string& name, const Line& line, std::string_view value,
                     std::string_view key) {
    const std::string_view t = trim_space(value);
    const std::size_t space = t.find_last_of(" \t");
    if (space == std::string_view::npos) {
        std::string what(key);
        what.append(": ").append(quote_input(t)).append(" is not '<length> <unit>'");
        throw tab::error_at(name, line.number, column_of(line.text, value), what);
    }
    const double length = header_positive(name, line, t.substr(0, space), key);
    return tab::to_um(length, header_unit(name, line, t.substr(space + 1), key));
}

// Reads a `#` line into the header when its key is known; other comments are ignored.
void read_header_line(const std::string& name, const Line& line, std::string_view body,
                      Header& header) {
    const std::size_t eq = body.find_first_of("=:");
    if (eq == std::string_view::npos) return;
    const std::string_view key = trim_space(body.substr(0, eq));
    const std::string_view value = body.substr(eq + 1);
    if (tab::same_key(key, "dx_um")) {
        header.dx_um = header_positive(name, line, value, key);
    } else if (tab::same_key(key, "dy_um")) {
        header.dy_um = header_positive(name, line, value, key);
    } else if (tab::same_key(key, "x_offset_um")) {
        header.x_offset_um = header_number(name, line, value, key);
    } else if (tab::same_key(key, "y_offset_um")) {
        header.y_offset_um = header_number(name, line, value, key);
    } else if (tab::same_key(key, "unit") || tab::same_key(key, "Value units")) {
        header.unit = header_unit(name, line, value, key);
    } else if (tab::same_key(key, "Width")) {
        header.width_um = header_length(name, line, value, key);
    } else if (tab::same_key(key, "Height")) {
        header.height_um = header_length(name, line, value, key);
    } else if (tab::same_key(key, "title") || tab::same_key(key, "Channel")) {
        header.title = std::string(trim_space(value));
    }
}

// A cell's value: a strict number, or NaN for an empty cell or "NaN" (only when allow_missing).
double cell_value(const std::string& name, const Line& line, std::string_view cell,
                  bool allow_missing, std::string_view what) {
    const std::string_view t = trim_space(cell);
    if (allow_missing && (t.empty() || tab::is_nan_text(t))) return kNaN;
    std::string reason;
    if (auto v = try_parse_number(t, reason)) return *v;
    std::string message(what);
    message.append(": ").append(quote_input(t)).append(" is ").append(reason);
    const std::size_t column = t.empty() ? column_of(line.text, cell) : column_of(line.text, t);
    throw tab::error_at(name, line.number, column, message);
}

// Walks the lines (io::TextLines: the byte-order mark, line ends and NUL bytes as every text
// reader takes them): header comments into `header`, data lines split into cells to `on_row` —
// by `,` or `;` (cells may be empty) or by runs of white space, as the first data line shows.
template <class OnRow>
void walk(std::string_view bytes, const std::string& name, Header& header, OnRow&& on_row) {
    io::TextLines lines(bytes, name);
    std::vector<std::string_view> cells;
    bool have_sep = false;
    char sep = 0;
    std::string_view text;
    while (lines.next(text)) {
        const Line line{text, lines.line_number()};
        const std::string_view t = trim_space(line.text);
        if (t.empty()) continue;
        if (t.front() == '#') {
            read_header_line(name, line, t.substr(1), header);
            continue;
        }
        if (!have_sep) {
            have_sep = true;
            if (t.find(',') != std::string_view::npos) {
                sep = ',';
            } else if (t.find(';') != std::string_view::npos) {
                sep = ';';
            }
        }
        if (sep != 0)
            io::split_fields(line.text, sep, cells);
        else
            io::split_whitespace(line.text, cells);
        on_row(line, cells);
    }
}

std::string note_assumed(std::string title) {
    if (!title.empty()) title.append(" ");
    title.append("(dx = dy = 1 um assumed: no spacing in the file or the options)");
    return title;
}

std::string header_text(const HeightMap& map, std::string_view what) {
    std::string out("# roughscope height map (");
    out.append(what).append(")\n");
    if (!map.title.empty()) {
        std::string title = map.title;
        std::replace_if(
            title.begin(), title.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
        out.append("# title = ").append(title).append("\n");
    }
    out.append("# unit = um\n");
    out.append("# dx_um = ").append(format_roundtrip(map.dx_um, "dx_um")).append("\n");
    out.append("# dy_um = ").append(format_roundtrip(map.dy_um, "dy_um")).append("\n");
    out.append("# x_offset_um = ")
        .append(format_roundtrip(map.x_offset_um, "x_offset_um"))
        .append("\n");
    out.append("# y_offset_um = ")
        .append(format_roundtrip(map.y_offset_um, "y_offset_um"))
        .append("\n");
    return out;
}

void append_height(std::string& out, double z) {
    if (std::isnan(z)) {
        out.append("NaN");
    } else {
        out.append(format_roundtrip(z, "height"));
    }
}

// One axis of an XYZ grid: node positions offset + i·step, i in [0, n).
struct Axis {
    double offset = 0.0;
    double step = 0.0;  // 0 while unknown (a single node)
    std::size_t n = 1;
};

Axis infer_axis(const std::string& name, std::vector<double> values,
                const std::optional<double>& header_step,
                const std::optional<double>& header_offset, std::string_view axis) {
    std::sort(values.begin(), values.end());
    values.erase(std::unique(values.begin(), values.end()), values.end());
    Axis a;
    a.offset = values.front();
    const double range = values.back() - values.front();
    if (range > 0.0) {
        // The smallest gap between distinct coordinates, ignoring jitter below 1e-6 of the range.
        double gap = std::numeric_limits<double>::infinity();
        for (std::size_t i = 1; i < values.size(); ++i) {
            const double g = values[i] - values[i - 1];
            if (g > 1e-6 * range) gap = std::min(gap, g);
        }
        if (!std::isfinite(gap)) {  // a million-point ramp: every gap below the jitter limit
            for (std::size_t i = 1; i < values.size(); ++i) {
                gap = std::min(gap, values[i] - values[i - 1]);
            }
        }
        const double steps = std::round(range / gap);
        if (!(steps < static_cast<double>(kMaxHeightMapPoints))) {
            std::string what(axis);
            what.append(" coordinates span ")
                .append(format_message(range))
                .append(" um in steps of ")
                .append(format_message(gap))
                .append(" um: more than ")
                .append(std::to_string(kMaxHeightMapPoints))
                .append(" grid nodes");
            throw DataError(name + ": " + what);
        }
        a.n = static_cast<std::size_t>(steps) + 1;
        a.step = range / steps;
        if (header_step && std::abs(*header_step - a.step) <= 1e-6 * a.step) a.step = *header_step;
    } else if (header_step) {
        a.step = *header_step;
    }
    if (header_offset &&
        std::abs(*header_offset - a.offset) <= kGridTolerance * (a.step > 0.0 ? a.step : 1.0)) {
        a.offset = *header_offset;
    }
    return a;
}

}  // namespace

HeightMap decode_csv_matrix(std::string_view bytes, const std::string& name,
                            const HeightReadOptions& options) {
    const auto option_unit = tab::unit_option(options);
    const tab::Spacings given = tab::spacings_from(options);
    Header header;
    std::vector<double> values;
    std::size_t nx = 0;
    std::size_t ny = 0;
    std::size_t first_line = 0;
    walk(bytes, name, header, [&](const Line& line, const std::vector<std::string_view>& cells) {
        if (ny == 0) {
            nx = cells.size();
            first_line = line.number;
        } else if (cells.size() != nx) {
            std::string what = std::to_string(cells.size());
            what.append(" values in this row, but the first row (line ")
                .append(std::to_string(first_line))
                .append(") has ")
                .append(std::to_string(nx));
            throw tab::error_at(name, line.number, 0, what);
        }
        for (const std::string_view cell : cells) {
            values.push_back(cell_value(name, line, cell, true, "height"));
        }
        ++ny;
    });
    if (ny == 0) throw DataError(name + ": no data rows (only comments or empty lines)");
    tab::check_grid_size(name, nx, ny, "matrix");

    const tab::LengthUnit unit =
        header.unit ? *header.unit : option_unit.value_or(tab::LengthUnit::um);
    HeightMap map;
    map.nx = nx;
    map.ny = ny;
    map.heights_um = std::move(values);
    for (double& z : map.heights_um) z = tab::to_um(z, unit);
    bool assumed = false;
    if (header.dx_um) {
        map.dx_um = *header.dx_um;
    } else if (header.width_um) {
        map.dx_um = *header.width_um / static_cast<double>(nx);
    } else {
        map.dx_um = given.dx_um;
        assumed = given.assumed;
    }
    if (header.dy_um) {
        map.dy_um = *header.dy_um;
    } else if (header.height_um) {
        map.dy_um = *header.height_um / static_cast<double>(ny);
    } else if (header.dx_um || header.width_um) {
        map.dy_um = options.dy_um ? given.dy_um : map.dx_um;
    } else {
        map.dy_um = given.dy_um;
    }
    map.x_offset_um = header.x_offset_um.value_or(0.0);
    map.y_offset_um = header.y_offset_um.value_or(0.0);
    map.title = assumed ? note_assumed(header.title) : header.title;
    return tab::finish(std::move(map), name);
}

std::string encode_csv_matrix(const HeightMap& map, const HeightWriteOptions&) {
    std::string out = header_text(map, "CSV matrix: one row of heights per line, x along a row");
    out.reserve(out.size() + map.size() * 20);
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            if (ix > 0) out.push_back(',');
            append_height(out, map.at(ix, iy));
        }
        out.push_back('\n');
    }
    return out;
}

HeightMap decode_xyz(std::string_view bytes, const std::string& name,
                     const HeightReadOptions& options) {
    const auto option_unit = tab::unit_option(options);
    Header header;
    std::vector<double> xs, ys, zs;
    std::vector<std::size_t> line_of;
    walk(bytes, name, header, [&](const Line& line, const std::vector<std::string_view>& cells) {
        if (cells.size() != 3) {
            std::string what = std::to_string(cells.size());
            what.append(" values; an XYZ line holds 3 (x, y, z)");
            throw tab::error_at(name, line.number, 0, what);
        }
        xs.push_back(cell_value(name, line, cells[0], false, "x"));
        ys.push_back(cell_value(name, line, cells[1], false, "y"));
        zs.push_back(cell_value(name, line, cells[2], true, "z"));
        line_of.push_back(line.number);
    });
    if (xs.empty()) throw DataError(name + ": no data lines (only comments or empty lines)");
    const tab::LengthUnit unit =
        header.unit ? *header.unit : option_unit.value_or(tab::LengthUnit::um);
    for (std::size_t i = 0; i < xs.size(); ++i) {
        xs[i] = tab::to_um(xs[i], unit);
        ys[i] = tab::to_um(ys[i], unit);
        zs[i] = tab::to_um(zs[i], unit);
    }

    Axis ax = infer_axis(name, xs, header.dx_um, header.x_offset_um, "x");
    Axis ay = infer_axis(name, ys, header.dy_um, header.y_offset_um, "y");
    if (ax.step == 0.0) ax.step = ay.step;
    if (ay.step == 0.0) ay.step = ax.step;
    const bool assumed = ax.step == 0.0;
    if (assumed) ax.step = ay.step = 1.0;
    tab::check_grid_size(name, ax.n, ay.n, "xyz grid");
    if (ax.n * ay.n / kMaxGridPerPoint > xs.size()) {
        std::string message = name;
        message.append(": the ")
            .append(std::to_string(xs.size()))
            .append(" points do not fill a regular grid: their coordinates span ")
            .append(std::to_string(ax.n))
            .append(" x ")
            .append(std::to_string(ay.n))
            .append(" nodes (spacings ")
            .append(format_message(ax.step))
            .append(", ")
            .append(format_message(ay.step))
            .append(" um), and at most 1/")
            .append(std::to_string(kMaxGridPerPoint))
            .append(" of the nodes may hold a point");
        throw DataError(message);
    }

    HeightMap map;
    map.nx = ax.n;
    map.ny = ay.n;
    map.dx_um = ax.step;
    map.dy_um = ay.step;
    map.x_offset_um = ax.offset;
    map.y_offset_um = ay.offset;
    map.heights_um.assign(map.nx * map.ny, kNaN);
    std::vector<std::size_t> taken(map.nx * map.ny, 0);  // line of the point at a node, 0 = none
    auto node = [&](double v, const Axis& a, std::size_t i, std::string_view axis) {
        const double f = (v - a.offset) / a.step;
        const double k = std::round(f);
        if (!(k >= 0.0 && k < static_cast<double>(a.n) && std::abs(f - k) <= kGridTolerance)) {
            std::string what = "point (";
            what.append(format_message(xs[i]))
                .append(", ")
                .append(format_message(ys[i]))
                .append(") um is off the regular grid along ")
                .append(axis)
                .append(" (nodes at ")
                .append(format_message(a.offset))
                .append(" + k * ")
                .append(format_message(a.step))
                .append(" um, tolerance 1% of the spacing)");
            throw tab::error_at(name, line_of[i], 0, what);
        }
        return static_cast<std::size_t>(k);
    };
    for (std::size_t i = 0; i < xs.size(); ++i) {
        const std::size_t ix = node(xs[i], ax, i, "x");
        const std::size_t iy = node(ys[i], ay, i, "y");
        const std::size_t k = iy * map.nx + ix;
        if (taken[k] != 0) {
            std::string what = "duplicate point (";
            what.append(format_message(xs[i]))
                .append(", ")
                .append(format_message(ys[i]))
                .append(") um: the same grid node as line ")
                .append(std::to_string(taken[k]));
            throw tab::error_at(name, line_of[i], 0, what);
        }
        taken[k] = line_of[i];
        map.heights_um[k] = zs[i];
    }
    map.title = assumed ? note_assumed(header.title) : header.title;
    return tab::finish(std::move(map), name);
}

std::string encode_xyz(const HeightMap& map, const HeightWriteOptions&) {
    std::string out = header_text(map, "XYZ: x y z per line, missing points z = NaN");
    out.reserve(out.size() + map.size() * 40);
    for (std::size_t iy = 0; iy < map.ny; ++iy) {
        const double y = map.y_offset_um + static_cast<double>(iy) * map.dy_um;
        for (std::size_t ix = 0; ix < map.nx; ++ix) {
            const double x = map.x_offset_um + static_cast<double>(ix) * map.dx_um;
            out.append(format_roundtrip(x, "x"))
                .append(" ")
                .append(format_roundtrip(y, "y"))
                .append(" ");
            append_height(out, map.at(ix, iy));
            out.push_back('\n');
        }
    }
    return out;
}

}  // namespace roughscope::surface::formats
