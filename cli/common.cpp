// Shared helpers of the `roughscope` command-line tool (see common.hpp).
#include "common.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <iostream>
#include <random>
#include <set>
#include <sstream>
#include <system_error>

#include <unistd.h>

namespace roughscope::cli {

namespace {

constexpr std::string_view kWhitespace = " \t\r\n\v\f";

std::string_view trim(std::string_view s) {
    const auto first = s.find_first_not_of(kWhitespace);
    if (first == std::string_view::npos) return {};
    const auto last = s.find_last_not_of(kWhitespace);
    return s.substr(first, last - first + 1);
}

std::vector<std::string_view> split(std::string_view s, char sep) {
    std::vector<std::string_view> out;
    std::size_t start = 0;
    while (true) {
        const auto pos = s.find(sep, start);
        if (pos == std::string_view::npos) {
            out.push_back(s.substr(start));
            return out;
        }
        out.push_back(s.substr(start, pos - start));
        start = pos + 1;
    }
}

std::string one_line(std::string_view message) {
    std::string s(trim(message));
    for (char& c : s) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    return s;
}

std::string join(const std::vector<std::string>& items, std::string_view sep) {
    std::string out;
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (i) out += sep;
        out += items[i];
    }
    return out;
}

std::string fmt_g(double value, int digits) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*g", digits, value);
    return buf;
}

// Shortest form of a limit for messages ("90", "0.5").
std::string fmt_limit(double value) { return fmt_g(value, 15); }

}  // namespace

// ---------------------------------------------------------------------------------------------
// Errors

void print_error(std::string_view message) {
    std::cerr << "roughscope: error: " << one_line(message) << std::endl;
}

int run_guarded(const std::function<int()>& body) {
    try {
        return body();
    } catch (const CLI::ParseError& e) {
        print_error(std::string(e.what()) + " (see --help)");
        return kExitUsage;
    } catch (const roughscope::InvalidArgument& e) {  // includes UsageError
        print_error(e.what());
        return kExitUsage;
    } catch (const roughscope::NoSolution& e) {
        print_error(e.what());
        return kExitNoSolution;
    } catch (const roughscope::DataError& e) {
        print_error(e.what());
        return kExitData;
    } catch (const roughscope::Error& e) {
        print_error(e.what());
        return kExitFailure;
    } catch (const std::filesystem::filesystem_error& e) {
        print_error(e.what());
        return kExitData;
    } catch (const std::ios_base::failure& e) {
        print_error(std::string("I/O error: ") + e.what());
        return kExitData;
    } catch (const CLI::Error& e) {
        print_error(e.what());
        return kExitFailure;
    } catch (const std::exception& e) {
        print_error(std::string("internal error: ") + e.what());
        return kExitFailure;
    } catch (...) {
        print_error("internal error: unknown exception");
        return kExitFailure;
    }
}

int run_app(CLI::App& app, int argc, char** argv) {
    return run_guarded([&]() -> int {
        // CLI11 reports an unknown subcommand as "A subcommand is required"; name it instead.
        if (argc > 1 && argv[1][0] != '-') {
            const std::string name = argv[1];
            std::vector<std::string> names;
            bool known = false;
            for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
                names.push_back(sub->get_name());
                known = known || sub->check_name(name);
            }
            if (!known) {
                throw UsageError("unknown subcommand '" + name +
                                 "' (available: " + join(names, ", ") + "; see --help)");
            }
        }
        try {
            app.parse(argc, argv);
        } catch (const CLI::Success& e) {  // --help, --help-all, --version
            return app.exit(e);
        }
        std::cout.flush();
        if (!std::cout) throw roughscope::DataError("cannot write to standard output");
        return kExitOk;
    });
}

// ---------------------------------------------------------------------------------------------
// Numbers

std::optional<double> parse_double(std::string_view text, std::string& reason) {
    std::string_view s = trim(text);
    if (s.empty()) {
        reason = "empty (a number is required)";
        return std::nullopt;
    }
    std::string_view digits = s;
    if (digits.front() == '+') digits.remove_prefix(1);
    double value = 0.0;
    const auto [ptr, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec == std::errc::result_out_of_range) {
        reason = "out of the range of double-precision numbers";
        return std::nullopt;
    }
    if (ec != std::errc() || ptr != digits.data() + digits.size() || digits.empty()) {
        reason = "not a number";
        return std::nullopt;
    }
    if (std::isnan(value)) {
        reason = "not a finite number (NaN is not accepted)";
        return std::nullopt;
    }
    if (std::isinf(value)) {
        reason = "not a finite number (infinity is not accepted)";
        return std::nullopt;
    }
    return value;
}

