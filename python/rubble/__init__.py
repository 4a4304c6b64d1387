"""Rubble: fracture closed meshes at an impact into pieces with mass properties and convex collision parts.

Meshes are numpy arrays in and out; library errors raise rubble.Error (a RuntimeError) with the library's message
and its error code (e.g. "invalid input"). Types: see __init__.pyi.
"""

from . import _rubble
from ._rubble import *  # noqa: F403 (the names are listed in __init__.pyi)

__all__ = [name for name in dir(_rubble) if not name.startswith("_")]
