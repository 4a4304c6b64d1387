// The Python module rubble._rubble (re-exported by rubble/__init__.py; typed in rubble/__init__.pyi): meshes
// as numpy arrays, checks, fracture with mass properties and convex parts, decomposition. Library errors
// become rubble.Error with the library's message; the GIL is released while the library works.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "rubble/collision/ConvexDecomposition.hpp"
#include "rubble/collision/DecomposeControl.hpp"
#include "rubble/collision/PartConcavity.hpp"
#include "rubble/core/ParameterCheck.hpp"
#include "rubble/core/ThreadPool.hpp"
#include "rubble/core/Version.hpp"
#include "rubble/fracture/Fracture.hpp"
#include "rubble/geometry/MassProperties.hpp"
#include "rubble/geometry/Mesh.hpp"
#include "rubble/geometry/MeshCheck.hpp"
#include "rubble/geometry/MeshRepair.hpp"
#include "rubble/io/MeshIO.hpp"
#include "rubble/runtime/Structure.hpp"
#include "rubble/structure/Material.hpp"

namespace py = pybind11;

namespace {

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;
using IndexArray = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;

/// A library error on its way to Python (becomes rubble.Error).
struct LibraryError {
    rubble::Error error;
};

template <class T>
T unwrap(rubble::Result<T> result) {
    if (!result)
        throw LibraryError{result.error()};
    return std::move(result).value();
}

void unwrap(const rubble::Status& status) {
    if (!status)
        throw LibraryError{status.error()};
}

/// An (n, columns) array copied from n records of `columns` numbers each: float64 for Vec3, float32 for the
/// mesh attributes (Vec3f, Vec2f).
template <class T, class Scalar = decltype(T::x)>
py::array_t<Scalar, py::array::c_style | py::array::forcecast> rows(const std::vector<T>& values,
                                                                    py::ssize_t columns) {
    static_assert(sizeof(T) % sizeof(Scalar) == 0);
    py::array_t<Scalar, py::array::c_style | py::array::forcecast> out(
        {static_cast<py::ssize_t>(values.size()), columns});
    if (!values.empty())
        std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(T));
    return out;
}

DoubleArray vec3(const rubble::Vec3& v) {
    DoubleArray out(3);
    auto d = out.mutable_unchecked<1>();
    d(0) = v.x;
    d(1) = v.y;
    d(2) = v.z;
    return out;
}

DoubleArray mat3(const rubble::Mat3& m) {
    DoubleArray out({3, 3});
    auto d = out.mutable_unchecked<2>();
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
            d(r, c) = m.m[r][c];
    return out;
}

/// An array of exactly `columns` columns (any number of rows), or ValueError naming `what`.
DoubleArray doubleRows(const py::object& input, py::ssize_t columns, const char* what) {
    DoubleArray a = DoubleArray::ensure(input);
    if (!a)
        throw py::value_error(std::string(what) + ": expected an array of numbers");
    if (a.ndim() != 2 || a.shape(1) != columns)
        throw py::value_error(std::string(what) + ": expected shape (n, " + std::to_string(columns) + ")");
    return a;
}

/// A length-3 vector, or ValueError naming `what`.
rubble::Vec3 toVec3(const py::object& input, const char* what) {
    DoubleArray a = DoubleArray::ensure(input);
    if (!a || a.ndim() != 1 || a.shape(0) != 3)
        throw py::value_error(std::string(what) + ": expected 3 numbers");
    return {a.at(0), a.at(1), a.at(2)};
}

template <class T>
std::vector<T> fromRows(const DoubleArray& a) {
    std::vector<T> out(static_cast<std::size_t>(a.shape(0)));
    if (!out.empty())
        std::memcpy(static_cast<void*>(out.data()), a.data(), out.size() * sizeof(T));
    return out;
}