double parse_double_or_throw(std::string_view text, std::string_view what) {
    std::string reason;
    const auto value = parse_double(text, reason);
    if (!value) {
        throw roughscope::InvalidArgument(std::string(what) + ": '" + std::string(trim(text)) +
                                          "' is " + reason);
    }
    return *value;
}

std::vector<double> parse_number_list(std::string_view text, std::size_t count,
                                      std::string_view what) {
    const auto parts = split(text, ',');
    if (parts.size() != count) {
        throw roughscope::InvalidArgument(
            std::string(what) + ": expected " + std::to_string(count) +
            " comma-separated numbers, got '" + std::string(trim(text)) + "'");
    }
    std::vector<double> out;
    out.reserve(count);
    for (std::size_t i = 0; i < parts.size(); ++i) {
        out.push_back(parse_double_or_throw(
            parts[i], std::string(what) + " (item " + std::to_string(i + 1) + ")"));
    }
    return out;
}

double round_significant(double value, int digits) {
    if (!std::isfinite(value) || value == 0.0) return value;
    return std::strtod(fmt_g(value, digits).c_str(), nullptr);
}

std::string format_result(double value, std::string_view name) {
    if (!std::isfinite(value)) {
        throw roughscope::Error("internal error: " + std::string(name) +
                                " is not a finite number; refusing to print it");
    }
    return fmt_g(value == 0.0 ? 0.0 : value, kPrintDigits);  // no "-0"
}

json finite_number(double value, std::string_view name) {
    if (!std::isfinite(value)) {
        throw roughscope::Error("internal error: " + std::string(name) +
                                " is not a finite number; refusing to print it");
    }
    return json(value == 0.0 ? 0.0 : round_significant(value));
}

json number_or_null(std::optional<double> value, std::string_view name) {
    if (!value) return json(nullptr);
    return finite_number(*value, name);
}

json number_or_null(double value, std::string_view name) { return finite_number(value, name); }

std::string dump_json(const json& value) { return value.dump(2) + "\n"; }

// ---------------------------------------------------------------------------------------------
// Files

void write_file_atomic(const std::filesystem::path& path, const std::string& content) {
    namespace fs = std::filesystem;
    const auto fail = [&](const std::string& reason) -> void {
        throw roughscope::DataError("cannot write " + path.string() + ": " + reason);
    };
    if (path.empty()) fail("empty file name");
    if (path.filename().empty()) fail("not a file name");
    std::error_code ec;
    if (fs::is_directory(path, ec)) fail("is a directory");
    const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec)) fail("directory " + dir.string() + " does not exist");

    std::random_device rd;
    const fs::path tmp = dir / ("." + path.filename().string() + ".tmp-" +
                                std::to_string(::getpid()) + "-" + std::to_string(rd()));
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) fail(std::strerror(errno));
        out.write(content.data(), static_cast<std::streamsize>(content.size()));
        out.flush();
        if (!out) {
            const std::string reason = std::strerror(errno);
            out.close();
            fs::remove(tmp, ec);
            fail(reason);
        }
        out.close();
        if (out.fail()) {
            fs::remove(tmp, ec);
            fail("error while closing the file");
        }
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        std::error_code ignored;
        fs::remove(tmp, ignored);
        fail(ec.message());
    }
}

void write_output(const std::optional<std::filesystem::path>& path, const std::string& content) {
    if (path) {
        write_file_atomic(*path, content);
    } else {
        std::cout << content;
        std::cout.flush();
        if (!std::cout) throw roughscope::DataError("cannot write to standard output");
    }
}

double CsvRow::at(const std::string& column) const {
    const auto it = values.find(column);
    if (it == values.end()) {
        throw roughscope::DataError("line " + std::to_string(line) + ": column '" + column +
                                    "' has no value");
    }
    return it->second;
}

std::optional<double> CsvRow::find(const std::string& column) const {
    const auto it = values.find(column);
    if (it == values.end()) return std::nullopt;
    return it->second;
}

