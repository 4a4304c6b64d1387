"""Typed interface of the rubble module (pybind11 extension rubble._rubble)."""

import os
from typing import Callable, Literal, Sequence

import numpy as np
import numpy.typing as npt

__all__ = [
    "INTERIOR_MATERIAL",
    "Error",
    "Mesh",
    "MeshReport",
    "Piece",
    "box",
    "check",
    "decompose",
    "fracture",
    "read_mesh",
    "repair",
    "write_gltf",
    "write_obj",
]

Float64Array = npt.NDArray[np.float64]
Float32Array = npt.NDArray[np.float32]
UInt32Array = npt.NDArray[np.uint32]
Vector3 = Sequence[float] | Float64Array
Backend = Literal["fast", "corefine", "nef"]
Pattern = Literal["single", "shatter", "adaptive"]

__version__: str  # "MAJOR.MINOR.PATCH", as RUBBLE_VERSION_STRING in rubble/Version.hpp
INTERIOR_MATERIAL: int
"""Material id of faces created by a cut (the inside of an object)."""

class Error(RuntimeError):
    """A library error; str(error) is the library's message (file, line and field where known)."""

    code: str
    """The kind of failure: "io error", "parse error", "invalid input", "unsupported", "no intersection",
    "geometry failure" or "cancelled"."""

class Mesh:
    """A triangle mesh (a value: properties return copies)."""

    def __init__(
        self,
        vertices: npt.ArrayLike,
        triangles: npt.ArrayLike,
        *,
        materials: npt.ArrayLike | None = None,
        uvs: npt.ArrayLike | None = None,
        normals: npt.ArrayLike | None = None,
    ) -> None:
        """vertices (n, 3) numbers, triangles (m, 3) integers in 0..n-1, counter-clockwise seen from outside;
        optional per-triangle materials (m,), per-corner uvs (3m, 2) and normals (3m, 3). Raises ValueError for
        wrong shapes or indices or attributes beyond float32's range (they are stored in float32) and Error for
        non-finite coordinates or inconsistent attributes."""
    @property
    def vertices(self) -> Float64Array:
        """(n, 3) float64 positions."""
    @property
    def triangles(self) -> UInt32Array:
        """(m, 3) uint32 vertex indices."""
    @property
    def materials(self) -> UInt32Array | None:
        """(m,) uint32 material ids, or None; cut faces carry INTERIOR_MATERIAL."""
    @property
    def uvs(self) -> Float32Array | None:
        """(3m, 2) float32 texture coordinates per triangle corner, or None."""
    @property
    def normals(self) -> Float32Array | None:
        """(3m, 3) float32 normals per triangle corner, or None."""
    @property
    def vertex_count(self) -> int:
        """Number of vertices."""
    @property
    def triangle_count(self) -> int:
        """Number of triangles."""
    @property
    def volume(self) -> float:
        """Signed volume (positive for a closed, outward-oriented mesh)."""
    def hash(self) -> int:
        """A 64-bit content hash, stable across runs and platforms."""
    def __eq__(self, other: object) -> bool: ...

class MeshReport:
    """What check() found."""

    @property
    def valid(self) -> bool:
        """A valid closed solid: fracture() accepts it."""
    @property
    def closed(self) -> bool:
        """Every edge has exactly two triangles."""
    @property
    def manifold(self) -> bool:
        """Edges and vertices are manifold."""
    @property
    def oriented(self) -> bool:
        """Triangles are consistently oriented."""
    @property
    def outward(self) -> bool:
        """The signed volume is positive."""
    @property
    def boundary_edges(self) -> int:
        """Edges with one triangle (holes)."""
    @property
    def non_manifold_edges(self) -> int:
        """Edges with three or more triangles."""
    @property
    def degenerate_triangles(self) -> int:
        """Triangles of zero area."""
    @property
    def self_intersections(self) -> int:
        """Intersecting pairs of triangles."""
    @property
    def shells(self) -> int:
        """Connected components."""
    @property
    def volume(self) -> float:
        """Signed volume."""
    @property
    def center_of_mass(self) -> Float64Array:
        """(3,) centre of mass for uniform density."""
    @property
    def problems(self) -> list[str]:
        """One sentence per problem, most important first; empty for a valid mesh."""