/// Mesh attributes (stored in float) from rows of numbers; ValueError naming `what` beyond float's range.
template <class T>
std::vector<T> attributeRows(const py::object& input, py::ssize_t columns, const char* what) {
    const DoubleArray a = doubleRows(input, columns, what);
    static_assert(sizeof(T) % sizeof(float) == 0);
    std::vector<float> f(static_cast<std::size_t>(a.size()));
    for (std::size_t i = 0; i < f.size(); ++i) {
        const double v = a.data()[i];
        if (std::isfinite(v) && !(std::abs(v) <= std::numeric_limits<float>::max()))
            throw py::value_error(std::string(what) + ": " + std::to_string(v) + " is beyond float's range");
        f[i] = static_cast<float>(v);
    }
    std::vector<T> out(static_cast<std::size_t>(a.shape(0)));
    if (!f.empty())
        std::memcpy(static_cast<void*>(out.data()), f.data(), f.size() * sizeof(float));
    return out;
}

/// A Mesh from numpy arrays; triangles must be integers in range.
rubble::Mesh makeMesh(const py::object& vertices, const py::object& triangles, const py::object& materials,
                      const py::object& uvs, const py::object& normals) {
    rubble::Mesh mesh;
    mesh.positions = fromRows<rubble::Vec3>(doubleRows(vertices, 3, "vertices"));
    py::array raw = py::array::ensure(triangles);
    if (!raw || (raw.size() > 0 && raw.dtype().kind() != 'i' && raw.dtype().kind() != 'u'))
        throw py::value_error("triangles: expected an array of integers");
    IndexArray tri = IndexArray::ensure(raw);
    if (tri.ndim() != 2 || tri.shape(1) != 3) {
        if (!(tri.ndim() == 1 && tri.shape(0) == 0))
            throw py::value_error("triangles: expected shape (m, 3)");
    }
    const std::size_t m = tri.ndim() == 2 ? static_cast<std::size_t>(tri.shape(0)) : 0;
    mesh.triangles.resize(m);
    const std::int64_t* t = tri.data();
    for (std::size_t i = 0; i < 3 * m; ++i) {
        if (t[i] < 0 || t[i] >= static_cast<std::int64_t>(mesh.positions.size()))
            throw py::value_error("triangles: index " + std::to_string(t[i]) + " of triangle " +
                                  std::to_string(i / 3) + " is out of range (" +
                                  std::to_string(mesh.positions.size()) + " vertices)");
        mesh.triangles[i / 3][i % 3] = static_cast<std::uint32_t>(t[i]);
    }
    if (!materials.is_none())
        mesh.materials = materials.cast<std::vector<std::uint32_t>>();
    if (!uvs.is_none())
        mesh.uvs = attributeRows<rubble::Vec2f>(uvs, 2, "uvs");
    if (!normals.is_none())
        mesh.normals = attributeRows<rubble::Vec3f>(normals, 3, "normals");
    unwrap(mesh.validate());
    return mesh;
}

py::object materialsOf(const rubble::Mesh& mesh) {
    if (mesh.materials.empty())
        return py::none();
    return py::array_t<std::uint32_t>(static_cast<py::ssize_t>(mesh.materials.size()), mesh.materials.data());
}

py::object uvsOf(const rubble::Mesh& mesh) {
    return mesh.uvs.empty() ? py::object(py::none()) : rows(mesh.uvs, 2);
}

py::object normalsOf(const rubble::Mesh& mesh) {
    return mesh.normals.empty() ? py::object(py::none()) : rows(mesh.normals, 3);
}

py::array_t<std::uint32_t> trianglesOf(const rubble::Mesh& mesh) {
    py::array_t<std::uint32_t> out({static_cast<py::ssize_t>(mesh.triangles.size()), py::ssize_t{3}});
    if (!mesh.triangles.empty())
        std::memcpy(out.mutable_data(), mesh.triangles.data(),
                    mesh.triangles.size() * sizeof(rubble::Triangle));
    return out;
}

