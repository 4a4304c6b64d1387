#pragma once
// Private helpers of the persist module: little-endian byte writing and bounds-checked reading whose errors
// name the offset and the field.

#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

#include "rubble/core/Result.hpp"

namespace rubble::persist {

/// Appends little-endian values to a byte vector.
class ByteWriter {
public:
    void u8(std::uint8_t v) { out_.push_back(v); }
    void u16(std::uint16_t v) { le(v, 2); }
    void u32(std::uint32_t v) { le(v, 4); }
    void u64(std::uint64_t v) { le(v, 8); }
    void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
    void f32(float v) { u32(std::bit_cast<std::uint32_t>(v)); }
    void f64(double v) { u64(std::bit_cast<std::uint64_t>(v)); }
    void bytes(const void* p, std::size_t n) {
        const auto* c = static_cast<const std::uint8_t*>(p);
        out_.insert(out_.end(), c, c + n);
    }
    /// Overwrites 4 bytes at offset (a length or checksum written after the data).
    void patchU32(std::size_t offset, std::uint32_t v) {
        for (int i = 0; i < 4; ++i)
            out_[offset + i] = static_cast<std::uint8_t>(v >> (8 * i));
    }
    std::size_t size() const { return out_.size(); }
    std::vector<std::uint8_t>& data() { return out_; }

private:
    void le(std::uint64_t v, int n) {
        std::uint8_t b[8];
        for (int i = 0; i < n; ++i)
            b[i] = static_cast<std::uint8_t>(v >> (8 * i));
        out_.insert(out_.end(), b, b + n);
    }
    std::vector<std::uint8_t> out_;
};

/// Reads little-endian values; the first failure (past the end) is kept with its offset and field name and
/// every later read returns zero.
class ByteReader {
public:
    /// Reads size bytes at data; messages name source and offsets counted from base.
    ByteReader(const std::uint8_t* data, std::size_t size, std::string source, std::size_t base = 0)
        : data_(data), size_(size), base_(base), source_(std::move(source)) {}

    std::uint8_t u8(std::string_view field) { return static_cast<std::uint8_t>(le(1, field)); }
    std::uint16_t u16(std::string_view field) { return static_cast<std::uint16_t>(le(2, field)); }
    std::uint32_t u32(std::string_view field) { return static_cast<std::uint32_t>(le(4, field)); }
    std::uint64_t u64(std::string_view field) { return le(8, field); }
    std::int32_t i32(std::string_view field) { return static_cast<std::int32_t>(u32(field)); }
    float f32(std::string_view field) { return std::bit_cast<float>(u32(field)); }
    double f64(std::string_view field) { return std::bit_cast<double>(u64(field)); }
    /// Copies n raw bytes to dst (fails naming the field when fewer are left).
    void raw(void* dst, std::size_t n, std::string_view field) {
        if (!ok())
            return;
        if (size_ - pos_ < n) {
            fail(pos_, field, "file ends before its " + std::to_string(n) + " bytes");
            return;
        }
        if (n > 0)
            std::memcpy(dst, data_ + pos_, n);
        pos_ += n;
    }
    /// A finite double (fails naming the field otherwise).
    double finite(std::string_view field) {
        const std::size_t at = pos_;
        const double v = f64(field);
        if (ok() && !(v - v == 0))
            fail(at, field, "is not finite");
        return ok() ? v : 0;
    }
    /// A count of records of at least minBytes each that fit in what is left (a hostile length fails here
    /// instead of allocating).
    std::uint32_t count(std::string_view field, std::size_t minBytes) {
        const std::size_t at = pos_;
        const std::uint32_t n = u32(field);
        if (ok() && static_cast<std::uint64_t>(n) * minBytes > size_ - pos_)
            fail(at, field,
                 "count " + std::to_string(n) + " exceeds the remaining " + std::to_string(size_ - pos_) +
                     " bytes");
        return ok() ? n : 0;
    }
    /// Records an error at offset naming the field (after the context, e.g. "objects[3].").
    void fail(std::size_t offset, std::string_view field, const std::string& what) {
        if (!error_.empty())
            return;
        error_ = source_ + ": offset " + std::to_string(base_ + offset) + ", field " + context_ +
                 std::string(field) + ": " + what;
    }
    /// What field names are prefixed with in errors from now on.
    void setContext(std::string context) { context_ = std::move(context); }
    bool ok() const { return error_.empty(); }
    const std::string& error() const { return error_; }
    std::size_t offset() const { return pos_; }
    std::size_t remaining() const { return size_ - pos_; }

private:
    std::uint64_t le(int n, std::string_view field) {
        if (!ok())
            return 0;
        if (size_ - pos_ < static_cast<std::size_t>(n)) {
            fail(pos_, field,
                 "file ends (" + std::to_string(size_) + " bytes) before its " + std::to_string(n) +
                     " bytes");
            return 0;
        }
        std::uint64_t v = 0;
        for (int i = 0; i < n; ++i)
            v |= static_cast<std::uint64_t>(data_[pos_ + i]) << (8 * i);
        pos_ += n;
        return v;
    }
    const std::uint8_t* data_;
    std::size_t size_;
    std::size_t base_;
    std::size_t pos_ = 0;
    std::string source_;
    std::string context_;
    std::string error_;
};

/// CRC-32 (IEEE 802.3, as zlib) of bytes.
std::uint32_t crc32(const std::uint8_t* data, std::size_t size);

} // namespace rubble::persist
