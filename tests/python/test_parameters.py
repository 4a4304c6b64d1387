"""The Python face of the shared parameter table (tests/data/parameter_cases.tsv): rubble.fracture refuses
every out-of-range value with a ValueError carrying the table's message, and accepts the values marked ok."""

import math
import pathlib

import pytest

import rubble

TABLE = pathlib.Path(__file__).resolve().parents[1] / "data" / "parameter_cases.tsv"


def _rows():
    for line in TABLE.read_text().splitlines():
        if not line or line.startswith("#"):
            continue
        faces, name, value, message = line.split("\t")
        if "py" in faces.split(","):
            yield pytest.param(name, value, message, id=f"{name}={value}")


def _value(text):
    """A table value as Python passes it: ints stay ints (any size), other numbers are floats."""
    parts = [int(p) if p.lstrip("-").isdigit() else float(p) for p in text.split(",")]
    return parts[0] if len(parts) == 1 else tuple(parts)


@pytest.mark.parametrize("name, value, message", list(_rows()))
def test_parameter_table(name, value, message):
    args = dict(point=(0.5, 0.5, 1.0), normal=(0, 0, 1), impulse=100, convex_parts=False)
    if name == "cells":
        args["pattern"] = "shatter"
    if name in ("hurst", "feature_size"):
        args["roughness"] = 0.1
    args[name] = _value(value)
    cube = rubble.box((0, 0, 0), (1, 1, 1))
    if message == "ok":
        assert len(rubble.fracture(cube, **args)) >= 1
    else:
        with pytest.raises(ValueError) as info:
            rubble.fracture(cube, **args)
        assert message in str(info.value)


def test_table_covers_every_python_parameter():
    names = {row.values[0] for row in _rows()}
    assert names == {"impulse", "normal", "point", "cells", "seed", "roughness", "hurst", "feature_size", "max_parts"}


def test_a_non_number_is_refused_with_the_range():
    cube = rubble.box((0, 0, 0), (1, 1, 1))
    with pytest.raises(ValueError, match=r"seed must be a whole number in \[0, 18446744073709551615\], got 'abc'"):
        rubble.fracture(cube, point=(0.5, 0.5, 1), seed="abc")
    with pytest.raises(ValueError, match="impulse must be a finite number"):
        rubble.fracture(cube, point=(0.5, 0.5, 1), impulse=math.inf)
