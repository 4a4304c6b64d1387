#include "rubble/enet/UdpRelay.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <mutex>
#include <queue>
#include <thread>

namespace rubble::net {

LinkModel::LinkModel(const LinkProfile& profile, std::uint64_t seed) : profile_(profile), rng_(seed) {
    const double loss = std::clamp(profile.loss, 0.0, 0.999);
    if (profile.burstLength > 1) {
        badToGood_ = 1 / profile.burstLength;
        goodToBad_ = loss * badToGood_ / (1 - loss); // stationary share of the bad state = loss
    } else {
        goodToBad_ = loss; // independent: every datagram starts from the good state
        badToGood_ = 1;
    }
}

double LinkModel::delay() {
    double d = profile_.delayMs;
    if (profile_.jitterMs > 0) { // Box-Muller, cut at ±3σ
        const double u1 = std::max(rng_.uniform(), 1e-300), u2 = rng_.uniform();
        const double z = std::sqrt(-2 * std::log(u1)) * std::cos(2 * 3.14159265358979323846 * u2);
        d += profile_.jitterMs * std::clamp(z, -3.0, 3.0);
    }
    if (profile_.reorder > 0 && rng_.uniform() < profile_.reorder) {
        d += profile_.reorderMs;
        ++stats_.reordered;
    }
    return std::max(0.0, d) / 1000;
}

std::vector<double> LinkModel::send(double now, std::size_t bytes) {
    ++stats_.sent;
    stats_.bytesSent += static_cast<long long>(bytes);
    // Every draw happens for every datagram, so a datagram's fate depends on its index only.
    const double lossDraw = rng_.uniform(), dupDraw = rng_.uniform();
    bad_ = bad_ ? lossDraw >= badToGood_ : lossDraw < goodToBad_;
    if (partitioned(now)) {
        ++stats_.partitionDrops;
        return {};
    }
    if (bad_) {
        ++stats_.lost;
        if (profile_.burstLength <= 1)
            bad_ = false;
        return {};
    }
    double leave = now;
    if (profile_.kbps > 0) {
        const double start = std::max(now, busyUntil_);
        if (start - now > profile_.queueMs / 1000) {
            ++stats_.queueDrops;
            return {};
        }
        busyUntil_ = start + static_cast<double>(bytes) * 8 / (profile_.kbps * 1000);
        leave = busyUntil_;
    }
    std::vector<double> at{leave + delay()};
    if (dupDraw < profile_.duplicate) {
        ++stats_.duplicated;
        at.push_back(leave + delay());
    }
    return at;
}

bool LinkModel::deliver(double now, std::size_t bytes) {
    if (partitioned(now)) {
        ++stats_.partitionDrops;
        return false;
    }
    ++stats_.delivered;
    stats_.bytesDelivered += static_cast<long long>(bytes);
    return true;
}

bool LinkModel::partitioned(double now) const {
    return forced_ || (profile_.partitionStartS >= 0 && now >= profile_.partitionStartS &&
                       now < profile_.partitionStartS + profile_.partitionS);
}

void LinkModel::setPartitioned(bool on) {
    forced_ = on;
}

namespace {

using Clock = std::chrono::steady_clock;

// A non-blocking UDP socket bound to 127.0.0.1 on a free port (-1 on failure).
int loopbackSocket() {
    const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (fd < 0)
        return -1;
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = 0;
    const int buffer = 4 << 20; // bursts of a dozen clients' datagrams (the kernel may cap it)
    (void)setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
    if (bind(fd, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
        close(fd);
        return -1;
    }
    return fd;
}

// A datagram in flight.
struct InFlight {
    double due = 0;
    std::uint64_t order = 0;
    int direction = 0; // 0 up (to the server), 1 down (to the client)
    std::vector<std::uint8_t> bytes;
    bool operator>(const InFlight& o) const { return due != o.due ? due > o.due : order > o.order; }
};

} // namespace

struct UdpRelay::Impl {
    Impl(const LinkProfile& up, const LinkProfile& down, std::uint64_t seed)
        : links{LinkModel(up, mixSeed(seed, 1)), LinkModel(down, mixSeed(seed, 2))} {}
    ~Impl() {
        stop = true;
        if (thread.joinable())
            thread.join();
        for (int fd : {front, back})
            if (fd >= 0)
                close(fd);
    }
    LinkModel links[2];
    mutable std::mutex mutex; // guards links
    int front = -1;           // the client's side
    int back = -1;            // the server's side
    sockaddr_in server{};
    sockaddr_in client{};
    bool haveClient = false;
    std::uint16_t port = 0;
    std::atomic<bool> stop{false};
    std::thread thread;
    std::priority_queue<InFlight, std::vector<InFlight>, std::greater<>> queue;
    std::uint64_t order = 0;
    Clock::time_point t0 = Clock::now();

