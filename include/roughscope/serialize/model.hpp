// JSON schema of the model outputs of `roughscope model` (docs/cli.md): the B–K mean scattered
// power of Eq. 1–5, and the records of one evaluation (one geometry or one CSV row) with their
// JSON, CSV and streamed forms.
#pragma once

#include <array>
#include <bit>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "roughscope/io/output_file.hpp"
#include "roughscope/scattering/beckmann.hpp"
#include "roughscope/scattering/reflectance_models.hpp"
#include "roughscope/serialize/json.hpp"

namespace roughscope::serialize {

// brightness, coherent (ρ0² e^{−g}), diffuse (D), total (P, Eq. 1), g, regime (the one used,
// never "auto"), roughness_class, method (how D was evaluated: "closed_form", "summation",
// "large_g_expansion") and relative_error_bound (0 for a closed form asked for by name).
Json to_json(const ScatteredPower& power);

// Lafortune lobes as the model record lists them: [{Cx, Cy, Cz, n, rho}, ...] (rho: the lobe's
// albedo).
Json to_json(const std::vector<LafortuneLobe>& lobes);

// A result record of `roughscope model`: its keys (string literals) in output order and their
// values. Unlike a JSON object it allocates no key, and one record is reused row after row
// (clear() keeps the slots and their strings' storage); to_json() gives the object, and
// ModelRecordWriter formats the record directly with the bytes the object's dump would give.
class ModelRecord {
  public:
    // A number to record: null when unknown or not finite, as serialize::number gives it.
    struct NumberOrNull {
        std::optional<double> value;
    };
    // A JSON value: null, a boolean, a number, a string, or (Nested) any other JSON value.
    struct Value {
        enum class Kind { Null, Boolean, Number, Text, Nested };
        Kind kind = Kind::Null;
        bool boolean = false;
        double number = 0.0;
        std::string text;
        Json nested;
        // The writer's last formatted number and its text: a record is reused row after row and
        // most of its numbers (the options echoed) repeat, so each is formatted once.
        enum class Style : std::uint8_t { None, Csv };
        mutable Style formatted_style = Style::None;
        mutable std::uint8_t formatted_size = 0;
        mutable std::uint64_t formatted_bits = 0;  // of the number formatted
        mutable std::array<char, 64> formatted{};

        // The text of `number` in `style`, by `format(buffer) -> end` when not the cached one.
        template <class Format>
        std::string_view number_text(Style style, Format&& format) const {
            const auto bits = std::bit_cast<std::uint64_t>(number);
            if (formatted_style != style || formatted_bits != bits) {
                const char* end = format(formatted.data());
                formatted_size = static_cast<std::uint8_t>(end - formatted.data());
                formatted_bits = bits;
                formatted_style = style;
            }
            return {formatted.data(), formatted_size};
        }

        Value& operator=(std::nullptr_t) {
            kind = Kind::Null;
            return *this;
        }
        Value& operator=(bool b) {
            kind = Kind::Boolean;
            boolean = b;
            return *this;
        }
        Value& operator=(std::string_view t) {
            kind = Kind::Text;
            text.assign(t);
            return *this;
        }
        Value& operator=(const char* t) { return *this = std::string_view(t); }
        // Numbers come as NumberOrNull (serialize::number's rule: finite, else null): a bare
        // double would otherwise convert to bool.
        Value& operator=(NumberOrNull n) {
            if (n.value && std::isfinite(*n.value)) {
                kind = Kind::Number;
                number = *n.value;
            } else {
                kind = Kind::Null;
            }
            return *this;
        }
        Value& operator=(double) = delete;
        Value& operator=(int) = delete;
        Value& operator=(const std::string& t) { return *this = std::string_view(t); }
        Value& operator=(const Json& j) {
            if (j.is_null()) return *this = nullptr;
            if (j.is_boolean()) return *this = j.get<bool>();
            if (j.is_string()) return *this = std::string_view(j.get_ref<const std::string&>());
            if (j.is_number_float()) {
                kind = Kind::Number;
                number = j.get<double>();
                return *this;
            }
            kind = Kind::Nested;
            nested = j;
            return *this;
        }
        Json to_json() const {
            switch (kind) {
                case Kind::Null:
                    return nullptr;
                case Kind::Boolean:
                    return boolean;
                case Kind::Number:
                    return number;
                case Kind::Text:
                    return text;
                case Kind::Nested:
                    break;
            }
            return nested;
        }
    };
    struct Item {
        std::string_view key;
        Value value;
    };

