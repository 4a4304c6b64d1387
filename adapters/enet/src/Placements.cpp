#include "Placements.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "Protocol.hpp"

namespace rubble::net::detail {

namespace {

constexpr double kMillimetres = 1000;
constexpr std::int64_t kMaxMillimetres = std::int64_t{1} << 40; // ±1.1e6 km: any world
constexpr double kHalfSqrt2 = 0.70710678118654752;
constexpr std::uint8_t kType = static_cast<std::uint8_t>(Message::Placements);
constexpr std::size_t kHeaderBytes = 1 + 4 + 10 + 5; // type, seq, frame and count varints

std::uint64_t zigzag(std::int64_t v) {
    return (static_cast<std::uint64_t>(v) << 1) ^ static_cast<std::uint64_t>(v >> 63);
}
std::int64_t unzigzag(std::uint64_t v) {
    return static_cast<std::int64_t>(v >> 1) ^ -static_cast<std::int64_t>(v & 1);
}

// One record: id field, (age << 2 | mask), changed position (delta or whole) and rotation (whole).
void putRecord(std::vector<std::uint8_t>& out, std::uint64_t idField, const Quantized* base,
               std::uint32_t age, const Quantized& q) {
    putVarint(out, idField);
    const bool moved = !base || base->p[0] != q.p[0] || base->p[1] != q.p[1] || base->p[2] != q.p[2];
    const bool turned = !base || base->q != q.q;
    putVarint(out, std::uint64_t{base ? age : 0} << 2 | (turned ? 2u : 0u) | (moved ? 1u : 0u));
    if (moved)
        for (int k = 0; k < 3; ++k)
            putVarint(out, zigzag(q.p[k] - (base ? base->p[k] : 0)));
    if (turned)
        for (int i = 0; i < 4; ++i)
            out.push_back(static_cast<std::uint8_t>(q.q >> (8 * i)));
}

} // namespace

void putVarint(std::vector<std::uint8_t>& out, std::uint64_t v) {
    for (; v >= 0x80; v >>= 7)
        out.push_back(static_cast<std::uint8_t>(v | 0x80));
    out.push_back(static_cast<std::uint8_t>(v));
}

bool getVarint(const std::uint8_t*& p, const std::uint8_t* end, std::uint64_t& v) {
    v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
        if (p == end)
            return false;
        const std::uint8_t b = *p++;
        v |= static_cast<std::uint64_t>(b & 0x7F) << shift;
        if (!(b & 0x80))
            return true;
    }
    return false;
}

Quantized quantize(const Frame& f) {
    Quantized q;
    for (int k = 0; k < 3; ++k) {
        const double mm = std::round(f.translation[k] * kMillimetres);
        q.p[k] =
            std::isfinite(mm)
                ? static_cast<std::int64_t>(std::clamp(mm, -double(kMaxMillimetres), double(kMaxMillimetres)))
                : 0;
    }
    std::array<double, 4> r = toQuaternion(f.rotation);
    std::size_t largest = 0;
    for (std::size_t i = 1; i < 4; ++i)
        if (std::abs(r[i]) > std::abs(r[largest]))
            largest = i;
    const double sign = r[largest] < 0 ? -1 : 1; // q and -q are the same rotation: the largest is positive
    std::uint32_t bits = static_cast<std::uint32_t>(largest);
    for (std::size_t i = 0; i < 4; ++i) {
        if (i == largest)
            continue;
        const double v = std::clamp(sign * r[i], -kHalfSqrt2, kHalfSqrt2);
        const double u = std::round((v / (2 * kHalfSqrt2) + 0.5) * 1023);
        bits = bits << 10 | static_cast<std::uint32_t>(std::isfinite(u) ? u : 511);
    }
    q.q = bits;
    return q;
}

Frame dequantize(const Quantized& q) {
    Frame f;
    for (int k = 0; k < 3; ++k)
        f.translation[k] = static_cast<double>(q.p[k]) / kMillimetres;
    const std::size_t largest = q.q >> 30;
    std::array<double, 4> r{};
    double sum = 0;
    int shift = 20;
    for (std::size_t i = 0; i < 4; ++i) {
        if (i == largest)
            continue;
        const double u = static_cast<double>((q.q >> shift) & 1023);
        r[i] = (u / 1023 - 0.5) * 2 * kHalfSqrt2;
        sum += r[i] * r[i];
        shift -= 10;
    }
    r[largest] = std::sqrt(std::max(0.0, 1 - sum));
    f.rotation = fromQuaternion(r);
    return f;
}

