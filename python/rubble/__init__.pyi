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
    "Structure",
    "StructureBreak",
    "StructureCollapse",
    "StructureStep",
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

class StructureBreak:
    """A bond that broke: where, how large, the force it carried and the two materials."""

    @property
    def step(self) -> int:
        """The step it broke in (1 for the first)."""
    @property
    def a(self) -> int:
        """The first body it joined (a < b)."""
    @property
    def b(self) -> int:
        """The second body."""
    @property
    def position(self) -> Float64Array:
        """Interface centroid (world)."""
    @property
    def normal(self) -> Float64Array:
        """Interface normal, from a to b."""
    @property
    def area(self) -> float:
        """Interface area (m^2)."""
    @property
    def force(self) -> Float64Array:
        """The force it carried the moment it broke, b on a (N)."""
    @property
    def utilisation(self) -> float:
        """Its largest stress over its limit (> 1 when its load broke it)."""
    @property
    def damaged(self) -> bool:
        """Impact damage broke it (health 0), not its load."""
    @property
    def material_a(self) -> str:
        """a's material preset."""
    @property
    def material_b(self) -> str:
        """b's material preset."""

class StructureCollapse:
    """A body that lost its support (it left the structure; the caller lets it fall)."""

    @property
    def step(self) -> int:
        """The step it fell in."""
    @property
    def body(self) -> int:
        """Its id."""
    @property
    def position(self) -> Float64Array:
        """Its centre of mass (world)."""
    @property
    def volume(self) -> float:
        """m^3."""
    @property
    def mass(self) -> float:
        """kg."""
    @property
    def material(self) -> str:
        """Its material preset."""

class StructureStep:
    """What one Structure.step did."""

    @property
    def breaks(self) -> list[StructureBreak]:
        """Bonds broken, in the order they broke."""
    @property
    def collapses(self) -> list[StructureCollapse]:
        """Bodies no bond holds up any more, ascending id."""
    @property
    def residual(self) -> float:
        """Relative residual of the step's last solve."""

class Structure:
    """Static bodies bonded where they touch, without a physics engine: each step solves them under gravity,
    loads and impact damage and returns the bonds that broke and the bodies that fell (docs/structure.md)."""

    def __init__(
        self,
        *,
        bearing_friction: float = 0.6,
        converged: bool = True,
        damage_radius: float = 1.0,
        damage_per_impulse: float = 1e-4,
    ) -> None:
        """bearing_friction > 0: bodies rest on each other with this friction, 0: welded; converged: solve to
        a relative residual of 1e-3 (else a sweep budget). Raises ValueError for a negative setting."""
    def add(
        self,
        id: int,
        mesh: Mesh,
        *,
        material: str = "",
        root: bool = False,
        position: Vector3 = (0.0, 0.0, 0.0),
        rotation: Float64Array | Sequence[Sequence[float]] | None = None,
    ) -> None:
        """Adds (or replaces) body id > 0: the mesh's convex parts placed at position and rotation, of a
        material preset ("": concrete); a root is held. Raises Error ("invalid input") for an unknown
        material, an open mesh or a rotation that is none, changing nothing."""
    def remove(self, id: int) -> bool: ...
    def __contains__(self, id: int) -> bool: ...
    def __len__(self) -> int: ...
    @property
    def bond_count(self) -> int:
        """Intact bonds."""
    def add_load(self, id: int, force: Vector3, point: Vector3) -> None:
        """A force (N) at a world point on a body for the next step."""
    def damage(self, point: Vector3, impulse: float) -> None:
        """Weakens the bonds near a hit (impulse in N s) at the next step."""
    def step(self, gravity: Vector3 = (0.0, -9.81, 0.0)) -> StructureStep:
        """Solves, breaks overstressed bonds and lets go of what they held."""

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
