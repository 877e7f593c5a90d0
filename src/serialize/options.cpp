// Typed look-ups in an options object (options.hpp).
#include "options.hpp"

#include <cmath>

namespace roughscope::serialize::detail {
namespace {

const Json* find(const Json& options, const char* key) {
    if (!options.is_object()) return nullptr;
    const auto it = options.find(key);
    if (it == options.end() || it->is_null()) return nullptr;
    return &*it;
}

[[noreturn]] void wrong_type(const char* key, const Json& value, const char* expected) {
    throw InvalidArgument(std::string("option '") + key + "' = " + value.dump() + " must be " +
                          expected);
}

}  // namespace

void check_keys(const Json& options, std::string_view what,
                std::initializer_list<std::string_view> known) {
    if (options.is_null()) return;
    if (!options.is_object())
        throw InvalidArgument(std::string(what) + " must be an object of named options, got " +
                              options.dump());
    for (const auto& item : options.items()) {
        bool ok = false;
        for (std::string_view k : known) ok = ok || item.key() == k;
        if (ok) continue;
        std::string list;
        for (std::string_view k : known) list += (list.empty() ? "" : ", ") + std::string(k);
        throw InvalidArgument("unknown " + std::string(what) + " '" + item.key() +
                              "' (known: " + list + ")");
    }
}

std::optional<double> get_number(const Json& options, const char* key) {
    const Json* v = find(options, key);
    if (!v) return std::nullopt;
    if (!v->is_number()) wrong_type(key, *v, "a number");
    return v->get<double>();
}

std::optional<int> get_int(const Json& options, const char* key) {
    const Json* v = find(options, key);
    if (!v) return std::nullopt;
    if (v->is_number_integer()) return v->get<int>();
    if (v->is_number_float()) {
        const double x = v->get<double>();
        if (std::isfinite(x) && x == std::floor(x) && std::abs(x) < 2e9) return static_cast<int>(x);
    }
    wrong_type(key, *v, "an integer");
}

std::optional<bool> get_bool(const Json& options, const char* key) {
    const Json* v = find(options, key);
    if (!v) return std::nullopt;
    if (!v->is_boolean()) wrong_type(key, *v, "true or false");
    return v->get<bool>();
}

std::optional<std::string> get_string(const Json& options, const char* key) {
    const Json* v = find(options, key);
    if (!v) return std::nullopt;
    if (!v->is_string()) wrong_type(key, *v, "a string");
    return v->get<std::string>();
}

std::optional<std::pair<double, double>> get_number_pair(const Json& options, const char* key) {
    const Json* v = find(options, key);
    if (!v) return std::nullopt;
    if (!v->is_array() || v->size() != 2 || !(*v)[0].is_number() || !(*v)[1].is_number())
        wrong_type(key, *v, "a pair [lower, upper] of numbers");
    return std::pair{(*v)[0].get<double>(), (*v)[1].get<double>()};
}

std::optional<std::pair<int, int>> get_int_pair(const Json& options, const char* key) {
    const Json* v = find(options, key);
    if (!v) return std::nullopt;
    if (!v->is_array() || v->size() != 2) wrong_type(key, *v, "a pair of integers");
    Json a = Json::object({{"0", (*v)[0]}, {"1", (*v)[1]}});
    const auto first = get_int(a, "0"), second = get_int(a, "1");
    if (!first || !second) wrong_type(key, *v, "a pair of integers");
    return std::pair{*first, *second};
}

}  // namespace roughscope::serialize::detail