std::vector<CsvRow> read_csv_with_header(const std::filesystem::path& path,
                                         const std::vector<std::string>& required,
                                         const std::vector<std::string>& optional) {
    const std::string file = path.string();
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec)) {
        throw roughscope::DataError(file + ": is a directory, not a CSV file");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw roughscope::DataError(file + ": cannot open: " + std::strerror(errno));
    }
    const auto where = [&](std::size_t line) { return file + ":" + std::to_string(line) + ": "; };

    std::vector<std::string> header;
    std::vector<int> kind;  // per column: 0 = text only, 1 = required, 2 = optional
    std::vector<CsvRow> rows;
    std::string raw;
    std::size_t line_no = 0;
    while (std::getline(in, raw)) {
        ++line_no;
        if (line_no == 1 && raw.size() >= 3 && raw.compare(0, 3, "\xEF\xBB\xBF") == 0) {
            raw.erase(0, 3);  // UTF-8 byte-order mark
        }
        const std::string_view line = trim(raw);
        if (line.empty() || line.front() == '#') continue;
        const auto fields = split(line, ',');

        if (header.empty()) {
            std::set<std::string> seen;
            for (const auto f : fields) {
                std::string name(trim(f));
                if (name.empty()) {
                    throw roughscope::DataError(where(line_no) +
                                                "empty column name in the header '" +
                                                std::string(line) + "'");
                }
                if (!seen.insert(name).second) {
                    throw roughscope::DataError(where(line_no) + "duplicate column '" + name +
                                                "' in the header");
                }
                header.push_back(std::move(name));
            }
            std::vector<std::string> missing;
            for (const auto& r : required) {
                if (!seen.count(r)) missing.push_back(r);
            }
            if (!missing.empty()) {
                throw roughscope::DataError(
                    where(line_no) + "missing required column" + (missing.size() > 1 ? "s " : " ") +
                    join(missing, ", ") + " (header has: " + join(header, ", ") +
                    "; required: " + join(required, ", ") +
                    (optional.empty() ? "" : "; optional: " + join(optional, ", ")) + ")");
            }
            for (const auto& name : header) {
                if (std::find(required.begin(), required.end(), name) != required.end()) {
                    kind.push_back(1);
                } else if (std::find(optional.begin(), optional.end(), name) != optional.end()) {
                    kind.push_back(2);
                } else {
                    kind.push_back(0);
                }
            }
            continue;
        }

        if (fields.size() != header.size()) {
            throw roughscope::DataError(
                where(line_no) + "expected " + std::to_string(header.size()) + " fields (" +
                join(header, ",") + "), found " + std::to_string(fields.size()));
        }
        CsvRow row;
        row.line = line_no;
        for (std::size_t c = 0; c < fields.size(); ++c) {
            const std::string_view cell = trim(fields[c]);
            row.text.emplace(header[c], std::string(cell));
            if (kind[c] == 0) continue;
            if (cell.empty() && kind[c] == 2) continue;  // optional, not given on this row
            std::string reason;
            const auto value = parse_double(cell, reason);
            if (!value) {
                throw roughscope::DataError(where(line_no) + "column '" + header[c] + "': '" +
                                            std::string(cell) + "' is " + reason);
            }
            row.values.emplace(header[c], *value);
        }
        rows.push_back(std::move(row));
    }
    if (in.bad()) throw roughscope::DataError(file + ": read error");
    if (header.empty()) {
        throw roughscope::DataError(file + ": no header line (expected columns " +
                                    join(required, ", ") + ")");
    }
    if (rows.empty()) throw roughscope::DataError(file + ": no data rows after the header");
    return rows;
}

std::string csv_field(std::string_view text) {
    if (text.find_first_of(",\"\n\r") == std::string_view::npos) return std::string(text);
    std::string out = "\"";
    for (char c : text) {
        if (c == '"') out += '"';
        out += c;
    }
    out += '"';
    return out;
}

// ---------------------------------------------------------------------------------------------
// Validated options

namespace {

// Builds a validator from a predicate on the parsed number and a description of the range.
CLI::Validator number_validator(std::function<bool(double)> ok, std::string range,
                                std::string tag) {
    return CLI::Validator(
        [ok = std::move(ok), range](std::string& text) -> std::string {
            std::string reason;
            const auto value = parse_double(text, reason);
            if (!value) return "'" + std::string(trim(text)) + "' is " + reason + "; " + range;
            if (!ok(*value))
                return "value " + std::string(trim(text)) + " is out of range; " + range;
            return {};
        },
        std::move(tag));
}

}  // namespace

