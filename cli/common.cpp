// Shared helpers of the `roughscope` command-line tool (see common.hpp).
#include "common.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>
#include <utility>
#include <vector>

#include "roughscope/core/text.hpp"
#include "roughscope/serialize/text.hpp"

namespace roughscope::cli {

namespace {

using roughscope::io::trim;

// The message on one line, printable and bounded (core/text.hpp): line breaks become spaces,
// other control characters and invalid UTF-8 are escaped, a very long message is cut. Library
// messages are already escaped; this is the last defence for text from elsewhere (CLI11, the
// standard library, the operating system).
std::string one_line(std::string_view message) {
    std::string s(trim(message));
    for (char& c : s) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    s = roughscope::printable_message(s);
    return s.empty() ? std::string("unknown error (no message)") : s;
}

// Shortest form of a limit for messages ("90", "0.5").
std::string fmt_limit(double value) { return roughscope::format_message(value, 15); }

// The long names ("--theta-i") of every option of `app` and its subcommands that takes a
// comma-separated list.
void collect_list_flags(const CLI::App& app, std::vector<std::string>& flags) {
    for (const CLI::Option* option : app.get_options())
        if (option->get_delimiter() != '\0')
            for (const std::string& name : option->get_lnames()) flags.push_back("--" + name);
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; }))
        collect_list_flags(*sub, flags);
}

// CLI11 drops the empty elements of a delimited list ("30,,40" reads as 30, 40, a trailing comma
// is ignored): a list with an empty element is refused before parsing, naming the flag. Every
// argument after a list flag up to the next flag is one of its values ("--flag=a,b" too).
void refuse_empty_list_elements(const CLI::App& app, int argc, char** argv) {
    std::vector<std::string> flags;
    collect_list_flags(app, flags);
    std::string current;  // the list flag whose values follow, or empty
    for (int i = 1; i < argc; ++i) {
        const std::string_view arg = argv[i];
        std::string_view value;
        bool has_value = false;
        if (arg == "--") break;
        if (arg.size() > 2 && arg.substr(0, 2) == "--") {
            const std::size_t eq = arg.find('=');
            const std::string name(arg.substr(0, eq));
            current = std::find(flags.begin(), flags.end(), name) != flags.end() ? name : "";
            if (eq != std::string_view::npos && !current.empty()) {
                value = arg.substr(eq + 1);
                has_value = true;
            }
        } else if (arg.size() > 1 && arg[0] == '-' &&
                   std::isdigit(static_cast<unsigned char>(arg[1])) == 0 && arg[1] != '.') {
            current.clear();  // a short flag
        } else if (!current.empty()) {
            value = arg;
            has_value = true;
        }
        if (!has_value || value.find(',') == std::string_view::npos) continue;
        std::size_t start = 0;
        for (;;) {
            const std::size_t comma = value.find(',', start);
            const std::string_view element = value.substr(
                start, comma == std::string_view::npos ? std::string_view::npos : comma - start);
            if (trim(element).empty())
                throw UsageError(concat(current, ": ", roughscope::quote_input(value),
                                        " has an empty element; give a value between every two "
                                        "commas (e.g. 30,35,40)"));
            if (comma == std::string_view::npos) break;
            start = comma + 1;
        }
    }
}

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
        refuse_empty_list_elements(app, argc, argv);
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

