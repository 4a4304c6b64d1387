"""The Python face of the structure without an engine (rubble.Structure): a cantilever stands or breaks as its
root bending stress 3 rho g L^2 / h says, breaks and collapses come back as records, bad input raises."""

import numpy as np
import pytest

import rubble

H, B = 0.2, 1.5  # the slab's depth and width


def cantilever(span, material="concrete"):
    """A slab of `span` welded to a held wall at x = 0, both of one material, its top at y = 2.2."""
    s = rubble.Structure(bearing_friction=0)
    s.add(1, rubble.box((-1, 0, -2), (0, 4, 2)), material=material, root=True)
    s.add(2, rubble.box((0, 2, -B / 2), (span, 2 + H, B / 2)), material=material)
    return s


def test_a_cantilever_stands_below_the_tensile_limit_and_breaks_above_it():
    concrete_limit = 2.9e6
    assert 3 * 2400 * 9.81 * 2.5**2 / H < concrete_limit < 3 * 2400 * 9.81 * 3.5**2 / H
    standing = cantilever(2.5)
    assert len(standing) == 2 and standing.bond_count == 1 and 2 in standing
    step = standing.step()
    assert step.breaks == [] and step.collapses == [] and step.residual <= 1e-3

    failing = cantilever(3.5)
    step = failing.step()
    (k,) = step.breaks
    assert (k.step, k.a, k.b, k.damaged) == (1, 1, 2, False)
    np.testing.assert_allclose(k.position, (0, 2.1, 0), atol=1e-9)
    assert k.area == pytest.approx(B * H) and k.utilisation > 1
    assert (k.material_a, k.material_b) == ("concrete", "concrete")
    (c,) = step.collapses
    assert c.body == 2 and c.material == "concrete"
    assert c.volume == pytest.approx(3.5 * B * H) and c.mass == pytest.approx(2400 * c.volume)
    np.testing.assert_allclose(c.position, (1.75, 2.1, 0), atol=1e-9)
    assert 2 not in failing and len(failing) == 1 and failing.bond_count == 0


def test_steel_stands_until_a_tip_load_passes_its_limit():
    s = cantilever(3.5, "steel")
    assert s.step().breaks == []
    # M c / I at the root: F L (h / 2) / (b h^3 / 12) = 350 F Pa/N, plus the slab's own 14 MPa
    s.add_load(2, (0, -5e5, 0), (3.5, 2.2, 0))  # 189 MPa against 355
    assert s.step().breaks == []
    s.add_load(2, (0, -1.2e6, 0), (3.5, 2.2, 0))  # 434 MPa
    step = s.step()
    assert len(step.breaks) == 1 and [c.body for c in step.collapses] == [2]


def test_a_placed_slab_bonds_where_it_lands_and_hits_near_its_root_break_it():
    half_turn = np.diag([-1.0, 1.0, -1.0])  # about y: the slab now sticks out of the wall's -x face at x = -1
    s = rubble.Structure(bearing_friction=0)
    s.add(1, rubble.box((-1, 0, -2), (0, 4, 2)), root=True)
    s.add(2, rubble.box((0, 2, -B / 2), (2.5, 2 + H, B / 2)), rotation=half_turn, position=(-1, 0, 0))
    assert s.bond_count == 1 and s.step().breaks == []
    hits = 0
    while 2 in s and hits < 100:
        s.damage((-1.05, 2.1, 0), 2000)
        step = s.step()
        hits += 1
    assert 1 < hits < 100
    (k,) = step.breaks
    assert not k.damaged and k.utilisation > 1  # the weakened section overstressed by the slab's weight
    np.testing.assert_allclose(k.position, (-1, 2.1, 0), atol=1e-9)
    np.testing.assert_allclose(step.collapses[0].position, (-2.25, 2.1, 0), atol=1e-9)


def test_bad_input_raises_and_changes_nothing():
    s = cantilever(2.5)
    cube = rubble.box((3, 0, 0), (4, 1, 1))
    with pytest.raises(rubble.Error, match="unknown material 'Wood'") as e:
        s.add(3, cube, material="Wood")
    assert e.value.code == "invalid input"
    with pytest.raises(rubble.Error, match="not a rigid motion"):
        s.add(3, cube, rotation=[[1, 0, 0], [0, 1, 0], [0, 0, 2]])
    with pytest.raises(ValueError, match="rotation"):
        s.add(3, cube, rotation=[1, 0, 0])
    with pytest.raises(ValueError, match="position"):
        s.add(3, cube, position=(0, float("nan"), 0))
    with pytest.raises(ValueError, match="no body 3"):
        s.add_load(3, (0, -1, 0), (0, 0, 0))
    with pytest.raises(ValueError, match="impulse"):
        s.damage((0, 0, 0), -1)
    with pytest.raises(ValueError, match="bearing_friction"):
        rubble.Structure(bearing_friction=-1)
    assert 3 not in s and len(s) == 2 and s.bond_count == 1
    assert not s.remove(3) and s.remove(2) and s.bond_count == 0