    ModelRecord() { items_.reserve(32); }  // every key of a record without regrowing
    void clear() {
        previous_size_ = size_;
        size_ = 0;
        same_prefix_ = true;
    }
    Value& operator[](std::string_view key) {
        // Row after row the keys come in the same order: while this record's keys so far are the
        // previous record's, a key that was new at this position then (it is not among them) is
        // new now, found without a search. Keys are literals, compared by address first.
        if (same_prefix_ && size_ < previous_size_) {
            const std::string_view slot = items_[size_].key;
            if (slot.data() == key.data() && slot.size() == key.size()) {
                Item& item = items_[size_++];
                item.value = nullptr;
                return item.value;
            }
        }
        for (std::size_t k = 0; k < size_; ++k)
            if (items_[k].key == key) return items_[k].value;
        same_prefix_ = false;
        if (size_ == items_.size()) items_.emplace_back();
        Item& item = items_[size_++];
        item.key = key;
        item.value = nullptr;
        return item.value;
    }
    bool contains(std::string_view key) const {
        return std::any_of(items_.begin(), items_.begin() + static_cast<std::ptrdiff_t>(size_),
                           [key](const Item& item) { return item.key == key; });
    }
    std::span<const Item> items() const { return {items_.data(), size_}; }
    Json to_json() const {
        Json out = Json::object();
        for (const Item& item : items()) out[std::string(item.key)] = item.value.to_json();
        return out;
    }

  private:
    std::vector<Item> items_;
    std::size_t size_ = 0;
    std::size_t previous_size_ = 0;  // the keys of the record before clear()
    bool same_prefix_ = false;       // items_[0, size_) are that record's first keys
};

// The keys of to_json(ScatteredPower) after brightness, set on `record` directly (once per CSV
// row): coherent, diffuse, total, g, regime, roughness_class, method, relative_error_bound.
void set_power(ModelRecord& record, const ScatteredPower& power);

// A record's value as a CSV or text cell: "" for null, true/false, the string, a number with
// `digits` significant digits (format_significant; an error for a value that is not finite),
// and the one-line dump of a list or object (Lafortune lobes).
std::string model_cell_text(const Json& value, int digits);

// A record as CSV: the header line of its keys and one line of its cells (model_cell_text).
std::string model_record_csv(const Json& record, int digits);

// Writes the records of `model --csv` one at a time: CSV (header from the first record, numbers
// with `csv_digits` significant digits) or a JSON array byte-identical to dump() of the whole
// versioned array, without holding the records. Each record is formatted straight into the
// chunk of rows that goes to the output once it holds kChunkBytes.
class ModelRecordWriter {
  public:
    ModelRecordWriter(io::OutputFile& out, bool json_output, int csv_digits);

    void add(const ModelRecord& record);
    // Closes the array (JSON) and writes what is pending; the caller commits the output.
    void finish();
    std::size_t count() const { return count_; }

  private:
    // Rows are written out in chunks of this size: large enough that the output file writes
    // them through without copying (io::OutputFile), small enough to stay in the cache.
    static constexpr std::size_t kChunkBytes = std::size_t{64} << 10;

    // The text before a record's value at one position: ",\n    \"key\": ", made once; `usable`
    // is false for a key that needs escaping or does not fit (the element then goes the slow
    // way).
    static constexpr std::size_t kBlock = 64;
    struct KeyText {
        std::string_view key;
        bool usable = false;
        std::uint8_t size = 0;
        std::array<char, kBlock> text{};
    };

    // Numbers formatted before, in a direct-mapped cache by their bits: the B-K records'
    // brightness, diffuse and total are often the same double, and the angles of a table of
    // measurements repeat from row to row (a grid of geometries).
    struct CachedNumber {
        std::uint64_t bits = 0;
        std::uint8_t size = 0;  // 0: empty
        std::array<char, kNumberBufferSize> text{};
    };
    static constexpr int kCacheBits = 10;

    void append_csv_row(const ModelRecord& record);
    void append_csv_cell(const ModelRecord::Value& v);
    // write_number's bytes, unless the same double is in the cache.
    char* write_cached_number(char* out, double value);
    // The key texts of the record's positions, made when a position's key is new: keys are
    // literals, so the same address and size is the same key.
    void update_keys(std::span<const ModelRecord::Item> items);
    // The element "  {\n    \"key\": value,\n ...\n  }" as dump(2) indents it inside the array;
    // false (chunk_ unchanged) when a value is nested or a key or string needs escaping.
    bool append_json_element(const ModelRecord& record);

    io::OutputFile& out_;
    bool json_;
    int csv_digits_;
    std::string head_;  // "  {\n    \"roughscope_version\": \"...\"": versioned()'s first key
    std::size_t count_ = 0;
    std::string chunk_;
    std::vector<KeyText> keys_;  // by position in the record
    std::vector<CachedNumber> cache_ = std::vector<CachedNumber>(std::size_t{1} << kCacheBits);
};

}  // namespace roughscope::serialize
