// Helpers shared by every `roughscope` subcommand (cli/*.cpp).
//
// Conventions of the command-line front end (docs/cli.md):
//  * Angles are given and printed in degrees, lengths in micrometres.
//  * Every failure prints exactly ONE line `roughscope: error: <message>` on stderr and exits with
//    a code from ExitCode below. Results are never printed as NaN/inf (format_result and
//    finite_number throw instead); outputs are written atomically (write_file_atomic).
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

// Parses the whole of `text` (surrounding spaces allowed, leading '+' allowed) as a finite
// double with std::from_chars. Returns std::nullopt and sets `reason` otherwise ("not a number",
// "not a finite number (nan)", ...).
std::optional<double> parse_double(std::string_view text, std::string& reason);

// As parse_double but throws InvalidArgument "<what>: '<text>' is <reason>".
double parse_double_or_throw(std::string_view text, std::string_view what);

// Parses "a,b,c" into exactly `count` finite numbers; throws InvalidArgument naming `what`.
std::vector<double> parse_number_list(std::string_view text, std::size_t count,
                                      std::string_view what);

// Rounds to `digits` significant digits (the precision of every printed result).
inline constexpr int kPrintDigits = 10;
double round_significant(double value, int digits = kPrintDigits);

// Human-readable result with kPrintDigits significant digits ("%.10g"). Throws roughscope::Error
// naming `name` if value is NaN or infinite: results are never printed as NaN.
std::string format_result(double value, std::string_view name = "result");

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

// Writes `content` to `path` atomically: a temporary file in the same directory is written,
// flushed and renamed over `path`. On any failure the temporary file is removed, `path` is left
// untouched, and DataError("cannot write <path>: <reason>") is thrown.
void write_file_atomic(const std::filesystem::path& path, const std::string& content);

// Writes `content` to `path` atomically when given, else to stdout.
void write_output(const std::optional<std::filesystem::path>& path, const std::string& content);

// One data row of a CSV file read by read_csv_with_header.
struct CsvRow {
    std::size_t line = 0;                        // 1-based line number in the file
    std::map<std::string, double> values;        // parsed required + present optional columns
    std::map<std::string, std::string> text;     // every column, trimmed, as written
    double at(const std::string& column) const;  // required column (asserted present)
    std::optional<double> find(const std::string& column) const;  // optional column
};

// Reads a comma-separated file with a header line.
//  * Blank lines and lines whose first non-space character is '#' are skipped (before or after
//    the header); fields are trimmed of spaces/tabs; CRLF line ends are accepted.
//  * The header must contain every column of `required`; columns of `optional` are parsed when
//    present; other columns are kept as text only. Column names are case-sensitive.
//  * Numeric fields are parsed strictly (parse_double): "nan", "inf", "1.5x" are rejected.
//    An empty cell of an optional column means "not given"; an empty required cell is an error.
// Errors throw DataError "<file>:<line>: <reason>" naming the column (missing file, missing
// header, missing required column — listing columns found and required —, duplicate column,
// wrong number of fields, bad number, no data rows).
std::vector<CsvRow> read_csv_with_header(const std::filesystem::path& path,
                                         const std::vector<std::string>& required,
                                         const std::vector<std::string>& optional = {});

// Quotes a CSV field only if it contains a comma, quote or newline.
std::string csv_field(std::string_view text);

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

// True if the option exists and was given on the command line.
bool given(const CLI::Option* option);

// Validators usable with Option::check (they parse the string strictly).
CLI::Validator polar_angle_validator();
CLI::Validator finite_validator();
CLI::Validator positive_validator(const std::string& unit = "");
CLI::Validator non_negative_validator(const std::string& unit = "");
CLI::Validator range_validator(double lo, double hi);

// Lower-cases `name` and replaces '-' by '_' (so "very-rough" == "very_rough").
std::string normalize_name(std::string_view name);

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

// --factor: the geometric factor (vh by default), shared by `model` and `estimate`.
CLI::Option* add_factor_option(CLI::App& app, GeometricFactor& factor);

// ---------------------------------------------------------------------------------------------
// Human-readable output

// Prints rows as an aligned text table: first column left-aligned, the others right-aligned,
// columns separated by two spaces, a dashed rule under the header.
void print_table(std::ostream& out, const std::vector<std::string>& header,
                 const std::vector<std::vector<std::string>>& rows);

// Prints "key  value" lines with the keys padded to the same width.
void print_key_values(std::ostream& out,
                      const std::vector<std::pair<std::string, std::string>>& items);

}  // namespace roughscope::cli
