#pragma once
// Helpers shared by Rubble's tests.

#include <gtest/gtest.h>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "rubble/core/Random.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"

namespace rubble::test {

/// The repository root (for assets/ and tests/data/).
std::filesystem::path sourceDir();
/// A fresh, empty temporary directory for one test (removed at process exit is not guaranteed).
std::filesystem::path tempDir(const std::string& name);
/// The thesis's media folder (../shared/seed/media) when present; tests using it call GTEST_SKIP otherwise.
std::optional<std::filesystem::path> seedMediaDir();
/// Writes text to a file, returning its path.
std::filesystem::path writeFile(const std::filesystem::path& path, const std::string& text);
/// The lines joined with newlines (for failure messages listing problems).
std::string joinLines(const std::vector<std::string>& lines);
/// True when some line contains text.
bool mentions(const std::vector<std::string>& lines, const std::string& text);
/// Every triangle gets its own three vertices (a "triangle soup", as some exporters write); with attributes,
/// also per-corner normals (the face normal), UVs (x, y) and three materials "a", "b", "c" in turn.
Mesh unwelded(const Mesh& m, bool withAttributes = false);
/// EXPECTs that after is closed, consistently oriented, without degenerate triangles, and encloses before's
/// volume (relative 1e-9): the contract of a lossless mesh operation.
void expectSameSolid(const Mesh& before, const Mesh& after);
/// A random point on the surface: a random triangle, a uniform point in it.
Vec3 surfacePoint(const Mesh& m, Rng& rng);
/// Closed, edge-manifold and consistently oriented: every directed edge once, and its reverse once (for
/// EXPECT_TRUE; the failure names the first bad edge).
::testing::AssertionResult closedAndOriented(const Mesh& m);
/// The mesh's triangles as corner coordinates, each rotated to start at its smallest corner, sorted: equal
/// for two meshes with the same triangles whatever their numbering.
std::vector<std::array<double, 9>> triangleSoup(const Mesh& m);
/// Largest relative deviation of mass from a full recomputation of mesh: volume against volume, centre of
/// mass against the bounds' diagonal, inertia against its largest entry.
double massError(const Mesh& mesh, const MassProperties& mass);

/// RUBBLE_SWEEP_SCALE (1 unless set; the sanitizer runs set 0.1): the share of a long sweep a run makes.
double sweepScale();
/// Seeds 1..count, or only `kept` (the regressions a sweep must always replay) when sweepScale() < 1.
std::vector<std::uint64_t> sweepSeeds(int count, std::vector<std::uint64_t> kept);

} // namespace rubble::test

/// Skips the current test when the seed media folder is absent (as in a user's clone).
#define RUBBLE_REQUIRE_SEED_MEDIA(var)                                                                       \
    auto var##_opt = ::rubble::test::seedMediaDir();                                                         \
    if (!var##_opt)                                                                                          \
        GTEST_SKIP() << "../shared/seed/media is absent";                                                    \
    const std::filesystem::path var = *var##_opt