/// One piece of a fracture as Python sees it: a Mesh with its mass properties, cell and convex parts.
struct PyPiece : rubble::Mesh {
    rubble::MassProperties mass;
    std::int32_t cell = -1;
    std::vector<std::vector<rubble::Vec3>> convexParts; // corner points per part
    double concavity = -1;                              // of the convex parts; -1: not measured
};

py::list convexPartsOf(const std::vector<std::vector<rubble::Vec3>>& parts) {
    py::list out;
    for (const auto& points : parts)
        out.append(rows(points, 3));
    return out;
}

rubble::BooleanKind backendOf(const std::string& name) {
    if (name == "fast")
        return rubble::BooleanKind::Fast;
    if (name == "corefine")
        return rubble::BooleanKind::Corefine;
    if (name == "nef")
        return rubble::BooleanKind::Nef;
    throw py::value_error("backend: expected 'fast', 'corefine' or 'nef', got '" + name + "'");
}

rubble::CellPattern patternOf(const std::optional<std::string>& name, int cells) {
    if (!name)
        return cells > 1 ? rubble::CellPattern::Shatter : rubble::CellPattern::SingleCell;
    if (*name == "single")
        return rubble::CellPattern::SingleCell;
    if (*name == "shatter")
        return rubble::CellPattern::Shatter;
    if (*name == "adaptive")
        return rubble::CellPattern::Adaptive;
    throw py::value_error("pattern: expected 'single', 'shatter' or 'adaptive', got '" + *name + "'");
}

/// ValueError with the library's message when status is an error.
void valueCheck(const rubble::Status& status) {
    if (!status)
        throw py::value_error(status.message());
}

/// A Python int or float as a number checkParam can judge (ints beyond 64 bits become +-inf), or ValueError
/// with checkParam's message naming `name` when it is neither.
long double numberOf(const py::handle& value, const char* name) {
    if (PyLong_Check(value.ptr())) {
        int overflow = 0;
        const long long v = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
        if (overflow == 0)
            return static_cast<long double>(v);
        if (overflow > 0) {
            const unsigned long long u = PyLong_AsUnsignedLongLong(value.ptr());
            if (!PyErr_Occurred())
                return static_cast<long double>(u);
            PyErr_Clear();
        }
        const double d = PyLong_AsDouble(value.ptr()); // rounded, as the CLI reads the digits
        if (!PyErr_Occurred())
            return d;
        PyErr_Clear();
        return overflow > 0 ? HUGE_VALL : -HUGE_VALL;
    }
    if (PyFloat_Check(value.ptr()))
        return PyFloat_AsDouble(value.ptr());
    valueCheck(rubble::checkParamText(name, py::str(value).cast<std::string>()));
    return 0;
}

/// A checked parameter `name` given from Python (checkParam's range), as T.
template <class T>
T checkedParam(const py::handle& value, const char* name) {
    const long double v = numberOf(value, name);
    valueCheck(rubble::checkParam(name, v));
    return static_cast<T>(v);
}

/// A checked point or direction parameter `name` given from Python.
rubble::Vec3 checkedVector(const py::object& value, const char* name) {
    const rubble::Vec3 v = toVec3(value, name);
    valueCheck(rubble::checkParam(name, v));
    return v;
}

