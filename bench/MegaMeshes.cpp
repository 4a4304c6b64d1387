#include "MegaMeshes.hpp"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <stdexcept>

#include "rubble/core/Random.hpp"
#include "rubble/io/MeshIO.hpp"

namespace rubble::bench {

Mesh subdivideTriangles(const Mesh& mesh, int n) {
    if (n <= 1)
        return mesh;
    Mesh out;
    out.positions = mesh.positions;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> edgeStart; // first point of an edge
    // Point k (1..n-1) of the edge from a to b, the same for the edge from b to a.
    auto edgePoint = [&](std::uint32_t a, std::uint32_t b, int k) {
        const bool flip = b < a;
        const std::uint32_t lo = flip ? b : a, hi = flip ? a : b;
        auto [it, fresh] = edgeStart.try_emplace({lo, hi}, static_cast<std::uint32_t>(out.positions.size()));
        if (fresh)
            for (int s = 1; s < n; ++s)
                out.positions.push_back(mesh.positions[lo] +
                                        (mesh.positions[hi] - mesh.positions[lo]) * (double(s) / n));
        return it->second + static_cast<std::uint32_t>((flip ? n - k : k) - 1);
    };
    std::vector<std::uint32_t> grid;
    for (const Triangle& t : mesh.triangles) {
        const Vec3 a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
        // grid point (i, j): a + (b - a) i/n + (c - a) j/n, i + j <= n
        grid.assign(static_cast<std::size_t>((n + 1) * (n + 1)), 0);
        auto at = [&](int i, int j) -> std::uint32_t& {
            return grid[static_cast<std::size_t>(i * (n + 1) + j)];
        };
        for (int i = 0; i <= n; ++i)
            for (int j = 0; i + j <= n; ++j) {
                if (i == 0 && j == 0)
                    at(i, j) = t[0];
                else if (i == n)
                    at(i, j) = t[1];
                else if (j == n)
                    at(i, j) = t[2];
                else if (j == 0)
                    at(i, j) = edgePoint(t[0], t[1], i);
                else if (i == 0)
                    at(i, j) = edgePoint(t[0], t[2], j);
                else if (i + j == n)
                    at(i, j) = edgePoint(t[1], t[2], j);
                else {
                    at(i, j) = static_cast<std::uint32_t>(out.positions.size());
                    out.positions.push_back(a + (b - a) * (double(i) / n) + (c - a) * (double(j) / n));
                }
            }
        for (int i = 0; i < n; ++i)
            for (int j = 0; i + j < n; ++j) {
                out.triangles.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
                if (i + j + 2 <= n)
                    out.triangles.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
            }
    }
    return out;
}

Mesh withFlatAttributes(Mesh m) {
    m.computeFlatNormals();
    m.uvs.reserve(3 * m.triangles.size());
    for (const Triangle& t : m.triangles)
        for (std::uint32_t v : t)
            m.uvs.push_back({m.positions[v].x, m.positions[v].z});
    return m;
}

Mesh megaMesh(const std::string& kind, std::size_t triangles) {
    const double t = static_cast<double>(triangles);
    if (kind == "sphere") { // 2 · slices · (stacks − 1) triangles, slices = 2 · stacks
        const int stacks = static_cast<int>(std::lround(std::sqrt(t / 4))) + 1;
        const int slices = static_cast<int>(std::lround(t / (2.0 * (stacks - 1))));
        return makeSphere({0, 0, 0}, 1.0, slices, stacks);
    }
    if (kind == "blob" || kind == "bumpy") { // organic: the geodesic sphere displaced along its radius
        Mesh m = megaMesh("geosphere", triangles);
        Rng rng(7);
        std::vector<Vec3> lobes;
        std::vector<double> reach, width;
        for (int k = 0; k < 7; ++k) {
            lobes.push_back(rng.unitVector());
            reach.push_back(rng.uniform(0.4, 1.0));
            width.push_back(rng.uniform(0.04, 0.12));
        }
        for (Vec3& p : m.positions) {
            double r = 1;
            if (kind == "blob") { // a body with seven limbs of Gaussian profile
                r = 0.7;
                for (std::size_t k = 0; k < lobes.size(); ++k)
                    r += reach[k] * std::exp(-(1 - dot(p, lobes[k])) / width[k]);
            } else { // a potato: smooth bumps of about a tenth of the radius
                r += 0.12 * std::sin(5 * p.x + 1) * std::sin(4 * p.y + 2) * std::sin(6 * p.z) +
                     0.06 * std::sin(11 * p.x + 13 * p.y);
            }
            p = p * r;
        }
        return m;
    }
    if (kind == "geosphere") { // an icosahedron's 20 faces split n² each, on the sphere: even density
        const double g = (1 + std::sqrt(5.0)) / 2;
        Mesh ico;
        ico.positions = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
        ico.triangles = {{0, 11, 5},  {0, 5, 1},  {0, 1, 7},  {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                         {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                         {3, 8, 9},   {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
        Mesh m = subdivideTriangles(ico, std::max(1, static_cast<int>(std::lround(std::sqrt(t / 20)))));
        for (Vec3& p : m.positions)
            p = p / length(p);
        return m;
    }
    if (kind == "torus") { // 2 · major · minor triangles, major = 3 · minor
        const int minor = static_cast<int>(std::lround(std::sqrt(t / 6)));
        const int major = static_cast<int>(std::lround(t / (2.0 * minor)));
        return makeTorus({0, 0, 0}, 1.0, 0.3, major, minor);
    }
    if (kind == "arch") {
        auto arch = readMesh(sourceDir() / "assets/models/arch.obj");
        if (!arch)
            throw std::runtime_error(arch.error().message);
        Mesh m = std::move(arch.value());
        const int n = std::max(
            1, static_cast<int>(std::lround(std::sqrt(t / static_cast<double>(m.triangles.size())))));
        Mesh plain;
        plain.positions = m.positions;
        plain.triangles = m.triangles;
        return subdivideTriangles(plain, n);
    }
    throw std::invalid_argument("megaMesh: unknown kind " + kind);
}

int writeMegaMeshes(const MegaArgs& args, const std::string& dir) {
    std::filesystem::create_directories(dir);
    for (const std::string& kind : args.kinds)
        for (std::size_t size : args.sizes) {
            const Mesh mesh = megaMesh(kind, size);
            const auto path =
                std::filesystem::path(dir) / (kind + "_" + std::to_string(mesh.triangles.size()) + ".obj");
            if (const Status s = writeObj(path, mesh); !s) {
                std::cerr << s.message() << "\n";
                return 1;
            }
            std::cout << path.string() << "\n";
        }
    return 0;
}

} // namespace rubble::bench
