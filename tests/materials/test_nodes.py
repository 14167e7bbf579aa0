"""Node programs without Blender: Cycles' hash and noise test vectors, the safe math of the converter nodes, colour
space round trips, image lookups under every extension mode, and a program's evaluation over a batch of hits."""
import numpy as np
import pytest

from restir_engine.core.materials.nodes import hashing, noise, ops_math, ops_texture
from restir_engine.core.materials.nodes.attributes import HitAttributes
from restir_engine.core.materials.nodes.program import Program, evaluate_constant
from restir_engine.core.scene import TriangleSet

F = np.float32


def test_jenkins_hash_matches_cycles_test_vectors():
    assert int(hashing.hash_uint(0)) == 2501500005
    assert int(hashing.hash_uint(1, 2)) == 272092061
    assert int(hashing.hash_uint(1, 2, 3)) == 3100736010
    assert int(hashing.hash_uint(1, 2, 3, 4)) == 92593857
    assert float(hashing.hash_floats(0.5, 1.5, 2.5)) == pytest.approx(0.204965711, abs=1e-8)


def test_perlin_matches_cycles_test_vectors():
    assert float(noise.perlin(F(0.3))) == pytest.approx(1.39230001, abs=1e-6)
    assert float(noise.perlin(F(0.3), F(1.7))) == pytest.approx(-0.976571858, abs=1e-6)
    assert float(noise.perlin(F(0.3), F(1.7), F(-2.2))) == pytest.approx(0.264878124, abs=1e-6)
    assert float(noise.perlin(F(0.3), F(1.7), F(-2.2), F(0.9))) == pytest.approx(-0.359881788, abs=1e-6)


def test_noise_offsets_match_cycles():
    expected = {0: (186.031281, 114.955956, 154.44751, 142.504913),
                4: (155.580917, 177.154633, 138.14003, 180.18573)}
    for seed, values in expected.items():
        np.testing.assert_allclose([float(v) for v in noise.offset(seed, 4)], values, atol=2e-4)


def test_fbm_is_a_normalized_sum_and_detail_fraction_blends():
    p = [np.linspace(-3, 3, 101, dtype=F) for _ in range(3)]
    one = noise.fractal("FBM", p, 0.0, 0.5, 2.0, 0, 0, True)
    np.testing.assert_allclose(one, 0.5 * noise.snoise(*p) + 0.5, atol=1e-6)
    two = noise.fractal("FBM", p, 1.0, 0.5, 2.0, 0, 0, True)
    half = noise.fractal("FBM", p, 0.5, 0.5, 2.0, 0, 0, True)
    np.testing.assert_allclose(half, 0.5 * (one + two), atol=1e-6)


@pytest.mark.parametrize("kind", ["FBM", "MULTIFRACTAL", "HETERO_TERRAIN", "HYBRID_MULTIFRACTAL",
                                  "RIDGED_MULTIFRACTAL"])
def test_every_noise_type_at_a_constant_point_is_its_value_in_a_batch(kind):
    """A Noise Texture fed constant coordinates is folded at export (0-d arrays); every type gives there what it
    gives in a batch (the hybrid and ridged types once recursed without end on 0-d points)."""
    p = [F(0.3), F(-1.7), F(2.2)]
    at = noise.fractal(kind, p, 3.5, 0.6, 2.0, 0.4, 1.1, True)
    batch = noise.fractal(kind, [np.full(4, v, F) for v in p], 3.5, 0.6, 2.0, 0.4, 1.1, True)
    assert np.ndim(at) == 0
    np.testing.assert_allclose(batch, at, rtol=1e-6)  # numpy 1.x computes 0-d float32 arithmetic in float64


def test_safe_math_follows_cycles():
    m = ops_math.MATH
    a, b, c = F(np.array([-2.0, 0.0, 3.0])), F(np.array([0.0, 0.0, 2.0])), F(np.array([0.1, 0.1, 0.1]))
    np.testing.assert_array_equal(m["DIVIDE"](a, b, c), [0, 0, 1.5])
    np.testing.assert_array_equal(ops_math._pow(F([-2.0, -2.0, 0.0]), F([0.5, 2.0, -1.0])), [0, 4, 0])
    np.testing.assert_allclose(m["WRAP"](F([2.5, -0.25]), F(1.0), F(0.0)), [0.5, 0.75])
    np.testing.assert_allclose(m["PINGPONG"](F([0.25, 1.25, 2.5]), F(1.0), F(0)), [0.25, 0.75, 0.5])
    np.testing.assert_array_equal(m["MODULO"](F([-3.0, 3.0]), F([2.0, 0.0]), F(0)), [-1, 0])
    np.testing.assert_array_equal(m["FLOORED_MODULO"](F([-3.0]), F([2.0]), F(0)), [1])
    assert float(m["SMOOTH_MIN"](F(1.0), F(1.0), F(0.5))) == pytest.approx(1 - 0.5 / 6)


def test_hsv_and_hsl_round_trip():
    rng = np.random.default_rng(1)
    c = rng.random((3, 50), dtype=np.float32)
    np.testing.assert_allclose(ops_math.hsv_to_rgb(ops_math.rgb_to_hsv(c)), c, atol=1e-5)
    np.testing.assert_allclose(ops_math.hsl_to_rgb(ops_math.rgb_to_hsl(c)), c, atol=1e-5)


