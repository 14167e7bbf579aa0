"""IES profiles (core/lights/ies.py): LM-63 parsing with every TILT form, the photometric types' frames and the
symmetries mirrored out to 0-360°, the candela conversion, and lookups (interpolation through the table's points,
zero outside its range, the value Cycles gives an unreadable profile). Against Cycles' images:
tests/cycles/test_lamp_textures_cycles.py::test_ies_lamps_match_cycles."""
import numpy as np
import pytest

from restir_engine.core.lights import ies


def _text(v, h, values, kind=1, tilt="TILT=NONE", multiplier=1.0, ballast=(1.0, 1.0)):
    rows = ["IESNA:LM-63-2002", "[TEST] probe", tilt, f"1 1000 {multiplier} {len(v)} {len(h)} {kind} 2 0 0 0",
            f"{ballast[0]} {ballast[1]} 50", " ".join(map(str, v)), " ".join(map(str, h))]
    rows += [" ".join(map(str, col)) for col in values]
    return "\n".join(rows) + "\n"


def _towards(v_deg, h_deg):
    """Unit directions (3, n) at vertical angle v (0 = -Z) and horizontal angle h (the node's atan2(x, y) + π)."""
    v, h = np.radians(v_deg), np.radians(h_deg) - np.pi
    return np.stack([np.sin(v) * np.sin(h), np.sin(v) * np.cos(h), -np.cos(v)]).astype(np.float32)


def test_table_points_units_and_range():
    v, h = [0, 30, 60, 90], [0, 90, 180, 270, 360]
    vals = [[100 + 10 * i + j for j in range(4)] for i in range(5)]
    t = ies.parse(_text(v, h, vals, multiplier=2.0, ballast=(0.5, 1.5)))
    assert np.allclose(np.degrees(t.h), h) and np.allclose(np.degrees(t.v), v, atol=1e-5)
    scale = 2.0 * 0.5 * 1.5 * 4 * np.pi / 177.83
    got = ies.evaluate(t, _towards(np.array([0.0, 30.0, 60.0]), np.array([90.0, 180.0, 270.0])))
    np.testing.assert_allclose(got, np.array([120, 121, 132]) * scale, rtol=1e-5)  # straight down: atan2(0, 0) + π
    # between points: the Catmull-Rom cubic (linear data stays linear), zero past the table's last angle
    mid = ies.evaluate(t, _towards(np.array([45.0]), np.array([90.0])))
    np.testing.assert_allclose(mid, 111.5 * scale, rtol=1e-4)
    assert ies.evaluate(t, _towards(np.array([120.0]), np.array([90.0])))[0] == 0.0
    assert np.all(ies.evaluate(None, _towards(np.array([10.0]), np.array([5.0]))) == ies.UNREADABLE)


def test_type_c_symmetries_are_mirrored_to_a_full_circle():
    v = [0, 45, 90]
    one = ies.parse(_text(v, [0], [[10, 20, 30]]))
    assert np.allclose(np.degrees(one.h), [0, 360]) and np.allclose(one.values[0], one.values[1])
    quadrant = ies.parse(_text(v, [0, 45, 90], [[1, 2, 3], [4, 5, 6], [7, 8, 9]]))
    assert np.allclose(np.degrees(quadrant.h), [0, 45, 90, 135, 180, 225, 270, 315, 360], atol=1e-4)
    np.testing.assert_allclose(quadrant.values[:, 0] / quadrant.values[0, 0], [1, 4, 7, 4, 1, 4, 7, 4, 1])
    shifted = ies.parse(_text(v, [90, 180, 270], [[1, 2, 3], [4, 5, 6], [7, 8, 9]]))
    assert np.allclose(np.degrees(shifted.h), [0, 90, 180, 270, 360], atol=1e-4)
    short = ies.parse(_text(v, [0, 90, 180, 270], [[1, 1, 1], [2, 2, 2], [3, 3, 3], [4, 4, 4]]))
    assert np.allclose(np.degrees(short.h), [0, 90, 180, 270, 360], atol=1e-4)  # closed with its 0° column


def test_types_a_and_b_and_tilt_blocks():
    a = ies.parse(_text([-90, 0, 90], [0, 45, 90], [[1, 2, 3], [4, 5, 6], [7, 8, 9]], kind=3))
    assert np.allclose(np.degrees(a.v), [0, 90, 180], atol=1e-4)
    assert np.allclose(np.degrees(a.h), [90, 135, 180, 225, 270], atol=1e-4)
    b = ies.parse(_text([0, 45, 90], [-90, 0, 90], [[1, 2, 3], [4, 5, 6], [7, 8, 9]], kind=2))
    assert np.allclose(np.degrees(b.h), [0, 45, 90, 135, 180], atol=1e-4)
    assert np.allclose(np.degrees(b.v), [0, 90, 180], atol=1e-4)
    tilted = ies.parse(_text([0, 90], [0], [[5, 6]], tilt="TILT=INCLUDE\n1\n3\n0 45 90\n1 0.9 0.8"))
    plain = ies.parse(_text([0, 90], [0], [[5, 6]]))
    np.testing.assert_allclose(tilted.values, plain.values)
    named = ies.parse(_text([0, 90], [0], [[5, 6]], tilt="TILT=lamp.tlt"))
    np.testing.assert_allclose(named.values, plain.values)


@pytest.mark.parametrize("text", ["", "no tilt line", "TILT=NONE\n1 1000 1 2 1 7 2 0 0 0 1 1 50 0 90 0 1 2",
                                  "TILT=NONE\n1 1000 1 3 1 1 2 0 0 0 1 1 50 0 45"])
def test_unreadable_texts_are_refused(text):
    with pytest.raises(ies.IesError):
        ies.parse(text)
