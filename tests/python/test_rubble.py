"""The Python module: round trips, volume conservation, determinism, errors on bad input, and the typed stub.
Run by CTest (python_pytest) with PYTHONPATH=build/python and the interpreter the module was built for."""

import ast
import math
import pathlib
import re

import numpy as np
import pytest

import rubble

ROOT = pathlib.Path(__file__).resolve().parents[2]
CUBE = ROOT / "assets" / "models" / "cube_588.obj"


def tetrahedron():
    vertices = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float64)
    triangles = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]], dtype=np.int64)
    return vertices, triangles


def fracture_cube(**kwargs):
    args = dict(point=(0.3, 1.0, 0.2), normal=(0, 1, 0), impulse=40, seed=7)
    args.update(kwargs)
    return rubble.fracture(rubble.box((-1, -1, -1), (1, 1, 1), 7), **args)


# Round trips


def test_mesh_from_numpy_round_trips():
    vertices, triangles = tetrahedron()
    mesh = rubble.Mesh(vertices, triangles)
    assert mesh.vertex_count == 4 and mesh.triangle_count == 4
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.shape == (4, 3)
    assert mesh.triangles.dtype == np.uint32 and mesh.triangles.shape == (4, 3)
    np.testing.assert_array_equal(mesh.vertices, vertices)
    np.testing.assert_array_equal(mesh.triangles, triangles)
    assert mesh.materials is None and mesh.uvs is None and mesh.normals is None
    assert mesh.volume == pytest.approx(1 / 6, abs=1e-15)
    # Arrays are copies: changing them does not change the mesh.
    mesh.vertices[0, 0] = 99
    assert mesh.vertices[0, 0] == 0
    # Attributes too, and lists work as well as arrays.
    with_attributes = rubble.Mesh(
        vertices.tolist(), triangles.tolist(), materials=[1, 2, 3, 4], uvs=np.zeros((12, 2)), normals=np.ones((12, 3))
    )
    np.testing.assert_array_equal(with_attributes.materials, [1, 2, 3, 4])
    assert with_attributes.uvs.shape == (12, 2) and with_attributes.normals.shape == (12, 3)
    # Attributes are stored in float32: given in float64, they come back rounded.
    assert with_attributes.uvs.dtype == np.float32 and with_attributes.normals.dtype == np.float32
    tenths = rubble.Mesh(vertices, triangles, uvs=np.full((12, 2), 0.1))
    np.testing.assert_array_equal(tenths.uvs, np.full((12, 2), 0.1, dtype=np.float32))
    assert with_attributes != mesh and rubble.Mesh(vertices, triangles) == mesh
    assert rubble.Mesh(vertices, triangles).hash() == mesh.hash()


def test_obj_round_trip(tmp_path):
    mesh = rubble.box((-1, -2, -3), (1, 2, 3), 2)
    path = tmp_path / "box.obj"
    rubble.write_obj(path, mesh)
    back = rubble.read_mesh(str(path))
    np.testing.assert_array_equal(back.vertices, mesh.vertices)
    np.testing.assert_array_equal(back.triangles, mesh.triangles)
    assert back.volume == pytest.approx(48)


def test_piece_round_trips_through_mesh_and_obj(tmp_path):
    piece = fracture_cube()[1]
    again = rubble.Mesh(piece.vertices, piece.triangles, materials=piece.materials, uvs=piece.uvs, normals=piece.normals)
    assert again == piece and again.hash() == piece.hash()
    path = tmp_path / "piece.obj"
    rubble.write_obj(path, piece)
    back = rubble.read_mesh(path)
    np.testing.assert_array_equal(back.vertices, piece.vertices)
    np.testing.assert_array_equal(back.triangles, piece.triangles)
    assert rubble.check(back).valid


# Checks


def test_check_reports_valid_and_open_meshes():
    vertices, triangles = tetrahedron()
    report = rubble.check(rubble.Mesh(vertices, triangles))
    assert report.valid and report.closed and report.manifold and report.oriented and report.outward
    assert report.problems == [] and report.volume == pytest.approx(1 / 6)
    np.testing.assert_allclose(report.center_of_mass, [0.25, 0.25, 0.25])
    open_report = rubble.check(rubble.Mesh(vertices, triangles[:3]))
    assert not open_report.valid and not open_report.closed
    assert open_report.boundary_edges == 3 and open_report.problems