void PlacementEncoder::setBaseline(ObjectId id, const Quantized& q) {
    Body& b = bodies_[id];
    b.hasBase = true;
    b.baseSeq = 0;
    b.base = q;
}

std::vector<std::vector<std::uint8_t>>
PlacementEncoder::encode(std::uint64_t frame, const std::vector<std::pair<ObjectId, Quantized>>& now,
                         std::size_t budget) {
    struct Candidate {
        ObjectId id;
        const Quantized* q;
        Body* body;
    };
    std::vector<Candidate> candidates;
    std::map<ObjectId, Body> kept; // bodies that are gone are forgotten
    ++encodes_;
    for (const auto& [id, q] : now) {
        auto it = bodies_.find(id);
        Body& b = kept[id] = it != bodies_.end() ? it->second : Body{};
        if (b.sentSeq != 0 && encodes_ - b.sentAt > kInFlightEncodes)
            b.sentSeq = 0; // never acknowledged: lost
        if ((b.hasBase && b.base == q) || (b.sentSeq != 0 && b.sent == q)) {
            b.priority = 0; // unchanged (asleep, frozen, static) or on its way: costs nothing
            continue;
        }
        const Quantized* has = b.sentSeq != 0 ? &b.sent : b.hasBase ? &b.base : nullptr;
        double cm = 100; // no baseline: a new piece
        if (has)
            cm = std::sqrt(std::pow(double(q.p[0] - has->p[0]), 2) + std::pow(double(q.p[1] - has->p[1]), 2) +
                           std::pow(double(q.p[2] - has->p[2]), 2)) /
                 10;
        b.priority += 1 + std::min(1000.0, cm);
        candidates.push_back({id, &q, nullptr});
    }
    bodies_ = std::move(kept);
    behind_ = candidates.size();
    for (Candidate& c : candidates)
        c.body = &bodies_[c.id];
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
        return a.body->priority != b.body->priority ? a.body->priority > b.body->priority : a.id < b.id;
    });
    // Choose by priority within the budget (each record's size bounded from above), in datagrams.
    std::vector<std::vector<const Candidate*>> groups;
    std::size_t total = 0, size = 0;
    std::vector<std::uint8_t> scratch;
    for (const Candidate& c : candidates) {
        scratch.clear();
        putRecord(scratch, c.id, nullptr, 0, *c.q);
        std::size_t bound = scratch.size();
        if (c.body->hasBase) {
            scratch.clear();
            putRecord(scratch, c.id, &c.body->base, kBaselineWindow, *c.q);
            bound = std::max(bound, scratch.size());
        }
        const bool fresh = groups.empty() || size + bound > kMaxPlacementDatagram;
        const std::size_t cost = bound + (fresh ? kHeaderBytes : 0);
        if (total + cost > budget)
            break;
        if (fresh) {
            groups.emplace_back();
            size = kHeaderBytes;
        }
        groups.back().push_back(&c);
        size += bound;
        total += cost;
    }
    std::vector<std::vector<std::uint8_t>> out;
    deferred_ = candidates.size();
    for (auto& group : groups) {
        deferred_ -= group.size();
        std::sort(group.begin(), group.end(),
                  [](const Candidate* a, const Candidate* b) { return a->id < b->id; });
        const std::uint32_t seq = ++seq_;
        std::vector<std::uint8_t> msg{kType};
        for (int i = 0; i < 4; ++i)
            msg.push_back(static_cast<std::uint8_t>(seq >> (8 * i)));
        putVarint(msg, frame);
        putVarint(msg, group.size());
        auto& sent = pending_[seq];
        ObjectId previous = 0;
        for (const Candidate* c : group) {
            const Body& b = *c->body;
            const bool delta = b.hasBase && seq - b.baseSeq < kBaselineWindow;
            putRecord(msg, c->id - previous, delta ? &b.base : nullptr, seq - b.baseSeq, *c->q);
            previous = c->id;
            sent.emplace_back(c->id, *c->q);
            c->body->priority = 0;
            c->body->sentSeq = seq;
            c->body->sent = *c->q;
            c->body->sentAt = encodes_;
        }
        out.push_back(std::move(msg));
    }
    while (!pending_.empty() && pending_.begin()->first + kBaselineWindow < seq_)
        pending_.erase(pending_.begin());
    return out;
}

