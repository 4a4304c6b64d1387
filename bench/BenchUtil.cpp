#include "BenchUtil.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <sstream>
#include <thread>

#include "RubblePaths.hpp"

namespace rubble::bench {

namespace fs = std::filesystem;

fs::path sourceDir() {
    return generated::sourceDir;
}

std::string resultsDir() {
    return (sourceDir() / "bench" / "results").string();
}

Stats stats(std::vector<double> samples) {
    if (samples.empty())
        return {};
    std::sort(samples.begin(), samples.end());
    return {samples[samples.size() / 2], samples.front(), samples.back()};
}

namespace {

// Busy and total ticks of all cores together ("cpu" line of /proc/stat) and this process's own ticks (utime +
// stime of /proc/self/stat): the kernel charges each tick to the machine and to the task that ran in it, so
// machine − own cancels exactly even over short intervals. False when unreadable.
bool cpuTicks(long long& busy, long long& total, long long& own) {
    std::ifstream in("/proc/stat");
    std::string cpu;
    long long v[8] = {};
    if (!(in >> cpu) || cpu != "cpu")
        return false;
    for (long long& x : v)
        if (!(in >> x))
            return false;
    total = 0;
    for (long long x : v) // user nice system idle iowait irq softirq steal
        total += x;
    busy = total - v[3] - v[4];
    std::ifstream self("/proc/self/stat");
    std::string line;
    std::getline(self, line);
    const std::size_t close = line.rfind(')'); // the command name may hold spaces and parentheses
    if (close == std::string::npos)
        return false;
    std::istringstream fields(line.substr(close + 1));
    std::string field;
    long long utime = 0, stime = 0;
    for (int i = 3; i <= 15 && fields >> field; ++i) { // fields 14 and 15 of proc(5)
        if (i == 14)
            utime = std::stoll(field);
        if (i == 15)
            stime = std::stoll(field);
    }
    own = utime + stime;
    return static_cast<bool>(fields);
}

} // namespace

CpuMeter::CpuMeter() {
    if (!cpuTicks(busyTicks_, totalTicks_, ownTicks_))
        totalTicks_ = -1;
}

CpuMeter::Reading CpuMeter::read() const {
    Reading r;
    long long busy = 0, total = 0, own = 0;
    // a reading over a few ticks says nothing (one tick of a kernel thread reads as a busy core)
    constexpr long long kMinTicks = 100; // ~0.5 s on two cores at 100 ticks/s each
    if (totalTicks_ < 0 || !cpuTicks(busy, total, own) || total - totalTicks_ < kMinTicks)
        return r;
    // /proc/stat's total counts every core's ticks: busy / total is the busy share of all cores
    const double cores = static_cast<double>(std::max(1u, std::thread::hardware_concurrency()));
    const double span = static_cast<double>(total - totalTicks_);
    r.machine = cores * static_cast<double>(busy - busyTicks_) / span;
    r.own = cores * static_cast<double>(own - ownTicks_) / span;
    r.other = std::max(0.0, r.machine - r.own);
    return r;
}

double msSince(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double threadCpuMs() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}

std::string fixed(double v, int digits) {
    if (v < 0)
        return "";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.*f", digits, v);
    return buf;
}

void printTable(const Table& table) {
    std::vector<std::size_t> width(table.header.size(), 0);
    auto measure = [&](const std::vector<std::string>& row) {
        for (std::size_t c = 0; c < row.size() && c < width.size(); ++c)
            width[c] = std::max(width[c], row[c].size());
    };
    measure(table.header);
    for (const auto& row : table.rows)
        measure(row);
    auto print = [&](const std::vector<std::string>& row) {
        std::string line;
        for (std::size_t c = 0; c < row.size() && c < width.size(); ++c) {
            const std::string pad(width[c] - row[c].size(), ' ');
            line += c == 0 ? row[c] + pad : "  " + pad + row[c];
        }
        std::cout << line << "\n";
    };
    print(table.header);
    std::size_t total = 0;
    for (std::size_t w : width)
        total += w + 2;
    std::cout << std::string(total > 2 ? total - 2 : 0, '-') << "\n";
    for (const auto& row : table.rows)
        print(row);
}

namespace {
std::string csvField(const std::string& s) {
    if (s.find_first_of(",\"\n") == std::string::npos)
        return s;
    std::string q = "\"";
    for (char c : s)
        q += c == '"' ? std::string("\"\"") : std::string(1, c);
    return q + "\"";
}
} // namespace

bool writeCsv(const fs::path& path, const Table& table) {
    std::error_code ec;
    if (path.has_parent_path())
        fs::create_directories(path.parent_path(), ec);
    std::ofstream out(path);
    auto line = [&](const std::vector<std::string>& row) {
        for (std::size_t c = 0; c < row.size(); ++c)
            out << (c ? "," : "") << csvField(row[c]);
        out << "\n";
    };
    line(table.header);
    for (const auto& row : table.rows)
        line(row);
    out.close();
    if (!out) {
        std::cerr << "cannot write " << path.string() << "\n";
        return false;
    }
    std::cout << "CSV: " << path.string() << "\n";
    return true;
}

std::vector<std::vector<std::string>> rowsOfOtherLabels(const std::filesystem::path& path,
                                                        const std::string& label, std::size_t columns) {
    std::vector<std::vector<std::string>> rows;
    std::ifstream in(path);
    std::string line;
    std::getline(in, line); // header
    while (std::getline(in, line)) {
        std::vector<std::string> cells;
        std::stringstream ss(line);
        for (std::string c; std::getline(ss, c, ',');)
            cells.push_back(c);
        if (!line.empty() && line.back() == ',') // an empty last cell
            cells.emplace_back();
        if (cells.size() == columns && cells[0] != label)
            rows.push_back(std::move(cells));
    }
    return rows;
}

bool makeResultsDir(const fs::path& dir) {
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) {
        std::cerr << "--out " << dir.string() << ": exists and is not a folder\n";
        return false;
    }
    fs::create_directories(dir, ec);
    if (ec) {
        std::cerr << "--out " << dir.string() << ": cannot create the folder: " << ec.message() << "\n";
        return false;
    }
    return true;
}

void plotPng(const fs::path& dir, const std::string& stem, const std::string& data, const std::string& plot) {
    if (std::system("command -v gnuplot >/dev/null 2>&1") != 0) {
        std::cout << "gnuplot not found: plot skipped\n";
        return;
    }
    const fs::path dat = dir / (stem + ".dat");
    const fs::path gp = dir / (stem + ".gp");
    const fs::path png = dir / (stem + ".png");
    {
        std::ofstream d(dat);
        d << data;
    }
    {
        std::ofstream g(gp);
        g << "set terminal pngcairo size 900,600\nset output '" << png.string() << "'\nDATA = '"
          << dat.string() << "'\n";
        std::string script = plot;
        for (std::size_t at = script.find("$DATA"); at != std::string::npos; at = script.find("$DATA", at))
            script.replace(at, 5, "DATA");
        g << script << "\n";
    }
    if (std::system(("gnuplot '" + gp.string() + "' 2>/dev/null").c_str()) == 0)
        std::cout << "plot: " << png.string() << "\n";
    else
        std::cout << "gnuplot failed: plot skipped\n";
    std::error_code ec;
    fs::remove(gp, ec);
    fs::remove(dat, ec);
}

std::vector<std::filesystem::path> repoModels() {
    namespace fs = std::filesystem;
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(sourceDir() / "assets" / "models", ec))
        if (e.path().extension() == ".obj" && e.path().stem().string().rfind("cube_", 0) != 0)
            files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

} // namespace rubble::bench
