// The one typed reader of JSON input documents (internal to the library: the capture file of
// measure, the paper-tables reference and the named options of serialize, through the private
// include path src/).
//
// A JsonNode is a value of a document together with where it is: the document's name (a file's
// path, or "fit options" for named arguments) and the key path from the root
// ("captures[1].theta_i_deg"). Every typed getter checks the value's type and range and throws
// naming both, with the valid range:
//   "c.json: captures[1].theta_i_deg: 95 must be in [0, 90)"
//   "tables.json: table1_slightly_rough.rows[0]: missing key 'R_spec'"
//   "c.json: object.colour: unknown key; valid keys: shape, axis, ..."
// A document read from a file throws DataError; named arguments (a Python dict, the CLI's flags
// gathered as options) throw InvalidArgument.
#pragma once

#include <cstddef>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "roughscope/core/errors.hpp"

namespace roughscope::io {

using JsonValue = nlohmann::ordered_json;  // keys in the order of the document

// What a document is, and so which error a bad value of it is.
enum class JsonSource {
    File,       // DataError
    Arguments,  // InvalidArgument
};

// Files larger than this are refused before they are read.
inline constexpr std::size_t kMaxJsonFileBytes = std::size_t{16} << 20;

// Parses a whole document. DataError "<name>: line L, column C: not valid JSON: <reason>" for a
// syntax error or a number beyond the double range, "<name>: line L, column C: not a text file:
// NUL byte" for binary content. A UTF-8 byte-order mark and CRLF line ends are accepted.
JsonValue parse_json_text(std::string_view text, const std::string& name);

// Reads and parses a JSON file. DataError "<path>: does not exist", "<path>: is a directory, not
// <kind>", a device/FIFO/socket (io/input_file.hpp), "<path>: larger than 16 MiB: not <kind>",
// "<path>: cannot open: <reason>", and parse_json_text's. `kind` names what was expected ("a
// capture file").
JsonValue read_json_file(const std::filesystem::path& path, std::string_view kind = "a file");

class JsonNode {
  public:
    // The root of a document named `document` (held by reference: `root` must outlive the nodes).
    JsonNode(const JsonValue& root, std::string document, JsonSource source = JsonSource::File);

    const JsonValue& json() const { return *value_; }
    // The key path from the root ("" at the root).
    const std::string& path() const { return path_; }
    // "<document>: <path>" ("<document>" at the root): the prefix of every message.
    std::string where() const;
    // Throws "<where>: <reason>" (DataError or InvalidArgument by the document's source).
    [[noreturn]] void fail(std::string_view reason) const;
    // Throws "<where>.<key>: <reason>": about a member, present or not.
    [[noreturn]] void fail_at(std::string_view key, std::string_view reason) const;

    bool is_null() const { return value_->is_null(); }
    bool is_object() const { return value_->is_object(); }
    bool is_array() const { return value_->is_array(); }
    // True when this is an object holding `key` (null included).
    bool has(std::string_view key) const;
    // True when this is an object holding `key` with a value other than null.
    bool given(std::string_view key) const;

    // The member `key`: "missing key '<key>'" here when absent (a required key), "must be an
    // object" when this is not one.
    JsonNode at(std::string_view key) const;
    // The member `key`, or nullopt when absent or null (an optional key).
    std::optional<JsonNode> find(std::string_view key) const;
    // Element k of an array (k < size()).
    JsonNode item(std::size_t k) const;
    // Elements of an array / members of an object; 0 for anything else.
    std::size_t size() const { return value_->size(); }

    // A finite number.
    double number() const;
    // A finite number in [lo, hi] ("<v> must be in [lo, hi]<unit>").
    double number(double lo, double hi, std::string_view unit = "") const;
    // A finite number > 0.
    double positive() const;
    // A whole number (1 or 1.0) in [lo, hi] ("<v> must be a whole number in [lo, hi]").
    long long integer(long long lo, long long hi) const;
    std::string string() const;
    bool boolean() const;
    // This must be an object; every key must be one of `keys` ("<path>.<key>: unknown key; valid
    // keys: a, b, c").
    void only(std::initializer_list<std::string_view> keys) const;
    // This must be an array of min..max elements (`what` says of what, for the message).
    std::vector<JsonNode> array(std::size_t min = 0,
                                std::size_t max = std::numeric_limits<std::size_t>::max(),
                                std::string_view what = "values") const;
    // An array of exactly n finite numbers.
    std::vector<double> numbers(std::size_t n) const;
    // A name (string) parsed by one of the library's parse_* functions; its InvalidArgument
    // (the list of valid names) reported here.
    template <class Parse>
    auto named(Parse parse) const {
        const std::string name = string();
        try {
            return parse(name);
        } catch (const InvalidArgument& e) {
            fail(e.what());
        }
    }
    // Runs `check` (a library check of values read from here); its InvalidArgument is reported
    // here.
    template <class Check>
    void checked(Check check) const {
        try {
            check();
        } catch (const InvalidArgument& e) {
            fail(e.what());
        }
    }

  private:
    struct Document {
        std::string name;
        JsonSource source;
    };
    JsonNode(const JsonValue& value, std::shared_ptr<const Document> document, std::string path);
    [[noreturn]] void wrong_type(std::string_view expected) const;
    std::string child_path(std::string_view key) const;

    const JsonValue* value_;
    std::shared_ptr<const Document> document_;
    std::string path_;
};

}  // namespace roughscope::io
