#pragma once
/// \file Mesh.hpp
/// The triangle mesh value type every Rubble module works on.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rubble/core/Aabb.hpp"
#include "rubble/core/Export.hpp"
#include "rubble/core/Result.hpp"
#include "rubble/core/Vec3.hpp"

namespace rubble {

/// Index of a triangle's three corners in Mesh::positions, counter-clockwise seen from outside.
using Triangle = std::array<std::uint32_t, 3>;

/// Material id given to faces created by a cut (the interior of an object).
inline constexpr std::uint32_t kInteriorMaterial = 0xFFFF'FFFEu;

/// A triangle mesh as a value type: copy it, compare it, hash it.
///
/// Attributes are optional. When present, `normals` and `uvs` hold one entry per triangle corner
/// (index 3*t + c, in float) and `materials` one entry per triangle; an empty vector means "not present".
struct RUBBLE_API Mesh {
    std::vector<Vec3> positions;            ///< vertex positions
    std::vector<Triangle> triangles;        ///< triangles as indices into positions
    std::vector<Vec3f> normals;             ///< per-corner normals (3 per triangle) or empty
    std::vector<Vec2f> uvs;                 ///< per-corner texture coordinates (3 per triangle) or empty
    std::vector<std::uint32_t> materials;   ///< per-triangle material id or empty
    std::vector<std::string> materialNames; ///< optional names for material ids (index = id)

    /// Number of vertices.
    std::size_t vertexCount() const { return positions.size(); }
    /// Number of triangles.
    std::size_t triangleCount() const { return triangles.size(); }
    /// True when the mesh has no triangles.
    bool empty() const { return triangles.empty(); }
    /// True when per-corner normals are present.
    bool hasNormals() const { return !normals.empty(); }
    /// True when per-corner texture coordinates are present.
    bool hasUvs() const { return !uvs.empty(); }
    /// True when per-triangle material ids are present.
    bool hasMaterials() const { return !materials.empty(); }

    /// Bounding box of all vertices referenced or not.
    Aabb bounds() const;
    /// Corner positions of triangle t.
    std::array<Vec3, 3> corners(std::size_t t) const {
        const Triangle& tri = triangles[t];
        return {positions[tri[0]], positions[tri[1]], positions[tri[2]]};
    }
    /// Area-weighted normal of triangle t (length = twice the area).
    Vec3 triangleNormal(std::size_t t) const;
    /// Material of triangle t (0 when materials are absent).
    std::uint32_t material(std::size_t t) const { return materials.empty() ? 0u : materials[t]; }

    /// Checks that indices are in range, coordinates finite and attribute sizes consistent.
    Status validate() const;
    /// Appends another mesh (its indices shifted), keeping attributes consistent.
    void append(const Mesh& other);
    /// Maps every position p to rotation * (scale ⊙ p) + translation in place; normals follow (and a
    /// mirroring scale swaps two corners of every triangle so that it stays outward).
    void transform(const Mat3& rotation, const Vec3& scale, const Vec3& translation);
    /// A copy transformed as by transform().
    Mesh transformed(const Mat3& rotation, const Vec3& scale, const Vec3& translation) const;
    /// A copy translated by t.
    Mesh translated(const Vec3& t) const;
    /// Flat per-corner normals computed from the triangles.
    void computeFlatNormals();
    /// Removes vertices that no triangle references (indices are remapped).
    void removeUnreferencedVertices();
    /// A 64-bit content hash of positions, triangles and attributes (stable across runs and platforms).
    std::uint64_t hash() const;
    /// Exact equality of all arrays.
    bool operator==(const Mesh&) const = default;
};

/// The generalized winding number of a closed mesh around p (1 inside an outward solid, 0 outside; the sum of
/// the triangles' signed solid angles over 4π).
RUBBLE_API double windingNumber(const Mesh& mesh, const Vec3& p);
/// Distance from p to the nearest point on any triangle of mesh (infinity for an empty mesh).
RUBBLE_API double distanceToSurface(const Mesh& mesh, const Vec3& p);

/// An axis-aligned box mesh from lo to hi with 12 triangles, outward oriented.
RUBBLE_API Mesh makeBox(const Vec3& lo, const Vec3& hi);
/// A box from lo to hi whose faces are each split into an n×n grid (12·n² triangles), like the seed's
/// cube_N.obj.
RUBBLE_API Mesh makeSubdividedBox(const Vec3& lo, const Vec3& hi, int n);
/// A UV sphere of radius r with the given numbers of slices and stacks, outward oriented.
RUBBLE_API Mesh makeSphere(const Vec3& center, double r, int slices, int stacks);
/// A torus in the xz-plane with major radius R and minor radius r.
RUBBLE_API Mesh makeTorus(const Vec3& center, double R, double r, int majorSegments, int minorSegments);

} // namespace rubble