def test_image_extension_modes():
    img = np.arange(4, dtype=F).reshape(1, 4, 1) * np.ones((2, 1, 1), F)  # columns 0..3
    u = F(np.array([-0.125, 1.125, 0.375]))
    v = F(np.full(3, 0.5))
    near = {ext: ops_texture.sample_image(img, u, v, "Closest", ext)[:, 0] for ext in
            ("REPEAT", "EXTEND", "CLIP", "MIRROR")}
    np.testing.assert_array_equal(near["REPEAT"], [3, 0, 1])
    np.testing.assert_array_equal(near["EXTEND"], [0, 3, 1])
    np.testing.assert_array_equal(near["CLIP"], [0, 0, 1])
    np.testing.assert_array_equal(near["MIRROR"], [0, 3, 1])
    flat = np.full((4, 4, 3), 0.7, F)
    for interp in ("Linear", "Cubic"):
        got = ops_texture.sample_image(flat, F(np.linspace(0, 1, 9)), F(np.linspace(1, 0, 9)), interp, "REPEAT")
        np.testing.assert_allclose(got, 0.7, atol=1e-6)


def test_program_evaluates_per_hit_and_constants_broadcast():
    verts = np.array([[[0, 0, 0], [1, 0, 0], [0, 1, 0]]], F)
    tris = TriangleSet(verts, np.tile(F([0, 0, 1]), (1, 3, 1)), np.zeros(1, np.int32))
    attrs = HitAttributes(tris, np.zeros(3, int), F([0.1, 0.5, 0.2]), F([0.2, 0.1, 0.7]), [])
    # x of the position, times 2, into a colour; and a constant colour output
    prog = Program(ops=[("attribute", (0,), (), {"name": "position"}), ("separate", (1, 2, 3), (0,), {}),
                        ("math", (5,), (1, 4, 4), {"op": "MULTIPLY"})],
                   consts={4: F(2.0), 6: F([[0.1], [0.2], [0.3]])},
                   outputs={"roughness": (5, "float"), "base_color": (6, "rgb")}, vectors=(0, 6))
    out = prog.run(attrs)
    np.testing.assert_allclose(out["roughness"], [0.2, 1.0, 0.4], atol=1e-6)
    assert out["base_color"].shape == (3, 3)
    assert float(evaluate_constant("math", {"op": "ADD"}, F(1), F(2), F(0))) == 3.0


def test_wireframe_marks_points_within_half_the_size_of_an_edge_line():
    """A right triangle with legs of 2 along x and y (edges y = 0, x = 0 and x + y = 2): Fac is 1 exactly where the
    distance to the nearest edge line is below half of Size (world units), or of Size times the footprint with Pixel
    Size; 0 in a world (no edges)."""
    from restir_engine.core.materials.nodes.attributes import DirectionAttributes
    verts = np.array([[[0, 0, 0], [2, 0, 0], [0, 2, 0]]], F)
    tris = TriangleSet(verts, np.tile(F([0, 0, 1]), (1, 3, 1)), np.zeros(1, np.int32))
    # points (x, y) = 2 (b1, b2): distances to the nearest edge 0.038, 0.06, 0.104 (y), 0.09 (x), 0.5 (centre-ish),
    # 0.0354 from the hypotenuse
    b1 = F([0.5, 0.5, 0.5, 0.045, 0.3, 0.475])
    b2 = F([0.019, 0.03, 0.052, 0.5, 0.25, 0.5])
    dist = np.minimum(np.minimum(2 * b1, 2 * b2), (2 - 2 * b1 - 2 * b2) / np.sqrt(2))
    attrs = HitAttributes(tris, np.zeros(len(b1), int), b1, b2, [], footprint=F([0.01] * len(b1)))
    for size, pixel in ((0.1, False), (0.2, False), (10.0, True), (8.0, True)):
        half = 0.5 * size * (0.01 if pixel else 1.0)
        got = ops_texture.wireframe(attrs, {"pixel_size": pixel}, F(size))
        np.testing.assert_array_equal(got, (dist < half).astype(F), err_msg=f"size {size} pixel {pixel}")
        assert 0 < got.sum() < len(b1)
    world = DirectionAttributes(np.tile(F([[0], [0], [1]]), (1, 4)), [])
    np.testing.assert_array_equal(ops_texture.wireframe(world, {}, F(1.0)), np.zeros(4, F))


@pytest.mark.parametrize("dims", [2, 3])
def test_gabor_is_pointwise_across_chunks_and_constants(dims):
    """The Gabor Texture's value at a point does not depend on the batch around it (chunks of gabor.CHUNK points, a
    constant folded at export); its patterns against Cycles: tests/cycles test_node_patterns_match_cycles[gabor]."""
    from restir_engine.core.materials.nodes import gabor
    from restir_engine.core.materials.nodes.program import evaluate_constant
    rng = np.random.default_rng(9)
    n = gabor.CHUNK + 37
    vec = rng.uniform(-3, 3, (3, n)).astype(F)
    params = {"dims": dims}
    args = (F(4.0), F(2.0), F(0.3), F(0.7), np.array([[0.3], [0.8], [0.1]], F))

    class Batch:
        def __len__(self):
            return n
    whole = gabor.gabor_texture(Batch(), params, vec, *args)
    assert all(np.isfinite(o).all() for o in whole) and whole[0].std() > 0.05
    for k in (5, gabor.CHUNK + 10):  # in the first chunk and in the second
        one = evaluate_constant("gabor_texture", params, vec[:, k:k + 1], *args)
        np.testing.assert_allclose([float(o) for o in one], [o[k] for o in whole], rtol=1e-6, atol=1e-7)