class Piece(Mesh):
    """One piece of a fracture: a closed Mesh in the input's coordinates (cut faces carry INTERIOR_MATERIAL and
    planar uvs) with its mass properties, its cell and its convex collision parts."""

    @property
    def volume(self) -> float:
        """Volume."""
    @property
    def center_of_mass(self) -> Float64Array:
        """(3,) centre of mass."""
    @property
    def inertia(self) -> Float64Array:
        """(3, 3) inertia tensor about the centre of mass for density 1."""
    @property
    def principal_moments(self) -> Float64Array:
        """(3,) eigenvalues of inertia, ascending."""
    @property
    def principal_axes(self) -> Float64Array:
        """(3, 3) columns are the unit axes of principal_moments."""
    @property
    def cell(self) -> int:
        """-1: part of the damaged remainder; i >= 0: debris of cell i."""
    @property
    def convex_parts(self) -> list[Float64Array]:
        """Convex collision parts, each the (k, 3) corner points of its hull (empty without convex_parts)."""
    @property
    def concavity(self) -> float | None:
        """How far the convex parts stray from the piece's surface (one-sided Hausdorff distance, as a fraction
        of its bounding-box diagonal, as decompose's); None without convex_parts."""

def read_mesh(path: str | os.PathLike[str]) -> Mesh:
    """Reads .obj, .off, .stl, .ply, .3ds, .gltf or .glb; Error names the file and line."""

def write_obj(path: str | os.PathLike[str], mesh: Mesh) -> None:
    """Writes OBJ (and an MTL file next to it when the mesh has materials)."""

def write_gltf(
    path: str | os.PathLike[str], nodes: Sequence[tuple[str, Mesh, Sequence[Float64Array]]]
) -> None:
    """Writes (name, mesh, convex_parts) pieces as glTF: a node per piece at its centre of mass with mass
    properties in extras, each convex part (its corner points) as a '-convcolonly' child node."""

def box(lo: Vector3, hi: Vector3, subdivisions: int = 1) -> Mesh:
    """A closed box from lo to hi, each face split into subdivisions x subdivisions squares."""

def check(mesh: Mesh) -> MeshReport:
    """Checks whether a mesh is a valid closed solid."""

def repair(mesh: Mesh) -> Mesh:
    """A repaired copy (duplicate vertices, degenerate and duplicate triangles, orientation, holes whose boundary is
    a simple, nearly planar loop closed). check() the result: other holes stay open."""

def fracture(
    mesh: Mesh,
    *,
    point: Vector3,
    normal: Vector3 = (0.0, 1.0, 0.0),
    impulse: float = 1.0,
    cells: int = 1,
    seed: int = 1,
    backend: Backend = "fast",
    convex_parts: bool = True,
    max_parts: int = 24,
    pattern: Pattern | None = None,
    material: str | None = None,
    roughness: float | None = None,
    hurst: float | None = None,
    feature_size: float | None = None,
) -> list[Piece]:
    """Breaks a closed mesh at an impact (point and outward normal in the mesh's coordinates; bigger impulses cut
    bigger cells). cells=1 cuts the thesis's single Voronoi cell, cells>1 a shatter pattern of that many cells;
    pattern='adaptive' chips one cell on a weak hit and shatters into cells on one of 400 N s or more.
    The same seed gives the same pieces. With convex_parts, every piece gets convex collision parts (the input
    is decomposed into at most max_parts first). material ('concrete', 'brick', 'stone', 'wood', 'glass',
    'steel') cuts with that material's rough cut faces; roughness (amplitude), hurst and feature_size
    (fractions of the cell size) set them by hand, roughness=0 is flat (docs/roughness.md). Raises ValueError
    naming the parameter and its range for a non-finite point, a zero or non-finite normal, an impulse outside
    [0, 1e12], cells outside 1..1000 (refused, not clamped), a seed outside 0..2**64-1 and a bad roughness
    value; raises Error (e.g. "invalid input" for an open mesh,
    "no intersection" when the cells miss it)."""

def decompose(
    mesh: Mesh,
    *,
    max_parts: int = 24,
    concavity: float = 0.02,
    progress: Callable[[float], bool | None] | None = None,
    threads: int = 1,
) -> list[Float64Array]:
    """Convex parts of a closed mesh (at most max_parts), each the (k, 3) corner points of its hull.

    progress(fraction) is called between steps (non-decreasing, 1 last); returning False or raising cancels,
    as Ctrl-C does (KeyboardInterrupt). threads share the search; the parts do not depend on them."""
