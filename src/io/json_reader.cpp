// The typed JSON reader (json_reader.hpp).
#include "json_reader.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <system_error>
#include <utility>

#include "roughscope/core/text.hpp"
#include "roughscope/io/input_file.hpp"

namespace roughscope::io {
namespace {

// "line L, column C" of byte `offset` (0-based) of `text`.
std::string line_and_column(std::string_view text, std::size_t offset) {
    offset = std::min(offset, text.size());
    const std::string_view before = text.substr(0, offset);
    const std::size_t line =
        1 + static_cast<std::size_t>(std::count(before.begin(), before.end(), '\n'));
    const std::size_t last_newline = before.rfind('\n');
    const std::size_t column =
        last_newline == std::string_view::npos ? offset + 1 : offset - last_newline;
    return concat("line ", std::to_string(line), ", column ", std::to_string(column));
}

// nlohmann's "[json.exception.parse_error.101] parse error at line L, column C: syntax error
// while parsing value - <what>; last read: '<text>'" as "<what>".
std::string parse_reason(const std::string& message) {
    std::string what = message;
    if (const auto column = what.find("column"); column != std::string::npos)
        if (const auto colon = what.find(": ", column); colon != std::string::npos)
            what = what.substr(colon + 2);
    if (const auto last = what.find("; last read"); last != std::string::npos) what.resize(last);
    if (what.rfind("[json.exception.", 0) == 0)
        if (const auto end = what.find("] "); end != std::string::npos) what = what.substr(end + 2);
    return what;
}

// A value in a message: compact JSON, cut when long.
std::string shown(const JsonValue& value) {
    constexpr std::size_t kMaxShown = 80;
    std::string text = value.dump(-1, ' ', false, JsonValue::error_handler_t::replace);
    if (text.size() > kMaxShown) text = concat(text.substr(0, kMaxShown), "…");
    return text;
}

}  // namespace

JsonValue parse_json_text(std::string_view text, const std::string& name) {
    if (const auto nul = text.find('\0'); nul != std::string_view::npos)
        throw DataError(
            concat(name, ": ", line_and_column(text, nul), ": not a text file: NUL byte"));
    try {
        return JsonValue::parse(text);
    } catch (const JsonValue::parse_error& e) {
        const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
        throw DataError(concat(name, ": ", line_and_column(text, offset),
                               ": not valid JSON: ", parse_reason(e.what())));
    } catch (const JsonValue::exception& e) {  // a number beyond the double range
        throw DataError(concat(name, ": not valid JSON: ", parse_reason(e.what())));
    }
}

JsonValue read_json_file(const std::filesystem::path& path, std::string_view kind) {
    const std::string name = path.string();
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw DataError(concat(name, ": does not exist"));
    if (std::filesystem::is_directory(path, ec))
        throw DataError(concat(name, ": is a directory, not ", kind));
    check_input_file(path, name);
    const auto too_large = [&] {
        return DataError(concat(name, ": larger than 16 MiB: not ", kind));
    };
    std::error_code size_ec;
    if (std::filesystem::file_size(path, size_ec) > kMaxJsonFileBytes && !size_ec)
        throw too_large();
    std::ifstream in(path, std::ios::binary);
    if (!in) throw DataError(concat(name, ": cannot open: ", std::strerror(errno)));
    std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (in.bad()) throw DataError(concat(name, ": read error"));
    if (text.size() > kMaxJsonFileBytes) throw too_large();
    return parse_json_text(text, name);
}

JsonNode::JsonNode(const JsonValue& root, std::string document, JsonSource source)
    : value_(&root),
      document_(std::make_shared<const Document>(Document{std::move(document), source})) {}

JsonNode::JsonNode(const JsonValue& value, std::shared_ptr<const Document> document,
                   std::string path)
    : value_(&value), document_(std::move(document)), path_(std::move(path)) {}

std::string JsonNode::where() const {
    return path_.empty() ? document_->name : concat(document_->name, ": ", path_);
}

void JsonNode::fail(std::string_view reason) const {
    const std::string message = concat(where(), ": ", reason);
    if (document_->source == JsonSource::Arguments) throw InvalidArgument(message);
    throw DataError(message);
}

std::string JsonNode::child_path(std::string_view key) const {
    return path_.empty() ? std::string(key) : concat(path_, ".", key);
}

void JsonNode::fail_at(std::string_view key, std::string_view reason) const {
    JsonNode(*value_, document_, child_path(key)).fail(reason);
}

void JsonNode::wrong_type(std::string_view expected) const {
    fail(concat("must be ", expected, ", not ", shown(*value_)));
}

bool JsonNode::has(std::string_view key) const {
    return value_->is_object() && value_->contains(key);
}

bool JsonNode::given(std::string_view key) const {
    if (!value_->is_object()) return false;
    const auto it = value_->find(key);
    return it != value_->end() && !it->is_null();
}

JsonNode JsonNode::at(std::string_view key) const {
    if (!value_->is_object()) wrong_type("an object");
    const auto it = value_->find(key);
    if (it == value_->end()) fail(concat("missing key '", key, "'"));
    return JsonNode(*it, document_, child_path(key));
}

std::optional<JsonNode> JsonNode::find(std::string_view key) const {
    if (!given(key)) return std::nullopt;
    return at(key);
}

JsonNode JsonNode::item(std::size_t k) const {
    return JsonNode((*value_)[k], document_, concat(path_, "[", std::to_string(k), "]"));
}

double JsonNode::number() const {
    if (!value_->is_number()) wrong_type("a number");
    const double v = value_->get<double>();
    if (!std::isfinite(v)) fail("must be finite");
    return v;
}

double JsonNode::number(double lo, double hi, std::string_view unit) const {
    const double v = number();
    if (!(v >= lo && v <= hi))
        fail(concat(check::format_number(v), " must be in [", check::format_number(lo), ", ",
                    check::format_number(hi), "]", unit));
    return v;
}

double JsonNode::positive() const {
    const double v = number();
    if (!(v > 0.0)) fail(concat(check::format_number(v), " must be > 0"));
    return v;
}

long long JsonNode::integer(long long lo, long long hi) const {
    if (value_->is_number_unsigned()) {
        const auto u = value_->get<unsigned long long>();
        if (u <= static_cast<unsigned long long>(std::numeric_limits<long long>::max()) &&
            static_cast<long long>(u) >= lo && static_cast<long long>(u) <= hi)
            return static_cast<long long>(u);
    } else if (value_->is_number_integer()) {
        const auto v = value_->get<long long>();
        if (v >= lo && v <= hi) return v;
    } else {
        const double v = number();
        if (v == std::floor(v) && v >= static_cast<double>(lo) && v <= static_cast<double>(hi))
            return static_cast<long long>(v);
    }
    fail(concat(shown(*value_), " must be a whole number in [", std::to_string(lo), ", ",
                std::to_string(hi), "]"));
}

std::string JsonNode::string() const {
    if (!value_->is_string()) wrong_type("a string");
    return value_->get<std::string>();
}

bool JsonNode::boolean() const {
    if (!value_->is_boolean()) wrong_type("true or false");
    return value_->get<bool>();
}

void JsonNode::only(std::initializer_list<std::string_view> keys) const {
    if (!value_->is_object()) wrong_type("an object");
    for (const auto& item : value_->items()) {
        if (std::find(keys.begin(), keys.end(), std::string_view(item.key())) != keys.end())
            continue;
        std::string valid;
        for (const auto k : keys) valid = concat(valid, valid.empty() ? "" : ", ", k);
        fail_at(item.key(), concat("unknown key; valid keys: ", valid));
    }
}

std::vector<JsonNode> JsonNode::array(std::size_t min, std::size_t max,
                                      std::string_view what) const {
    if (!value_->is_array() || value_->size() < min || value_->size() > max) {
        const bool unbounded = max == std::numeric_limits<std::size_t>::max();
        const std::string count =
            min == max  ? concat(std::to_string(min), " ")
            : unbounded ? (min == 0 ? std::string() : concat("at least ", std::to_string(min), " "))
                        : concat(std::to_string(min), " to ", std::to_string(max), " ");
        wrong_type(concat("an array of ", count, what));
    }
    std::vector<JsonNode> out;
    out.reserve(value_->size());
    for (std::size_t k = 0; k < value_->size(); ++k) out.push_back(item(k));
    return out;
}

std::vector<double> JsonNode::numbers(std::size_t n) const {
    std::vector<double> out;
    for (const JsonNode& v : array(n, n, "numbers")) out.push_back(v.number());
    return out;
}

}  // namespace roughscope::io