std::string format_fixed(double value, int decimals, std::string_view name) {
    return serialize::format_fixed(value, decimals, name);
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
// Validated options

namespace {

// Builds a validator from a predicate on the parsed number and a description of the range.
CLI::Validator number_validator(std::function<bool(double)> ok, std::string range,
                                std::string tag) {
    return CLI::Validator(
        [ok = std::move(ok), range = std::move(range)](std::string& text) -> std::string {
            std::string reason;
            const auto value = parse_double(text, reason);
            if (!value) return roughscope::quote_input(trim(text)) + " is " + reason + "; " + range;
            if (!ok(*value))
                return "value " + roughscope::format_message(*value) + " is out of range; " + range;
            text = std::string(trim(text));  // CLI11 converts the text: no surrounding spaces
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

CLI::Validator integer_validator(long long lo, long long hi) {
    const std::string range = "in [" + std::to_string(lo) + "," + std::to_string(hi) + "]";
    return CLI::Validator(
        [lo, hi](std::string& text) -> std::string {
            std::string reason;
            const auto value = roughscope::try_parse_integer(text, lo, hi, reason);
            if (!value) return roughscope::quote_input(trim(text)) + " is " + reason;
            text = std::to_string(*value);  // the decimal form CLI11 converts
            return {};
        },
        "INT " + range);
}

CLI::Validator range_validator(double lo, double hi) {
    return number_validator([lo, hi](double v) { return v >= lo && v <= hi; },
                            "must be in [" + fmt_limit(lo) + ", " + fmt_limit(hi) + "]",
                            "in [" + fmt_limit(lo) + "," + fmt_limit(hi) + "]");
}

CLI::Option* add_angle_option(CLI::App& app, const std::string& flag, double& deg,
                              const std::string& description) {
    return app.add_option(flag, deg, description)->transform(polar_angle_validator());
}

CLI::Option* add_azimuth_option(CLI::App& app, const std::string& flag, double& deg,
                                const std::string& description) {
    return app.add_option(flag, deg, description)->transform(finite_validator());
}

CLI::Option* add_positive_option(CLI::App& app, const std::string& flag, double& value,
                                 const std::string& description, const std::string& unit) {
    return app.add_option(flag, value, description)->transform(positive_validator(unit));
}

CLI::Option* add_non_negative_option(CLI::App& app, const std::string& flag, double& value,
                                     const std::string& description, const std::string& unit) {
    return app.add_option(flag, value, description)->transform(non_negative_validator(unit));
}

CLI::Option* add_range_option(CLI::App& app, const std::string& flag, double& value, double lo,
                              double hi, const std::string& description) {
    return app.add_option(flag, value, description)->transform(range_validator(lo, hi));
}

bool given(const CLI::Option* option) { return option != nullptr && option->count() > 0; }

std::optional<Correlation> parse_correlation_or_both(std::string_view name) {
    if (name_matches("both", name)) return std::nullopt;
    try {
        return parse_correlation(name);
    } catch (const roughscope::InvalidArgument&) {
        throw_unknown_name("correlation", name,
                           std::string(to_string(Correlation::Gaussian)) + ", " +
                               std::string(to_string(Correlation::Exponential)) + ", both");
    }
}

CLI::Option* add_factor_option(CLI::App& app, GeometricFactor& factor) {
    return add_enum_option(app, "--factor", factor, parse_geometric_factor,
                           "Geometric factor: vh (default), beckmann, ogilvy, kirchhoff");
}

// ---------------------------------------------------------------------------------------------
// Human-readable output

void print_table(std::ostream& out, const std::vector<std::string>& header,
                 const std::vector<std::vector<std::string>>& rows) {
    out << serialize::text_table(header, rows);
}

void print_key_values(std::ostream& out,
                      const std::vector<std::pair<std::string, std::string>>& items) {
    out << serialize::key_value_lines(items);
}

std::vector<Geometry> geometries_from_angle_lists(const std::vector<double>& theta_i_deg,
                                                  const std::vector<double>& theta_s_deg,
                                                  const std::vector<double>& phi_s_deg,
                                                  std::string_view alternative) {
    const std::size_t n = std::max({theta_i_deg.size(), theta_s_deg.size(), phi_s_deg.size()});
    for (const auto& [values, flag] : {std::pair{&theta_i_deg, "--theta-i"},
                                       {&theta_s_deg, "--theta-s"},
                                       {&phi_s_deg, "--phi-s"}}) {
        if (values->empty())
            throw UsageError(concat("missing ", flag,
                                    ": give --theta-i DEG --theta-s DEG --phi-s DEG (lists "
                                    "separated by commas; phi_s = 0 is the specular plane)",
                                    alternative));
        if (values->size() != 1 && values->size() != n)
            throw UsageError(concat(flag, " has ", std::to_string(values->size()),
                                    " values; give 1 or ", std::to_string(n),
                                    " (as many as the longest geometry list)"));
    }
    auto pick = [](const std::vector<double>& v, std::size_t i) {
        return v.size() == 1 ? v[0] : v[i];
    };
    std::vector<Geometry> out;
    out.reserve(n);
    for (std::size_t i = 0; i < n; ++i)
        out.push_back(make_geometry(deg_to_rad(pick(theta_i_deg, i)),
                                    deg_to_rad(pick(theta_s_deg, i)),
                                    deg_to_rad(pick(phi_s_deg, i))));
    return out;
}

}  // namespace roughscope::cli
