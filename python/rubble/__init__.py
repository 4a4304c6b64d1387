"""Rubble: fracture closed meshes at an impact into pieces with mass properties and convex collision parts.

Meshes are numpy arrays in and out; library errors raise rubble.Error (a RuntimeError) with the library's message
and its error code (e.g. "invalid input"). Types: see __init__.pyi.
"""

from ._rubble import (
    INTERIOR_MATERIAL,
    Error,
    Mesh,
    MeshReport,
    Piece,
    box,
    check,
    decompose,
    fracture,
    read_mesh,
    repair,
    write_obj,
)

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
    "write_obj",
]