void PlacementEncoder::acked(std::uint32_t latest, std::uint32_t mask) {
    for (auto it = pending_.begin(); it != pending_.end() && it->first <= latest;) {
        const std::uint32_t seq = it->first;
        const bool got = seq == latest || (latest - seq <= 32 && (mask >> (latest - seq - 1) & 1));
        for (const auto& [id, q] : it->second) {
            const auto b = bodies_.find(id);
            if (b == bodies_.end())
                continue;
            Body& body = b->second;
            if (body.sentSeq == seq)
                body.sentSeq = 0; // arrived, or lost: what the client has is its baseline either way
            if (got && (!body.hasBase || seq > body.baseSeq)) {
                body.hasBase = true;
                body.baseSeq = seq;
                body.base = q;
            }
        }
        it = got || latest - seq > 32 ? pending_.erase(it) : std::next(it);
    }
}

void PlacementDecoder::setBaseline(ObjectId id, const Quantized& q) {
    history_[id][0] = q;
}

bool PlacementDecoder::decode(const std::uint8_t* data, std::size_t size, std::uint64_t& frame,
                              std::vector<DecodedPlacement>& out) {
    if (size < 5 || data[0] != kType)
        return false;
    const std::uint32_t seq = readU32(data + 1);
    const std::uint8_t *p = data + 5, *end = data + size;
    std::uint64_t count = 0;
    if (seq == 0 || !getVarint(p, end, frame) || !getVarint(p, end, count) || count > size)
        return false;
    std::vector<DecodedPlacement> records;
    bool whole = true;
    std::uint64_t id = 0;
    for (std::uint64_t i = 0; i < count; ++i) {
        std::uint64_t delta = 0, field = 0;
        if (!getVarint(p, end, delta) || !getVarint(p, end, field))
            return false;
        id += delta;
        const std::uint64_t age = field >> 2, mask = field & 3;
        if (id > 0xFFFFFFFFu || mask == 0 || (age == 0 && mask != 3) || age >= kBaselineWindow)
            return false;
        Quantized q;
        bool based = true;
        if (age > 0) {
            based = false;
            if (auto h = history_.find(static_cast<ObjectId>(id)); h != history_.end())
                if (auto b = h->second.find(seq - static_cast<std::uint32_t>(age)); b != h->second.end()) {
                    q = b->second;
                    based = true;
                }
        }
        if (mask & 1)
            for (std::int64_t& c : q.p) {
                std::uint64_t v = 0;
                if (!getVarint(p, end, v))
                    return false;
                const std::int64_t d = unzigzag(v);
                if (d > kMaxMillimetres || d < -kMaxMillimetres)
                    return false;
                c = (age > 0 ? c : 0) + d;
            }
        if (mask & 2) {
            if (end - p < 4)
                return false;
            q.q = readU32(p);
            p += 4;
        }
        if (based)
            records.push_back({static_cast<ObjectId>(id), q});
        whole = whole && based;
    }
    if (p != end)
        return false;
    for (const DecodedPlacement& r : records) {
        history_[r.id][seq] = r.q;
        out.push_back(r);
    }
    if (whole) {
        if (seq > latest_) {
            const std::uint32_t shift = seq - latest_;
            const std::uint32_t moved = shift >= 32 ? 0 : mask_ << shift;
            mask_ = latest_ > 0 && shift <= 32 ? moved | 1u << (shift - 1) : moved;
            latest_ = seq;
        } else if (seq < latest_ && latest_ - seq <= 32) {
            mask_ |= 1u << (latest_ - seq - 1);
        }
    }
    if (latest_ - pruned_ >= kBaselineWindow / 2) { // forget what the host will not refer to any more
        pruned_ = latest_;
        for (auto h = history_.begin(); h != history_.end();) {
            auto& entries = h->second;
            while (!entries.empty() && entries.begin()->first + kBaselineWindow < latest_)
                entries.erase(entries.begin());
            h = entries.empty() ? history_.erase(h) : std::next(h);
        }
    }
    return true;
}

} // namespace rubble::net::detail
