#include "rubble/geometry/MassProperties.hpp"

#include <Eigen/Eigenvalues>

namespace rubble {

// Each triangle (a,b,c) forms a tetrahedron with the reference. Covariance of the canonical tetrahedron is
// [[2,1,1],[1,2,1],[1,1,2]]/120 (Blow & Binstock).
void VolumeIntegrals::addRelative(const Vec3& a, const Vec3& b, const Vec3& c, double sign) {
    const double det = sign * dot(a, cross(b, c));
    volume += det / 6.0;
    first += (a + b + c) * (det / 24.0);
    const Vec3 s = a + b + c;
    const Vec3 cols[3] = {a, b, c};
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
            double sum = 0;
            for (const Vec3& v : cols)
                sum += v[i] * v[j];
            cov[i][j] += det / 120.0 * (sum + s[i] * s[j]);
        }
}

void VolumeIntegrals::accumulate(const VolumeIntegrals& o, double sign) {
    volume += sign * o.volume;
    first += o.first * sign;
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
            cov[i][j] += sign * o.cov[i][j];
}

VolumeIntegrals volumeIntegrals(const Mesh& mesh, const Vec3& reference) {
    VolumeIntegrals acc;
    acc.reference = reference;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        acc.add(mesh, t);
    return acc;
}

VolumeIntegrals volumeIntegrals(const Mesh& mesh) {
    return volumeIntegrals(mesh, mesh.positions.empty() ? Vec3{} : mesh.bounds().center());
}

double signedVolume(const Mesh& mesh) {
    const Vec3 r = mesh.positions.empty() ? Vec3{} : mesh.bounds().center();
    double v = 0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const auto c = mesh.corners(t);
        v += dot(c[0] - r, cross(c[1] - r, c[2] - r));
    }
    return v / 6.0;
}

MassProperties computeMassProperties(const Mesh& mesh) {
    if (mesh.triangles.empty())
        return {};
    return massProperties(volumeIntegrals(mesh));
}

MassProperties massProperties(const VolumeIntegrals& acc) {
    MassProperties mp;
    const Vec3& r = acc.reference;
    mp.volume = acc.volume;
    if (acc.volume == 0) {
        mp.centerOfMass = r;
        return mp;
    }
    const Vec3 com = acc.first / acc.volume; // relative to r
    mp.centerOfMass = com + r;
    // Covariance about the centre of mass, then inertia = trace(C)·I − C.
    double C[3][3];
    for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j) {
            C[i][j] = acc.cov[i][j] - acc.volume * com[i] * com[j];
            C[j][i] = C[i][j];
        }
    const double tr = C[0][0] + C[1][1] + C[2][2];
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            mp.inertia.m[i][j] = (i == j ? tr : 0.0) - C[i][j];

    Eigen::Matrix3d I;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            I(i, j) = mp.inertia.m[i][j];
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(I);
    Eigen::Matrix3d axes = solver.eigenvectors();
    if (axes.determinant() < 0)
        axes.col(2) = -axes.col(2);
    for (int i = 0; i < 3; ++i) {
        mp.principalMoments[i] = solver.eigenvalues()(i);
        for (int j = 0; j < 3; ++j)
            mp.principalAxes.m[i][j] = axes(i, j);
    }
    return mp;
}

} // namespace rubble
