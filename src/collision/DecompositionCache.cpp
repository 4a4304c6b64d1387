// In-memory and on-disk cache of decompositions. Files are "<key>.rdc": a header, the parts and an FNV-1a
// checksum; a file that is truncated, corrupt or from another version is ignored and rewritten.
#include <algorithm>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/collision/DecomposeControl.hpp"

namespace rubble {

namespace {

constexpr char kMagic[8] = {'R', 'U', 'B', 'D', 'E', 'C', '0', '1'};

std::uint64_t fnv1a(const char* data, std::size_t n) {
    std::uint64_t h = 0xcbf29ce484222325ull;
    for (std::size_t i = 0; i < n; ++i) {
        h ^= static_cast<unsigned char>(data[i]);
        h *= 0x100000001b3ull;
    }
    return h;
}

std::uint64_t keyOf(const Mesh& mesh, const DecompositionParams& p) {
    std::uint64_t h = mesh.hash();
    auto mix = [&h](std::uint64_t v) { h ^= v + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2); };
    std::uint64_t bits;
    mix(static_cast<std::uint64_t>(p.maxParts));
    std::memcpy(&bits, &p.concavity, 8);
    mix(bits);
    std::memcpy(&bits, &p.minPartVolumeFraction, 8);
    mix(bits);
    mix(static_cast<std::uint64_t>(p.proxyAboveTriangles));
    mix(static_cast<std::uint64_t>(p.maxPartFaces));
    return h;
}

class Writer {
public:
    template <class T>
    void put(const T& v) {
        buf.append(reinterpret_cast<const char*>(&v), sizeof v);
    }
    std::string buf;
};

class Reader {
public:
    Reader(const std::string& s) : data_(s) {}
    template <class T>
    bool get(T& v) {
        if (pos_ + sizeof v > data_.size())
            return false;
        std::memcpy(&v, data_.data() + pos_, sizeof v);
        pos_ += sizeof v;
        return true;
    }
    std::size_t remaining() const { return data_.size() - pos_; }

private:
    const std::string& data_;
    std::size_t pos_ = 0;
};

std::string serialize(std::uint64_t key, const Decomposition& d) {
    Writer w;
    w.buf.append(kMagic, 8);
    w.put(key);
    w.put(d.meshVolume);
    w.put(d.hullVolume);
    w.put(static_cast<std::uint32_t>(d.parts.size()));
    for (const ConvexPolytope& p : d.parts) {
        w.put(static_cast<std::uint32_t>(p.faces().size()));
        for (const PolytopeFaceView& f : p.faces()) {
            w.put(f.plane.normal);
            w.put(f.plane.offset);
            w.put(f.tag);
            w.put(static_cast<std::uint32_t>(f.corners.size()));
            for (const Vec3& c : f.corners)
                w.put(c);
        }
    }
    w.put(fnv1a(w.buf.data(), w.buf.size()));
    return w.buf;
}

bool deserialize(const std::string& s, std::uint64_t key, Decomposition& d) {
    if (s.size() < 8 + 8 + 8 || std::memcmp(s.data(), kMagic, 8) != 0)
        return false;
    std::uint64_t sum;
    std::memcpy(&sum, s.data() + s.size() - 8, 8);
    if (fnv1a(s.data(), s.size() - 8) != sum)
        return false;
    const std::string body = s.substr(8, s.size() - 16);
    Reader r(body);
    std::uint64_t k;
    std::uint32_t nparts;
    if (!r.get(k) || k != key || !r.get(d.meshVolume) || !r.get(d.hullVolume) || !r.get(nparts))
        return false;
    if (nparts > r.remaining() / 4)
        return false;
    for (std::uint32_t i = 0; i < nparts; ++i) {
        std::uint32_t nfaces;
        if (!r.get(nfaces) || nfaces > r.remaining() / 40)
            return false;
        std::vector<PolytopeFace> faces(nfaces);
        for (PolytopeFace& f : faces) {
            std::uint32_t nc;
            if (!r.get(f.plane.normal) || !r.get(f.plane.offset) || !r.get(f.tag) || !r.get(nc) ||
                nc > r.remaining() / sizeof(Vec3))
                return false;
            f.corners.resize(nc);
            for (Vec3& c : f.corners)
                if (!r.get(c) || !isFinite(c))
                    return false;
        }
        d.parts.push_back(ConvexPolytope::fromFaces(std::move(faces)));
    }
    return r.remaining() == 0;
}

} // namespace

DecompositionCache::DecompositionCache(std::filesystem::path directory, std::size_t capacity)
    : directory_(std::move(directory)), capacity_(std::max<std::size_t>(1, capacity)) {}

std::size_t DecompositionCache::hits() const {
    std::lock_guard lock(mutex_);
    return hits_;
}

std::size_t DecompositionCache::size() const {
    std::lock_guard lock(mutex_);
    return memory_.size();
}

void DecompositionCache::store(std::uint64_t key, const Decomposition& d) {
    if (auto it = memory_.find(key); it != memory_.end()) {
        it->second.decomposition = d;
        recency_.splice(recency_.begin(), recency_, it->second.recency);
        return;
    }
    recency_.push_front(key);
    memory_.emplace(key, Entry{d, recency_.begin()});
    while (memory_.size() > capacity_) {
        memory_.erase(recency_.back());
        recency_.pop_back();
    }
}

Result<Decomposition> DecompositionCache::get(const Mesh& mesh, const DecompositionParams& params) {
    return get(mesh, params, DecomposeControl{});
}

Result<Decomposition> DecompositionCache::get(const Mesh& mesh, const DecompositionParams& params,
                                              const DecomposeControl& control) {
    const std::uint64_t key = keyOf(mesh, params);
    // A hit is done at once: its progress is 1.
    auto hit = [&control](Decomposition d) -> Result<Decomposition> {
        if (control.progress)
            control.progress(1.0);
        return d;
    };
    std::optional<Decomposition> held;
    {
        std::lock_guard lock(mutex_);
        auto it = memory_.find(key);
        if (it != memory_.end()) {
            ++hits_;
            recency_.splice(recency_.begin(), recency_, it->second.recency);
            held = it->second.decomposition;
        }
    }
    if (held)
        return hit(std::move(*held));
    char name[32];
    std::snprintf(name, sizeof name, "%016llx.rdc", static_cast<unsigned long long>(key));
    const std::filesystem::path file = directory_.empty() ? std::filesystem::path{} : directory_ / name;
    if (!file.empty()) {
        std::ifstream in(file, std::ios::binary);
        if (in) {
            std::ostringstream ss;
            ss << in.rdbuf();
            Decomposition d;
            if (deserialize(ss.str(), key, d)) {
                {
                    std::lock_guard lock(mutex_);
                    ++hits_;
                    store(key, d);
                }
                return hit(std::move(d));
            }
        }
    }
    auto d = decompose(mesh, params, control);
    if (!d)
        return d;
    if (!file.empty()) {
        std::error_code ec;
        std::filesystem::create_directories(directory_, ec);
        const std::filesystem::path tmp = file.string() + ".tmp";
        {
            std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
            const std::string bytes = serialize(key, d.value());
            out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        }
        std::filesystem::rename(tmp, file, ec);
        if (ec)
            std::filesystem::remove(tmp, ec);
    }
    std::lock_guard lock(mutex_);
    store(key, d.value());
    return d;
}

} // namespace rubble