def test_repair_turns_an_inward_mesh_outward():
    vertices, triangles = tetrahedron()
    inward = rubble.Mesh(vertices, triangles[:, ::-1])
    assert not rubble.check(inward).outward
    repaired = rubble.repair(inward)
    assert rubble.check(repaired).valid and repaired.volume == pytest.approx(1 / 6)


# Fracture: volume, closed pieces, materials, mass properties, convex parts


def test_fracture_conserves_volume_and_gives_closed_pieces():
    pieces = fracture_cube()
    assert len(pieces) >= 2
    assert sum(p.volume for p in pieces) == pytest.approx(8, rel=1e-9)
    assert {p.cell for p in pieces} >= {-1, 0}
    interior = 0
    for p in pieces:
        assert isinstance(p, rubble.Mesh) and rubble.check(p).valid
        assert rubble.Mesh(p.vertices, p.triangles).volume == pytest.approx(p.volume, rel=1e-9)
        assert p.vertices.shape[1] == 3 and p.triangles.shape[1] == 3
        assert p.materials.shape == (p.triangles.shape[0],)
        assert p.uvs.shape == (3 * p.triangles.shape[0], 2)
        interior += int(np.count_nonzero(p.materials == rubble.INTERIOR_MATERIAL))
    assert interior > 0


def test_mass_properties_of_pieces():
    for p in fracture_cube():
        # The centre of mass is the volume-weighted mean of the tetrahedra from the origin.
        v = p.vertices[p.triangles]
        signed = np.einsum("ij,ij->i", v[:, 0], np.cross(v[:, 1], v[:, 2])) / 6
        centroid = (signed[:, None] * v.sum(axis=1) / 4).sum(axis=0) / signed.sum()
        np.testing.assert_allclose(p.center_of_mass, centroid, atol=1e-9)
        assert p.inertia.shape == (3, 3)
        np.testing.assert_allclose(p.inertia, p.inertia.T, atol=1e-12)
        np.testing.assert_allclose(np.linalg.eigvalsh(p.inertia), p.principal_moments, rtol=1e-6, atol=1e-12)
        axes = p.principal_axes
        np.testing.assert_allclose(axes.T @ axes, np.eye(3), atol=1e-9)


def test_convex_parts_cover_each_piece():
    for p in fracture_cube(max_parts=8):
        assert 1 <= len(p.convex_parts) <= 8
        for part in p.convex_parts:
            assert part.ndim == 2 and part.shape[1] == 3 and part.shape[0] >= 4
            assert np.all(np.abs(part) <= 1 + 1e-9)
    assert all(p.convex_parts == [] for p in fracture_cube(convex_parts=False))


def test_each_piece_reports_the_concavity_of_its_parts():
    # A piece of a cube is convex or a cube with a bite: its parts stray at most a few % of its diagonal.
    pieces = fracture_cube(max_parts=8)
    assert all(p.concavity is not None and 0 <= p.concavity < 0.05 for p in pieces), [p.concavity for p in pieces]
    # A single part for a bitten remainder covers the bite: its concavity is the bite's depth.
    bitten = [p for p in fracture_cube(max_parts=1) if p.cell < 0]
    assert bitten and max(p.concavity for p in bitten) > 0.01, [p.concavity for p in bitten]
    assert all(p.concavity is None for p in fracture_cube(convex_parts=False))


def test_shatter_and_backends_conserve_volume():
    for backend in ("fast", "corefine"):
        pieces = fracture_cube(cells=4, backend=backend)
        assert len(pieces) >= 3
        assert sum(p.volume for p in pieces) == pytest.approx(8, rel=1e-9)
        assert max(p.cell for p in pieces) >= 1


def test_adaptive_pattern_chips_weak_hits_and_shatters_strong_ones():
    cube = rubble.box((-1, -1, -1), (1, 1, 1))
    weak = rubble.fracture(cube, point=(0, 1, 0), impulse=10, cells=8, pattern="adaptive", convex_parts=False)
    strong = rubble.fracture(cube, point=(0, 1, 0), impulse=2000, cells=8, pattern="adaptive", convex_parts=False)
    assert max(p.cell for p in weak) == 0, "one cell"
    assert max(p.cell for p in strong) >= 3, "a shatter"
    for pieces in (weak, strong):
        assert sum(p.volume for p in pieces) == pytest.approx(8, rel=1e-9)
    single = rubble.fracture(cube, point=(0, 1, 0), impulse=2000, cells=8, pattern="single", convex_parts=False)
    assert max(p.cell for p in single) == 0
    with pytest.raises(ValueError, match="pattern"):
        rubble.fracture(cube, point=(0, 1, 0), pattern="voxel")


