#pragma once
// Reads typed values from a fuzzer's byte string; past the end every read returns zero.

#include <cstddef>
#include <cstdint>
#include <cstring>

namespace rubble::fuzz {

/// A cursor over fuzzer input.
class FuzzInput {
public:
    FuzzInput(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
    /// Next byte (0 past the end).
    std::uint8_t byte() { return pos_ < size_ ? data_[pos_++] : 0; }
    /// Next 64-bit value.
    std::uint64_t u64() {
        std::uint64_t v = 0;
        for (int i = 0; i < 8; ++i)
            v = (v << 8) | byte();
        return v;
    }
    /// Next raw double (may be NaN or infinite).
    double rawDouble() {
        const std::uint64_t bits = u64();
        double d;
        std::memcpy(&d, &bits, sizeof d);
        return d;
    }
    /// A small grid coordinate in [-2, 2] with step 1/8, or rarely a raw double.
    double coordinate() {
        const std::uint8_t b = byte();
        if (b == 0xFF)
            return rawDouble();
        return (static_cast<int>(b % 33) - 16) / 8.0;
    }
    /// True when input is left.
    bool more() const { return pos_ < size_; }

private:
    const std::uint8_t* data_;
    std::size_t size_;
    std::size_t pos_ = 0;
};

} // namespace rubble::fuzz
