"""Rubble: fracture closed meshes at an impact into pieces with mass properties and convex collision parts.

Meshes are numpy arrays in and out; library errors raise rubble.Error (a RuntimeError) with the library's message
and its error code (e.g. "invalid input"); out-of-range parameters raise ValueError naming the parameter and its
range. Types: see __init__.pyi.
"""

import sys

from . import _build


def _needs(what, error):
    """ImportError saying what is missing, which interpreter runs and which one the module is built for."""
    running = "%s (Python %d.%d)" % (sys.executable or "this interpreter", *sys.version_info[:2])
    return ImportError(
        "rubble needs %s, but %s cannot import it (%s). The module is built for %s (Python %s) with Debian's "
        "python3-numpy: run that interpreter (e.g. `%s`, or `pyenv shell system` when pyenv's python comes first "
        "on PATH), or rebuild Rubble with -DRUBBLE_PYTHON=%s and numpy installed for it."
        % (what, running, error, _build.PYTHON, _build.PYTHON_VERSION, _build.PYTHON, sys.executable)
    )


try:
    import numpy  # noqa: F401 (checked here so that a missing numpy fails at import, not at the first array)
except ImportError as e:
    raise _needs("numpy", e) from e
try:
    from . import _rubble
except ImportError as e:
    raise _needs("its extension module _rubble", e) from e
from ._rubble import *  # noqa: E402,F403 (the names are listed in __init__.pyi)

__version__ = _rubble.__version__
__all__ = [name for name in dir(_rubble) if not name.startswith("_")]