std::vector<PyPiece> fractureMesh(const rubble::Mesh& mesh, const py::object& point, const py::object& normal,
                                  const py::object& impulse, const py::object& cellsArg,
                                  const py::object& seedArg, const std::string& backend, bool convexParts,
                                  int maxParts, const std::optional<std::string>& pattern,
                                  const std::optional<std::string>& material,
                                  const std::optional<double>& roughness, const std::optional<double>& hurst,
                                  const std::optional<double>& featureSize) {
    rubble::Impact impact;
    impact.point = checkedVector(point, "point");
    impact.normal = checkedVector(normal, "normal");
    impact.impulse = checkedParam<double>(impulse, "impulse");
    const int cells = checkedParam<int>(cellsArg, "cells");
    const auto seed = checkedParam<std::uint64_t>(seedArg, "seed");
    valueCheck(rubble::checkParam("max_parts", maxParts));
    rubble::FractureParams params;
    params.backend = backendOf(backend);
    params.pattern = patternOf(pattern, cells);
    params.cells = cells;
    auto rough = rubble::chooseRoughness({material.value_or(""), roughness, hurst, featureSize});
    if (!rough)
        throw py::value_error(rough.error().message);
    params.roughness = *rough;
    std::vector<PyPiece> pieces;
    py::gil_scoped_release unlocked;
    rubble::FractureResult result = unwrap(rubble::fracture(mesh, impact, params, seed));
    std::vector<std::vector<rubble::ConvexPolytope>> parts;
    std::vector<double> concavity;
    if (convexParts) {
        rubble::DecompositionParams dp;
        dp.maxParts = maxParts;
        parts = rubble::updateDecomposition(unwrap(rubble::decompose(mesh, dp)).parts, result, dp);
        concavity = rubble::pieceConcavity(result, parts);
    }
    for (std::size_t i = 0; i < result.pieces.size(); ++i) {
        PyPiece& p = pieces.emplace_back();
        static_cast<rubble::Mesh&>(p) = std::move(result.pieces[i].mesh);
        p.mass = result.pieces[i].mass;
        p.cell = result.pieces[i].cell;
        p.concavity = i < concavity.size() ? concavity[i] : -1.0;
        if (i < parts.size())
            for (const rubble::ConvexPolytope& part : parts[i])
                p.convexParts.push_back(part.vertices());
    }
    return pieces;
}

/// Writes pieces as Rubble's engine-ready glTF: nodes (name, mesh, convex parts as point arrays) at their
/// centres of mass with mass properties in extras and "-convcolonly" children.
void writeGltfPieces(const std::filesystem::path& path, const py::list& nodes) {
    std::vector<rubble::GltfNode> out;
    for (const py::handle item : nodes) {
        const auto t = item.cast<py::tuple>();
        if (t.size() != 3)
            throw py::value_error("nodes: expected (name, mesh, convex_parts) tuples");
        rubble::GltfNode node;
        node.name = t[0].cast<std::string>();
        node.mesh = t[1].cast<rubble::Mesh>();
        const rubble::MassProperties mass = rubble::computeMassProperties(node.mesh);
        node.origin = mass.centerOfMass;
        node.extras = rubble::pieceExtras(mass, 1);
        for (const py::handle part : t[2].cast<py::list>()) {
            const DoubleArray points =
                doubleRows(py::reinterpret_borrow<py::object>(part), 3, "convex_parts");
            node.collision.push_back(unwrap(rubble::convexHull(fromRows<rubble::Vec3>(points))).toMesh());
        }
        out.push_back(std::move(node));
    }
    py::gil_scoped_release unlocked;
    unwrap(rubble::writeGltf(path, out));
}