CLI::Validator polar_angle_validator() {
    return number_validator([](double v) { return v >= 0.0 && v < 90.0; },
                            "a polar angle must be in [0, 90) degrees", "DEG in [0,90)");
}

CLI::Validator finite_validator() {
    return number_validator([](double) { return true; }, "a finite number is required", "FINITE");
}

CLI::Validator positive_validator(const std::string& unit) {
    return number_validator([](double v) { return v > 0.0; },
                            "must be > 0" + (unit.empty() ? "" : " " + unit), "> 0");
}

CLI::Validator non_negative_validator(const std::string& unit) {
    return number_validator([](double v) { return v >= 0.0; },
                            "must be >= 0" + (unit.empty() ? "" : " " + unit), ">= 0");
}

CLI::Validator range_validator(double lo, double hi) {
    return number_validator([lo, hi](double v) { return v >= lo && v <= hi; },
                            "must be in [" + fmt_limit(lo) + ", " + fmt_limit(hi) + "]",
                            "in [" + fmt_limit(lo) + "," + fmt_limit(hi) + "]");
}

CLI::Option* add_angle_option(CLI::App& app, const std::string& flag, double& deg,
                              const std::string& description) {
    return app.add_option(flag, deg, description)->check(polar_angle_validator());
}

CLI::Option* add_azimuth_option(CLI::App& app, const std::string& flag, double& deg,
                                const std::string& description) {
    return app.add_option(flag, deg, description)->check(finite_validator());
}

CLI::Option* add_positive_option(CLI::App& app, const std::string& flag, double& value,
                                 const std::string& description, const std::string& unit) {
    return app.add_option(flag, value, description)->check(positive_validator(unit));
}

CLI::Option* add_non_negative_option(CLI::App& app, const std::string& flag, double& value,
                                     const std::string& description, const std::string& unit) {
    return app.add_option(flag, value, description)->check(non_negative_validator(unit));
}

CLI::Option* add_range_option(CLI::App& app, const std::string& flag, double& value, double lo,
                              double hi, const std::string& description) {
    return app.add_option(flag, value, description)->check(range_validator(lo, hi));
}

std::string normalize_name(std::string_view name) {
    std::string out(trim(name));
    for (char& c : out) {
        if (c == '-') c = '_';
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
    return out;
}

bool given(const CLI::Option* option) { return option != nullptr && option->count() > 0; }

CLI::Option* add_factor_option(CLI::App& app, GeometricFactor& factor) {
    return add_enum_option(app, "--factor", factor, parse_geometric_factor,
                           "Geometric factor: vh (default), beckmann, ogilvy, kirchhoff");
}

// ---------------------------------------------------------------------------------------------
// Human-readable output

void print_table(std::ostream& out, const std::vector<std::string>& header,
                 const std::vector<std::vector<std::string>>& rows) {
    std::size_t ncol = header.size();
    for (const auto& r : rows) ncol = std::max(ncol, r.size());
    std::vector<std::size_t> width(ncol, 0);
    const auto measure = [&](const std::vector<std::string>& r) {
        for (std::size_t c = 0; c < r.size(); ++c) width[c] = std::max(width[c], r[c].size());
    };
    measure(header);
    for (const auto& r : rows) measure(r);
    const auto emit = [&](const std::vector<std::string>& r) {
        std::string line;
        for (std::size_t c = 0; c < ncol; ++c) {
            const std::string cell = c < r.size() ? r[c] : "";
            const std::string pad(width[c] - cell.size(), ' ');
            if (c) line += "  ";
            line += c == 0 ? cell + pad : pad + cell;
        }
        while (!line.empty() && line.back() == ' ') line.pop_back();
        out << line << '\n';
    };
    if (!header.empty()) {
        emit(header);
        std::size_t total = 0;
        for (std::size_t c = 0; c < ncol; ++c) total += width[c] + (c ? 2 : 0);
        out << std::string(total, '-') << '\n';
    }
    for (const auto& r : rows) emit(r);
}

void print_key_values(std::ostream& out,
                      const std::vector<std::pair<std::string, std::string>>& items) {
    std::size_t width = 0;
    for (const auto& [k, v] : items) width = std::max(width, k.size());
    for (const auto& [k, v] : items) {
        out << k << std::string(width - k.size() + 2, ' ') << v << '\n';
    }
}

}  // namespace roughscope::cli
