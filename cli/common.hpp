// Helpers shared by every `roughscope` subcommand (cli/*.cpp).
//
// Conventions of the command-line front end (docs/cli.md):
//  * Angles are given and printed in degrees, lengths in micrometres.
//  * Every failure prints exactly ONE line `roughscope: error: <message>` on stderr and exits with
//    a code from ExitCode below. Results are never printed as NaN/inf (format_result and
//    finite_number throw instead); every output goes through io::OutputFile (atomic replace of
//    regular files, written through symlinks, direct to devices/FIFOs/stdout).
//  * Subcommand callbacks report errors by throwing: roughscope::InvalidArgument (or
//    cli::UsageError) for bad input, roughscope::NoSolution, roughscope::DataError for files.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <iosfwd>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "roughscope/core/errors.hpp"
#include "roughscope/core/names.hpp"
#include "roughscope/core/numbers.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/io/data_locator.hpp"
#include "roughscope/io/output_file.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/factors.hpp"

namespace roughscope::cli {

using json = nlohmann::ordered_json;  // keys keep the order in which they are inserted

// ---------------------------------------------------------------------------------------------
// Exit codes and error handling

enum ExitCode : int {
    kExitOk = 0,
    kExitFailure = 1,     // anything unexpected (internal error, non-finite result, ...)
    kExitUsage = 2,       // bad command line or invalid input value (CLI11 errors, InvalidArgument)
    kExitNoSolution = 3,  // roughscope::NoSolution: the inversion has no solution for the data
    kExitData = 4,        // roughscope::DataError, I/O and filesystem errors
};

// A command-line usage problem found by a subcommand (conflicting or missing flags). Exit code 2.
class UsageError : public roughscope::InvalidArgument {
  public:
    using roughscope::InvalidArgument::InvalidArgument;
};

// Runs `body`, catching every exception: prints one line `roughscope: error: <message>` on stderr
// and returns the exit code of ExitCode; returns body's result when nothing is thrown.
int run_guarded(const std::function<int()>& body);

// Parses argv into `app` (which runs the subcommand callbacks) under run_guarded. --help and
// --version print to stdout and return 0. Returns the process exit code.
int run_app(CLI::App& app, int argc, char** argv);

// Prints the one-line error message (newlines in `message` are replaced by spaces).
void print_error(std::string_view message);

// ---------------------------------------------------------------------------------------------
// Numbers: strict parsing and safe printing

// The library's strict parser (roughscope/core/numbers.hpp): the whole of `text` (surrounding
// spaces allowed, leading '+' allowed) as a finite double. Returns std::nullopt and sets `reason`
// otherwise ("not a number", "not a finite number (NaN is not accepted)", ...).
inline std::optional<double> parse_double(std::string_view text, std::string& reason) {
    return roughscope::try_parse_number(text, reason);
}

// As parse_double but throws InvalidArgument "<what>: '<text>' is <reason>".
inline double parse_double_or_throw(std::string_view text, std::string_view what) {
    return roughscope::parse_number(text, what);
}

// Parses "a,b,c" into exactly `count` finite numbers; throws InvalidArgument naming `what`.
using roughscope::parse_number_list;

// Rounds to `digits` significant digits (the precision of every printed result).
inline constexpr int kPrintDigits = 10;
inline double round_significant(double value, int digits = kPrintDigits) {
    return roughscope::round_significant(value, digits);
}

// Human-readable result with kPrintDigits significant digits ("%.10g"). Throws roughscope::Error
// naming `name` if value is NaN or infinite: results are never printed as NaN.
inline std::string format_result(double value, std::string_view name = "result") {
    return roughscope::format_significant(value, kPrintDigits, name);
}

// `decimals` digits after the decimal point ("%.*f", as the paper prints its tables):
// serialize::format_fixed (serialize/text.hpp). Throws roughscope::Error naming `name` if value
// is NaN or infinite.
std::string format_fixed(double value, int decimals, std::string_view name = "value");

// JSON number rounded to kPrintDigits significant digits; throws roughscope::Error naming `name`
// if the value is not finite.
json finite_number(double value, std::string_view name = "result");

// JSON null for std::nullopt (an unknown quantity), else finite_number(*value).
json number_or_null(std::optional<double> value, std::string_view name = "result");
// Same for a plain double: throws (never emits null) if not finite.
json number_or_null(double value, std::string_view name = "result");

// Serialises JSON for output (2-space indentation, trailing newline).
std::string dump_json(const json& value);

// ---------------------------------------------------------------------------------------------
// Files

// The library's writers and CSV reader (roughscope/io/output_file.hpp, roughscope/io/csv.hpp):
//  * OutputFile / open_output(path or nullopt): the streaming sink (write chunks, then commit;
//    destroyed without commit = nothing changed). A regular file is replaced atomically (temporary
//    file + rename, mode kept), a symlink is written through, a device, FIFO or "-" directly; a
//    file the user may not write is a DataError. DataError("cannot write <path>: <reason>");
//  * write_file_atomic(path, content), write_output(path or nullopt, content): the same for a
//    whole content at once (stdout when no path);
//  * io::CsvReader: streams the rows of a CSV file with a header (comments, blank lines, CRLF,
//    UTF-8 BOM accepted; strict numbers; DataError "<file>:<line>: <reason>" naming the column);
//    read_csv_with_header(path, required, optional) reads every row at once (small files only);
//  * csv_field(text): quotes a field only if it contains a comma, quote or line break.
using roughscope::io::csv_field;
using roughscope::io::CsvRow;
using roughscope::io::open_output;
using roughscope::io::OutputFile;
using roughscope::io::write_file_atomic;
using roughscope::io::write_output;
inline std::vector<CsvRow> read_csv_with_header(const std::filesystem::path& path,
                                                const std::vector<std::string>& required,
                                                const std::vector<std::string>& optional = {}) {
    return roughscope::io::read_csv(path, required, optional);
}

// ---------------------------------------------------------------------------------------------
// Options with validation at parse time (errors name the flag and the valid range)

// Polar angle in degrees, 0 <= θ < 90.
CLI::Option* add_angle_option(CLI::App& app, const std::string& flag, double& deg,
                              const std::string& description);

// Any finite angle in degrees (azimuths).
CLI::Option* add_azimuth_option(CLI::App& app, const std::string& flag, double& deg,
                                const std::string& description);

// Finite number > 0 (lengths in µm, ...). `unit` is shown in messages (e.g. "um").
CLI::Option* add_positive_option(CLI::App& app, const std::string& flag, double& value,
                                 const std::string& description, const std::string& unit = "");

// Finite number >= 0.
CLI::Option* add_non_negative_option(CLI::App& app, const std::string& flag, double& value,
                                     const std::string& description, const std::string& unit = "");

// Finite number in [lo, hi].
CLI::Option* add_range_option(CLI::App& app, const std::string& flag, double& value, double lo,
                              double hi, const std::string& description);

// Geometries from the lists of --theta-i, --theta-s, --phi-s (degrees): each list has 1 value
// (repeated) or as many as the longest. UsageError naming the flag for a missing or mismatched
// list (`alternative` is appended to the "missing" message, e.g. ", or --csv FILE");
// InvalidArgument from make_geometry for an angle out of range.
std::vector<Geometry> geometries_from_angle_lists(const std::vector<double>& theta_i_deg,
                                                  const std::vector<double>& theta_s_deg,
                                                  const std::vector<double>& phi_s_deg,
                                                  std::string_view alternative = "");

// True if the option exists and was given on the command line.
bool given(const CLI::Option* option);

// Validators for Option::transform (not check, which keeps the text unchanged): they parse the
// string strictly and hand CLI11 the text without surrounding spaces.
CLI::Validator polar_angle_validator();
CLI::Validator finite_validator();
CLI::Validator positive_validator(const std::string& unit = "");
CLI::Validator non_negative_validator(const std::string& unit = "");
CLI::Validator range_validator(double lo, double hi);
// An integer in [lo, hi] by the library's strict parser (decimal digits only: "0x19", "25.0",
// "1e3" are refused; surrounding spaces allowed). Use it for every integer option.
CLI::Validator integer_validator(long long lo, long long hi);

// Lower-cases `name` and replaces '-' by '_' (so "very-rough" == "very_rough"): the library's
// enum-name scheme (roughscope/core/names.hpp).
using roughscope::normalize_name;

// An enum option parsed by one of the library's parse_* functions (parse_correlation,
// parse_geometric_factor, parse_regime, parse_radiometry, ...). The value is normalised with
// normalize_name first; a name the library rejects becomes a CLI11 ValidationError
// "<flag>: <library message listing the accepted names>" (exit code 2).
template <class Enum, class Parse>
CLI::Option* add_enum_option(CLI::App& app, const std::string& flag, Enum& var, Parse parse,
                             const std::string& description) {
    auto* opt = app.add_option_function<std::string>(
        flag,
        [&var, parse, flag](const std::string& text) {
            try {
                var = parse(normalize_name(text));
            } catch (const roughscope::Error& e) {
                throw CLI::ValidationError(flag, e.what());
            }
        },
        description);
    return opt;
}

// One correlation function or both side by side (`estimate slope`, `estimate fit`): "both" →
// std::nullopt, else the library's parse_correlation. An unknown name throws InvalidArgument
// "correlation '<name>' is not recognised; valid values: gaussian, exponential, both".
std::optional<Correlation> parse_correlation_or_both(std::string_view name);

// --factor: the geometric factor (vh by default), shared by `model` and `estimate`.
CLI::Option* add_factor_option(CLI::App& app, GeometricFactor& factor);

// ---------------------------------------------------------------------------------------------
// Human-readable output

// Prints rows as an aligned text table (serialize::text_table): first column left-aligned, the
// others right-aligned, columns separated by two spaces, a dashed rule under the header.
void print_table(std::ostream& out, const std::vector<std::string>& header,
                 const std::vector<std::vector<std::string>>& rows);

// Prints "key  value" lines with the keys padded to the same width.
void print_key_values(std::ostream& out,
                      const std::vector<std::pair<std::string, std::string>>& items);

}  // namespace roughscope::cli