py::list decomposeMesh(const rubble::Mesh& mesh, int maxParts, double concavity, const py::object& progress,
                       int threads) {
    valueCheck(rubble::checkParam("max_parts", maxParts));
    if (threads < 1 || threads > 256)
        throw py::value_error("threads must be in [1, 256], got " + std::to_string(threads));
    rubble::DecompositionParams params;
    params.maxParts = maxParts;
    params.concavity = concavity;
    // Between steps: Ctrl-C (KeyboardInterrupt) or an exception or False from progress(fraction) cancels;
    // the Python error is raised again once decompose has returned.
    std::optional<py::error_already_set> raised;
    rubble::DecomposeControl control;
    control.progress = [&](double fraction) {
        py::gil_scoped_acquire locked;
        if (PyErr_CheckSignals() != 0) {
            raised.emplace();
            return false;
        }
        if (progress.is_none())
            return true;
        try {
            const py::object answer = progress(fraction);
            const int truth = answer.is_none() ? 1 : PyObject_IsTrue(answer.ptr());
            if (truth < 0)
                raised.emplace();
            return truth == 1;
        } catch (py::error_already_set& e) {
            raised.emplace(std::move(e));
            return false;
        }
    };
    std::optional<rubble::ThreadPool> pool;
    if (threads > 1) {
        pool.emplace(threads - 1);
        control.jobs = &*pool;
    }
    std::vector<std::vector<rubble::Vec3>> parts;
    rubble::Result<rubble::Decomposition> d = rubble::makeError(rubble::ErrorCode::Cancelled, "");
    {
        py::gil_scoped_release unlocked;
        d = rubble::decompose(mesh, params, control);
    }
    if (raised)
        throw std::move(*raised);
    for (const rubble::ConvexPolytope& part : unwrap(std::move(d)).parts)
        parts.push_back(part.vertices());
    return convexPartsOf(parts);
}

} // namespace

/// A structure's settings from Python keywords (ValueError for a negative or non-finite one).
rubble::StructurePolicy structurePolicy(double bearingFriction, bool converged, double damageRadius,
                                        double damagePerImpulse) {
    for (const auto& [name, value] :
         {std::pair{"bearing_friction", bearingFriction}, std::pair{"damage_radius", damageRadius},
          std::pair{"damage_per_impulse", damagePerImpulse}})
        if (!(value >= 0) || !std::isfinite(value))
            throw py::value_error(std::string(name) + ": expected a finite number >= 0");
    rubble::StructurePolicy p;
    p.bearingFriction = bearingFriction;
    p.damageRadius = damageRadius;
    p.damagePerImpulse = damagePerImpulse;
    p.stress.method = converged ? rubble::StressMethod::Auto : rubble::StressMethod::SweepBudget;
    return p;
}

/// A length-3 vector of finite numbers, or ValueError naming `what`.
rubble::Vec3 finiteVec3(const py::object& input, const char* what) {
    const rubble::Vec3 v = toVec3(input, what);
    if (!rubble::isFinite(v))
        throw py::value_error(std::string(what) + ": expected finite numbers");
    return v;
}

/// A placement from a position and an optional (3, 3) rotation.
rubble::Frame placementOf(const py::object& position, const py::object& rotation) {
    rubble::Frame f{rubble::Mat3::identity(), finiteVec3(position, "position")};
    if (!rotation.is_none()) {
        const DoubleArray r = doubleRows(rotation, 3, "rotation");
        if (r.shape(0) != 3)
            throw py::value_error("rotation: expected shape (3, 3)");
        for (py::ssize_t i = 0; i < 3; ++i)
            for (py::ssize_t j = 0; j < 3; ++j)
                f.rotation.m[i][j] = r.at(i, j);
    }
    return f;
}