def test_fracture_of_a_file():
    mesh = rubble.read_mesh(CUBE)
    pieces = rubble.fracture(mesh, point=(0.3, 1, 0.2), impulse=40, seed=2)
    assert sum(p.volume for p in pieces) == pytest.approx(mesh.volume, rel=1e-9)


def test_decompose():
    parts = rubble.decompose(rubble.box((0, 0, 0), (1, 2, 3)), max_parts=4)
    assert len(parts) == 1  # a convex mesh is one part
    np.testing.assert_allclose(np.sort(np.unique(parts[0], axis=0), axis=0).min(axis=0), [0, 0, 0])
    np.testing.assert_allclose(parts[0].max(axis=0), [1, 2, 3])
    torus_like = rubble.read_mesh(ROOT / "assets" / "models" / "building.obj")
    assert 1 < len(rubble.decompose(torus_like, max_parts=6)) <= 6


def test_decompose_progress_cancel_and_threads():
    building = rubble.read_mesh(ROOT / "assets" / "models" / "building.obj")
    seen = []
    parts = rubble.decompose(building, max_parts=6, progress=seen.append)
    assert seen and seen[-1] == 1 and all(0 < a < b for a, b in zip(seen, seen[1:]))
    same = rubble.decompose(building, max_parts=6, threads=2)
    assert len(same) == len(parts) and all(np.array_equal(a, b) for a, b in zip(parts, same))
    with pytest.raises(rubble.Error, match="cancelled"):
        rubble.decompose(building, max_parts=6, progress=lambda f: False)

    def interrupt(fraction):
        raise KeyboardInterrupt  # as Ctrl-C in the middle of a decomposition

    with pytest.raises(KeyboardInterrupt):
        rubble.decompose(building, max_parts=6, progress=interrupt)
    with pytest.raises(ValueError, match="threads"):
        rubble.decompose(building, threads=0)


# Determinism


def test_same_seed_same_pieces_other_seed_other_pieces():
    a, b, c = fracture_cube(seed=11), fracture_cube(seed=11), fracture_cube(seed=12)
    assert [p.hash() for p in a] == [p.hash() for p in b]
    for p, q in zip(a, b):
        np.testing.assert_array_equal(p.vertices, q.vertices)
        np.testing.assert_array_equal(p.triangles, q.triangles)
    assert [p.hash() for p in a] != [p.hash() for p in c]


def test_rough_cut_faces_by_material_or_by_hand():
    flat = fracture_cube(seed=11)
    rough = fracture_cube(seed=11, material="concrete")
    assert sum(p.volume for p in rough) == pytest.approx(8, rel=1e-9)
    assert all(rubble.check(p).valid for p in rough)
    assert sum(len(p.triangles) for p in rough) > sum(len(p.triangles) for p in flat)
    assert [p.hash() for p in fracture_cube(seed=11, material="concrete", roughness=0)] == [p.hash() for p in flat]
    by_hand = fracture_cube(seed=11, roughness=0.1, hurst=0.5, feature_size=0.3)
    assert [p.hash() for p in by_hand] != [p.hash() for p in rough]
    with pytest.raises(ValueError, match="hurst"):
        fracture_cube(roughness=0.1, hurst=2.0)
    with pytest.raises(ValueError, match="material"):
        fracture_cube(material="cheese")


# Errors


def test_errors_carry_the_library_message_and_code(tmp_path):
    missing = tmp_path / "missing.obj"
    with pytest.raises(rubble.Error) as info:
        rubble.read_mesh(missing)
    assert info.value.code == "io error" and "missing.obj" in str(info.value)
    assert isinstance(info.value, RuntimeError)

    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(rubble.Error) as info:
        rubble.read_mesh(bad)
    assert info.value.code == "parse error" and "bad.obj:4" in str(info.value)

    vertices, triangles = tetrahedron()
    with pytest.raises(rubble.Error) as info:
        rubble.fracture(rubble.Mesh(vertices, triangles[:3]), point=(0.1, 0.1, 0.1))
    assert info.value.code == "invalid input"

    with pytest.raises(rubble.Error) as info:
        fracture_cube(point=(50, 50, 50))
    assert info.value.code == "no intersection"


