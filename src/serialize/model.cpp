// JSON schema of the model outputs and the records of `roughscope model` (serialize/model.hpp).
#include "roughscope/serialize/model.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <string>

#include "roughscope/core/numbers.hpp"
#include "roughscope/io/csv.hpp"
#include "roughscope/scattering/validity.hpp"
#include "roughscope/version.hpp"

namespace roughscope::serialize {

Json to_json(const ScatteredPower& p) {
    return {{"brightness", number(p.brightness)},
            {"coherent", number(p.coherent)},
            {"diffuse", number(p.diffuse)},
            {"total", number(p.total)},
            {"g", number(p.g)},
            {"regime", std::string(to_string(p.regime))},
            {"roughness_class", std::string(to_string(p.roughness_class))},
            {"method", std::string(to_string(p.method))},
            {"relative_error_bound", number(p.relative_error_bound)}};
}

Json to_json(const std::vector<LafortuneLobe>& lobes) {
    Json out = Json::array();
    for (const auto& l : lobes) {
        out.push_back({{"Cx", number(l.Cx)},
                       {"Cy", number(l.Cy)},
                       {"Cz", number(l.Cz)},
                       {"n", number(l.n)},
                       {"rho", number(l.albedo)}});
    }
    return out;
}

void set_power(ModelRecord& record, const ScatteredPower& power) {
    record["coherent"] = ModelRecord::NumberOrNull{power.coherent};
    record["diffuse"] = ModelRecord::NumberOrNull{power.diffuse};
    record["total"] = ModelRecord::NumberOrNull{power.total};
    record["g"] = ModelRecord::NumberOrNull{power.g};
    record["regime"] = to_string(power.regime);
    record["roughness_class"] = to_string(power.roughness_class);
    record["method"] = to_string(power.method);
    record["relative_error_bound"] = ModelRecord::NumberOrNull{power.relative_error_bound};
}

std::string model_cell_text(const Json& v, int digits) {
    if (v.is_null()) return "";
    if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
    if (v.is_string()) return v.get<std::string>();
    if (v.is_number()) return format_significant(v.get<double>(), digits, "result");
    return v.dump();  // arrays/objects (Lafortune lobes)
}

std::string model_record_csv(const Json& record, int digits) {
    std::string out;
    bool first = true;
    for (const auto& [key, value] : record.items()) {
        if (!first) out += ',';
        out += io::csv_field(key);
        first = false;
    }
    out += '\n';
    first = true;
    for (const auto& [key, value] : record.items()) {
        if (!first) out += ',';
        const std::string cell = model_cell_text(value, digits);
        if (cell.find_first_of(",\"\n\r") == std::string::npos)
            out += cell;  // csv_field would return it unchanged
        else
            out += io::csv_field(cell);
        first = false;
    }
    out += '\n';
    return out;
}

namespace {

// A string that JSON and CSV output write as its bytes: printable ASCII without quote, backslash
// or CSV separator (every key and word of a record). One table look-up per character.
bool plain_text(std::string_view text) {
    static constexpr auto kPlain = [] {
        std::array<bool, 256> plain{};
        for (int c = 0x20; c < 0x7f; ++c) plain[static_cast<std::size_t>(c)] = true;
        for (char c : {'"', '\\', ','}) plain[static_cast<unsigned char>(c)] = false;
        return plain;
    }();
    for (char c : text)
        if (!kPlain[static_cast<unsigned char>(c)]) return false;
    return true;
}

}  // namespace

ModelRecordWriter::ModelRecordWriter(io::OutputFile& out, bool json_output, int csv_digits)
    : out_(out),
      json_(json_output),
      csv_digits_(csv_digits),
      head_(std::string("  {\n    \"") + kVersionKey + "\": \"" ROUGHSCOPE_VERSION_STRING "\"") {}

void ModelRecordWriter::add(const ModelRecord& record) {
    if (json_) {
        chunk_.append(count_ == 0 ? "[\n" : ",\n");
        if (!append_json_element(record)) {
            // Nested values (Lafortune lobes) or strings to escape: the element as the whole
            // array's dump indents it: "[\n" + element + "\n]\n".
            Json one = Json::array();
            one.push_back(versioned(record.to_json()));
            const std::string text = dump(one);
            chunk_.append(text, 2, text.size() - 5);
        }
    } else {
        append_csv_row(record);
    }
    ++count_;
    if (chunk_.size() >= kChunkBytes) {
        out_.write(chunk_);
        chunk_.clear();
    }
}

void ModelRecordWriter::finish() {
    if (json_ && count_ > 0) chunk_ += "\n]\n";
    out_.write(chunk_);
    chunk_.clear();
}

// The header line (first record) and the record's line.
void ModelRecordWriter::append_csv_row(const ModelRecord& record) {
    if (count_ == 0) {
        bool first = true;
        for (const auto& item : record.items()) {
            if (!first) chunk_ += ',';
            chunk_ += io::csv_field(std::string(item.key));
            first = false;
        }
        chunk_ += '\n';
    }
    bool first = true;
    for (const auto& item : record.items()) {
        if (!first) chunk_ += ',';
        append_csv_cell(item.value);
        first = false;
    }
    chunk_ += '\n';
}

// The CSV cell of a value (model_cell_text, quoted by csv_field when needed).
void ModelRecordWriter::append_csv_cell(const ModelRecord::Value& v) {
    using Kind = ModelRecord::Value::Kind;
    if (v.kind == Kind::Number && std::isfinite(v.number)) {
        // format_significant's "%.<digits>g" (no "-0"), without a temporary string.
        static_assert(kSignificantBufferSize <= 64);
        chunk_ += v.number_text(ModelRecord::Value::Style::Csv, [&](char* buf) {
            return write_significant(buf, v.number == 0.0 ? 0.0 : v.number, csv_digits_);
        });
        return;
    }
    if (v.kind == Kind::Null) return;  // model_cell_text: ""
    if (v.kind == Kind::Boolean) {
        chunk_ += v.boolean ? "true" : "false";
        return;
    }
    if (v.kind == Kind::Text && plain_text(v.text)) {
        chunk_ += v.text;
        return;
    }
    const std::string cell = model_cell_text(v.to_json(), csv_digits_);
    if (cell.find_first_of(",\"\n\r") == std::string::npos)
        chunk_ += cell;  // csv_field would return it unchanged
    else
        chunk_ += io::csv_field(cell);
}

char* ModelRecordWriter::write_cached_number(char* out, double value) {
    const auto bits = std::bit_cast<std::uint64_t>(value);
    CachedNumber& c = cache_[(bits * 0x9E3779B97F4A7C15ULL) >> (64 - kCacheBits)];
    if (c.size != 0 && c.bits == bits) return std::copy_n(c.text.data(), c.size, out);
    char* const end = write_number(out, value);
    c.bits = bits;
    c.size = static_cast<std::uint8_t>(end - out);
    std::copy(out, end, c.text.data());
    return end;
}

void ModelRecordWriter::update_keys(std::span<const ModelRecord::Item> items) {
    if (keys_.size() < items.size()) keys_.resize(items.size());
    for (std::size_t k = 0; k < items.size(); ++k) {
        const std::string_view key = items[k].key;
        KeyText& slot = keys_[k];
        if (slot.key.data() == key.data() && slot.key.size() == key.size()) continue;
        slot.key = key;
        constexpr std::string_view kBefore = ",\n    \"", kAfter = "\": ";
        const std::size_t size = kBefore.size() + key.size() + kAfter.size();
        slot.usable = plain_text(key) && size <= kBlock;
        if (!slot.usable) continue;
        char* p = std::copy(kBefore.begin(), kBefore.end(), slot.text.data());
        p = std::copy(key.begin(), key.end(), p);
        std::copy(kAfter.begin(), kAfter.end(), p);
        slot.size = static_cast<std::uint8_t>(size);
    }
}

bool ModelRecordWriter::append_json_element(const ModelRecord& record) {
    using Kind = ModelRecord::Value::Kind;
    static constexpr std::string_view kTail = "\n  }";
    const std::string_view head = head_;
    const std::span<const ModelRecord::Item> items = record.items();
    update_keys(items);
    // Pass 1: whether every value is written as is, and room for the text (whole blocks).
    std::size_t room = head.size() + kTail.size();
    for (std::size_t k = 0; k < items.size(); ++k) {
        const ModelRecord::Value& v = items[k].value;
        if (!keys_[k].usable || v.kind == Kind::Nested) return false;
        if (v.kind == Kind::Text && !plain_text(v.text)) return false;
        room += keys_[k].size + (v.kind == Kind::Text ? v.text.size() + 2 : kNumberBufferSize);
    }
    // Pass 2: the text, straight into the chunk.
    const std::size_t mark = chunk_.size();
    chunk_.resize(mark + room);
    char* p = std::copy(head.begin(), head.end(), chunk_.data() + mark);
    for (std::size_t k = 0; k < items.size(); ++k) {
        const KeyText& key = keys_[k];
        p = std::copy_n(key.text.data(), key.size, p);
        const ModelRecord::Value& v = items[k].value;
        switch (v.kind) {
            case Kind::Null:
                p = std::copy_n("null", 4, p);
                break;
            case Kind::Boolean:
                p = v.boolean ? std::copy_n("true", 4, p) : std::copy_n("false", 5, p);
                break;
            case Kind::Number:
                p = write_cached_number(p, v.number);
                break;
            case Kind::Text:
                *p++ = '"';
                p = std::copy(v.text.begin(), v.text.end(), p);
                *p++ = '"';
                break;
            case Kind::Nested:
                break;  // refused in pass 1
        }
    }
    p = std::copy(kTail.begin(), kTail.end(), p);
    chunk_.resize(static_cast<std::size_t>(p - chunk_.data()));
    return true;
}

}  // namespace roughscope::serialize
