"""`import rubble` fails early and says why: without numpy it raises ImportError naming numpy, the interpreter
running and the one the module is built for; rubble.__version__ is the C++ headers' version."""

import pathlib
import re
import subprocess
import sys

import rubble

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_version_is_the_headers_version():
    header = (ROOT / "include" / "rubble" / "core" / "Version.hpp").read_text()
    parts = [re.search(r"#define RUBBLE_VERSION_%s (\d+)" % p, header).group(1) for p in ("MAJOR", "MINOR", "PATCH")]
    assert rubble.__version__ == ".".join(parts)


def test_without_numpy_import_fails_at_once_naming_the_interpreter():
    # numpy made unimportable, as under a pyenv python without it.
    code = "import sys; sys.modules['numpy'] = None\nimport rubble"
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=False)
    assert run.returncode != 0
    assert "ImportError" in run.stderr, run.stderr
    message = run.stderr.strip().splitlines()[-1]
    assert "rubble needs numpy" in message, message
    assert rubble._build.PYTHON in message and sys.executable in message, message
