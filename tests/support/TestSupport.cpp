#include "TestSupport.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>

#include "RubblePaths.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/MeshCheck.hpp"

namespace rubble::test {

std::filesystem::path sourceDir() {
    return generated::sourceDir;
}

std::filesystem::path tempDir(const std::string& name) {
    const auto dir = std::filesystem::path(generated::binaryDir) / "test-tmp" / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

std::optional<std::filesystem::path> seedMediaDir() {
    if (const char* env = std::getenv("RUBBLE_SEED_MEDIA"))
        if (std::filesystem::is_directory(env))
            return std::filesystem::path(env);
    for (const auto& candidate : {sourceDir() / ".." / "shared" / "seed" / "media",
                                  sourceDir() / ".." / ".." / "shared" / "seed" / "media"}) {
        if (std::filesystem::is_directory(candidate))
            return std::filesystem::canonical(candidate);
    }
    return std::nullopt;
}

std::filesystem::path writeFile(const std::filesystem::path& path, const std::string& text) {
    std::filesystem::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << text;
    return path;
}

std::string joinLines(const std::vector<std::string>& lines) {
    std::string s;
    for (const std::string& line : lines)
        s += line + "\n";
    return s;
}

bool mentions(const std::vector<std::string>& lines, const std::string& text) {
    for (const std::string& line : lines)
        if (line.find(text) != std::string::npos)
            return true;
    return false;
}

Vec3 surfacePoint(const Mesh& m, Rng& rng) {
    const auto t = static_cast<std::size_t>(rng.below(m.triangleCount()));
    double a = rng.uniform(), b = rng.uniform();
    if (a + b > 1) {
        a = 1 - a;
        b = 1 - b;
    }
    const auto c = m.corners(t);
    return c[0] + (c[1] - c[0]) * a + (c[2] - c[0]) * b;
}

Mesh unwelded(const Mesh& m, bool withAttributes) {
    Mesh out;
    for (std::size_t t = 0; t < m.triangles.size(); ++t) {
        const auto c = m.corners(t);
        const auto base = static_cast<std::uint32_t>(out.positions.size());
        out.positions.insert(out.positions.end(), c.begin(), c.end());
        out.triangles.push_back({base, base + 1, base + 2});
        if (!withAttributes)
            continue;
        const Vec3 n = normalized(m.triangleNormal(t));
        for (int k = 0; k < 3; ++k) {
            out.normals.emplace_back(n);
            out.uvs.push_back({c[k].x, c[k].y});
        }
        out.materials.push_back(static_cast<std::uint32_t>(t % 3));
    }
    if (withAttributes)
        out.materialNames = {"a", "b", "c"};
    return out;
}

double massError(const Mesh& mesh, const MassProperties& mass) {
    const MassProperties full = computeMassProperties(mesh);
    double e = std::abs(mass.volume - full.volume) / full.volume;
    e = std::max(e, length(mass.centerOfMass - full.centerOfMass) / mesh.bounds().diagonal());
    double d = 0, big = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            d = std::max(d, std::abs(mass.inertia.m[i][j] - full.inertia.m[i][j]));
            big = std::max(big, std::abs(full.inertia.m[i][j]));
        }
    return std::max(e, d / big);
}

::testing::AssertionResult closedAndOriented(const Mesh& m) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const Triangle& t : m.triangles)
        for (std::size_t c = 0; c < 3; ++c)
            ++directed[{t[c], t[(c + 1) % 3]}];
    for (const auto& [e, count] : directed) {
        if (count != 1)
            return ::testing::AssertionFailure()
                   << "edge " << e.first << "-" << e.second << " used " << count;
        if (!directed.count({e.second, e.first}))
            return ::testing::AssertionFailure() << "open edge " << e.first << "-" << e.second;
    }
    return ::testing::AssertionSuccess();
}

void expectSameSolid(const Mesh& before, const Mesh& after) {
    const MeshReport r = checkMesh(after);
    EXPECT_TRUE(r.closed);
    EXPECT_TRUE(r.oriented);
    EXPECT_EQ(r.degenerateTriangles, 0u);
    EXPECT_NEAR(signedVolume(after), signedVolume(before), 1e-9 * std::abs(signedVolume(before)));
}

std::vector<std::array<double, 9>> triangleSoup(const Mesh& m) {
    std::vector<std::array<double, 9>> out;
    out.reserve(m.triangles.size());
    for (const Triangle& t : m.triangles) {
        std::array<std::array<double, 3>, 3> c;
        for (int k = 0; k < 3; ++k) {
            const Vec3& p = m.positions[t[static_cast<std::size_t>(k)]];
            c[static_cast<std::size_t>(k)] = {p.x, p.y, p.z};
        }
        const auto first = std::min_element(c.begin(), c.end()) - c.begin();
        std::array<double, 9> row;
        for (int k = 0; k < 3; ++k)
            for (int d = 0; d < 3; ++d)
                row[static_cast<std::size_t>(3 * k + d)] =
                    c[static_cast<std::size_t>((first + k) % 3)][static_cast<std::size_t>(d)];
        out.push_back(row);
    }
    std::sort(out.begin(), out.end());
    return out;
}

double sweepScale() {
    const char* scale = std::getenv("RUBBLE_SWEEP_SCALE");
    const double f = scale ? std::atof(scale) : 1.0;
    return f > 0 ? f : 1.0;
}

std::vector<std::uint64_t> sweepSeeds(int count, std::vector<std::uint64_t> kept) {
    if (sweepScale() < 1)
        return kept;
    std::vector<std::uint64_t> all;
    for (int s = 1; s <= count; ++s)
        all.push_back(static_cast<std::uint64_t>(s));
    return all;
}

} // namespace rubble::test