PYBIND11_MODULE(_rubble, m) {
    m.doc() =
        "Rubble: fracture closed meshes at an impact into pieces with mass properties and convex parts.";
    static py::exception<LibraryError> error(m, "Error", PyExc_RuntimeError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p)
                std::rethrow_exception(p);
        } catch (const LibraryError& e) {
            py::object instance = py::reinterpret_borrow<py::object>(error.ptr())(e.error.message);
            instance.attr("code") = rubble::toString(e.error.code);
            PyErr_SetObject(error.ptr(), instance.ptr());
        }
    });
    m.attr("INTERIOR_MATERIAL") = rubble::kInteriorMaterial;
    m.attr("__version__") = RUBBLE_VERSION_STRING;

    py::class_<rubble::Mesh>(m, "Mesh")
        .def(py::init(&makeMesh), py::arg("vertices"), py::arg("triangles"), py::kw_only(),
             py::arg("materials") = py::none(), py::arg("uvs") = py::none(), py::arg("normals") = py::none())
        .def_property_readonly("vertices", [](const rubble::Mesh& mesh) { return rows(mesh.positions, 3); })
        .def_property_readonly("triangles", &trianglesOf)
        .def_property_readonly("materials", &materialsOf)
        .def_property_readonly("uvs", &uvsOf)
        .def_property_readonly("normals", &normalsOf)
        .def_property_readonly("vertex_count", &rubble::Mesh::vertexCount)
        .def_property_readonly("triangle_count", &rubble::Mesh::triangleCount)
        .def_property_readonly("volume", [](const rubble::Mesh& mesh) { return rubble::signedVolume(mesh); })
        .def("hash", &rubble::Mesh::hash)
        .def("__eq__", [](const rubble::Mesh& a, const rubble::Mesh& b) { return a == b; })
        .def("__repr__", [](const rubble::Mesh& mesh) {
            return "<rubble.Mesh " + std::to_string(mesh.vertexCount()) + " vertices, " +
                   std::to_string(mesh.triangleCount()) + " triangles>";
        });

    py::class_<rubble::MeshReport>(m, "MeshReport")
        .def_property_readonly("valid", &rubble::MeshReport::valid)
        .def_readonly("closed", &rubble::MeshReport::closed)
        .def_property_readonly("manifold", &rubble::MeshReport::manifold)
        .def_readonly("oriented", &rubble::MeshReport::oriented)
        .def_readonly("outward", &rubble::MeshReport::outward)
        .def_readonly("boundary_edges", &rubble::MeshReport::boundaryEdges)
        .def_readonly("non_manifold_edges", &rubble::MeshReport::nonManifoldEdges)
        .def_readonly("degenerate_triangles", &rubble::MeshReport::degenerateTriangles)
        .def_readonly("self_intersections", &rubble::MeshReport::selfIntersections)
        .def_readonly("shells", &rubble::MeshReport::shells)
        .def_readonly("volume", &rubble::MeshReport::volume)
        .def_property_readonly("center_of_mass",
                               [](const rubble::MeshReport& r) { return vec3(r.centerOfMass); })
        .def_readonly("problems", &rubble::MeshReport::problems)
        .def("__repr__", [](const rubble::MeshReport& r) {
            return std::string("<rubble.MeshReport ") + (r.valid() ? "valid" : "invalid") + ", " +
                   std::to_string(r.problems.size()) + " problems>";
        });

    py::class_<PyPiece, rubble::Mesh>(m, "Piece")
        .def_property_readonly("volume", [](const PyPiece& p) { return p.mass.volume; })
        .def_property_readonly("center_of_mass", [](const PyPiece& p) { return vec3(p.mass.centerOfMass); })
        .def_property_readonly("inertia", [](const PyPiece& p) { return mat3(p.mass.inertia); })
        .def_property_readonly("principal_moments",
                               [](const PyPiece& p) { return vec3(p.mass.principalMoments); })
        .def_property_readonly("principal_axes", [](const PyPiece& p) { return mat3(p.mass.principalAxes); })
        .def_readonly("cell", &PyPiece::cell)
        .def_property_readonly("convex_parts", [](const PyPiece& p) { return convexPartsOf(p.convexParts); })
        .def_property_readonly("concavity",
                               [](const PyPiece& p) -> std::optional<double> {
                                   if (p.concavity < 0)
                                       return std::nullopt;
                                   return p.concavity;
                               })
        .def("__repr__", [](const PyPiece& p) {
            return "<rubble.Piece " + std::to_string(p.triangleCount()) + " triangles, volume " +
                   std::to_string(p.mass.volume) + ", cell " + std::to_string(p.cell) + ">";
        });

    py::class_<rubble::StructureBreak>(m, "StructureBreak")
        .def_readonly("step", &rubble::StructureBreak::frame)
        .def_readonly("a", &rubble::StructureBreak::a)
        .def_readonly("b", &rubble::StructureBreak::b)
        .def_property_readonly("position", [](const rubble::StructureBreak& k) { return vec3(k.position); })
        .def_property_readonly("normal", [](const rubble::StructureBreak& k) { return vec3(k.normal); })
        .def_readonly("area", &rubble::StructureBreak::area)
        .def_property_readonly("force", [](const rubble::StructureBreak& k) { return vec3(k.force); })
        .def_readonly("utilisation", &rubble::StructureBreak::utilisation)
        .def_readonly("damaged", &rubble::StructureBreak::damaged)
        .def_readonly("material_a", &rubble::StructureBreak::materialA)
        .def_readonly("material_b", &rubble::StructureBreak::materialB)
        .def("__repr__", [](const rubble::StructureBreak& k) {
            return "<rubble.StructureBreak " + std::to_string(k.a) + "-" + std::to_string(k.b) + ", step " +
                   std::to_string(k.frame) + (k.damaged ? ", damaged>" : ">");
        });
    py::class_<rubble::StructureCollapse>(m, "StructureCollapse")
        .def_readonly("step", &rubble::StructureCollapse::frame)
        .def_readonly("body", &rubble::StructureCollapse::body)
        .def_property_readonly("position",
                               [](const rubble::StructureCollapse& c) { return vec3(c.position); })
        .def_readonly("volume", &rubble::StructureCollapse::volume)
        .def_readonly("mass", &rubble::StructureCollapse::mass)
        .def_readonly("material", &rubble::StructureCollapse::material)
        .def("__repr__", [](const rubble::StructureCollapse& c) {
            return "<rubble.StructureCollapse body " + std::to_string(c.body) + ", step " +
                   std::to_string(c.frame) + ">";
        });
    py::class_<rubble::StructureStep>(m, "StructureStep")
        .def_readonly("breaks", &rubble::StructureStep::breaks)
        .def_readonly("collapses", &rubble::StructureStep::collapses)
        .def_readonly("residual", &rubble::StructureStep::residual)
        .def("__repr__", [](const rubble::StructureStep& s) {
            return "<rubble.StructureStep " + std::to_string(s.breaks.size()) + " breaks, " +
                   std::to_string(s.collapses.size()) + " collapses>";
        });
    py::class_<rubble::Structure>(m, "Structure")
        .def(py::init([](double friction, bool converged, double radius, double perImpulse) {
                 return rubble::Structure(structurePolicy(friction, converged, radius, perImpulse));
             }),
             py::kw_only(), py::arg("bearing_friction") = 0.6, py::arg("converged") = true,
             py::arg("damage_radius") = 1.0, py::arg("damage_per_impulse") = 1e-4)
        .def(
            "add",
            [](rubble::Structure& s, rubble::BodyId id, const rubble::Mesh& mesh, const std::string& material,
               bool root, const py::object& position, const py::object& rotation) {
                const rubble::Frame place = placementOf(position, rotation);
                py::gil_scoped_release unlocked;
                unwrap(s.add(id, mesh, place, material, root));
            },
            py::arg("id"), py::arg("mesh"), py::kw_only(), py::arg("material") = "", py::arg("root") = false,
            py::arg("position") = py::make_tuple(0.0, 0.0, 0.0), py::arg("rotation") = py::none())
        .def("remove", &rubble::Structure::remove, py::arg("id"))
        .def("__contains__", &rubble::Structure::contains)
        .def("__len__", &rubble::Structure::size)
        .def_property_readonly("bond_count", [](const rubble::Structure& s) { return s.bonds().size(); })
        .def(
            "add_load",
            [](rubble::Structure& s, rubble::BodyId id, const py::object& force, const py::object& point) {
                if (!s.contains(id))
                    throw py::value_error("id: no body " + std::to_string(id));
                s.addLoad(id, checkedVector(force, "force"), checkedVector(point, "point"));
            },
            py::arg("id"), py::arg("force"), py::arg("point"))
        .def(
            "damage",
            [](rubble::Structure& s, const py::object& point, const py::object& impulse) {
                s.damage(checkedVector(point, "point"), checkedParam<double>(impulse, "impulse"));
            },
            py::arg("point"), py::arg("impulse"))
        .def(
            "step",
            [](rubble::Structure& s, const py::object& gravity) {
                const rubble::Vec3 g = finiteVec3(gravity, "gravity");
                py::gil_scoped_release unlocked;
                return s.step(g);
            },
            py::arg("gravity") = py::make_tuple(0.0, -9.81, 0.0));

    m.def(
        "read_mesh",
        [](const std::filesystem::path& path) {
            py::gil_scoped_release unlocked;
            return unwrap(rubble::readMesh(path));
        },
        py::arg("path"), "Reads a mesh file (.obj, .off, .stl, .ply, .3ds, .gltf, .glb).");
    m.def(
        "write_obj",
        [](const std::filesystem::path& path, const rubble::Mesh& mesh) {
            py::gil_scoped_release unlocked;
            unwrap(rubble::writeObj(path, mesh));
        },
        py::arg("path"), py::arg("mesh"), "Writes a mesh as OBJ (and an MTL file when it has materials).");
    m.def(
        "write_gltf", &writeGltfPieces, py::arg("path"), py::arg("nodes"),
        "Writes (name, mesh, convex_parts) pieces as glTF: a node per piece at its centre of mass with mass "
        "properties in extras, its convex parts as '-convcolonly' children.");
    m.def(
        "box",
        [](const py::object& lo, const py::object& hi, int subdivisions) {
            if (subdivisions < 1 || subdivisions > 1000)
                throw py::value_error("subdivisions: expected 1..1000");
            return rubble::makeSubdividedBox(toVec3(lo, "lo"), toVec3(hi, "hi"), subdivisions);
        },
        py::arg("lo"), py::arg("hi"), py::arg("subdivisions") = 1,
        "A closed box from lo to hi, each face split into subdivisions x subdivisions squares.");
    m.def(
        "check",
        [](const rubble::Mesh& mesh) {
            py::gil_scoped_release unlocked;
            return rubble::checkMesh(mesh);
        },
        py::arg("mesh"), "Checks whether a mesh is a valid closed solid.");
    m.def(
        "repair",
        [](rubble::Mesh mesh) {
            py::gil_scoped_release unlocked;
            rubble::repairMesh(mesh);
            return mesh;
        },
        py::arg("mesh"),
        "A repaired copy (duplicate vertices, degenerate triangles, orientation, planar holes).");
    m.def("fracture", &fractureMesh, py::arg("mesh"), py::kw_only(), py::arg("point"),
          py::arg("normal") = py::make_tuple(0.0, 1.0, 0.0), py::arg("impulse") = 1.0, py::arg("cells") = 1,
          py::arg("seed") = 1, py::arg("backend") = "fast", py::arg("convex_parts") = true,
          py::arg("max_parts") = 24, py::arg("pattern") = py::none(), py::arg("material") = py::none(),
          py::arg("roughness") = py::none(), py::arg("hurst") = py::none(),
          py::arg("feature_size") = py::none(),
          "Breaks a closed mesh at an impact into pieces (by default cells > 1 is a shatter pattern of that "
          "many cells; pattern='adaptive' chips on a weak hit and shatters on a strong one; material= cuts "
          "with that material's rough cut faces, roughness= (amplitude) sets them by hand, 0 is flat).");
    m.def("decompose", &decomposeMesh, py::arg("mesh"), py::kw_only(), py::arg("max_parts") = 24,
          py::arg("concavity") = 0.02, py::arg("progress") = py::none(), py::arg("threads") = 1,
          "Convex parts of a closed mesh, each as its corner points. progress(fraction) is called between "
          "steps (non-decreasing, 1 last); returning False or raising cancels, as Ctrl-C does "
          "(KeyboardInterrupt). threads share the search; the parts do not depend on them.");
}
