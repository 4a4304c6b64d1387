#pragma once
// Helpers shared by the rubble-bench suites: timing statistics, aligned tables on stdout, CSV files and
// gnuplot PNGs in the results folder.

#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

namespace rubble::bench {

/// The source tree this bench was built from.
std::filesystem::path sourceDir();

/// The default results folder (bench/results in the source tree).
std::string resultsDir();

/// Median, minimum and maximum of a set of samples (milliseconds).
struct Stats {
    double median = 0; ///< middle sample (upper middle for an even count)
    double min = 0;    ///< smallest sample
    double max = 0;    ///< largest sample
};

/// Statistics of samples; all zero for no samples.
Stats stats(std::vector<double> samples);

/// Milliseconds since t0 on the steady clock.
double msSince(std::chrono::steady_clock::time_point t0);

/// This thread's CPU time in ms (the machine is shared: wall time includes waiting for a core).
double threadCpuMs();

/// Runs f `runs` times and returns the statistics of its wall-clock durations in milliseconds.
template <class F>
Stats timeIt(int runs, F&& f) {
    std::vector<double> ms;
    for (int i = 0; i < runs; ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        f();
        ms.push_back(msSince(t0));
    }
    return stats(ms);
}

/// CPU use while a benchmark runs, in average busy cores since construction: the whole machine's
/// (/proc/stat), this process's own (/proc/self/stat) and the rest of the machine's (machine − own). `other`
/// says whether a run was disturbed by other work; the load average does not (it read 0.8 here while a busy
/// loop and a scene run kept both cores busy). Counted in 10 ms ticks per core: unknown (−1) over fewer than
/// 100 ticks (about half a second on two cores), so a suite of short cases takes one reading for all of them.
class CpuMeter {
public:
    /// Starts measuring.
    CpuMeter();
    /// Busy cores since construction; all −1 when unknown (/proc unreadable or too short a time).
    struct Reading {
        double machine = -1; ///< all processes
        double own = -1;     ///< this process
        double other = -1;   ///< everything else (machine − own, at least 0)
    };
    /// The reading from construction until now.
    Reading read() const;

private:
    long long busyTicks_ = 0, totalTicks_ = -1, ownTicks_ = 0;
};

/// A number with `digits` digits after the point ("" for a negative value, meaning "no value").
std::string fixed(double v, int digits = 3);

/// A table of text cells: printed with aligned columns on stdout, or written as CSV.
struct Table {
    std::vector<std::string> header;            ///< column names
    std::vector<std::vector<std::string>> rows; ///< cells, one vector per row (same length as header)
};

/// Prints the table with right-aligned columns (first column left-aligned) to stdout.
void printTable(const Table& table);

/// Writes the table as CSV (fields with commas or quotes are quoted), creating the folder; prints the path.
/// Returns false (after printing why) when the file cannot be written.
bool writeCsv(const std::filesystem::path& path, const Table& table);

/// The rows of an earlier CSV at path with `columns` cells whose first cell (the label) is not `label`, so
/// that a before and an after run share one file.
std::vector<std::vector<std::string>> rowsOfOtherLabels(const std::filesystem::path& path,
                                                        const std::string& label, std::size_t columns);

/// Creates the results folder dir; false (after printing why on stderr) when it cannot be, e.g. when dir
/// names a file.
bool makeResultsDir(const std::filesystem::path& dir);

/// Draws DIR/<stem>.png with gnuplot (pngcairo, 900x600): `data` is written to a temporary data file and
/// `plot` is a gnuplot script in which $DATA names that file (e.g. "set logscale y\nplot $DATA u 1:2 w lp").
/// Prints where the plot is, or why it was skipped (no gnuplot, gnuplot failed); temporary files are removed.
void plotPng(const std::filesystem::path& dir, const std::string& stem, const std::string& data,
             const std::string& plot);

/// The repository's own models: assets/models/*.obj except the generated cubes (cube_*), sorted by path.
std::vector<std::filesystem::path> repoModels();

} // namespace rubble::bench