def test_bad_arrays_and_arguments_raise_value_errors():
    vertices, triangles = tetrahedron()
    with pytest.raises(ValueError, match="vertices"):
        rubble.Mesh(vertices[:, :2], triangles)
    with pytest.raises(ValueError, match="out of range"):
        rubble.Mesh(vertices, triangles + 1)
    with pytest.raises(ValueError, match="out of range"):
        rubble.Mesh(vertices, -triangles - 1)
    with pytest.raises(ValueError, match="integers"):
        rubble.Mesh(vertices, triangles.astype(np.float64))
    with pytest.raises(ValueError, match="triangles"):
        rubble.Mesh(vertices, triangles.reshape(-1))
    with pytest.raises(ValueError, match="uvs"):
        rubble.Mesh(vertices, triangles, uvs=np.zeros((12, 3)))
    with pytest.raises(ValueError, match="normals: .* beyond float's range"):
        rubble.Mesh(vertices, triangles, normals=np.full((12, 3), 1e39))
    with pytest.raises(rubble.Error):  # attribute arrays of the wrong length
        rubble.Mesh(vertices, triangles, materials=[1, 2])
    bad = vertices.copy()
    bad[1, 1] = math.nan
    with pytest.raises(rubble.Error) as info:
        rubble.Mesh(bad, triangles)
    assert info.value.code == "invalid input"
    cube = rubble.box((-1, -1, -1), (1, 1, 1))
    with pytest.raises(ValueError, match="backend"):
        rubble.fracture(cube, point=(0, 1, 0), backend="quantum")
    with pytest.raises(ValueError, match="point"):
        rubble.fracture(cube, point=(0, 1))
    with pytest.raises(ValueError, match="cells"):
        rubble.fracture(cube, point=(0, 1, 0), cells=0)
    with pytest.raises(TypeError):
        rubble.fracture(cube, (0, 1, 0))  # point is keyword-only


# The stub names what the module has, with the same parameters


def _stub():
    return ast.parse((pathlib.Path(rubble.__file__).parent / "__init__.pyi").read_text())


def _parameters(signature):
    """(positional, keyword-only) parameter names of a pybind11 signature line, without self."""
    inside = signature[signature.index("(") + 1 : signature.rindex(") ->")]
    names, depth, start = [], 0, 0
    for i, ch in enumerate(inside + ","):
        if ch in "([{":
            depth += 1
        elif ch in ")]}":
            depth -= 1
        if ch == "," and depth == 0:
            names.append(re.match(r"\s*(\*|\w+)", inside[start:i]).group(1))
            start = i + 1
    names = [n for n in names if n != "self"]
    star = names.index("*") if "*" in names else len(names)
    return names[:star], names[star + 1 :]


def _stub_parameters(function):
    return [a.arg for a in function.args.args if a.arg != "self"], [a.arg for a in function.args.kwonlyargs]


def test_stub_ships_and_matches_the_module():
    tree = _stub()
    assert (pathlib.Path(rubble.__file__).parent / "py.typed").exists()
    stub_names = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    stub_names |= {n.target.id for n in tree.body if isinstance(n, ast.AnnAssign) and not n.target.id.startswith("_")}
    public = {n for n in dir(rubble) if not n.startswith("_") and not isinstance(getattr(rubble, n), type(rubble))}
    assert stub_names == public == set(rubble.__all__)
    for node in tree.body:
        if isinstance(node, ast.FunctionDef):
            signature = getattr(rubble, node.name).__doc__.splitlines()[0]
            assert _stub_parameters(node) == _parameters(signature), (node.name, signature)
        if isinstance(node, ast.ClassDef) and node.name != "Error":
            cls = getattr(rubble, node.name)
            assert [b.__name__ for b in cls.__bases__] == [b.id for b in node.bases] or not node.bases, node.name
            members = {m.name: m for m in node.body if isinstance(m, ast.FunctionDef)}
            inherited = {m for b in cls.__bases__ for m in dir(b) if not m.startswith("_")}
            public_members = {m for m in dir(cls) if not m.startswith("_")}
            assert public_members == {m for m in set(members) | inherited if not m.startswith("_")}, node.name
            if "__init__" in members:
                signature = cls.__init__.__doc__.splitlines()[0]
                assert _stub_parameters(members["__init__"]) == _parameters(signature), (node.name, signature)
