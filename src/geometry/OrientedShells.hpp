#pragma once
// Private to the core: one linear pass that both verifies that a mesh is closed and consistently oriented
// and labels its shells. The fracture pipeline runs it on every split output and reuses the labels for the
// islands, instead of verifying and labelling separately. Also the shells' nesting, which check, repair and
// fracture judge orientation by.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rubble/geometry/Mesh.hpp"

namespace rubble::detail {

/// When every triangle index is in range, no edge is a loop, and every directed edge appears exactly once
/// with its reverse exactly once: labels the shells exactly as labelShells does (when triangleShell is not
/// null) and returns their number. Otherwise returns -1. No hashing: per vertex, the sorted outgoing and
/// incoming neighbour lists must be equal and free of repeats, which pairs every half-edge with its twin.
std::int64_t closedOrientedShells(const Mesh& mesh, std::vector<std::uint32_t>* triangleShell);

/// Signed volume of each shell (its triangles in trisOf) and its nesting depth: how many of the other shells
/// contain it (ray parity from one of its triangles' centroid, against shells whose box holds its box and
/// differs from it). Only
/// shells with closed[i] set (all when closed is null) take part, and only they get a depth.
struct ShellNesting {
    std::vector<double> volume;
    std::vector<std::size_t> depth;
};
ShellNesting shellNesting(const Mesh& mesh, const std::vector<std::vector<std::size_t>>& trisOf,
                          const std::vector<bool>* closed = nullptr);

/// The shells facing the wrong way for their nesting (one inside an odd number of others must face inward,
/// any other outward), with up to maxListed of them described in listed. The mesh is closed, oriented and
/// finite, and shellOf labels its shells.
std::size_t misnestedShells(const Mesh& mesh, const std::vector<std::uint32_t>& shellOf, std::size_t shells,
                            std::size_t maxListed, std::vector<std::string>& listed);

} // namespace rubble::detail