    double now() const { return std::chrono::duration<double>(Clock::now() - t0).count(); }

    void take(int fd, int direction) {
        std::vector<std::uint8_t> buf(65536);
        for (;;) {
            sockaddr_in from{};
            socklen_t len = sizeof from;
            const ssize_t n =
                recvfrom(fd, buf.data(), buf.size(), 0, reinterpret_cast<sockaddr*>(&from), &len);
            if (n < 0)
                return;
            if (direction == 0) { // the client is whoever sends to the front (loopback only)
                if ((ntohl(from.sin_addr.s_addr) >> 24) != 127)
                    continue;
                client = from;
                haveClient = true;
            }
            std::vector<double> due;
            {
                const std::lock_guard lock(mutex);
                due = links[direction].send(now(), static_cast<std::size_t>(n));
            }
            for (double d : due)
                if (queue.size() < 100000)
                    queue.push(
                        {d, order++, direction, std::vector<std::uint8_t>(buf.begin(), buf.begin() + n)});
        }
    }

    void run() {
        while (!stop) {
            const double t = now();
            while (!queue.empty() && queue.top().due <= t) {
                const InFlight& p = queue.top();
                bool arrives;
                {
                    const std::lock_guard lock(mutex);
                    arrives = links[p.direction].deliver(t, p.bytes.size());
                }
                if (arrives) {
                    const sockaddr_in& to = p.direction == 0 ? server : client;
                    if (p.direction == 0 || haveClient)
                        (void)sendto(p.direction == 0 ? back : front, p.bytes.data(), p.bytes.size(), 0,
                                     reinterpret_cast<const sockaddr*>(&to), sizeof to);
                }
                queue.pop();
            }
            int wait = 20; // ms; also bounds the time to notice stop
            if (!queue.empty())
                wait = std::clamp(static_cast<int>(std::ceil((queue.top().due - now()) * 1000)), 0, 20);
            pollfd fds[2] = {{front, POLLIN, 0}, {back, POLLIN, 0}};
            if (poll(fds, 2, wait) > 0) {
                if (fds[0].revents & POLLIN)
                    take(front, 0);
                if (fds[1].revents & POLLIN)
                    take(back, 1);
            }
        }
    }
};

UdpRelay::UdpRelay(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

UdpRelay::~UdpRelay() = default;

Result<std::unique_ptr<UdpRelay>> UdpRelay::start(std::uint16_t serverPort, const LinkProfile& up,
                                                  const LinkProfile& down, std::uint64_t seed) {
    if (serverPort == 0)
        return Error{ErrorCode::InvalidInput, "relay: the server's port must not be 0"};
    auto impl = std::make_unique<Impl>(up, down, seed);
    impl->front = loopbackSocket();
    impl->back = loopbackSocket();
    if (impl->front < 0 || impl->back < 0)
        return Error{ErrorCode::IoError, "relay: cannot bind a UDP socket on 127.0.0.1"};
    sockaddr_in a{};
    socklen_t len = sizeof a;
    getsockname(impl->front, reinterpret_cast<sockaddr*>(&a), &len);
    impl->port = ntohs(a.sin_port);
    impl->server.sin_family = AF_INET;
    impl->server.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    impl->server.sin_port = htons(serverPort);
    Impl* raw = impl.get();
    impl->thread = std::thread([raw] { raw->run(); });
    return std::unique_ptr<UdpRelay>(new UdpRelay(std::move(impl)));
}

std::uint16_t UdpRelay::port() const {
    return impl_->port;
}

void UdpRelay::setPartitioned(bool on) {
    const std::lock_guard lock(impl_->mutex);
    for (LinkModel& l : impl_->links)
        l.setPartitioned(on);
}

LinkStats UdpRelay::up() const {
    const std::lock_guard lock(impl_->mutex);
    return impl_->links[0].stats();
}

LinkStats UdpRelay::down() const {
    const std::lock_guard lock(impl_->mutex);
    return impl_->links[1].stats();
}

} // namespace rubble::net
