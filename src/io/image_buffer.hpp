// The samples the PNG and TIFF codecs (io/png_codec.hpp, io/tiff_codec.hpp) decode into and
// encode from: rows of interleaved samples in the machine's byte order. Internal (src/).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace roughscope::io::codec {

using Bytes = std::span<const std::uint8_t>;

// The bytes of a string (a file held in a std::string) as Bytes.
inline Bytes as_bytes(std::string_view text) {
    return {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()};
}

// How one sample is stored: unsigned 8 or 16 bits, or IEEE float of 32 or 64 bits.
struct SampleType {
    int bits = 8;
    bool is_float = false;
    std::size_t bytes() const { return static_cast<std::size_t>(bits) / 8; }
};

// Samples to encode: `height` rows of `width` pixels of `channels` samples each, row r starting at
// data + r · row_stride bytes (0: rows packed one after the other).
struct ImageView {
    const void* data = nullptr;
    std::size_t width = 0;
    std::size_t height = 0;
    std::size_t channels = 1;
    SampleType type;
    std::size_t row_stride = 0;

    std::size_t row_bytes() const { return width * channels * type.bytes(); }
    const std::uint8_t* row(std::size_t r) const {
        return static_cast<const std::uint8_t*>(data) + r * (row_stride ? row_stride : row_bytes());
    }
};

// A sample of type T at `at` (any alignment) as a double.
template <class T>
double load_sample(const std::uint8_t* at) {
    T v{};
    std::memcpy(&v, at, sizeof v);
    return static_cast<double>(v);
}

// Decoded samples, rows packed (ImageView's layout with row_stride 0).
struct ImageBuffer {
    ImageBuffer() = default;
    // Room for width × height pixels of `channels` samples of `type` (zeros).
    ImageBuffer(std::size_t w, std::size_t h, std::size_t c, SampleType t)
        : width(w), height(h), channels(c), type(t), data(w * h * c * t.bytes()) {}

    std::size_t width = 0;
    std::size_t height = 0;
    std::size_t channels = 1;
    SampleType type;
    std::vector<std::uint8_t> data;

    ImageView view() const { return {data.data(), width, height, channels, type, 0}; }
    // The sample of channel c at (x, y) as a double.
    double sample(std::size_t x, std::size_t y, std::size_t c = 0) const {
        const std::uint8_t* at = data.data() + ((y * width + x) * channels + c) * type.bytes();
        return sample_at(at, type);
    }
    // The sample at `at` of type t as a double.
    static double sample_at(const std::uint8_t* at, SampleType t) {
        if (t.is_float && t.bits == 32) return load_sample<float>(at);
        if (t.is_float) return load_sample<double>(at);
        if (t.bits == 16) return load_sample<std::uint16_t>(at);
        return *at;
    }
};

}  // namespace roughscope::io::codec
